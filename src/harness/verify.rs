//! `verify`'s own parts: its options, its summary (`verify.json`), the
//! starts it selects and the oracle's run with its predicted time. The
//! study itself runs on [`super::study`]'s one path; its result is what
//! `verify.csv` and `verify.json` hold ([`Verification`]).

use std::time::Instant;

use kneeform_oracle::{KneeFormDims, OracleOptions, StartTrace};
use serde::{Deserialize, Serialize};

use super::compare::{
    AreaDistance, CHAIN_BLOCK, Comparison, Counts, StartSelection, select_starts,
};
use super::error::HarnessError;
use super::method::MemoryLimit;
use super::metrics::{Stats, TieBand};
use crate::analysis::Progress;
use crate::grid::{GridSpec, HeightGrid};
use crate::input::PartFile;
use crate::kneeform::{GridFootprint, KneeForm};
use crate::mesh::Triangle;
use crate::setup::{GIB, Setup};
use crate::strike::Level;
use crate::summary::Outcome;

/// How to verify, beside the analysis [`Setup`].
#[derive(Debug, Clone, PartialEq)]
pub struct VerifyOptions {
    /// Which starts to compare.
    pub selection: StartSelection,
    /// The tie band's growth with the pitch ([`TieBand`], per mm).
    pub tie_band_per_mm: f64,
    /// The largest error allowed for every decided metric (mm).
    pub tolerance: f64,
    /// The longest the exact oracle may take (s): predicted from a sample
    /// of the starts traced first, beyond it the verification is refused
    /// naming the `--shard` count that would fit. Unbounded when `None`.
    pub budget_s: Option<f64>,
}

impl VerifyOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), HarnessError> {
        check_selection(&self.selection)?;
        check_tie_band(self.tie_band_per_mm)?;
        check_tolerance(self.tolerance)?;
        match self.budget_s {
            Some(b) if !(b.is_finite() && b > 0.0) => Err(HarnessError::Budget(b)),
            _ => Ok(()),
        }
    }
}

pub(super) fn check_selection(selection: &StartSelection) -> Result<(), HarnessError> {
    match *selection {
        StartSelection::Sample { count: 0, .. }
        | StartSelection::Runs { count: 0, .. }
        | StartSelection::Patches { count: 0, .. }
        | StartSelection::Patches { rows: 0, .. } => Err(HarnessError::EmptySample),
        StartSelection::Runs { length, .. } | StartSelection::Patches { length, .. }
            if !(1..=CHAIN_BLOCK).contains(&length) =>
        {
            Err(HarnessError::RunLength {
                length,
                max: CHAIN_BLOCK,
            })
        }
        StartSelection::At(ref starts) if starts.is_empty() => Err(HarnessError::EmptySample),
        StartSelection::Strip { z } if !(z[0].is_finite() && z[1].is_finite() && z[0] <= z[1]) => {
            Err(HarnessError::Strip(z))
        }
        _ => Ok(()),
    }
}

pub(super) fn check_tie_band(per_mm: f64) -> Result<(), HarnessError> {
    if per_mm.is_finite() && per_mm >= 0.0 {
        Ok(())
    } else {
        Err(HarnessError::TieBand(per_mm))
    }
}

pub(super) fn check_tolerance(tolerance: f64) -> Result<(), HarnessError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(HarnessError::Tolerance(tolerance))
    }
}

/// Everything `verify` computes, before it is written.
#[derive(Debug, Clone)]
pub struct Verification {
    /// The comparison: per-start rows, statistics, counts.
    pub comparison: Comparison,
    /// `verify.json`.
    pub summary: VerifySummary,
}

/// The oracle's options for a study whose finest pitch is `pitch` and whose
/// grid starts at `x_min` (mm).
pub fn oracle_options(knee: &KneeForm, pitch: f64, x_min: f64) -> OracleOptions {
    OracleOptions {
        knee_form: KneeFormDims {
            length: knee.triangle_side,
            radius: knee.radius,
            width: knee.thickness,
        },
        // SPEC: bisect where witnesses are further apart than a tenth of
        // the pitch checked.
        witness_tolerance: pitch / 10.0,
        // A witness beyond the grid's last column could not be met by it.
        x_min: x_min - pitch / 2.0,
        ..OracleOptions::default()
    }
}

