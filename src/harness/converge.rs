//! Convergence over the pitch: the same starts (the coarsest grid's; grids
//! on multiples of the pitch nest) compared at `p, p/2, p/4, ...`, a
//! power law `error ~ C p^alpha` fitted in log-log per metric, and the
//! coarsest pitch that meets a tolerance.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::compare::{
    CompareOptions, Comparison, GridSide, PairResult, StartSelection, assemble, chain_of,
    covering_nodes, pair_results,
};
use super::error::HarnessError;
use super::method::{Laid, Method, Pitch, Tracing, sampled_at, spec_at};
use super::metrics::{METRICS, TieBand};
use super::pairs::{Pairs, PitchPart};
use super::trace::Fault;
use super::verify::{
    check_selection, check_tie_band, check_tolerance, oracle_options, run_oracle, start_positions,
    tie_band_rule,
};
use crate::analysis::Progress;
use crate::engine::{AngleMask, EngineOptions, colliding_masks};
use crate::grid::{GridSpec, HeightGrid};
use crate::input::PartFile;
use crate::mesh::Triangle;
use crate::setup::{Sampled, Setup};
use crate::summary::Outcome;
use kneeform_oracle::StartTrace;

/// One pitch of a convergence study.
#[derive(Debug, Clone)]
pub struct PitchResult {
    /// The pitch (mm).
    pub pitch: f64,
    /// The comparison with the exact traces.
    pub comparison: Comparison,
    /// Wall-clock time of the engine's full push and slide at this pitch,
    /// for the study's angles (s).
    pub seconds: f64,
    /// Grid nodes.
    pub nodes: usize,
}

/// `error ~ c * pitch^alpha`, fitted by least squares on logarithms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The order of convergence.
    pub alpha: f64,
    /// The constant (mm per mm^alpha).
    pub c: f64,
    /// Pitches with a positive error that entered the fit.
    pub points: usize,
}

/// Errors at or below this (mm) are rounding, not error: a push error of
/// 1e-15 mm at every pitch is exact there, and fitting it gave orders
/// such as "alpha = -0.50" that mean nothing.
pub const ROUNDING_MM: f64 = 1e-9;

/// Fits `y ~ c x^alpha` through the points with `x > 0` and `y` above
/// rounding ([`ROUNDING_MM`]); `None` with fewer than two such points (an
/// error that is zero, or rounding, at every pitch has no order: it is
/// exact there).
pub fn fit_power_law(points: &[(f64, f64)]) -> Option<Fit> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > ROUNDING_MM && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let alpha = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    Some(Fit {
        alpha,
        c: (my - alpha * mx).exp(),
        points: logs.len(),
    })
}

/// The fits of every metric's max error over `results`.
pub(crate) fn fits(results: &[PitchResult]) -> Vec<(String, Option<Fit>)> {
    METRICS
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let points: Vec<(f64, f64)> = results
                .iter()
                .map(|r| (r.pitch, r.comparison.stats[k].1.max))
                .collect();
            (m.to_string(), fit_power_law(&points))
        })
        .collect()
}

/// The coarsest pitch whose outcome at `tolerance` is `PASS` (measured,
/// not extrapolated): the figure `verify` and `--pitch auto` judge.
pub(crate) fn recommended_pitch(results: &[PitchResult], tolerance: f64) -> Option<&PitchResult> {
    results
        .iter()
        .filter(|r| outcome_at(results, r, tolerance).0 == Outcome::Pass)
        .max_by(|a, b| a.pitch.total_cmp(&b.pitch))
}

/// The outcome of `result`, one of `results` (coarsest first, whose grid
/// chose the starts), at `tolerance` (mm), and why where inconclusive.
pub(crate) fn outcome_at(
    results: &[PitchResult],
    result: &PitchResult,
    tolerance: f64,
) -> (Outcome, Option<String>) {
    let coarsest = results.first().map_or(result.pitch, |r| r.pitch);
    // Grids nest: the coarsest grid's adjacent starts lie this many nodes
    // apart on this one.
    let step = ((coarsest / result.pitch).round() as usize).max(1);
    result.comparison.outcome(tolerance, step)
}

