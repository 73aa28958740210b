//! Push-and-slide's studies (SPEC's verification and convergence of the
//! grid engine against the exact oracle): what the one study path
//! ([`super::study`]) asks of the approach ([`StudyApproach`]), its pairs
//! in a shard's `shard.bin`, and its results' files and words. Its steps
//! are [`super::converge::Ladder`]'s, its comparison `compare`'s and
//! `metrics`'.

use std::path::Path;

use kneeform_oracle::FailureReason;

use super::approach::{
    LogLogPlot, PlotLine, Said, ShareKnown, Study, StudyApproach, StudyFile, StudyOptions,
    StudyResult,
};
use super::codec::{Reader, put_f64s, put_nodes, put_opt, put_points, put_u64};
use super::compare::{PairResult, STATUSES, assemble, row_of};
use super::converge::{ConvergeSummary, Convergence, Ladder, PitchResult, fits};
use super::error::HarnessError;
use super::method::Method;
use super::metrics::{DECIDED_METRICS, StartComparison, StartPoints};
use super::pairs::{Pair, Pairs, read_each};
use super::sharded::{
    KnownSummary, StudyKind, StudyPart, StudySummary, merged_pitches, only, oracle_s, read_summary,
};
use super::trace::Fault;
use super::verify::{Verification, VerifySummary};
use crate::frame::Approach;
use crate::input::PartFile;
use crate::limits::short;
use crate::setup::Setup;
use crate::summary::Outcome;

/// Push-and-slide's studies.
pub(crate) struct Slide;

impl StudyApproach for Slide {
    fn approach(&self) -> Approach {
        Approach::Slide
    }

    fn kind_word(&self, kind: StudyKind) -> &'static str {
        match kind {
            StudyKind::Verify => "verify",
            StudyKind::Converge => "converge",
        }
    }

    fn refinement_bytes(&self, setup: &Setup, spec: &crate::grid::GridSpec, threads: usize) -> f64 {
        super::compare::refinement_bytes(*spec, &setup.knee, &setup.angles, threads)
    }

    fn shard_words(&self, kind: StudyKind) -> &'static str {
        match kind {
            StudyKind::Verify => "a verification (verify --shard)",
            StudyKind::Converge => "a convergence study (converge --shard)",
        }
    }

    fn lay<'a>(
        &self,
        input: &'a PartFile,
        coarse: &Setup,
        options: StudyOptions,
        fault: Option<Fault>,
    ) -> Result<Box<dyn Method + 'a>, HarnessError> {
        let ladder = Ladder::lay(
            input,
            coarse,
            options.selection(),
            options.tie_band_per_mm(),
            fault,
        )?;
        Ok(Box::new(ladder))
    }

    fn summary_as_known(&self, share: ShareKnown) -> StudySummary {
        let ShareKnown {
            input,
            setup,
            options,
            coarse,
            starts,
            parts,
            sample_s,
            oracle_s,
        } = share;
        match options {
            StudyOptions::Verify(o) => {
                // A verification compares one pitch.
                let pitch = &parts[0];
                let none = assemble(Vec::new(), &setup.angles, pitch.band, 0.0, &[]);
                let mut s = VerifySummary::new(input, setup, o, coarse, &none, sample_s, oracle_s);
                s.timings.grid_s = pitch.grid_s;
                StudySummary::new(self.named(StudyKind::Verify), s)
            }
            StudyOptions::Converge(o) => {
                let s = ConvergeSummary::new(input, setup, o, starts, &[]);
                StudySummary::new(self.named(StudyKind::Converge), s)
            }
        }
    }

    fn summary_from_json(
        &self,
        kind: StudyKind,
        json: serde_json::Value,
    ) -> Result<Box<dyn KnownSummary>, String> {
        match kind {
            StudyKind::Verify => read_summary::<VerifySummary>(json),
            StudyKind::Converge => read_summary::<ConvergeSummary>(json),
        }
    }

    fn merged_fields(&self, kind: StudyKind) -> serde_json::Value {
        match kind {
            StudyKind::Verify => serde_json::json!({
                "pass": false,
                "outcome": "INCONCLUSIVE",
                "outcome_reason": null,
                "area_distance_decided_mm": null,
                "area_distance_mm": null,
                "area_miss_decided_mm": null,
                "area_false_alarm_decided_mm": null,
                "area_distance": [],
                "metrics": {},
                "area_iou": 0.0,
                "counts": super::compare::Counts::default(),
                "worst_starts": [],
                "undecided_area_mm2": null,
                "undecided_nodes": null,
            }),
            StudyKind::Converge => serde_json::json!({
                "fits": {},
                "recommended_pitch_mm": null,
                "predicted_full_time_s": null,
                "seconds": [],
            }),
        }
    }

    fn clock_fields(&self, kind: StudyKind) -> &'static [&'static str] {
        match kind {
            StudyKind::Verify => &["timings"],
            StudyKind::Converge => &[],
        }
    }

    fn read_pairs(
        &self,
        r: &mut Reader,
        count: usize,
        at: &dyn Fn(usize) -> ([f64; 2], f64),
    ) -> Result<Pairs, String> {
        read_each(count, |k| read_pair(r, at(k).1))
    }

    fn merge(&self, summary: StudySummary, parts: &mut [StudyPart]) -> Option<Study> {
        let first = parts.first()?;
        let (angles, spec) = (first.angles_deg.clone(), first.spec);
        let oracle_s = oracle_s(parts);
        let sample_s = parts.iter().map(|p| p.sample_s).fold(0.0, f64::max);
        let results = merged_pitches(parts, |clocks, pairs| PitchResult {
            pitch: clocks.pitch,
            comparison: assemble(pairs, &angles, clocks.band, clocks.grid_s, &clocks.covering),
            seconds: clocks.seconds,
            nodes: clocks.nodes,
        })?;
        Some(match summary.kind {
            StudyKind::Verify => {
                let mut summary = summary.take::<VerifySummary>()?;
                let result = only(results)?;
                summary.set_comparison(&result.comparison, &spec);
                summary.timings.sample_s = sample_s;
                summary.timings.oracle_s = oracle_s;
                Study::of(Verification {
                    comparison: result.comparison,
                    summary,
                })
            }
            StudyKind::Converge => {
                let mut summary = summary.take::<ConvergeSummary>()?;
                summary.set_results(&results);
                Study::of(Convergence {
                    fits: fits(&results),
                    results,
                    summary,
                    oracle_s,
                })
            }
        })
    }
}