/// `verify`'s default tolerance at `pitch` (mm): sqrt 2 pitches, rounded
/// up to the micrometre, the grid's sampling error at that pitch (a point
/// of the part lies up to that far from its nearest node). The sample
/// check of every analysis warns beyond it too.
pub fn sampling_tolerance(pitch: f64) -> f64 {
    (std::f64::consts::SQRT_2 * pitch * 1e6).ceil() / 1e6
}

/// The tie band's rule in words, for the summaries: under the window rule
/// (`window_mm`) the drop's band ([`super::metrics::ExactRule::Window`]),
/// under x-slope the rate's ([`TieBand`]).
pub(crate) fn tie_band_rule(per_mm: f64, window_mm: Option<f64>, level: Level) -> String {
    let both = match level {
        Level::Node => "",
        Level::Surface => {
            "; under --level surface the band is instead the grid's surface's own error, measured against the mesh, either way: a decided strike when the drop exceeds sigma x W by more than its error plus how far the surface may stand proud of the mesh within half a pitch of the contact W back and how far it lies below the touched point now (S - y there), plus the exact level's fall over one step (p / 8) W back; a decided non-strike when it falls short by more than its error plus the mirror terms (S - y W back, the surface standing proud near the contact now, the fall over a step now); the surface's error measured on the mesh sampled 8 times per pitch on each cell within half a pitch, unbounded on a cell where the grid has no surface over the mesh (the part's edge between its last node and the true edge) or a surface over no mesh"
        }
    };
    match window_mm {
        Some(w) => format!(
            "an exact contact is a decided strike when its drop over the last {w} mm exceeds sigma x {w} mm by more than its stated error plus how far the lowest node within sqrt 2 pitches of the touched point that the slide met by sqrt 2 pitches more of travel lies above it (the grid judges those nodes; none: undecided), a decided non-strike when it falls short by more than its error plus the bound of the grid's level error {w} mm back (the exact level's fall over the pitch before that travel plus the rise of the surface within sqrt 2 pitches of the exact contacts in force, unbounded where the slide met no node that near: the grid's level is deeper by at most that, which only ever adds strikes), undecided otherwise; a grid strike whose node lies within that bound of touching the exact knee-form, and whose drop the bound can explain, is the level error's (a false alarm on the safe side); disagreements from the exact knee-form's first touch of a flagged blind spot on are blind{both}"
        ),
        None => format!(
            "an exact contact is undecided when its deflection rate, widened by its rate_error, overlaps [sigma / (1 + m), sigma * (1 + m)] with m = {per_mm} x pitch (mm)"
        ),
    }
}

/// The starts of `selection` on `grid` (placed at one of `footprints` at
/// least), as positions (mm); an error when there is none.
pub(super) fn start_positions(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    selection: &StartSelection,
) -> Result<Vec<[f64; 2]>, HarnessError> {
    if let StartSelection::At(starts) = selection {
        // As given: the comparison says which are not nodes.
        return Ok(starts.clone());
    }
    let spec = grid.spec;
    let starts: Vec<[f64; 2]> = select_starts(grid, footprints, selection)
        .iter()
        .map(|&(i, j)| [spec.x(i), spec.z(j)])
        .collect();
    if starts.is_empty() {
        let placed = select_starts(grid, footprints, &StartSelection::All).len();
        return Err(super::compare::none_chosen(selection, placed));
    }
    Ok(starts)
}

/// The share of the start-angle pairs traced first to predict the
/// oracle's time: one in twenty, spread over the starts and angles.
const SAMPLE_EVERY: usize = 20;

