//! The fast path and the paper-literal path against a brute-force
//! transcription of SPEC, on seeded random grids.

use kneeform::strike::RateEstimate;
use kneeform::{
    Algorithm, EngineOptions, Footprint, GridFootprint, GridSpec, HeightGrid, KneeForm, StrikeRule,
    colliding_masks,
};

use crate::util::{
    BruteRule, SEEDS, brute_force_rules, distance_to_triangle, mask_diff, random_grid_quantised,
};

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
    rule: StrikeRule,
) -> Vec<kneeform::AngleMask> {
    let footprints: Vec<GridFootprint> = angles
        .iter()
        .map(|&a| GridFootprint::new(knee, a, &grid.spec))
        .collect();
    let options = EngineOptions {
        rule,
        algorithm,
        start_rows: None,
        probes: Vec::new(),
    };
    colliding_masks(grid, &footprints, &options, &|| {})
}

/// The deflection thresholds SPEC asks the comparison for: the paper's
/// literal rule (0), the default (0.5 degrees) and a steep one (3 degrees).
const DEFLECTIONS_DEG: [f64; 3] = [0.0, 0.5, 3.0];

/// Both implementations equal brute force, mask and placed count, for each
/// grid shape, seed, angle and deflection threshold (rounding tolerance
/// SPEC's default).
fn check_against_brute_force(nx: usize, nz: usize, pitch: f64, knee: &KneeForm) -> Vec<usize> {
    check_rules(nx, nz, pitch, knee, &default_rules(pitch))
}

/// SPEC's three thresholds with the default rounding tolerance, under the
/// x-slope rule and the window rule, the window from below one pitch
/// (0.6 p) through SPEC's default (5 mm) to many pitches (4.5 p).
fn default_rules(pitch: f64) -> Vec<StrikeRule> {
    let x_slope = DEFLECTIONS_DEG
        .map(|d| StrikeRule::new(d, StrikeRule::DEFAULT_E0).with_rate(RateEstimate::XSlope));
    let windows = [0.6 * pitch, StrikeRule::DEFAULT_WINDOW_MM, 4.5 * pitch];
    let window = DEFLECTIONS_DEG
        .into_iter()
        .flat_map(|d| windows.map(|w| StrikeRule::new(d, StrikeRule::DEFAULT_E0).with_window(w)));
    x_slope.into_iter().chain(window).collect()
}

/// Both implementations equal brute force under each of `rules`, on
/// coarse heights (0.5 mm: exact ties in height and at the thresholds) and
/// fine, gentle ones (rises of hundredths of a mm: rates on both sides of a
/// small threshold).
fn check_rules(
    nx: usize,
    nz: usize,
    pitch: f64,
    knee: &KneeForm,
    rules: &[StrikeRule],
) -> Vec<usize> {
    let coarse = SEEDS
        .iter()
        .map(|&seed| random_grid_quantised(seed ^ pitch.to_bits(), nx, nz, pitch, 0.5));
    let fine = SEEDS[..2]
        .iter()
        .map(|&seed| random_grid_quantised(seed ^ pitch.to_bits(), nx, nz, pitch, 0.001));
    let pairs: Vec<BruteRule> = rules
        .iter()
        .map(|r| (r.e0, r.sigma, r.window_mm()))
        .collect();
    let mut collisions = vec![0; rules.len()];
    let mut contacts_not_struck = vec![0; rules.len()];
    for (s, grid) in coarse.chain(fine).enumerate() {
        let any_rise = run(
            &grid,
            knee,
            &ANGLES,
            Algorithm::Fast,
            StrikeRule::new(0.0, StrikeRule::DEFAULT_E0),
        );
        let brute: Vec<(Vec<Vec<u8>>, usize)> = ANGLES
            .iter()
            .map(|&a| brute_force_rules(&grid, knee, a, &pairs))
            .collect();
        for (r, &rule) in rules.iter().enumerate() {
            let fast = run(&grid, knee, &ANGLES, Algorithm::Fast, rule);
            let paper = run(&grid, knee, &ANGLES, Algorithm::Paper, rule);
            for (k, &angle) in ANGLES.iter().enumerate() {
                let (want, placed) = (&brute[k].0[r], brute[k].1);
                let what = format!(
                    "grid #{s}, {nx}x{nz} at p={pitch}, angle {angle}, e0 {}, sigma {}, window {:?}",
                    rule.e0,
                    rule.sigma,
                    rule.window_mm()
                );
                assert!(
                    fast[k].mask == *want,
                    "fast vs brute force, {what}: {}",
                    mask_diff(&grid, &fast[k].mask, want)
                );
                assert!(
                    paper[k].mask == *want,
                    "paper vs brute force, {what}: {}",
                    mask_diff(&grid, &paper[k].mask, want)
                );
                assert_eq!(fast[k].placed, placed, "{what}");
                assert_eq!(paper[k].placed, placed, "{what}");
                collisions[r] += fast[k].colliding;
                // At sigma = 0 (itself checked against brute force when it
                // is among the rules) more is struck: the threshold works.
                contacts_not_struck[r] += any_rise[k]
                    .mask
                    .iter()
                    .zip(want)
                    .filter(|(a, w)| a > w)
                    .count();
            }
        }
    }
    for (r, rule) in rules.iter().enumerate() {
        // The grids are built to make the knee-form strike things.
        assert!(
            collisions[r] > 0,
            "no collision at all under {rule:?}: the comparison proved nothing"
        );
    }
    contacts_not_struck
}