/// `converge.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergeSummary {
    /// Which part, read how, by which kneeform: the same record, in the
    /// same order, in every study's JSON.
    #[serde(flatten)]
    pub run: super::identity::RunIdentity,
    /// Knee-form L, R, W (mm).
    #[serde(default)]
    pub knee_form_mm: [f64; 3],
    /// The strike rule of every pitch, as in `summary.json`: sigma =
    /// tan(deflection) and how the grid's rate is estimated.
    pub sigma: f64,
    /// `window` or `x-slope` (`summary.json`'s `rate`).
    pub rate: String,
    /// The level the grid's knee-form follows (`summary.json`'s `level`).
    #[serde(default)]
    pub level: crate::strike::Level,
    /// The deflection window (mm) of the `window` rule (`summary.json`'s
    /// `window_mm`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_mm: Option<f64>,
    /// The pitches, coarsest first (mm).
    pub pitches_mm: Vec<f64>,
    /// Per metric, the fit of its max error, where it has one.
    pub fits: std::collections::BTreeMap<String, Fit>,
    /// The tolerance asked for (mm).
    pub tolerance_mm: Option<f64>,
    /// The coarsest pitch meeting it (mm).
    pub recommended_pitch_mm: Option<f64>,
    /// Predicted time of a full 61-angle analysis at that pitch (s): the
    /// measured time for the study's angles, scaled to 61.
    pub predicted_full_time_s: Option<f64>,
    /// Angles of the study (degrees).
    pub angles_deg: Vec<f64>,
    /// Deflection threshold delta (degrees).
    pub deflection_deg: f64,
    /// Rounding tolerance e0 (mm).
    pub e0_mm: f64,
    /// The tie band's rule, in words.
    pub tie_band_rule: String,
    /// Starts compared per angle.
    pub starts: usize,
    /// Per pitch: engine seconds for the study's angles.
    pub seconds: Vec<f64>,
    /// Per pitch, at the tolerance asked for: the verdict and every figure
    /// beyond it with its mechanism (as `verify.json`'s); empty without a
    /// tolerance.
    #[serde(default)]
    pub verdicts: Vec<PitchVerdict>,
    /// How the exact traces were shared between the starts of a row (a
    /// strip's: [`kneeform_oracle::Chain`]); absent where each start was
    /// traced on its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oracle_chain: Option<kneeform_oracle::Chain>,
    /// What a reader must know first, one line each, as `verify.json`'s:
    /// the part's sanity checks and the coarsest pitch's comparison's.
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// One pitch's verdict in a convergence study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PitchVerdict {
    /// The pitch (mm).
    pub pitch_mm: f64,
    /// Whether its outcome is `PASS`.
    pub pass: bool,
    /// Its outcome, as `verify.json`'s.
    #[serde(default = "super::verify::inconclusive")]
    pub outcome: Outcome,
    /// Why it is `INCONCLUSIVE`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome_reason: Option<String>,
    /// Misses and false alarms apart, in words.
    pub verdict: String,
    /// The figures beyond the tolerance, with their mechanism.
    pub failures: Vec<super::causes::Failure>,
}

