//! Choosing the pitch for the user (`analyze --pitch auto --tolerance MM`):
//! a quick convergence study on the user's own part, then the coarsest
//! pitch that meets the tolerance ([`choose_pitch`]).
//!
//! The study halves the pitch from a start derived from the tolerance. At
//! each pitch it measures, on the study's angles (the setup's first, middle
//! and last):
//!
//! * the **exact error**: the area distance against the exact oracle, on
//!   a seeded sample of starts taken on the coarsest grid (so every grid
//!   holds them), traced once, as `verify` judges it: from the decided
//!   exact strikes away from flagged blind spots to the grid's, and from
//!   the grid strikes the grid's level error does not explain to the
//!   exact ones (the level error's false alarms are shown beside it);
//! * the **grid change**: the area distance between this pitch's colliding
//!   area and the previous, coarser pitch's, over the whole part (the
//!   sample cannot see a feature its starts do not cross; this does). It is
//!   shown, not judged: strikes whose deflection rate is near the threshold
//!   come and go with the pitch (the harness's tie band, which the exact
//!   comparison sets aside), so this distance stays at several pitches on
//!   smooth parts where the decided error is below one pitch;
//! * the engine's time, from which a full analysis's time is predicted
//!   (scaled to the setup's angle count), and the memory estimate.
//!
//! A pitch **meets** the tolerance when its exact error is within it. The
//! study stops at the first pitch that meets it, and refuses when the next
//! pitch it would need exceeds the time budget or the memory limit. The
//! blind spots ([`crate::blind`]) of the chosen pitch are the analysis's
//! to report.

use std::time::Instant;

use super::compare::StartSelection;
use super::converge::Ladder;
use super::error::HarnessError;
use super::method::{Method, Tracing};
use super::metrics::TieBand;
use super::nearest::PointSet;
use crate::analysis::Progress;
use crate::engine::AngleMask;
use crate::grid::{GridSpec, HeightGrid};
use crate::input::PartFile;
use crate::setup::{GIB, Setup};
use crate::summary::{Outcome, PitchChoice, PitchStudyRow};

/// How to choose the pitch.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoPitch {
    /// The largest decided area distance allowed (mm).
    pub tolerance: f64,
    /// The longest predicted analysis allowed (s).
    pub budget_s: f64,
    /// The starts traced by the exact oracle, on the study's first
    /// (coarsest) grid: `verify`'s and `converge`'s default
    /// ([`StartSelection::default_for`]), so that `converge --tolerance`
    /// on the same starts recommends the pitch chosen here.
    pub selection: StartSelection,
}

impl AutoPitch {
    /// The default time budget (s).
    pub const DEFAULT_BUDGET_S: f64 = 600.0;
}

/// How many halvings the study may take from its first pitch.
const MAX_HALVINGS: usize = 6;

/// The study's first pitch: four times the tolerance (smooth parts meet a
/// tolerance at about one pitch), to the power of 2 at or above it, within
/// 0.25..8 mm.
fn first_pitch(tolerance: f64) -> f64 {
    (4.0 * tolerance).log2().ceil().exp2().clamp(0.25, 8.0)
}

