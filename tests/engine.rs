//! The fast path and the paper-literal path against a brute-force
//! transcription of SPEC, on seeded random grids.

use kneeform::{
    Algorithm, EngineOptions, Footprint, GridFootprint, HeightGrid, KneeForm, colliding_masks,
};

use crate::util::{SEEDS, brute_force, mask_diff, random_grid};

/// A knee-form smaller than the test grids.
const SMALL: KneeForm = KneeForm {
    triangle_side: 40.0,
    radius: 12.0,
    thickness: 120.0,
};

const ANGLES: [f64; 5] = [-30.0, -7.0, 0.0, 12.0, 30.0];

fn run(
    grid: &HeightGrid,
    knee: &KneeForm,
    angles: &[f64],
    algorithm: Algorithm,
    eps: f64,
) -> Vec<kneeform::AngleMask> {
    let footprints: Vec<GridFootprint> = angles
        .iter()
        .map(|&a| GridFootprint::new(&Footprint::new(knee, a), a, grid.spec.pitch))
        .collect();
    let options = EngineOptions {
        eps,
        algorithm,
        start_rows: None,
    };
    colliding_masks(grid, &footprints, &options, &|| {})
}

/// Both implementations equal brute force, mask and placed count, for each
/// grid shape, seed, angle and tolerance.
fn check_against_brute_force(nx: usize, nz: usize, pitch: f64, knee: &KneeForm, eps: f64) {
    let mut collisions = 0;
    for (s, &seed) in SEEDS.iter().enumerate() {
        let grid = random_grid(seed ^ pitch.to_bits(), nx, nz, pitch);
        let fast = run(&grid, knee, &ANGLES, Algorithm::Fast, eps);
        let paper = run(&grid, knee, &ANGLES, Algorithm::Paper, eps);
        for (k, &angle) in ANGLES.iter().enumerate() {
            let (want, placed) = brute_force(&grid, knee, angle, eps);
            let what = format!("seed #{s}, {nx}x{nz} at p={pitch}, angle {angle}, eps {eps}");
            assert_eq!(
                fast[k].mask,
                want,
                "fast vs brute force, {what}: {}",
                mask_diff(&grid, &fast[k].mask, &want)
            );
            assert_eq!(
                paper[k].mask,
                want,
                "paper vs brute force, {what}: {}",
                mask_diff(&grid, &paper[k].mask, &want)
            );
            assert_eq!(fast[k].placed, placed, "{what}");
            assert_eq!(paper[k].placed, placed, "{what}");
            collisions += fast[k].colliding;
            eprintln!("{what}: {} colliding, {placed} placed", fast[k].colliding);
        }
    }
    // The grids are built to make the knee-form strike things.
    assert!(
        collisions > 0,
        "no collision at all: the comparison proved nothing"
    );
}

#[test]
fn fast_and_paper_equal_brute_force_off_node_boundaries() {
    check_against_brute_force(60, 45, 5.3, &KneeForm::default(), 1e-3);
    check_against_brute_force(45, 40, 7.7, &KneeForm::default(), 1e-3);
}

#[test]
fn fast_and_paper_equal_brute_force_with_boundaries_on_nodes() {
    // a(0) = -60 mm is a multiple of these pitches: footprint boundaries fall
    // exactly on nodes.
    check_against_brute_force(50, 40, 4.0, &KneeForm::default(), 1e-3);
    check_against_brute_force(60, 30, 2.0, &KneeForm::default(), 1e-3);
    // a(0) = -12 mm for this one.
    check_against_brute_force(50, 30, 1.0, &SMALL, 1e-3);
}

#[test]
fn fast_and_paper_equal_brute_force_at_an_exact_tolerance() {
    // Heights are multiples of 0.5 mm: with eps = 0.5 some nodes sit exactly
    // at the tolerance and must not collide.
    check_against_brute_force(50, 40, 4.0, &KneeForm::default(), 0.5);
}

#[test]
fn fast_and_paper_equal_brute_force_for_a_small_knee_form() {
    // A knee-form smaller than the grid, so that many starts are interior
    // and many slides run off the -x edge.
    check_against_brute_force(60, 40, 2.0, &SMALL, 1e-3);
    check_against_brute_force(50, 40, 3.3, &SMALL, 1e-3);
}
