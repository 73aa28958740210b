//! The sample check every analysis carries: the exact oracle on a small
//! seeded sample of the analysis's own starts, compared with its grid as
//! `verify` compares them, so that a result states its measured accuracy
//! beside it (issue 26: `analyze` said nothing on three real parts where
//! `verify` at the same settings failed).
//!
//! It reuses the analysis's grid and footprints; it samples nothing
//! again. Its starts are nodes on the part (each lies in its own
//! footprint, so it is placed at every angle), a seeded sample like
//! `verify`'s. Its cost is the oracle's on [`CHECK_STARTS`] starts at three
//! angles (0.37 s on the bundled console, against 3.0 s for its analysis).

use super::causes::Cells;
use super::compare::{CompareOptions, GridSide, StartSelection, choose_nodes, compare_grid_with};
use super::error::HarnessError;
use super::metrics::TieBand;
use crate::analysis::{Analysis, Progress};
use crate::frame::Approach;
use crate::summary::{CheckStatus, SampleCheck};

/// Starts in the sample.
pub(crate) const CHECK_STARTS: usize = 5;

/// The sample's seed: the same starts on every machine and run.
pub(crate) const CHECK_SEED: u64 = 1;

/// The angles checked among `angles` (degrees): the first, the middle and
/// the last, without repeats.
fn check_angles(angles: &[f64]) -> Vec<usize> {
    let n = angles.len();
    let mut picked: Vec<usize> = Vec::new();
    for k in [0, n / 2, n.saturating_sub(1)] {
        if k < n && !picked.contains(&k) {
            picked.push(k);
        }
    }
    picked
}