/// Runs the study on `input` for `setup` (its pitch ignored) and returns
/// the coarsest pitch meeting `auto.tolerance`; an error saying which pitch
/// and how long when the budget or the memory limit comes first.
pub fn choose_pitch(
    input: &PartFile,
    setup: &Setup,
    auto: &AutoPitch,
    progress: &dyn Progress,
) -> Result<PitchChoice, HarnessError> {
    if setup.approach == crate::frame::Approach::Direct {
        return Err(HarnessError::DirectApproach);
    }
    super::verify::check_tolerance(auto.tolerance)?;
    if !(auto.budget_s.is_finite() && auto.budget_s > 0.0) {
        return Err(HarnessError::Budget(auto.budget_s));
    }
    let started = Instant::now();
    let p0 = first_pitch(auto.tolerance);
    let pitches: Vec<f64> = (0..=MAX_HALVINGS)
        .map(|k| p0 / f64::from(1u32 << k))
        .collect();
    // The grid's error is of the order of its pitch: a tolerance below the
    // finest pitch tried is never met, and would only cost the study's
    // finest oracle (1e-9 mm ran 300 s against a budget of 5).
    let finest = pitches[pitches.len() - 1];
    if auto.tolerance < finest {
        return Err(HarnessError::ToleranceTooFine {
            tolerance: auto.tolerance,
            finest,
        });
    }
    let angles = study_angles(&setup.angles);
    let mut ladder = Ladder::lay(
        input,
        &Setup {
            pitch: p0,
            angles: angles.clone(),
            ..setup.clone()
        },
        &auto.selection,
        TieBand::DEFAULT_PER_MM,
        None,
    )?;
    // The exact side is resolved to a tenth of the pitch it is traced for
    // (the oracle's witness tolerance): half the tolerance judged is fine
    // enough for every pitch whose figure is held to that tolerance, and
    // it is what `converge --pitches p0,..,T/2 --tolerance T` traces, so
    // the two compare the same exact traces. The ladder's finest pitch,
    // p0 / 64, made the console's 450 pairs about an hour.
    let tracing = Tracing {
        share: ladder.laid().starts.clone(),
        finest: finest.max(auto.tolerance / 2.0),
        within_s: Some(auto.budget_s),
        refuse_beyond_s: None,
        memory: None,
    };
    ladder.trace(tracing, progress)?;
    let scale = setup.angles.len() as f64 / angles.len() as f64;
    let memory = |spec: &GridSpec| {
        setup
            .memory_estimate(spec, input.part.triangles.len())
            .bytes()
    };

    let mut rows: Vec<PitchStudyRow> = Vec::new();
    // The struck points per angle at the previous (coarser) pitch.
    let mut previous: Option<Vec<Vec<[f64; 2]>>> = None;
    // The study's own time counts against the budget: the whole command
    // stays within it (the exact traces are taken once, then each pitch
    // costs about 8 times the coarser one's).
    let mut last_measure_s: Option<f64> = None;
    for &p in &pitches {
        let spent_s = started.elapsed().as_secs_f64();
        let next_s = last_measure_s.map_or(0.0, |s| 8.0 * s);
        if spent_s + next_s > auto.budget_s {
            return Err(HarnessError::StudyBudget {
                tolerance: auto.tolerance,
                spent_s,
                next: if next_s > 0.0 {
                    format!(
                        " and {} mm would take about {next_s:.0} s more",
                        crate::limits::short(p)
                    )
                } else {
                    String::new()
                },
                budget_s: auto.budget_s,
                studied: studied(&rows),
            });
        }
        let spec = ladder.spec_at(p);
        let need = memory(&spec);
        // Cost grows as p^-3 (nodes p^-2, footprint rows p^-1).
        let predicted_here = rows.last().map_or(0.0, |r| r.predicted_s * 8.0);
        if need > setup.max_memory_bytes || predicted_here > auto.budget_s {
            return Err(HarnessError::PitchBudget {
                tolerance: auto.tolerance,
                pitch: p,
                predicted_s: predicted_here,
                memory_gib: need / GIB,
                budget_s: auto.budget_s,
                max_memory_gib: setup.max_memory_bytes / GIB,
                studied: studied(&rows),
            });
        }
        let measuring = Instant::now();
        let (result, masks, grid) = ladder.measure(p, progress)?;
        last_measure_s = Some(measuring.elapsed().as_secs_f64());
        let (comparison, seconds) = (&result.comparison, result.seconds);
        // Judged as `verify` and `converge` judge it: the outcome of the
        // decided, non-blind area miss distance at the worst angle, on the
        // coarsest grid's starts (`p0 / p` nodes apart here).
        let step = ((p0 / p).round() as usize).max(1);
        let (outcome, why) = comparison.outcome(auto.tolerance, step);
        let decided = comparison.area_miss_decided();
        let level_error = comparison
            .area
            .iter()
            .map(|a| a.false_alarm_decided)
            .fold(0.0, f64::max);
        let finite = decided.is_finite();
        let struck = struck_points(&grid, &masks);
        let row = PitchStudyRow {
            pitch_mm: p,
            exact_area_distance_mm: finite.then_some(decided),
            level_error_area_mm: Some(level_error).filter(|v| v.is_finite()),
            grid_change_mm: previous
                .as_ref()
                .and_then(|prev| area_change(prev, &struck)),
            predicted_s: seconds * scale,
            memory_gib: need / GIB,
            meets: outcome == Outcome::Pass,
            outcome,
        };
        rows.push(row);
        if outcome == Outcome::Inconclusive {
            // A finer grid on the same starts has no more evidence to
            // give where the oracle failed or the sample is too thin.
            return Err(HarnessError::Inconclusive {
                tolerance: auto.tolerance,
                pitch: p,
                why: why.unwrap_or_default(),
            });
        }
        if row.meets {
            return Ok(PitchChoice {
                pitch_mm: p,
                tolerance_mm: auto.tolerance,
                study: rows,
                predicted_s: row.predicted_s,
                study_s: started.elapsed().as_secs_f64(),
                reason: format!(
                    "the coarsest pitch whose outcome is PASS at {} mm: every decided exact strike away from flagged blind spots lies within {:.3} mm of the grid's colliding area on {} sampled starts at angles {:?}, as `kneeform verify` and `converge` judge it; the grid's area reaches {:.3} mm beyond the exact one (the decided area false-alarm distance, shown, not judged); the whole-part change from the coarser pitch is shown, not judged",
                    auto.tolerance,
                    decided,
                    ladder.starts.len(),
                    angles,
                    level_error
                ),
            });
        }
        previous = Some(struck);
    }
    Err(HarnessError::PitchNotFound {
        tolerance: auto.tolerance,
        finest: pitches[pitches.len() - 1],
        studied: studied(&rows),
    })
}

