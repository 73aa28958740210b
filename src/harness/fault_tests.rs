//! The harness must catch a broken engine: each test compares a correct
//! grid and one with a deliberate [`Fault`] with the oracle, and only the
//! faulty one must fail. (Crate-private: the faults are in no public
//! option.)

use super::study::verify_with;
use super::trace::Fault;
use super::{Comparison, StartSelection, TieBand, VerifyOptions};
use crate::frame::Side;
use crate::input::PartFile;
use crate::mesh::{Part, Triangle};
use crate::scenario::{axis, tessellate};
use crate::setup::Setup;

/// Verifies `tris` at `pitch` and `angles` on the starts of `selection`,
/// with an optional fault.
fn compare(
    tris: Vec<Triangle>,
    pitch: f64,
    angles: &[f64],
    selection: StartSelection,
    fault: Option<Fault>,
) -> Comparison {
    let part = Part::from_triangles("test", tris, 1.0, Side::Left).unwrap();
    let setup = Setup {
        pitch,
        angles: angles.to_vec(),
        ..Setup::default()
    };
    let options = VerifyOptions {
        selection,
        tie_band_per_mm: TieBand::DEFAULT_PER_MM,
        tolerance: 1.0,
        budget_s: None,
    };
    verify_with(
        &PartFile::in_memory("test", part),
        &setup,
        &options,
        &(),
        fault,
    )
    .unwrap()
    .comparison
}

fn max_of(c: &Comparison, metric: &str) -> f64 {
    c.stat(metric).max
}

/// A flat wall at y = 0, 300 x 200 mm.
fn flat_wall() -> Vec<Triangle> {
    let (xs, zs) = (
        axis((-150.0, 150.0), 10.0, &[]),
        axis((-100.0, 100.0), 10.0, &[]),
    );
    tessellate(&xs, &zs, |_, _| 0.0)
}

#[test]
fn heights_offset_by_half_a_pitch_are_caught() {
    // On a flat wall the correct grid is exact (every node on the wall):
    // all errors are 0. Heights offset by p/2 = 2 mm push the knee-form 2 mm
    // too deep: a push error of exactly 2 mm, beyond the 1 mm tolerance.
    let sel = StartSelection::Sample { count: 30, seed: 7 };
    let good = compare(flat_wall(), 4.0, &[0.0, 30.0], sel.clone(), None);
    let bad = compare(
        flat_wall(),
        4.0,
        &[0.0, 30.0],
        sel,
        Some(Fault::HeightsOffsetHalfPitch),
    );
    assert!(good.counts.compared > 20);
    assert!(good.passes(1.0), "{:?}", good.stats);
    assert!(!bad.passes(1.0));
    assert!(
        (max_of(&bad, "push_error") - 2.0).abs() < 1e-6,
        "{:?}",
        bad.stats
    );
}

/// A flat wall with a rib 1 mm wide along x at z = 0, rising smoothly
/// towards -x to 10 mm proud over 20 mm, flat on top for 40 mm.
fn rib() -> Vec<Triangle> {
    let y = |x: f64, z: f64| {
        if z.abs() > 0.5 {
            return 0.0;
        }
        -10.0 * ((-x) / 20.0).clamp(0.0, 1.0) * f64::from(x >= -60.0)
    };
    let xs = axis((-150.0, 150.0), 2.0, &[-60.1, -60.0]);
    let zs = axis((-100.0, 100.0), 10.0, &[-0.6, -0.5, 0.5, 0.6]);
    tessellate(&xs, &zs, |i, k| y(xs[i], zs[k]))
}

#[test]
fn a_footprint_one_row_short_is_caught() {
    // At angle 0 the footprint's leading row is the front corner's, z = z0.
    // Starts on z = 0 meet the rib only in that row. The correct grid
    // strikes the rib's ramp node by node: misses within about a pitch
    // (2 mm). Without the row the grid strikes nothing while the exact
    // knee-form is lifted 10 mm by the rib: an unmatched deflection of
    // 10 mm, beyond the 5 mm tolerance.
    let starts = StartSelection::At(
        [60.0, 80.0, 100.0, 120.0]
            .iter()
            .map(|&x| [x, 0.0])
            .collect(),
    );
    let good = compare(rib(), 2.0, &[0.0], starts.clone(), None);
    let bad = compare(rib(), 2.0, &[0.0], starts, Some(Fault::FootprintRowShort));
    assert_eq!(good.counts.compared, 4);
    assert!(good.passes(5.0), "{:?} {:?}", good.stats, good.counts);
    assert!(!bad.passes(5.0));
    assert!(
        max_of(&bad, "unmatched_deflection") > 9.0,
        "{:?}",
        bad.stats
    );
}

/// A flat wall with two blocks in front of the start row z = 0: A at
/// z in [15, 25], x <= -50.5, 5 mm proud; B at z in [-25, -15],
/// x <= -51.5, 5.5 mm proud.
fn two_blocks() -> Vec<Triangle> {
    let y = |x: f64, z: f64| {
        if (15.0..=25.0).contains(&z) && x <= -50.5 {
            -5.0
        } else if (-25.0..=-15.0).contains(&z) && x <= -51.5 {
            -5.5
        } else {
            0.0
        }
    };
    let xs = axis((-150.0, 150.0), 2.0, &[-51.6, -51.5, -50.6, -50.5]);
    let zs = axis((-100.0, 100.0), 2.0, &[-25.1, -14.9, 14.9, 25.1]);
    tessellate(&xs, &zs, |i, k| y(xs[i], zs[k]))
}

#[test]
fn a_slide_ignoring_tie_groups_is_caught() {
    // At angle 0 the footprint is symmetric in z: rows +dz and -dz meet
    // their nodes at the same distance. Both blocks' first nodes are at
    // x = -52 (pitch 2), in tied rows. The exact knee-form strikes A's
    // corner first, drops to -5, then strikes B (5.5 proud): contacts on
    // both fronts. Tie groups judged at one level strike both blocks; judged
    // one by one in row order, B (lower rows) drops the level to -5.5 and A
    // is never struck: A's contacts are then 30+ mm from any grid point.
    // The blocks' fronts are 5-5.5 mm risers whose contacts all map to the
    // node at their foot, so even the correct grid misses by up to about
    // sqrt(1.5^2 + 5.5^2 + 1) = 5.8 mm: the tolerance is 10 mm.
    let starts = StartSelection::At(vec![[20.0, 0.0], [40.0, 0.0]]);
    let good = compare(two_blocks(), 2.0, &[0.0], starts.clone(), None);
    let bad = compare(two_blocks(), 2.0, &[0.0], starts, Some(Fault::IgnoreTies));
    assert_eq!(good.counts.compared, 2);
    assert!(good.passes(10.0), "{:?} {:?}", good.stats, good.counts);
    assert!(!bad.passes(10.0));
    assert!(max_of(&bad, "miss_distance") > 25.0, "{:?}", bad.stats);
}