/// Asserts that each rule with a positive threshold rejected some contact
/// that `sigma = 0` strikes, over every comparison of a test (a knee-form
/// as large as the grid meets little but the proud blocks, so not every
/// single grid shape exercises the threshold).
fn assert_thresholds_exercised(rules: &[StrikeRule], not_struck: &[Vec<usize>]) {
    for (r, rule) in rules.iter().enumerate() {
        let total: usize = not_struck.iter().map(|v| v[r]).sum();
        assert!(
            rule.sigma == 0.0 || total > 0,
            "sigma {} rejected no contact: the threshold was not exercised",
            rule.sigma
        );
    }
}

/// Whether some footprint row at one of the test angles is shorter than a
/// pitch and holds no node (SPEC's exception for `sigma = 0`).
fn has_a_row_without_nodes(knee: &KneeForm, pitch: f64) -> bool {
    ANGLES.iter().any(|&a| {
        GridFootprint::new(knee, a, &GridSpec::explicit(0.0, 0.0, 1, 1, pitch))
            .rows
            .iter()
            .any(|r| r.klo > r.khi)
    })
}

#[test]
fn fast_and_paper_equal_brute_force_off_node_boundaries() {
    let counts = [
        check_against_brute_force(60, 45, 5.3, &KneeForm::default()),
        check_against_brute_force(45, 40, 7.7, &KneeForm::default()),
    ];
    assert_thresholds_exercised(&default_rules(5.3), &counts);
}

#[test]
fn fast_and_paper_equal_brute_force_with_footprint_rows_holding_no_node() {
    // The footprint spans z in [-160, 160] mm at angle 0; at this pitch the
    // outermost rows (dz = +-30 p = +-159.995 mm) cut the rounding discs
    // 0.005 mm from their edge: rows 1.6 mm long, shorter than the pitch,
    // holding no node (SPEC's exception for sigma = 0).
    let pitch = 160.0 / 30.01;
    assert!(has_a_row_without_nodes(&KneeForm::default(), pitch));
    let counts = check_against_brute_force(50, 70, pitch, &KneeForm::default());
    assert_thresholds_exercised(&default_rules(pitch), &[counts]);
}

#[test]
fn fast_and_paper_equal_brute_force_with_boundaries_on_nodes() {
    // a(0) = -60 mm is a multiple of these pitches: footprint boundaries fall
    // exactly on nodes.
    let counts = [
        check_against_brute_force(50, 40, 4.0, &KneeForm::default()),
        check_against_brute_force(60, 30, 2.0, &KneeForm::default()),
        // a(0) = -12 mm for this one.
        check_against_brute_force(50, 30, 1.0, &SMALL),
    ];
    // (The rules' order is the same at every pitch: only their windows
    // scale with it.)
    assert_thresholds_exercised(&default_rules(1.0), &counts);
}

#[test]
fn fast_and_paper_equal_brute_force_at_exact_thresholds() {
    // Heights are multiples of 0.5 mm. With e0 = 0.5 some nodes sit exactly
    // at the rounding tolerance and must not be contacts; with sigma = 0.125
    // at a 4 mm pitch a rise of one 0.5 mm step is exactly the threshold
    // and must not strike, two steps must. (The fine grids of
    // `check_rules` are compared too.)
    // Under the window rule at W = 4 mm, a drop of one 0.5 mm step is
    // exactly sigma W and must not strike, two steps must.
    let rule = |e0, sigma, rate| StrikeRule {
        e0,
        sigma,
        rate,
        window: 4.0,
        ..StrikeRule::default()
    };
    let rules = [
        rule(0.5, 0.0, RateEstimate::XSlope),
        rule(1e-6, 0.125, RateEstimate::XSlope),
        rule(0.5, 0.0, RateEstimate::Window),
        rule(1e-6, 0.125, RateEstimate::Window),
    ];
    let counts = check_rules(50, 40, 4.0, &KneeForm::default(), &rules);
    assert_thresholds_exercised(&rules, &[counts]);
}

#[test]
fn fast_and_paper_equal_brute_force_for_a_small_knee_form() {
    // A knee-form smaller than the grid, so that many starts are interior
    // and many slides run off the -x edge.
    let counts = [
        check_against_brute_force(60, 40, 2.0, &SMALL),
        check_against_brute_force(50, 40, 3.3, &SMALL),
    ];
    assert_thresholds_exercised(&default_rules(2.0), &counts);
}

#[test]
fn row_interval_endpoints_lie_on_the_boundary() {
    // The footprint's closed form against the brute-force distance to its
    // triangle: every row end lies at distance R, just outside is further.
    let knee = KneeForm::default();
    for angle in [-30.0, -17.0, 0.0, 5.5, 30.0] {
        let fp = Footprint::new(&knee, angle);
        let (zlo, zhi) = fp.z_range();
        let mut dz = zlo + 0.01;
        while dz < zhi {
            let (a, b) = fp.row_interval(dz).unwrap();
            assert!(a <= b);
            for x in [a, b] {
                let d = distance_to_triangle(&fp.vertices, x, dz);
                assert!((d - knee.radius).abs() < 1e-9, "angle {angle} dz {dz}: {d}");
            }
            // Just outside the interval is outside the footprint.
            assert!(distance_to_triangle(&fp.vertices, a - 1e-6, dz) > knee.radius);
            assert!(distance_to_triangle(&fp.vertices, b + 1e-6, dz) > knee.radius);
            dz += 0.77;
        }
        assert!(fp.row_interval(zhi + 1e-6).is_none());
        assert!(fp.row_interval(zlo - 1e-6).is_none());
    }
}