impl KnownSummary for VerifySummary {
    fn angles_and_pitches(&self) -> (&[f64], Vec<f64>) {
        (&self.angles_deg, vec![self.pitch_mm])
    }
}

impl KnownSummary for ConvergeSummary {
    fn angles_and_pitches(&self) -> (&[f64], Vec<f64>) {
        (&self.angles_deg, self.pitches_mm.clone())
    }
}

/// A verification's files: `verify.csv` (one row per start and angle) and
/// `verify.json`.
impl StudyResult for Verification {
    fn files(&self) -> Vec<StudyFile<'_>> {
        StudyFile::verification(&self.comparison.rows, &self.summary)
    }

    fn said(&self, out: &Path) -> Said {
        verification_said(self, out)
    }
}

/// A convergence study's files: `converge.csv` (every metric at every
/// pitch), `verify_<pitch>mm.csv` (each pitch's per-start rows, as
/// `verify.csv` has them: where each figure of `converge.csv` comes
/// from), `converge.json` and the plots.
impl StudyResult for Convergence {
    fn files(&self) -> Vec<StudyFile<'_>> {
        let results = &self.results;
        let tolerance = self.summary.tolerance_mm;
        let table = move |csv: &mut csv::Writer<&mut dyn std::io::Write>| {
            csv.write_record([
                "pitch_mm", "metric", "max", "p95", "mean", "n", "seconds", "area_iou", "pass",
            ])?;
            for r in results {
                let pass = tolerance.map_or(String::new(), |t| {
                    (super::converge::outcome_at(results, r, t).0 == Outcome::Pass).to_string()
                });
                for (metric, s) in &r.comparison.stats {
                    csv.write_record([
                        r.pitch.to_string(),
                        metric.clone(),
                        s.max.to_string(),
                        s.p95.to_string(),
                        s.mean.to_string(),
                        s.n.to_string(),
                        r.seconds.to_string(),
                        r.comparison.area_iou.to_string(),
                        pass.clone(),
                    ])?;
                }
            }
            Ok(())
        };
        let pitches = results.iter().map(|r| (r.pitch, &r.comparison.rows[..]));
        let mut files = StudyFile::convergence(table, pitches, &self.summary);
        files.extend(plots(results, &self.fits).map(StudyFile::Plot));
        files
    }

    fn said(&self, out: &Path) -> Said {
        convergence_said(self, out)
    }

    fn oracle_line(&self, angles: usize) -> Option<String> {
        Some(format!(
            "exact oracle: {} starts x {} angles in {:.1} s",
            self.summary.starts, angles, self.oracle_s
        ))
    }
}