/// The memory a study holds per exact contact of its traces, with the
/// comparison's per-strike distances and points (bytes): measured as peak
/// RSS over exact strikes on the console, 333 for one start row at four
/// angles (2.1 GB, 6.3 million strikes) and 326 for 20 rows at one angle
/// (10.7 GB, 32.8 million). Counted per contact (every strike is one), it
/// over-estimates a little.
const BYTES_PER_CONTACT: f64 = 340.0;

/// The oracle's traces of `starts` at `angles`, reported as one stage,
/// angle-major. A sample of the pairs, spread over the starts and angles,
/// is traced first: its time predicts the whole (said as a note), and a
/// prediction beyond `budget_s` (`limits.0`), or a predicted memory
/// beyond `limits.1`, is refused before the rest is traced.
pub(super) fn run_oracle(
    triangles: &[Triangle],
    starts: &[[f64; 2]],
    angles: &[f64],
    options: &OracleOptions,
    limits: (Option<f64>, Option<MemoryLimit>),
    progress: &dyn Progress,
) -> Result<(Vec<StartTrace>, f64), HarnessError> {
    let (budget_s, memory) = limits;
    let pairs = starts.len() * angles.len();
    let what = format!(
        "exact oracle: {} starts x {} angles",
        starts.len(),
        angles.len()
    );
    super::stage::in_stage(progress, &what, Some(pairs as u64), || {
        let t = Instant::now();
        let part = kneeform_oracle::Part::from_triangles(triangles)?;
        let trace = |pairs: &[(usize, usize)]| {
            kneeform_oracle::evaluate_pairs(&part, starts, angles, pairs, options, &|| {
                progress.step()
            })
        };
        // One pair in SAMPLE_EVERY, spread over the starts and the angles
        // (start s at angle a when (s + a) is a multiple of it: every
        // start at about one angle in twenty). The first starts alone (the
        // lowest start rows) predicted the console's 167 s as 44 s, every
        // twentieth start at every angle as 317 s: a trace's cost varies
        // more between starts than between angles.
        // Starts traced in chains along their rows are sampled a whole
        // chain at a time (by its first pair), so that no chain is traced
        // twice; without chains every pair is its own.
        let n = starts.len();
        let all: Vec<(usize, usize)> = (0..pairs).map(|k| (k % n, k / n)).collect();
        let groups = match options.chain {
            Some(chain) => kneeform_oracle::chain_groups(starts, &all, &chain),
            None => (0..pairs).map(|k| vec![k]).collect(),
        };
        let mut sampled = vec![false; pairs];
        for group in groups {
            let (s, a) = all[group[0]];
            if (s + a) % SAMPLE_EVERY == 0 {
                for k in group {
                    sampled[k] = true;
                }
            }
        }
        let pick = |want: bool| -> Vec<(usize, usize)> {
            (0..pairs)
                .filter(|&k| sampled[k] == want)
                .map(|k| all[k])
                .collect()
        };
        let (first, rest) = (pick(true), pick(false));
        let sample = trace(&first)?;
        let sample_s = t.elapsed().as_secs_f64();
        let predicted_s = sample_s * pairs as f64 / first.len().max(1) as f64;
        // The study's memory, predicted from the sample's contacts.
        let traces_need = memory.map(|memory| {
            let contacts: usize = sample.iter().map(|t| t.contacts.len()).sum();
            let traces = BYTES_PER_CONTACT * memory.pitches as f64 * contacts as f64 * pairs as f64
                / first.len().max(1) as f64;
            (traces, traces + memory.held_bytes)
        });
        if !rest.is_empty() {
            progress.note(&format!(
                "exact oracle: about {} for {pairs} start-angle pairs (predicted from {} of them spread over the starts and angles, {:.1} s){}",
                crate::limits::duration_words(predicted_s),
                first.len(),
                sample_s,
                traces_need.map_or(String::new(), |(_, need)| format!(
                    "; the study should hold about {:.2} GiB",
                    need / GIB
                ))
            ));
        }
        if let (Some(memory), Some((traces, need))) = (memory, traces_need) {
            let limit = match crate::memory::limit_bytes() {
                Some((machine, _)) => memory.bytes.min(machine),
                None => memory.bytes,
            };
            if need > limit {
                // Shards divide the traces; what every shard holds
                // whatever its starts (the part, the grids, the finer
                // bands) they do not.
                let room = limit - memory.held_bytes;
                return Err(HarnessError::StudyMemory {
                    need_gib: need / GIB,
                    held_gib: memory.held_bytes / GIB,
                    limit_gib: limit / GIB,
                    pairs,
                    shards: if room > 0.0 {
                        ((traces / room).ceil() as usize).clamp(2, starts.len().max(2))
                    } else {
                        0
                    },
                });
            }
        }
        if let Some(budget_s) = budget_s
            && predicted_s > budget_s
        {
            return Err(HarnessError::VerifyBudget {
                predicted_s,
                pairs,
                budget_s,
                shards: ((predicted_s / budget_s).ceil() as usize).clamp(2, starts.len().max(2)),
            });
        }
        let rest = trace(&rest)?;
        // Angle-major over every start, as `evaluate` orders them.
        let (mut sample, mut rest) = (sample.into_iter(), rest.into_iter());
        let traces = (0..pairs)
            .filter_map(|k| {
                if sampled[k] {
                    sample.next()
                } else {
                    rest.next()
                }
            })
            .collect();
        Ok((traces, t.elapsed().as_secs_f64()))
    })
}