/// Runs the sample check on `analysis` (the slide approach; the direct
/// approach's record says it is not run: `verify --approach direct`
/// checks it). A shard's analysis checks the pairs at its own angles
/// alone (`analysis.angles`): the shards' checks merge into the whole
/// run's ([`SampleCheck::merged`]).
pub fn check_analysis(
    analysis: &Analysis,
    progress: &dyn Progress,
) -> Result<SampleCheck, HarnessError> {
    let setup = &analysis.setup;
    if setup.approach == Approach::Direct {
        return Ok(SampleCheck::not_run(
            CheckStatus::NotRun,
            "not run for the direct approach: `kneeform verify --approach direct` checks it",
        ));
    }
    // The oracle's copy of the part comes on top of what the analysis
    // holds: where the two would pass the memory allowed, the check is not
    // run (issue 41, item 7: it was, and the run was killed).
    let mut need = analysis.memory.clone();
    if !need.items.iter().any(|(item, _)| *item == "sample check") {
        need.add_sample_check(analysis.input.part.triangles.len());
    }
    if let Err(limit) = crate::setup::check_estimate(&need, setup.max_memory_bytes) {
        let gib = |b: f64| crate::limits::short(b / crate::setup::GIB);
        let beyond = match limit {
            crate::setup::Limit::Allowed(b) => format!("--max-memory {} GiB", gib(b)),
            crate::setup::Limit::Machine(b, what) => format!("{what} ({} GiB)", gib(b)),
        };
        return Ok(SampleCheck::not_run(
            CheckStatus::NotRun,
            format!(
                "not run: the exact oracle's copy of the part would take this run's memory to {} GiB, beyond {beyond}; `kneeform verify` on a sample of starts measures the accuracy",
                gib(need.bytes())
            ),
        ));
    }
    let picked = check_angles(&setup.angles);
    let footprints: Vec<_> = picked
        .iter()
        .filter(|&&k| analysis.angles.has(k))
        .filter_map(|&k| analysis.footprints.get(k).cloned())
        .collect();
    let angles: Vec<f64> = footprints.iter().map(|fp| fp.angle_deg).collect();
    let grid = &analysis.grid;
    let spec = grid.spec;
    let selection = StartSelection::Sample {
        count: CHECK_STARTS,
        seed: CHECK_SEED,
    };
    // Nodes on the part: each lies in its own footprint, so its start is
    // placed at every angle (no push over the whole grid to find them).
    let on_part: Vec<(usize, usize)> = (0..spec.len())
        .filter(|&n| grid.h[n].is_finite())
        .map(|n| (n % spec.nx, n / spec.nx))
        .collect();
    let starts: Vec<[f64; 2]> = choose_nodes(&spec, on_part, &selection)
        .iter()
        .map(|&(i, j)| [spec.x(i), spec.z(j)])
        .collect();
    if starts.is_empty() {
        return Ok(SampleCheck::not_run(
            CheckStatus::NotRun,
            "not run: the grid samples no node of the part",
        ));
    }
    let triangles = &analysis.input.part.triangles;
    let oracle = super::verify::oracle_options(&setup.knee, setup.pitch, spec.x(0));
    let pairs = starts.len() * angles.len();
    let tolerance = super::verify::sampling_tolerance(setup.pitch);
    let note = format!(
        "the exact oracle on {} seeded starts at {} angles, compared with the grid as `kneeform verify` does: a sample, not the evidence",
        starts.len(),
        picked.len()
    );
    if pairs == 0 {
        // A shard holding none of the angles checked.
        return Ok(SampleCheck {
            status: CheckStatus::Checked,
            note,
            starts: starts.len(),
            start_positions: starts.iter().map(|p| p.map(to_um)).collect(),
            seed: CHECK_SEED,
            tolerance_mm: tolerance,
            ..SampleCheck::not_run(CheckStatus::Checked, "")
        });
    }
    let what = format!(
        "sample check: exact oracle on {} starts x {} angles",
        starts.len(),
        angles.len()
    );
    let traces = super::stage::in_stage(progress, &what, Some(pairs as u64), || {
        let part = kneeform_oracle::Part::from_triangles(triangles)?;
        kneeform_oracle::evaluate_reporting(&part, &starts, &angles, &oracle, &|| progress.step())
    })?;
    let compare = CompareOptions::of(setup, TieBand::DEFAULT_PER_MM);
    // The analysis's blind spots: not found again.
    let cells = Cells::of_blind_spots(grid, &analysis.blind_spots);
    let given = GridSide {
        cells: Some(&cells),
        fault: None,
        tick: None,
    };
    let comparison = compare_grid_with(
        triangles,
        grid,
        &footprints,
        &starts,
        &traces,
        &compare,
        given,
    )?;
    let worst = |name: &str| {
        let s = comparison.stat(name);
        (s.n > 0).then_some(s.max)
    };
    let miss = worst("miss_distance_decided");
    let false_alarm = worst("false_alarm_distance_decided");
    // Over the grid strikes the level error does not explain (0 when it
    // explains them all); those with no exact contact to measure from are
    // counted apart.
    let unexplained = false_alarm.map(|_| comparison.unexplained.false_alarm_distance);
    let counts = &comparison.counts;
    Ok(SampleCheck {
        status: CheckStatus::Checked,
        note,
        starts: starts.len(),
        // Nodes, so to the micrometre (no float noise in the record).
        start_positions: starts.iter().map(|p| p.map(to_um)).collect(),
        angles_deg: angles,
        seed: CHECK_SEED,
        compared_pairs: counts.compared,
        oracle_failed: counts.oracle_failed,
        miss_distance_decided_mm: miss,
        false_alarm_distance_decided_mm: false_alarm,
        false_alarm_unexplained_mm: unexplained,
        unmatched_exact_decided: counts.unmatched_exact_decided,
        unmatched_grid_decided: comparison.unexplained.unmatched_grid,
        tolerance_mm: tolerance,
        exceeds_tolerance: false,
        decided_strikes: counts.exact_strikes_decided,
        outcome: None,
    }
    .judged())
}

