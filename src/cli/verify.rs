//! `kneeform verify`: the grid engine and the exact oracle on the same
//! starts; `verify.csv` (one row per start and angle) and `verify.json`
//! (statistics, counts, worst starts, pass or fail).

use std::process::ExitCode;

use kneeform::Approach;
use kneeform::harness::{self, VerifyOptions};
use kneeform::output;

use super::args::VerifyArgs;
use super::progress::Bars;

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

pub fn run(args: &VerifyArgs) -> anyhow::Result<ExitCode> {
    let options = VerifyOptions {
        selection: args.study.starts.validate()?,
        tie_band_per_mm: args.study.starts.tie_band,
        tolerance: args.tolerance,
    };
    let (input, setup) = super::study_inputs(&args.study, options.validate())?;
    if setup.approach == Approach::Direct {
        return run_direct(args, &input, &setup, &options);
    }
    let result = harness::verify(&input, &setup, &options, &Bars::default())
        .map_err(super::harness_error)?;
    output::write_verification(&args.out, &result)?;
    let s = &result.summary;
    for name in kneeform::harness::METRICS {
        let stats = &s.metrics[name];
        eprintln!(
            "{name:>29}: max {:.4}  p95 {:.4}  mean {:.4} mm  (n = {})",
            stats.max, stats.p95, stats.mean, stats.n
        );
    }
    let c = &s.counts;
    eprintln!(
        "{:>29}: {:.3}; {} start-angle pairs compared, {} oracle failures",
        "area IoU", s.area_iou, c.compared, c.oracle_failed
    );
    eprintln!(
        "{:>29}: {} exact strikes, {} contacts undecided (deflection rate in [{:.3}, {:.3}] deg); {} exact strikes with no grid strike in their start ({} decided); {} grid strikes with no exact one ({} decided)",
        "strikes",
        c.exact_strikes,
        c.exact_undecided,
        s.tie_band.bounds().0.atan().to_degrees(),
        s.tie_band.bounds().1.atan().to_degrees(),
        c.unmatched_exact,
        c.unmatched_exact_decided,
        c.unmatched_grid,
        c.unmatched_grid_decided
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
    if s.pass {
        eprintln!(
            "kneeform: PASS at tolerance {} mm; results in {}",
            s.tolerance_mm,
            args.out.display()
        );
        Ok(ExitCode::SUCCESS)
    } else {
        let worst = s.worst_starts.first().map_or(String::new(), |w| {
            let at = w.at.map_or(String::new(), |[x, z]| {
                format!(" (the disagreement lies at x = {x:.1}, z = {z:.1} mm)")
            });
            format!(
                "; worst: {} = {:.3} mm, start ({}, {}) angle {}{at}{}",
                w.metric,
                w.value,
                w.x,
                w.z,
                w.angle_deg,
                resolving_pitch(s.pitch_mm, s.tolerance_mm, &w.metric, w.value)
            )
        });
        eprintln!(
            "kneeform: FAIL at tolerance {} mm ({}){worst}; results in {}",
            s.tolerance_mm,
            result.comparison.failures(s.tolerance_mm).join("; "),
            args.out.display()
        );
        Ok(ExitCode::from(1))
    }
}

/// `verify --approach direct`: the grid's first contacts against the exact
/// casts along -x.
fn run_direct(
    args: &VerifyArgs,
    input: &kneeform::PartFile,
    setup: &kneeform::Setup,
    options: &VerifyOptions,
) -> anyhow::Result<ExitCode> {
    let result = harness::verify_direct(input, setup, options, &Bars::default())
        .map_err(super::harness_error)?;
    output::write_direct_verification(&args.out, &result)?;
    let s = &result.summary;
    for name in harness::DIRECT_METRICS {
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
        s.tolerance_mm,
        args.out.display()
    );
    Ok(if s.pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