impl VerifySummary {
    pub(super) fn new(
        input: &PartFile,
        setup: &Setup,
        options: &VerifyOptions,
        spec: &GridSpec,
        comparison: &Comparison,
        sample_s: f64,
        oracle_s: f64,
    ) -> VerifySummary {
        let (starts, seed) = selection_words(&options.selection);
        let mut summary = VerifySummary {
            run: super::identity::RunIdentity::of(input),
            pitch_mm: setup.pitch,
            tolerance_mm: options.tolerance,
            pass: false,
            outcome: Outcome::Inconclusive,
            outcome_reason: None,
            warnings: crate::sanity::part_warnings(&input.part, input.side, &setup.knee)
                .iter()
                .chain(&crate::sanity::angle_warnings(&setup.angles))
                .map(ToString::to_string)
                .collect(),
            verdict: String::new(),
            failures: Vec::new(),
            unexplained: Default::default(),
            oracle_failures: Default::default(),
            angles_deg: setup.angles.clone(),
            knee_form_mm: [
                setup.knee.triangle_side,
                setup.knee.radius,
                setup.knee.thickness,
            ],
            triangle_side_assumed: setup.knee.triangle_side == KneeForm::default().triangle_side,
            deflection_deg: setup.rule.deflection_deg(),
            sigma: setup.rule.sigma,
            e0_mm: setup.rule.e0,
            rate: setup.rule.rate.name().into(),
            level: setup.rule.level,
            window_mm: setup.rule.window_mm(),
            tie_band: comparison.band,
            tie_band_rule: tie_band_rule(
                options.tie_band_per_mm,
                setup.rule.window_mm(),
                setup.rule.level,
            ),
            area_distance_decided_mm: None,
            area_distance_mm: None,
            area_miss_decided_mm: None,
            area_false_alarm_decided_mm: None,
            area_distance: Vec::new(),
            undecided_area_mm2: None,
            undecided_nodes: None,
            starts,
            seed,
            metrics: std::collections::BTreeMap::new(),
            area_iou: 0.0,
            counts: Counts::default(),
            worst_starts: Vec::new(),
            timings: VerifyTimings {
                sample_s,
                grid_s: comparison.grid_s,
                oracle_s,
            },
            oracle_chain: super::compare::chain_of(&options.selection, setup.pitch),
        };
        summary.set_comparison(comparison, spec);
        summary
    }