/// The study's exact errors in words: `4 mm: 3.997 mm, 2 mm: ...`.
fn studied(rows: &[PitchStudyRow]) -> String {
    let words: Vec<String> = rows
        .iter()
        .map(|r| match r.exact_area_distance_mm {
            Some(d) => format!("{} mm: {d:.3} mm", crate::limits::short(r.pitch_mm)),
            None => format!(
                "{} mm: infinite (one side strikes nothing)",
                crate::limits::short(r.pitch_mm)
            ),
        })
        .collect();
    if words.is_empty() {
        "none measured".into()
    } else {
        words.join(", ")
    }
}

/// The study's angles: the setup's first, middle and last (distinct).
fn study_angles(angles: &[f64]) -> Vec<f64> {
    let mut picked = vec![
        angles[0],
        angles[angles.len() / 2],
        angles[angles.len() - 1],
    ];
    picked.dedup();
    picked
}

/// Per angle, the struck nodes' positions (mm).
fn struck_points(grid: &HeightGrid, masks: &[AngleMask]) -> Vec<Vec<[f64; 2]>> {
    let spec = grid.spec;
    masks
        .iter()
        .map(|m| {
            m.mask
                .iter()
                .enumerate()
                .filter(|(_, c)| **c != 0)
                .map(|(k, _)| [spec.x(k % spec.nx), spec.z(k / spec.nx)])
                .collect()
        })
        .collect()
}

/// The largest Hausdorff distance, both ways, between two pitches' struck
/// points at each angle; `None` where one side is empty and the other not.
fn area_change(coarse: &[Vec<[f64; 2]>], fine: &[Vec<[f64; 2]>]) -> Option<f64> {
    let mut worst: f64 = 0.0;
    for (a, b) in coarse.iter().zip(fine) {
        let d = PointSet::new(a.clone())
            .hausdorff_from(b)
            .max(PointSet::new(b.clone()).hausdorff_from(a));
        worst = worst.max(d);
    }
    worst.is_finite().then_some(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_study_starts_at_four_tolerances_on_powers_of_two() {
        assert_eq!(first_pitch(1.0), 4.0);
        assert_eq!(first_pitch(0.3), 2.0);
        assert_eq!(first_pitch(0.01), 0.25);
        assert_eq!(first_pitch(10.0), 8.0);
        assert_eq!(study_angles(&[-30.0, 0.0, 30.0]), vec![-30.0, 0.0, 30.0]);
        assert_eq!(study_angles(&[5.0]), vec![5.0]);
    }
}