/// `v` to two decimal places, never `-0.00` (a fitted order of -0.001).
fn two_places(v: f64) -> String {
    let text = format!("{v:.2}");
    if text == "-0.00" {
        "0.00".to_string()
    } else {
        text
    }
}

/// A convergence study's plots: the log-log error plot (one series per
/// decided metric, its fitted order in the legend: the guarantee a user
/// reads) and the engine's time against the pitch.
fn plots(
    results: &[PitchResult],
    fits: &[(String, Option<super::converge::Fit>)],
) -> [LogLogPlot; 2] {
    let pitches: Vec<f64> = results.iter().map(|r| r.pitch).collect();
    let positive: Vec<f64> = results
        .iter()
        .flat_map(|r| r.comparison.stats.iter().map(|s| s.1.max))
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    let (emin, emax) = (
        positive
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
            .min(1e-3),
        positive.iter().copied().fold(0.0, f64::max).max(1e-2),
    );
    let series = fits
        .iter()
        .enumerate()
        .filter(|(_, (m, _))| DECIDED_METRICS.contains(&m.as_str()))
        .map(|(k, (metric, fit))| {
            let label = match fit {
                Some(f) => format!("{metric}: alpha = {}", two_places(f.alpha)),
                None => format!("{metric}: no fit"),
            };
            let points = results
                .iter()
                .map(|r| (r.pitch, r.comparison.stats[k].1.max))
                .filter(|(_, e)| *e > 0.0 && e.is_finite())
                .collect();
            PlotLine {
                label: Some(label),
                points,
            }
        })
        .collect();
    let times: Vec<(f64, f64)> = results
        .iter()
        .map(|r| (r.pitch, r.seconds.max(1e-4)))
        .collect();
    let (tmin, tmax) = (
        times.iter().map(|t| t.1).fold(f64::INFINITY, f64::min),
        times.iter().map(|t| t.1).fold(0.0, f64::max),
    );
    [
        LogLogPlot {
            file: "error_vs_pitch.png",
            caption: "Grid vs exact, decided strikes: largest error against pitch (log-log)",
            x_desc: "pitch (mm)",
            y_desc: "max error (mm)",
            pitches: pitches.clone(),
            values: emin / 2.0..emax * 2.0,
            series,
        },
        LogLogPlot {
            file: "time_vs_pitch.png",
            caption: "Engine time against pitch (log-log)",
            x_desc: "pitch (mm)",
            y_desc: "push + slide, study angles (s)",
            pitches,
            values: tmin / 2.0..tmax * 2.0,
            series: vec![PlotLine {
                label: None,
                points: times,
            }],
        },
    ]
}