    /// Sets what the summary says of `comparison` (on the grid `spec`):
    /// pass or fail at the summary's tolerance, the area distances, the
    /// statistics, counts and worst starts, and the grid side's seconds.
    /// A merge of shards sets them from the merged comparison this way.
    pub fn set_comparison(&mut self, comparison: &Comparison, spec: &GridSpec) {
        let (outcome, why) = comparison.outcome(self.tolerance_mm, 1);
        self.outcome = outcome;
        self.outcome_reason = why;
        self.pass = outcome == Outcome::Pass;
        self.warnings
            .retain(|w| !w.starts_with(VERIFICATION_WARNING));
        self.warnings.extend(comparison_warnings(comparison));
        self.verdict = comparison.verdict(self.tolerance_mm);
        self.failures = comparison.failures(self.tolerance_mm);
        self.unexplained = comparison.unexplained;
        self.oracle_failures = comparison.oracle_failures();
        self.tie_band = comparison.band;
        self.area_distance_decided_mm =
            Some(comparison.stat("area_distance_decided").max).filter(|_| {
                comparison
                    .area
                    .iter()
                    .all(|a| a.miss_decided.is_finite() && a.false_alarm_decided.is_finite())
            });
        self.area_distance_mm = Some(comparison.stat("area_distance").max).filter(|_| {
            comparison
                .area
                .iter()
                .all(|a| a.miss.is_finite() && a.false_alarm.is_finite())
        });
        self.area_distance = comparison.area.clone();
        let worst = |f: fn(&AreaDistance) -> f64| {
            let v = comparison.area.iter().map(f).fold(0.0, f64::max);
            v.is_finite().then_some(v)
        };
        let undecided = crate::zones::NodeRuns::of(&comparison.undecided_nodes, spec);
        self.undecided_area_mm2 = Some(undecided.area_mm2());
        self.undecided_nodes = Some(undecided);
        self.area_miss_decided_mm = worst(|a| a.miss_decided);
        self.area_false_alarm_decided_mm = worst(|a| a.false_alarm_decided);
        self.metrics = comparison.stats.iter().cloned().collect();
        self.area_iou = comparison.area_iou;
        self.counts = comparison.counts;
        self.worst_starts = comparison
            .worst(
                10,
                &self
                    .failures
                    .iter()
                    .filter(|f| f.fails_verdict)
                    .map(|f| (f.metric.as_str(), f.value.unwrap_or(f64::INFINITY)))
                    .collect::<Vec<(&str, f64)>>(),
            )
            .into_iter()
            .map(|(row, metric, value)| WorstStart {
                i: row.i,
                j: row.j,
                x: spec.x(row.i),
                z: spec.z(row.j),
                angle_deg: row.angle_deg,
                metric,
                value,
                at: row.worst_x.zip(row.worst_z).map(|(x, z)| [x, z]),
            })
            .collect();
        self.timings.grid_s = comparison.grid_s;
    }
}