/// Nested grids over the coarsest grid's extent (pitches dividing its
/// pitch), sharing its starts and the oracle's traces of them: the slide's
/// [`Method`] of every study, and what [`super::choose_pitch`] measures at
/// each pitch.
pub(super) struct Ladder<'a> {
    triangles: &'a [Triangle],
    /// The study's setup at the coarsest pitch.
    setup: Setup,
    /// The coarsest grid, every start of the study on it.
    laid: Laid,
    /// The coarsest grid, kept until its pitch is measured (a
    /// verification's one grid is sampled once).
    coarse_grid: Option<Sampled>,
    /// The starts traced (mm), nodes of every grid of the ladder: a
    /// shard's share of `all_starts`, or all of them.
    pub starts: Vec<[f64; 2]>,
    traces: Vec<StartTrace>,
    compare: CompareOptions,
    /// A deliberate mistake on the grid side (tests only).
    fault: Option<Fault>,
    /// How the oracle shares traces between the starts of a row: along
    /// every row of a strip or run of starts ([`chain_of`]), else not at all.
    chain: Option<kneeform_oracle::Chain>,
}

/// The exact traces of `starts` at `angles` (in [`run_oracle`]'s order),
/// taken a few starts at a time and given up as soon as `budget_s`
/// seconds are spent, with what the rest would take: a pitch study keeps
/// within its budget, the oracle included (a 5 s budget once ran 300 s).
fn traces_within(
    triangles: &[Triangle],
    starts: &[[f64; 2]],
    angles: &[f64],
    options: &kneeform_oracle::OracleOptions,
    budget_s: f64,
    progress: &dyn Progress,
) -> Result<(Vec<StartTrace>, f64), HarnessError> {
    let started = Instant::now();
    let part = kneeform_oracle::Part::from_triangles(triangles)?;
    let pairs = starts.len() * angles.len();
    progress.begin(
        &format!(
            "exact oracle: {} starts x {} angles",
            starts.len(),
            angles.len()
        ),
        Some(pairs as u64),
    );
    let chunk = (2 * rayon::current_num_threads()).max(4);
    let mut traces = Vec::with_capacity(pairs);
    for &angle in angles {
        for share in starts.chunks(chunk) {
            let spent_s = started.elapsed().as_secs_f64();
            if spent_s > budget_s {
                progress.end();
                let done = traces.len().max(1) as f64;
                return Err(HarnessError::OracleBudget {
                    predicted_s: spent_s * pairs as f64 / done,
                    pairs,
                    budget_s,
                });
            }
            traces.extend(kneeform_oracle::evaluate(&part, share, &[angle], options)?);
            for _ in share {
                progress.step();
            }
        }
    }
    progress.end();
    Ok((traces, started.elapsed().as_secs_f64()))
}