/// A pair in `shard.bin`: status, node, then its comparison's values and
/// points, the grid's nodes, the snapped exact strikes and the nodes of
/// the undecided contacts (the row is
/// rebuilt from them by [`row_of`], as the comparison builds it;
/// [`read_pair`] reads it back).
impl Pair for PairResult {
    fn put(&self, out: &mut Vec<u8>) {
        let pair = self;
        let status = STATUSES
            .iter()
            .position(|s| *s == pair.row.status)
            .unwrap_or(STATUSES.len());
        out.push(status as u8);
        put_u64(out, pair.row.i as u64);
        put_u64(out, pair.row.j as u64);
        let c = &pair.cmp;
        for v in [
            c.push_error,
            c.first_contact_error,
            c.first_contact_error_decided,
            c.first_contact_error_blind,
            c.first_contact_late_inside,
            c.miss_half_pitch,
            c.miss_quarter_pitch,
        ] {
            put_opt(out, v);
        }
        out.push(flags(c));
        out.push(c.oracle_failure.map_or(0, |r| 1 + failure_index(r)));
        for v in [
            &c.miss,
            &c.miss_decided,
            &c.miss_blind,
            &c.false_alarm,
            &c.false_alarm_decided,
            &c.false_alarm_blind,
            &c.unmatched_deflection,
            &c.unmatched_deflection_decided,
            &c.unmatched_deflection_inside,
            &c.unmatched_deflection_blind,
            &c.level_clearance,
            &c.level_bound,
        ] {
            put_f64s(out, v);
        }
        for flags in [&c.false_alarm_explained, &c.miss_rim, &c.miss_brief] {
            put_u64(out, flags.len() as u64);
            out.extend(flags.iter().map(|&b| u8::from(b)));
        }
        put_u64(out, c.exact_strikes as u64);
        put_u64(out, c.undecided as u64);
        put_u64(out, c.blind_strikes as u64);
        for v in c.points.sets() {
            put_points(out, v);
        }
        put_nodes(out, &pair.grid_nodes);
        put_nodes(out, &pair.snapped);
        put_nodes(out, &pair.undecided);
    }
}

/// The oracle's failure reasons, in the order a shard's file numbers them
/// (from 1; 0 is no failure).
const FAILURE_REASONS: [FailureReason; 5] = [
    FailureReason::CastNotConverged,
    FailureReason::UnconfirmedMiss,
    FailureReason::PenetratingStart,
    FailureReason::CastBudgetExhausted,
    FailureReason::Unsupported,
];

fn failure_index(reason: FailureReason) -> u8 {
    FAILURE_REASONS
        .iter()
        .position(|&r| r == reason)
        .map_or(u8::MAX, |k| k as u8)
}

/// A pair's yes-no facts, one bit each: whether its exact knee-form
/// touched a blind spot, its push contact lies on one, its push error and
/// its first grid strike are explained by the level error.
fn flags(c: &StartComparison) -> u8 {
    u8::from(c.blind)
        | u8::from(c.push_blind) << 1
        | u8::from(c.push_explained) << 2
        | u8::from(c.first_contact_explained) << 3
}

/// A pair as [`PairResult`]'s [`Pair::put`] wrote it, at `angle_deg`.
fn read_pair(r: &mut Reader, angle_deg: f64) -> Result<PairResult, String> {
    let status = *STATUSES
        .get(usize::from(r.u8()?))
        .ok_or("a start-angle pair of unknown status")?;
    let (i, j) = (r.len()?, r.len()?);
    let (push_error, first_contact_error, first_contact_error_decided) =
        (r.opt()?, r.opt()?, r.opt()?);
    let first_contact_error_blind = r.opt()?;
    let first_contact_late_inside = r.opt()?;
    let (miss_half_pitch, miss_quarter_pitch) = (r.opt()?, r.opt()?);
    let flags = r.u8()?;
    if flags >> 4 != 0 {
        return Err(format!("pair flags {flags}"));
    }
    let oracle_failure = match r.u8()? {
        0 => None,
        k => Some(
            *FAILURE_REASONS
                .get(usize::from(k) - 1)
                .ok_or_else(|| format!("an oracle failure reason {k}"))?,
        ),
    };
    let mut cmp = StartComparison {
        push_error,
        push_blind: flags & 2 != 0,
        push_explained: flags & 4 != 0,
        first_contact_error,
        first_contact_error_decided,
        first_contact_error_blind,
        first_contact_explained: flags & 8 != 0,
        first_contact_late_inside,
        miss: r.f64s()?,
        miss_decided: r.f64s()?,
        miss_blind: r.f64s()?,
        false_alarm: r.f64s()?,
        false_alarm_decided: r.f64s()?,
        false_alarm_blind: r.f64s()?,
        unmatched_deflection: r.f64s()?,
        unmatched_deflection_decided: r.f64s()?,
        unmatched_deflection_inside: r.f64s()?,
        unmatched_deflection_blind: r.f64s()?,
        level_clearance: r.f64s()?,
        level_bound: r.f64s()?,
        false_alarm_explained: r.bools()?,
        miss_rim: r.bools()?,
        miss_brief: r.bools()?,
        miss_half_pitch,
        miss_quarter_pitch,
        oracle_failure,
        exact_strikes: r.len()?,
        undecided: r.len()?,
        blind: flags & 1 != 0,
        blind_strikes: r.len()?,
        points: StartPoints::default(),
    };
    for set in cmp.points.sets_mut() {
        *set = r.points()?;
    }
    Ok(PairResult {
        row: row_of(i, j, angle_deg, status, &cmp),
        cmp,
        grid_nodes: r.nodes()?,
        snapped: r.nodes()?,
        undecided: r.nodes()?,
    })
}