impl VerifySummary {
    /// The sentence a user signs (SPEC, "The verdict"): the outcome with
    /// its tolerance and pitch, the sample, the undecided contacts and how
    /// far they may move the area's boundary, the cost side, the blind
    /// spots met, and the knee-form's L, marked assumed where it is.
    pub fn sentence(&self) -> String {
        let short = crate::limits::short;
        let mm = |v: Option<f64>| v.map_or("infinite".to_string(), |v| format!("{v:.3} mm"));
        let c = &self.counts;
        let judged = match self.outcome {
            Outcome::Inconclusive => format!(
                "no claim ({})",
                self.outcome_reason
                    .as_deref()
                    .unwrap_or("the evidence is too thin")
            ),
            Outcome::Pass => format!(
                "every decided exact strike away from blind spots lies within {} of the grid's colliding area (the analysis's, every start's strikes; worst angle)",
                mm(self.area_miss_decided_mm)
            ),
            Outcome::Fail => format!(
                "a decided exact strike lies {} from the grid's colliding area (the analysis's, every start's strikes; worst angle)",
                mm(self.area_miss_decided_mm)
            ),
        };
        let decided_and_undecided = c.exact_strikes_decided + c.exact_undecided;
        let share = if decided_and_undecided == 0 {
            0.0
        } else {
            100.0 * c.exact_undecided as f64 / decided_and_undecided as f64
        };
        format!(
            "{} at tolerance {} mm, pitch {} mm: {judged}; sample: {} start-angle pairs ({} starts), {} decided exact strikes; undecided: {} exact contacts ({share:.0}% of the decided strikes and undecided contacts) at {} of the grid's nodes ({} mm^2), which may move the area's boundary by up to {} (the all-strikes area distance); cost: the grid's area reaches {} beyond the exact one (decided area false-alarm distance); blind spots: {} pairs touched one ({} exact strikes judged apart); knee-form L = {} mm{}",
            self.outcome.word(),
            short(self.tolerance_mm),
            short(self.pitch_mm),
            c.pairs,
            self.starts,
            c.exact_strikes_decided,
            c.exact_undecided,
            self.undecided_nodes.as_ref().map_or(0, |n| n.nodes),
            self.undecided_area_mm2.map_or("unknown".to_string(), short),
            mm(self.area_distance_mm),
            mm(self.area_false_alarm_decided_mm),
            c.blind_pairs,
            c.blind_strikes,
            short(self.knee_form_mm[0]),
            if self.triangle_side_assumed {
                " (ASSUMED: set it with --triangle-side)"
            } else {
                " (given)"
            }
        )
    }
}

/// How the warnings a comparison gives begin, apart from the part's (which
/// a shard's summary knows before its comparison is merged).
pub(super) const VERIFICATION_WARNING: &str = "verification: ";

/// The warnings of `comparison`, each beginning [`VERIFICATION_WARNING`]:
/// what a reader must know before reading its outcome.
pub(super) fn comparison_warnings(comparison: &Comparison) -> Vec<String> {
    let c = &comparison.counts;
    let mut warnings = Vec::new();
    // (A share's summary, before its pairs are merged, compared none.)
    if c.pairs == 0 {
        return warnings;
    }
    if c.exact_strikes == 0 {
        let grid = comparison.rows.iter().any(|r| r.grid_colliding > 0);
        warnings.push(format!(
            "{VERIFICATION_WARNING}the exact knee-form strikes nothing on these starts{}: a verification with nothing to miss proves nothing (a part smaller than the knee-form, or its surface on the other side: see --scale and --side)",
            if grid { "" } else { ", nor does the grid" }
        ));
    }
    if c.exact_strikes > 0 && c.exact_strikes_decided == 0 {
        warnings.push(format!(
            "{VERIFICATION_WARNING}none of the {} exact strikes on these starts is decided (each within the tie band of the threshold, or blind): the area miss distance is measured from nothing",
            c.exact_strikes
        ));
    }
    if c.oracle_failed > 0 {
        warnings.push(format!(
            "{VERIFICATION_WARNING}the exact oracle failed on {} start-angle pairs: they are counted as failures, never as clear",
            c.oracle_failed
        ));
    }
    if c.blind_pairs > 0 {
        warnings.push(format!(
            "{VERIFICATION_WARNING}{} start-angle pairs touched a flagged blind spot: their {} exact strikes from there on are blind, judged apart",
            c.blind_pairs, c.blind_strikes
        ));
    }
    warnings
}

/// `selection` as `verify.json` says it: `all`, the sample size,
/// `strip:Z0:Z1`, `runs:N:L` or `N given`; and the sample's seed (0 for
/// no sample).
pub(super) fn selection_words(selection: &StartSelection) -> (String, u64) {
    match *selection {
        StartSelection::All => ("all".into(), 0),
        StartSelection::Sample { count, seed } => (count.to_string(), seed),
        StartSelection::Strip { z } => (
            format!(
                "strip:{}:{}",
                crate::limits::echo(z[0]),
                crate::limits::echo(z[1])
            ),
            0,
        ),
        StartSelection::Runs {
            count,
            length,
            seed,
        } => (format!("runs:{count}:{length}"), seed),
        StartSelection::Patches {
            count,
            length,
            rows,
            seed,
        } => (format!("patches:{count}:{length}:{rows}"), seed),
        StartSelection::At(ref starts) => (format!("{} given", starts.len()), 0),
    }
}