impl<'a> Ladder<'a> {
    /// The coarsest grid of `setup` (its pitch) on `input` and the starts
    /// of `selection` on it, not yet traced ([`Method::trace`]).
    pub(super) fn lay(
        input: &'a PartFile,
        setup: &Setup,
        selection: &StartSelection,
        tie_band_per_mm: f64,
        fault: Option<Fault>,
    ) -> Result<Ladder<'a>, HarnessError> {
        setup.validate()?;
        let triangles = &input.part.triangles;
        let t = Instant::now();
        let (coarse, _) = setup.lay(&input.part)?;
        let sampled = setup.sample_on(coarse, triangles, None);
        let sample_s = t.elapsed().as_secs_f64();
        let all_starts = start_positions(&sampled.grid, &sampled.footprints, selection)?;
        Ok(Ladder {
            triangles,
            setup: setup.clone(),
            laid: Laid {
                coarse,
                starts: all_starts,
                sample_s,
            },
            coarse_grid: Some(sampled),
            starts: Vec::new(),
            traces: Vec::new(),
            compare: CompareOptions::of(setup, tie_band_per_mm),
            fault,
            chain: chain_of(selection, coarse.pitch),
        })
    }

    /// The grid at pitch `p`: exactly the coarse grid's extent from its
    /// origin.
    pub(super) fn spec_at(&self, p: f64) -> GridSpec {
        spec_at(&self.laid.coarse, p)
    }

    /// The grid at pitch `p` sampled, the engine timed over the ladder's
    /// angles, and the comparison on the ladder's starts; with the masks
    /// and the grid.
    pub(super) fn measure(
        &mut self,
        p: f64,
        progress: &dyn Progress,
    ) -> Result<(PitchResult, Vec<AngleMask>, HeightGrid), HarnessError> {
        let at = Pitch {
            p,
            converging: true,
        };
        let (pairs, pitch, masks, grid) = self.measure_raw(at, progress)?;
        let result = PitchResult {
            pitch: p,
            comparison: assemble(
                pairs,
                &self.setup.angles,
                pitch.band,
                pitch.grid_s,
                &pitch.covering,
            ),
            seconds: pitch.seconds,
            nodes: pitch.nodes,
        };
        Ok((result, masks, grid))
    }

    /// The pairs of pitch `at`, and the pitch's part without them (its
    /// timings), its masks (none but for a convergence study's pitch,
    /// whose engine is timed) and grid.
    fn measure_raw(
        &mut self,
        at: Pitch,
        progress: &dyn Progress,
    ) -> Result<(Vec<PairResult>, PitchPart, Vec<AngleMask>, HeightGrid), HarnessError> {
        let p = at.p;
        let spec = self.spec_at(p);
        progress.begin(&at.stage(&spec, self.traces.len(), ""), None);
        let Sampled {
            grid, footprints, ..
        } = sampled_at(&mut self.coarse_grid, &self.setup, self.triangles, spec);
        let (masks, seconds) = if at.converging {
            let t = Instant::now();
            let masks = colliding_masks(
                &grid,
                &footprints,
                &EngineOptions {
                    rule: self.setup.rule,
                    ..EngineOptions::default()
                },
                &|| {},
            );
            (masks, t.elapsed().as_secs_f64())
        } else {
            // A verification does not time the engine.
            (Vec::new(), 0.0)
        };
        // The comparison, pair by pair with the time left (a minute on
        // the console's default verification).
        let comparing = super::stage::comparing(self.traces.len());
        progress.begin(
            &if at.converging {
                format!("pitch {p} mm: {comparing}")
            } else {
                comparing
            },
            Some(self.traces.len() as u64),
        );
        let step = || progress.step();
        let t = Instant::now();
        let pairs = pair_results(
            self.triangles,
            &grid,
            &footprints,
            &self.starts,
            &self.traces,
            &self.compare,
            GridSide {
                cells: None,
                fault: self.fault,
                tick: Some(&step),
            },
        );
        progress.end();
        let pairs = pairs?;
        // The analysis's area nearest to each exact strike: what the
        // area's misses are measured to (none where a deliberate mistake
        // is on the grid side: the engine would hide it).
        let covering = match self.fault {
            Some(_) => Vec::new(),
            None => super::stage::in_stage(
                progress,
                &super::stage::covering(footprints.len()),
                Some(footprints.len() as u64),
                || {
                    let step = || progress.step();
                    covering_nodes(
                        &grid,
                        &footprints,
                        &self.setup.rule,
                        &pairs,
                        at.converging.then_some(&masks[..]),
                        &step,
                    )
                },
            ),
        };
        let grid_s = t.elapsed().as_secs_f64();
        let part = PitchPart {
            pitch: p,
            pairs: Pairs::of(Vec::<PairResult>::new()),
            band: TieBand::new(self.compare.rule.sigma, p, self.compare.tie_band_per_mm),
            grid_s,
            seconds,
            nodes: spec.len(),
            covering,
        };
        Ok((pairs, part, masks, grid))
    }
}