/// What would resolve a failure, in words: the pitch a first-order error
/// (`error ~ C p`, what the evidence in `results/` shows for push, miss and
/// first contact on smooth parts) would need; a disagreement where the grid
/// strikes nothing, or one that is not first order, may need more, which
/// `kneeform converge` measures.
fn resolving_pitch(pitch: f64, tolerance: f64, metric: &str, value: f64) -> String {
    if !(value.is_finite() && value > tolerance) {
        return String::new();
    }
    let what = if metric.starts_with("unmatched_deflection") {
        "the grid strikes nothing where the exact knee-form is deflected: a feature narrower than the pitch (a rib, an edge, a boss) that no node samples; "
    } else {
        ""
    };
    let mut p = pitch;
    while p * value / pitch > tolerance && p > pitch / 8.0 {
        p /= 2.0;
    }
    if p * value / pitch > tolerance {
        // More than a factor 8 in pitch: not a sampling error a finer grid
        // removes at a usable cost.
        return format!(
            "; {what}{value:.1} mm is no sampling error: at first order it would need a pitch below {:.3} mm; see results/README.md (thin features, grazing flanks, crests crossed nearly level) and `kneeform converge` on this part",
            pitch * tolerance / value
        );
    }
    format!(
        "; {what}if the error is first order in the pitch, {p} mm would bring it within {tolerance} mm (`kneeform converge --pitches {pitch},{p}` measures it)"
    )
}