/// `verify.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerifySummary {
    /// Which part, read how, by which kneeform: the same record, in the
    /// same order, in every study's JSON.
    #[serde(flatten)]
    pub run: super::identity::RunIdentity,
    /// Grid pitch (mm).
    pub pitch_mm: f64,
    /// The tolerance every metric's max is held to (mm).
    pub tolerance_mm: f64,
    /// Whether no failing figure fails the verdict: every decided figure
    /// away from blind spots within tolerance or explained by the grid's
    /// level error, no oracle failure, nothing contradictory (undecided
    /// and blind disagreements are reported in `failures`, never failing).
    pub pass: bool,
    /// SPEC's verdict: `PASS`, `FAIL` (the decided, non-blind area miss
    /// distance at the worst angle beyond the tolerance) or `INCONCLUSIVE`
    /// (the evidence cannot support a claim: `outcome_reason` says why).
    /// `pass` is whether it is `PASS`.
    #[serde(default = "inconclusive")]
    pub outcome: Outcome,
    /// Why the outcome is `INCONCLUSIVE`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome_reason: Option<String>,
    /// What a reader must know before the outcome, one line each: the
    /// part's sanity checks (units, facing side, angles) and the
    /// comparison's (nothing struck, oracle failures, blind spots met).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The verdict in words: misses (safety) and false alarms (cost)
    /// apart, each failing figure with its mechanism.
    #[serde(default)]
    pub verdict: String,
    /// Every figure beyond the tolerance: `metric`, `value`, `mechanism`
    /// (`blind`, `level-error`, `undecided`, `oracle-failure`, `rim` or
    /// `unexplained`), `side` and whether it fails the verdict.
    #[serde(default)]
    pub failures: Vec<crate::harness::causes::Failure>,
    /// The figures the level error can explain, over what it does not.
    #[serde(default)]
    pub unexplained: crate::harness::compare::Unexplained,
    /// The oracle's failures by reason (pairs each; never counted clear).
    #[serde(default)]
    pub oracle_failures: std::collections::BTreeMap<String, usize>,
    /// Angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Knee-form L, R, W (mm).
    pub knee_form_mm: [f64; 3],
    /// True when L is the assumed default of 200 mm (as `summary.json`'s).
    #[serde(default)]
    pub triangle_side_assumed: bool,
    /// Deflection threshold delta (degrees).
    pub deflection_deg: f64,
    /// The same threshold as a rate, `sigma = tan(delta)`.
    pub sigma: f64,
    /// Rounding tolerance e0 (mm).
    pub e0_mm: f64,
    /// How the grid's deflection is measured (`window` or `x-slope`).
    pub rate: String,
    /// The level the grid's knee-form follows: `node` or `surface`
    /// (SPEC v4); `node` in files of earlier versions.
    #[serde(default)]
    pub level: crate::strike::Level,
    /// The deflection window (mm) of the `window` rule.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_mm: Option<f64>,
    /// The tie band at this pitch: `sigma`, `m`, and its bounds as rates.
    pub tie_band: TieBand,
    /// The tie band's rule, in words.
    pub tie_band_rule: String,
    /// The headline: the area distance, decided (mm; `null` if infinite).
    pub area_distance_decided_mm: Option<f64>,
    /// The area distance over all strikes (mm; `null` if infinite): how
    /// far the undecided contacts may move the area's boundary.
    pub area_distance_mm: Option<f64>,
    /// The figure the outcome judges: the decided, non-blind area miss
    /// distance at the worst angle (mm; `null` if infinite: a decided
    /// exact strike at an angle where the grid strikes nothing).
    #[serde(default)]
    pub area_miss_decided_mm: Option<f64>,
    /// The cost side beside it: the decided area false-alarm distance at
    /// the worst angle, how far the grid's area reaches beyond the exact
    /// one (mm; `null` if infinite).
    #[serde(default)]
    pub area_false_alarm_decided_mm: Option<f64>,
    /// The area distance per angle.
    pub area_distance: Vec<AreaDistance>,
    /// Where the grid's boundary is undecided, as an area (mm^2): the
    /// nodes of `undecided_nodes` times the pitch squared (`null` in files
    /// of earlier versions).
    #[serde(default)]
    pub undecided_area_mm2: Option<f64>,
    /// The nodes of the verified grid nearest an undecided exact contact,
    /// over every pair and angle, as row runs in lattice indices
    /// ([`crate::zones::NodeRuns`]: `x = column x pitch`,
    /// `z = row x pitch`, mm, analysis frame).
    #[serde(default)]
    pub undecided_nodes: Option<crate::zones::NodeRuns>,
    /// `all`, or the sample size.
    pub starts: String,
    /// The sample's seed.
    pub seed: u64,
    /// Per metric: max, p95, mean over the values (mm).
    pub metrics: std::collections::BTreeMap<String, Stats>,
    /// Grid mask against exact contacts snapped to nodes.
    pub area_iou: f64,
    /// Counts.
    pub counts: Counts,
    /// The worst start-angle pairs.
    pub worst_starts: Vec<WorstStart>,
    /// Seconds on each side.
    pub timings: VerifyTimings,
    /// How the exact traces were shared between the starts of a row (a
    /// strip's: [`kneeform_oracle::Chain`]); absent where each start was
    /// traced on its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oracle_chain: Option<kneeform_oracle::Chain>,
}

