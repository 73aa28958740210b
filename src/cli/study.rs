//! What `verify` and `converge` print of their results (with `--approach
//! direct` too), and `kneeform merge` of their shards alike: the
//! statistics, the verdict and `verify`'s exit status.

use std::path::Path;
use std::process::ExitCode;

use kneeform::harness::{
    Convergence, DECIDED_METRICS, DIRECT_METRICS, DirectConvergence, DirectVerification, Study,
    Verification,
};
use kneeform::limits::short;

/// Prints what `study` found (its results are in `out`) and returns the
/// command's exit status: a verification's 0 when it passes, 1 when it
/// fails; a convergence study's 0.
pub fn print_study(study: &Study, out: &Path) -> ExitCode {
    match study {
        Study::Verify(v) => print_verification(v, out),
        Study::Converge(c) => {
            print_convergence(c, out);
            ExitCode::SUCCESS
        }
        Study::VerifyDirect(v) => print_direct_verification(v, out),
        Study::ConvergeDirect(c) => {
            print_direct_convergence(c, out);
            ExitCode::SUCCESS
        }
    }
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

/// Prints a verification's statistics, counts and verdict (its results
/// are in `out`) and returns `verify`'s exit status: 0 when it passes, 1
/// when it fails.
fn print_verification(result: &Verification, out: &Path) -> ExitCode {
    let s = &result.summary;
    for name in kneeform::harness::METRICS {
        let stats = &s.metrics[name];
        eprintln!(
            "{name:>29}: max {:.4}  p95 {:.4}  mean {:.4} mm  (n = {})",
            stats.max, stats.p95, stats.mean, stats.n
        );
    }
    let c = &s.counts;
    let reasons: Vec<String> = s
        .oracle_failures
        .iter()
        .map(|(why, n)| format!("{n}: {why}"))
        .collect();
    eprintln!(
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
    );
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
    eprintln!(
        "{:>29}: {} exact strikes, {} contacts undecided ({band}); {} exact strikes with no grid strike in their start ({} decided); {} grid strikes with no exact one ({} decided)",
        "strikes",
        c.exact_strikes,
        c.exact_undecided,
        c.unmatched_exact,
        c.unmatched_exact_decided,
        c.unmatched_grid,
        c.unmatched_grid_decided
    );
    eprintln!(
        "{:>29}: {} start-angle pairs touched a flagged blind spot ({} exact strikes from there on, reported as blind); {} grid strikes within the bound of the grid's level error (max {:.4} mm from touching the exact knee-form, bound up to {:.4} mm)",
        "blind and level error",
        c.blind_pairs,
        c.blind_strikes,
        c.level_error_strikes,
        s.metrics["level_error_clearance"].max,
        s.metrics["level_error_bound"].max,
    );
    if c.exact_strikes == 0 && result.comparison.rows.iter().all(|r| r.grid_colliding == 0) {
        eprintln!(
            "kneeform: warning: neither the grid nor the exact knee-form strikes anything on these starts: a pass here proves only that (a part smaller than the knee-form, or its surface on the other side: see --scale and --side)"
        );
    }
    let mm = |v: Option<f64>| v.map_or("infinite".to_string(), |v| format!("{v:.3} mm"));
    eprintln!(
        "{:>29}: decided {} (all strikes, undecided included: {})",
        "area distance",
        mm(s.area_distance_decided_mm),
        mm(s.area_distance_mm)
    );
    eprintln!("{:>29}: {}", "verdict", s.verdict);
    if s.pass {
        let explained = if s.failures.is_empty() {
            String::new()
        } else {
            " (the figures beyond it are blind, undecided or the level error's, named above)".into()
        };
        eprintln!(
            "kneeform: PASS at tolerance {} mm{explained}; results in {}",
            kneeform::limits::short(s.tolerance_mm),
            out.display()
        );
        ExitCode::SUCCESS
    } else {
        let worst = s.worst_starts.first().map_or(String::new(), |w| {
            let at = w.at.map_or(String::new(), |[x, z]| {
                format!(" (the disagreement lies at x = {x:.1}, z = {z:.1} mm)")
            });
            // The hint follows the figure's mechanism: a rim or a brief
            // strike is the grid's sampling, not a feature's width.
            use kneeform::harness::Mechanism;
            let mechanism = s
                .failures
                .iter()
                .find(|f| {
                    f.metric == w.metric && f.value.is_some_and(|v| (v - w.value).abs() < 1e-9)
                })
                .map(|f| f.mechanism);
            let hint = match mechanism {
                Some(Mechanism::Rim) => "; it lies in the knee-form's rim, which the grid samples late (the nearest node met more than sqrt 2 pitches of travel after the touch, where the outline crosses the grid's rows at a shallow angle): a finer pitch narrows the rim, at half order along the slide".to_string(),
                Some(Mechanism::Sampling) if w.value > std::f64::consts::SQRT_2 * s.pitch_mm => {
                    if s.unexplained.miss_brief >= w.value - 1e-9 {
                        "; a strike lasting less than sqrt 2 pitches of travel before the knee-form touches elsewhere (brief): the grid meets its nodes after it; a pitch finer than the touch resolves it".to_string()
                    } else {
                        "; it falls with the pitch against the same exact trace (to half or less at half the pitch, or to a quarter or less at a quarter: first order), as where the exact knee-form strikes along a crease of the part between node rows that the grid's strikes meet later; a finer pitch resolves it".to_string()
                    }
                }
                _ => resolving_pitch(s.pitch_mm, s.tolerance_mm, &w.metric, w.value),
            };
            let short = kneeform::limits::short;
            format!(
                "; worst: {} = {:.3} mm, start ({}, {}) angle {}{at}{hint}",
                w.metric,
                w.value,
                short(w.x),
                short(w.z),
                short(w.angle_deg),
            )
        });
        eprintln!(
            "kneeform: FAIL at tolerance {} mm ({}){worst}; results in {}",
            kneeform::limits::short(s.tolerance_mm),
            s.failures
                .iter()
                .filter(|f| f.fails_verdict)
                .map(|f| f.phrase())
                .collect::<Vec<_>>()
                .join("; "),
            out.display()
        );
        ExitCode::from(1)
    }
}

/// Prints a convergence study's errors per pitch, fitted orders and the
/// pitch it recommends (its results are in `out`).
fn print_convergence(study: &Convergence, out: &Path) {
    let results = &study.results;
    let fitted = &study.fits;
    for r in results {
        let maxes: Vec<String> = r
            .comparison
            .stats
            .iter()
            .filter(|(m, _)| DECIDED_METRICS.contains(&m.as_str()))
            .map(|(m, s)| format!("{m} {:.3}", s.max))
            .collect();
        eprintln!(
            "p = {:>6} mm: {} | all strikes: area_distance {:.3} | IoU {:.3} | {} undecided | {:.2} s",
            r.pitch,
            maxes.join(", "),
            r.comparison.stat("area_distance").max,
            r.comparison.area_iou,
            r.comparison.counts.exact_undecided,
            r.seconds
        );
    }
    for (m, f) in fitted {
        if !DECIDED_METRICS.contains(&m.as_str()) {
            continue;
        }
        let exact = results
            .iter()
            .all(|r| r.comparison.stat(m).max <= kneeform::harness::ROUNDING_MM);
        match f {
            Some(f) => eprintln!("{m:>22}: error ~ {:.3} p^{:.2}", f.c, f.alpha),
            None if exact => eprintln!("{m:>22}: exact at every pitch (at most rounding, 1e-9 mm)"),
            None => {
                eprintln!("{m:>22}: no fit (an error above rounding at fewer than two pitches)")
            }
        }
    }
    match (study.summary.tolerance_mm, study.recommended()) {
        (Some(t), Some(r)) => eprintln!(
            "kneeform: the coarsest pitch within {t} mm is {} mm; a full 61-angle analysis at it takes about {:.1} s",
            r.pitch,
            study.summary.predicted_full_time_s.unwrap_or(f64::NAN)
        ),
        (Some(t), None) => {
            // Why not: the finest pitch's figures that fail the verdict.
            let why = study.summary.verdicts.last().map_or(String::new(), |v| {
                let failing: Vec<String> = v
                    .failures
                    .iter()
                    .filter(|f| f.fails_verdict)
                    .map(|f| f.phrase())
                    .collect();
                format!(": at {} mm, {}", short(v.pitch_mm), failing.join("; "))
            });
            eprintln!("kneeform: no pitch tried is within {} mm{why}", short(t))
        }
        _ => {}
    }
    eprintln!("kneeform: results in {}", out.display());
}

/// Prints a direct verification's statistics, counts and verdict (its
/// results are in `out`) and returns `verify`'s exit status: 0 when it
/// passes, 1 when it fails.
fn print_direct_verification(result: &DirectVerification, out: &Path) -> ExitCode {
    let s = &result.summary;
    for name in DIRECT_METRICS {
        let stats = &s.metrics[name];
        eprintln!(
            "{name:>16}: max {:.4}  p95 {:.4}  median {:.4} mm  (n = {})",
            stats.max, stats.p95, stats.median, stats.n
        );
    }
    let c = &s.counts;
    eprintln!(
        "{:>16}: {} position-angle pairs, {} touched on both sides, {} on the grid only, {} exactly only, {} oracle failures, {} engine levels unlike the harness's",
        "positions",
        c.compared,
        c.both,
        c.grid_only,
        c.exact_only,
        c.oracle_failed,
        c.engine_mismatch
    );
    let verdict = if s.pass { "PASS" } else { "FAIL" };
    eprintln!(
        "kneeform: {verdict} (direct approach) at tolerance {} mm; results in {}",
        kneeform::limits::short(s.tolerance_mm),
        out.display()
    );
    if s.pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// Prints a direct convergence study's errors per pitch, fitted orders
/// and the pitch it recommends (its results are in `out`).
fn print_direct_convergence(study: &DirectConvergence, out: &Path) {
    for r in &study.results {
        let c = &r.comparison;
        let stats: Vec<String> = c
            .stats
            .iter()
            .map(|(m, s)| format!("{m} max {:.4} median {:.4}", s.max, s.median))
            .collect();
        eprintln!(
            "p = {:>6} mm: {} | {} both, {} grid only, {} exact only, {} failed, {} engine mismatches",
            r.pitch,
            stats.join(", "),
            c.counts.both,
            c.counts.grid_only,
            c.counts.exact_only,
            c.counts.oracle_failed,
            c.counts.engine_mismatch
        );
    }
    for (m, f) in &study.summary.fits {
        eprintln!("{m:>16}: max error ~ {:.3} p^{:.2}", f.c, f.alpha);
    }
    match (
        study.summary.tolerance_mm,
        study.summary.recommended_pitch_mm,
    ) {
        (Some(t), Some(p)) => eprintln!(
            "kneeform: the coarsest pitch within {} mm is {} mm",
            short(t),
            short(p)
        ),
        (Some(t), None) => eprintln!("kneeform: no pitch tried is within {} mm", short(t)),
        _ => {}
    }
    eprintln!("kneeform: results in {}", out.display());
}