/// What a verification says: its statistics, counts and verdict (its
/// results are in `out`); it passes as its summary does.
fn verification_said(result: &Verification, out: &Path) -> Said {
    let s = &result.summary;
    let mut lines = Vec::new();
    for name in super::metrics::METRICS {
        let stats = &s.metrics[name];
        lines.push(format!(
            "{name:>29}: max {:.4}  p95 {:.4}  mean {:.4} mm  (n = {})",
            stats.max, stats.p95, stats.mean, stats.n
        ));
    }
    let c = &s.counts;
    let reasons: Vec<String> = s
        .oracle_failures
        .iter()
        .map(|(why, n)| format!("{n}: {why}"))
        .collect();
    lines.push(format!(
        "{:>29}: {:.3} (exact strikes snapped to their nearest nodes: blind to differences under half a pitch; the area distance measures them); {} start-angle pairs compared, {} oracle failures{}",
        "area IoU",
        s.area_iou,
        c.compared,
        c.oracle_failed,
        if reasons.is_empty() {
            String::new()
        } else {
            format!(" ({})", reasons.join("; "))
        }
    ));
    let band = match s.window_mm {
        Some(w) => format!(
            "drop over {} mm within its bound of sigma x {} mm",
            short(w),
            short(w)
        ),
        None => format!(
            "deflection rate in [{:.3}, {:.3}] deg",
            s.tie_band.bounds().0.atan().to_degrees(),
            s.tie_band.bounds().1.atan().to_degrees()
        ),
    };
    lines.push(format!(
        "{:>29}: {} exact strikes, {} contacts undecided ({band}); {} exact strikes with no grid strike in their start ({} decided); {} grid strikes with no exact one ({} decided)",
        "strikes",
        c.exact_strikes,
        c.exact_undecided,
        c.unmatched_exact,
        c.unmatched_exact_decided,
        c.unmatched_grid,
        c.unmatched_grid_decided
    ));
    lines.push(format!(
        "{:>29}: {} start-angle pairs touched a flagged blind spot ({} exact strikes from there on, reported as blind); {} grid strikes within the bound of the grid's level error (max {:.4} mm from touching the exact knee-form, bound up to {:.4} mm)",
        "blind and level error",
        c.blind_pairs,
        c.blind_strikes,
        c.level_error_strikes,
        s.metrics["level_error_clearance"].max,
        s.metrics["level_error_bound"].max,
    ));
    for w in &s.warnings {
        lines.push(format!("kneeform: warning: {w}"));
    }
    let mm = |v: Option<f64>| v.map_or("infinite".to_string(), |v| format!("{v:.3} mm"));
    lines.push(format!(
        "{:>29}: decided {} (all strikes, undecided included: {})",
        "area distance",
        mm(s.area_distance_decided_mm),
        mm(s.area_distance_mm)
    ));
    lines.push(format!("{:>29}: {}", "figures beyond tolerance", s.verdict));
    if let Some(w) = s.worst_starts.first() {
        lines.push(format!(
            "{:>29}: {}",
            "worst start (diagnostic)",
            worst_start_words(result, w)
        ));
    }
    lines.push(format!(
        "kneeform: {}; results in {}",
        s.sentence(),
        out.display()
    ));
    Said {
        lines,
        outcome: Some(s.outcome),
    }
}

/// The worst start of a verification, a diagnostic of its area figures
/// (never its verdict): its figure, where, and what the figure's
/// mechanism, or refinement against the same exact trace, showed.
fn worst_start_words(result: &Verification, w: &super::verify::WorstStart) -> String {
    use super::causes::Mechanism;
    let s = &result.summary;
    let at = w.at.map_or(String::new(), |[x, z]| {
        format!(" (the disagreement lies at x = {x:.1}, z = {z:.1} mm)")
    });
    let mechanism = s
        .failures
        .iter()
        .find(|f| f.metric == w.metric && f.value.is_some_and(|v| (v - w.value).abs() < 1e-9))
        .map(|f| f.mechanism);
    let row = result
        .comparison
        .rows
        .iter()
        .find(|r| r.i == w.i && r.j == w.j && r.angle_deg == w.angle_deg);
    let half = short(s.pitch_mm / 2.0);
    let refined = row.and_then(|r| r.miss_distance_half_pitch).map(|h| {
        let quarter = row
            .and_then(|r| r.miss_distance_quarter_pitch)
            .map_or(String::new(), |q| {
                format!(", {q:.3} mm at {} mm", short(s.pitch_mm / 4.0))
            });
        // What the refinement showed: a miss that drops far below half
        // at half the pitch is a second contact site resolved (the grid's
        // level set by another one), not an error first order in the pitch.
        let shape = if h <= w.value / 4.0 {
            "it collapses at half the pitch: the grid's level at this start is set by another contact site, which a finer grid resolves; not an error of first order"
        } else if h <= w.value / 2.0 {
            "it falls to half at half the pitch: first order in the pitch"
        } else {
            "it falls by less than half at half the pitch"
        };
        format!(
            "; against the same exact trace it is {h:.3} mm at {half} mm{quarter}: {shape}"
        )
    });
    let hint = match (mechanism, refined) {
        (_, Some(refined)) => refined,
        (Some(Mechanism::Rim), None) => format!(
            "; it lies in the knee-form's rim, which the grid samples late (the nearest node met more than sqrt 2 pitches of travel after the touch): a finer pitch narrows the rim, at half order along the slide (`kneeform verify --pitch {half}` measures it)"
        ),
        (Some(Mechanism::Sampling), None) if s.unexplained.miss_brief >= w.value - 1e-9 => {
            format!(
                "; a strike lasting less than sqrt 2 pitches of travel before the knee-form touches elsewhere (brief): this start's grid meets its nodes after it, its neighbours' may not (`kneeform verify --pitch {half}` measures it)"
            )
        }
        (Some(Mechanism::LevelError), None) => "; the grid's level error (its level deeper than the exact one by at most the stated bound): a false alarm on the safe side, which the outcome does not judge".to_string(),
        _ => resolving_pitch(s.pitch_mm, s.tolerance_mm, &w.metric, w.value),
    };
    format!(
        "{} = {:.3} mm, start ({}, {}) angle {}{at}{hint}",
        w.metric,
        w.value,
        short(w.x),
        short(w.z),
        short(w.angle_deg),
    )
}