/// `v` (mm) rounded to the micrometre.
fn to_um(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Side;
    use crate::partition::Shard;
    use crate::setup::Setup;

    fn bump(approach: Approach) -> Analysis {
        let setup = Setup {
            pitch: 4.0,
            angles: vec![-30.0, 0.0, 30.0],
            approach,
            ..Setup::default()
        };
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bump.toml");
        Analysis::of_file(&path, 1.0, Side::Left, &setup, &()).unwrap()
    }

    /// The bump at 4 mm passes its check, whose figures are `verify`'s
    /// on the same start-angle pairs.
    #[test]
    fn the_check_is_verify_on_a_sample_of_the_analysis_starts() {
        let analysis = bump(Approach::Slide);
        let check = check_analysis(&analysis, &()).unwrap();
        assert_eq!(check.status, CheckStatus::Checked);
        assert_eq!((check.starts, check.angles_deg.len()), (CHECK_STARTS, 3));
        assert_eq!(check.compared_pairs, CHECK_STARTS * 3, "{check:?}");
        assert_eq!(check.tolerance_mm, super::super::sampling_tolerance(4.0));
        let miss = check.miss_distance_decided_mm.expect("decided strikes");
        assert!(miss <= check.tolerance_mm, "{check:?}");
        assert!(!check.exceeds_tolerance, "{check:?}");
        assert!(
            check.line().contains("within the tolerance"),
            "{}",
            check.line()
        );

        // The check measures what `verify` measures on the same pairs.
        let options = super::super::VerifyOptions {
            selection: StartSelection::At(check.start_positions.clone()),
            tie_band_per_mm: TieBand::DEFAULT_PER_MM,
            tolerance: check.tolerance_mm,
            budget_s: None,
        };
        let verified =
            super::super::verify(&analysis.input, &analysis.setup, &options, &()).unwrap();
        let c = &verified.comparison;
        assert_eq!(c.counts.compared, check.compared_pairs);
        // The same pairs, traced from the recorded positions (to 1 um).
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        assert!(near(c.stat("miss_distance_decided").max, miss), "{c:?}");
        let false_alarm = check.false_alarm_distance_decided_mm.unwrap();
        assert!(near(
            c.stat("false_alarm_distance_decided").max,
            false_alarm
        ));
        assert_eq!(c.passes(check.tolerance_mm), !check.exceeds_tolerance);
    }

    /// Three shards' checks merge into the whole run's, figure for figure.
    #[test]
    fn the_shards_checks_merge_into_the_whole_runs() {
        let analysis = bump(Approach::Slide);
        let whole = check_analysis(&analysis, &()).unwrap();
        assert_eq!(analysis.setup.angles.len(), 3);
        let parts: Vec<SampleCheck> = (1..=3)
            .map(|index| {
                let shard = Analysis {
                    angles: Shard { index, count: 3 },
                    ..analysis.clone()
                };
                check_analysis(&shard, &()).unwrap()
            })
            .collect();
        assert!(parts.iter().all(|p| p.compared_pairs == CHECK_STARTS));
        assert_eq!(
            SampleCheck::merged(&parts, &analysis.setup.angles),
            Some(whole)
        );
    }

    #[test]
    fn the_direct_approach_says_it_is_not_checked_here() {
        let check = check_analysis(&bump(Approach::Direct), &()).unwrap();
        assert_eq!(check.status, CheckStatus::NotRun);
        assert!(
            check.line().contains("verify --approach direct"),
            "{}",
            check.line()
        );
    }

    #[test]
    fn three_angles_at_most_without_repeats() {
        assert_eq!(check_angles(&[]), Vec::<usize>::new());
        assert_eq!(check_angles(&[5.0]), vec![0]);
        assert_eq!(check_angles(&[-30.0, 30.0]), vec![0, 1]);
        assert_eq!(check_angles(&[-30.0, 0.0, 30.0]), vec![0, 1, 2]);
        let all: Vec<f64> = (-30..=30).map(f64::from).collect();
        assert_eq!(check_angles(&all), vec![0, 30, 60]);
    }
}