/// What a file written before outcomes were recorded is read as: it
/// claimed on evidence no minimum was held to.
pub(super) fn inconclusive() -> Outcome {
    Outcome::Inconclusive
}

/// One of the worst start-angle pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstStart {
    /// Grid column.
    pub i: usize,
    /// Grid row.
    pub j: usize,
    /// Start position x (mm, analysis frame).
    pub x: f64,
    /// Start position z (mm).
    pub z: f64,
    /// Angle (degrees).
    pub angle_deg: f64,
    /// The metric that is worst there.
    pub metric: String,
    /// Its value (mm).
    pub value: f64,
    /// Where the disagreement lies, `[x, z]` (mm, analysis frame): the
    /// missed exact strike or the false-alarm grid strike.
    pub at: Option<[f64; 2]>,
}

/// Seconds spent by each side.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct VerifyTimings {
    /// Sampling the grid.
    pub sample_s: f64,
    /// Grid push and slide of the compared starts.
    pub grid_s: f64,
    /// The oracle's traces.
    pub oracle_s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{axis, tessellate};

    #[test]
    fn a_study_beyond_its_memory_is_refused_naming_the_shards_that_fit() {
        // A wall rising towards the knee ahead of the slide (y = x / 5),
        // 300 x 200 mm: every slide is deflected. Two starts, one angle.
        let (xs, zs) = (
            axis((-150.0, 150.0), 10.0, &[]),
            axis((-100.0, 100.0), 10.0, &[]),
        );
        let tris = tessellate(&xs, &zs, |i, _| 0.2 * xs[i]);
        let starts = [[0.0, 0.0], [20.0, 10.0]];
        let options = oracle_options(&KneeForm::default(), 4.0, -150.0);
        let run = |bytes: f64| {
            let memory = MemoryLimit {
                bytes,
                pitches: 1,
                held_bytes: 0.0,
            };
            run_oracle(&tris, &starts, &[0.0], &options, (None, Some(memory)), &())
        };
        match run(1.0) {
            Err(HarnessError::StudyMemory { pairs, shards, .. }) => {
                assert_eq!((pairs, shards), (2, 2));
            }
            other => panic!("not refused: {other:?}"),
        }
        let (traces, _) = run(1e12).unwrap();
        assert_eq!(traces.len(), 2);
        assert!(traces.iter().all(|t| !t.contacts.is_empty()));
    }
}