/// What a convergence study says: its errors per pitch, fitted orders and
/// the pitch it recommends (its results are in `out`).
fn convergence_said(study: &Convergence, out: &Path) -> Said {
    let results = &study.results;
    let mut lines = Vec::new();
    let fitted = &study.fits;
    for r in results {
        let maxes: Vec<String> = r
            .comparison
            .stats
            .iter()
            .filter(|(m, _)| DECIDED_METRICS.contains(&m.as_str()))
            .map(|(m, s)| format!("{m} {:.3}", s.max))
            .collect();
        let outcome = study.summary.tolerance_mm.map_or(String::new(), |t| {
            format!("{}: ", super::converge::outcome_at(results, r, t).0.word())
        });
        lines.push(format!(
            "p = {:>6} mm: {outcome}{} | all strikes: area_distance {:.3} | IoU {:.3} | {} undecided | {:.2} s",
            r.pitch,
            maxes.join(", "),
            r.comparison.stat("area_distance").max,
            r.comparison.area_iou,
            r.comparison.counts.exact_undecided,
            r.seconds
        ));
    }
    // No exact strike at any pitch: every error is zero because there was
    // nothing to miss, which is no order and no exactness.
    let nothing = results
        .iter()
        .all(|r| r.comparison.counts.exact_strikes == 0);
    if nothing {
        lines.push(
            "kneeform: warning: the exact knee-form strikes nothing on these starts at any pitch: no error was measured (nothing to miss is not evidence)".into(),
        );
    }
    for (m, f) in fitted {
        if nothing || !DECIDED_METRICS.contains(&m.as_str()) {
            continue;
        }
        let exact = results
            .iter()
            .all(|r| r.comparison.stat(m).max <= super::converge::ROUNDING_MM);
        match f {
            Some(f) => lines.push(format!("{m:>22}: error ~ {:.3} p^{:.2}", f.c, f.alpha)),
            None if exact => lines.push(format!(
                "{m:>22}: exact at every pitch (at most rounding, 1e-9 mm)"
            )),
            None => lines.push(format!(
                "{m:>22}: no fit (an error above rounding at fewer than two pitches)"
            )),
        }
    }
    match (study.summary.tolerance_mm, study.recommended()) {
        (Some(t), Some(r)) => lines.push(format!(
            "kneeform: the coarsest pitch whose outcome at {t} mm is PASS (its decided area miss distance within it, on enough evidence) is {} mm; a full 61-angle analysis at it takes about {:.1} s",
            r.pitch,
            study.summary.predicted_full_time_s.unwrap_or(f64::NAN)
        )),
        (Some(t), None) => {
            // Why not: the finest pitch's outcome and why.
            let why = study.summary.verdicts.last().map_or(String::new(), |v| {
                let because = match &v.outcome_reason {
                    Some(reason) => reason.clone(),
                    None => format!(
                        "decided area miss distance {}",
                        results.last().map_or("-".into(), |r| format!(
                            "{:.3} mm",
                            r.comparison.area_miss_decided()
                        ))
                    ),
                };
                format!(
                    ": at {} mm, {} ({because})",
                    short(v.pitch_mm),
                    v.outcome.word()
                )
            });
            lines.push(format!(
                "kneeform: no pitch tried is within {} mm{why}",
                short(t)
            ))
        }
        _ => {}
    }
    lines.push(format!("kneeform: results in {}", out.display()));
    Said {
        lines,
        outcome: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::harness::codec::{put_opt, put_u64};

    pub(super) fn pair() -> PairResult {
        let cmp = StartComparison {
            push_error: Some(-0.25),
            push_blind: true,
            push_explained: false,
            first_contact_error: None,
            first_contact_error_decided: Some(f64::MIN_POSITIVE),
            first_contact_error_blind: Some(-2.0),
            first_contact_explained: true,
            first_contact_late_inside: Some(0.75),
            miss: vec![1.5, f64::INFINITY],
            miss_decided: vec![f64::INFINITY],
            miss_rim: vec![true],
            miss_brief: vec![false],
            miss_half_pitch: Some(0.25),
            miss_quarter_pitch: Some(f64::INFINITY),
            miss_blind: vec![0.5],
            false_alarm: vec![0.1 + 0.2, 7.0],
            false_alarm_decided: vec![0.3],
            false_alarm_explained: vec![true],
            false_alarm_blind: vec![7.0],
            unmatched_deflection: vec![3.0],
            unmatched_deflection_decided: vec![-0.0],
            unmatched_deflection_inside: vec![2.5],
            unmatched_deflection_blind: Vec::new(),
            level_clearance: vec![0.01],
            level_bound: vec![0.25],
            oracle_failure: Some(FailureReason::UnconfirmedMiss),
            exact_strikes: 2,
            undecided: 1,
            blind: true,
            blind_strikes: 1,
            points: StartPoints {
                grid: vec![[1.0, 2.0], [9.0, 9.5]],
                grid_decided: vec![[1.0, 2.0]],
                grid_unexplained: Vec::new(),
                grid_blind: vec![[9.0, 9.5]],
                strikes: vec![[3.0, 4.0], [5.0, 6.0]],
                decided: vec![[5.0, 6.0]],
                blind: vec![[3.0, 4.0]],
                decided_inside: Vec::new(),
                decided_refined: vec![[0.5, 1.5]],
                possible: Vec::new(),
                undecided: vec![[2.0, 3.5]],
                push: vec![[-7.5, 8.25]],
            },
        };
        PairResult {
            row: row_of(4, 9, -30.0, "grid_not_placed", &cmp),
            cmp,
            grid_nodes: vec![(1, 2), (3, 4)],
            snapped: vec![(5, 6)],
            undecided: vec![(2, 3)],
        }
    }

    #[test]
    fn a_fitted_order_is_written_to_two_places_never_minus_zero() {
        assert_eq!(two_places(-0.001), "0.00");
        assert_eq!(two_places(1.305), format!("{:.2}", 1.305));
    }

    #[test]
    fn a_pair_reads_back_bit_for_bit() {
        let p = pair();
        let mut bin = Vec::new();
        p.put(&mut bin);
        let mut r = Reader::new(&bin);
        let back = read_pair(&mut r, -30.0).unwrap();
        assert_eq!(r.at, bin.len());
        // PartialEq on f64 would take -0.0 for 0.0: compare the bits too.
        assert_eq!(back, p);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&back.cmp.unmatched_deflection_decided),
            bits(&p.cmp.unmatched_deflection_decided)
        );
    }

    #[test]
    fn a_cut_or_damaged_pair_is_an_error_not_a_panic() {
        let mut bin = Vec::new();
        pair().put(&mut bin);
        for end in 0..bin.len() {
            let mut r = Reader::new(&bin[..end]);
            assert!(read_pair(&mut r, 0.0).is_err(), "cut at {end}");
        }
        // A count far beyond the bytes left allocates nothing.
        let mut huge = vec![0u8];
        put_u64(&mut huge, 0);
        put_u64(&mut huge, 0);
        for _ in 0..3 {
            put_opt(&mut huge, None);
        }
        put_u64(&mut huge, u64::MAX);
        let mut r = Reader::new(&huge);
        assert!(read_pair(&mut r, 0.0).is_err());
        // An unknown status.
        let mut bad = bin.clone();
        bad[0] = STATUSES.len() as u8;
        assert!(read_pair(&mut Reader::new(&bad), 0.0).is_err());
    }
}