impl Method for Ladder<'_> {
    fn laid(&self) -> &Laid {
        &self.laid
    }

    fn trace(&mut self, what: Tracing, progress: &dyn Progress) -> Result<f64, HarnessError> {
        let Tracing {
            share,
            finest,
            refuse_beyond_s,
            within_s,
            memory,
        } = what;
        let oracle = kneeform_oracle::OracleOptions {
            chain: self.chain,
            ..oracle_options(&self.setup.knee, finest, self.laid.coarse.x(0))
        };
        let (traces, oracle_s) = match within_s {
            None => run_oracle(
                self.triangles,
                &share,
                &self.setup.angles,
                &oracle,
                (refuse_beyond_s, memory),
                progress,
            )?,
            Some(budget_s) => traces_within(
                self.triangles,
                &share,
                &self.setup.angles,
                &oracle,
                budget_s,
                progress,
            )?,
        };
        self.starts = share;
        self.traces = traces;
        Ok(oracle_s)
    }

    fn pitch(&mut self, at: Pitch, progress: &dyn Progress) -> Result<PitchPart, HarnessError> {
        let (pairs, pitch, _, _) = self.measure_raw(at, progress)?;
        Ok(PitchPart {
            pairs: Pairs::of(pairs),
            ..pitch
        })
    }
}

/// How to run a convergence study, beside the analysis [`Setup`] (whose
/// pitch it ignores).
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergeOptions {
    /// The pitches (mm), coarsest first, each dividing the coarsest so that
    /// every grid holds the coarsest grid's starts.
    pub pitches: Vec<f64>,
    /// Which starts to compare (on the coarsest grid).
    pub selection: StartSelection,
    /// The tie band's growth with the pitch ([`super::TieBand`], per mm).
    pub tie_band_per_mm: f64,
    /// The tolerance to name the coarsest pitch for (mm).
    pub tolerance: Option<f64>,
    /// The longest the exact oracle may take (seconds), as verify's
    /// ([`super::VerifyOptions::budget_s`]): a prediction beyond it is
    /// refused, naming the `--shard` count that fits. No limit when `None`.
    pub budget_s: Option<f64>,
}

impl ConvergeOptions {
    /// Checks the options: at least two distinct positive pitches,
    /// coarsest first, each dividing the coarsest.
    pub fn validate(&self) -> Result<(), HarnessError> {
        check_selection(&self.selection)?;
        check_tie_band(self.tie_band_per_mm)?;
        if let Some(t) = self.tolerance {
            check_tolerance(t)?;
        }
        let bad = |why: String| Err(HarnessError::Pitches(why));
        if self.pitches.len() < 2 {
            return bad("a convergence study needs at least two pitches".into());
        }
        if let Some(p) = self.pitches.iter().find(|p| !(p.is_finite() && **p > 0.0)) {
            return bad(format!(
                "every pitch must be a finite number of mm > 0, got {p}"
            ));
        }
        if self.pitches.windows(2).any(|w| w[0] <= w[1]) {
            return bad("the pitches must be distinct, coarsest first".into());
        }
        let coarsest = self.pitches[0];
        for &p in &self.pitches {
            let ratio = coarsest / p;
            if (ratio - ratio.round()).abs() >= 1e-9 * ratio {
                return bad(format!(
                    "{p} mm does not divide {coarsest} mm, so the grids would not share the coarsest grid's starts"
                ));
            }
        }
        Ok(())
    }
}

/// A convergence study's results.
#[derive(Debug, Clone)]
pub struct Convergence {
    /// Every pitch's comparison, coarsest first.
    pub results: Vec<PitchResult>,
    /// Per metric ([`METRICS`] order), the fit of its max error.
    pub fits: Vec<(String, Option<Fit>)>,
    /// `converge.json`.
    pub summary: ConvergeSummary,
    /// Seconds the oracle took.
    pub oracle_s: f64,
}

impl Convergence {
    /// The coarsest pitch meeting the study's tolerance, if one was asked
    /// for and one meets it.
    pub fn recommended(&self) -> Option<&PitchResult> {
        recommended_pitch(&self.results, self.summary.tolerance_mm?)
    }
}

impl ConvergeSummary {
    /// `converge.json` of a study of `starts` starts on `input` whose
    /// pitches gave `results`.
    pub(super) fn new(
        input: &PartFile,
        setup: &Setup,
        options: &ConvergeOptions,
        starts: usize,
        results: &[PitchResult],
    ) -> ConvergeSummary {
        let mut summary = ConvergeSummary {
            run: super::identity::RunIdentity::of(input),
            knee_form_mm: [
                setup.knee.triangle_side,
                setup.knee.radius,
                setup.knee.thickness,
            ],
            sigma: setup.rule.sigma,
            rate: setup.rule.rate.name().into(),
            level: setup.rule.level,
            window_mm: setup.rule.window_mm(),
            pitches_mm: options.pitches.clone(),
            fits: Default::default(),
            tolerance_mm: options.tolerance,
            recommended_pitch_mm: None,
            predicted_full_time_s: None,
            angles_deg: setup.angles.clone(),
            deflection_deg: setup.rule.deflection_deg(),
            e0_mm: setup.rule.e0,
            tie_band_rule: tie_band_rule(
                options.tie_band_per_mm,
                setup.rule.window_mm(),
                setup.rule.level,
            ),
            starts,
            seconds: Vec::new(),
            verdicts: Vec::new(),
            oracle_chain: chain_of(&options.selection, options.pitches[0]),
            warnings: crate::sanity::part_warnings(&input.part, input.side, &setup.knee)
                .iter()
                .chain(&crate::sanity::angle_warnings(&setup.angles))
                .map(ToString::to_string)
                .collect(),
        };
        summary.set_results(results);
        summary
    }

    /// Sets what the summary says of `results` (every pitch's comparison,
    /// coarsest first): the fits, the pitch recommended at the summary's
    /// tolerance and its predicted time, the engine's seconds. A merge of
    /// shards sets them from the merged comparisons this way.
    pub fn set_results(&mut self, results: &[PitchResult]) {
        let recommended = self
            .tolerance_mm
            .and_then(|t| recommended_pitch(results, t));
        let full_angles = 61.0 / self.angles_deg.len() as f64;
        self.fits = fits(results)
            .into_iter()
            .filter_map(|(m, f)| f.map(|f| (m, f)))
            .collect();
        self.recommended_pitch_mm = recommended.map(|r| r.pitch);
        self.predicted_full_time_s = recommended.map(|r| r.seconds * full_angles);
        self.seconds = results.iter().map(|r| r.seconds).collect();
        self.verdicts = match self.tolerance_mm {
            Some(t) => results
                .iter()
                .map(|r| {
                    let (outcome, outcome_reason) = outcome_at(results, r, t);
                    PitchVerdict {
                        pitch_mm: r.pitch,
                        pass: outcome == Outcome::Pass,
                        outcome,
                        outcome_reason,
                        verdict: r.comparison.verdict(t),
                        failures: r.comparison.failures(t),
                    }
                })
                .collect(),
            None => Vec::new(),
        };
        // The starts are the same at every pitch: the coarsest pitch's
        // comparison says what they hold.
        self.warnings
            .retain(|w| !w.starts_with(super::verify::VERIFICATION_WARNING));
        if let Some(coarsest) = results.first() {
            self.warnings
                .extend(super::verify::comparison_warnings(&coarsest.comparison));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_power_law() {
        let points: Vec<(f64, f64)> = [8.0, 4.0, 2.0, 1.0]
            .iter()
            .map(|&p: &f64| (p, 0.3 * p.powf(1.7)))
            .collect();
        let fit = fit_power_law(&points).unwrap();
        assert!(
            (fit.alpha - 1.7).abs() < 1e-12 && (fit.c - 0.3).abs() < 1e-12,
            "{fit:?}"
        );
        assert_eq!(fit.points, 4);
        // Zero errors carry no order.
        assert!(fit_power_law(&[(8.0, 0.0), (4.0, 0.0), (2.0, 1.0)]).is_none());
        // Issue 24, item 5: rounding-level errors are exact, not an order.
        assert!(fit_power_law(&[(8.0, 2e-15), (4.0, 3e-15), (2.0, 4e-15)]).is_none());
    }
}
