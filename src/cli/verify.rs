//! `kneeform verify`: the grid engine and the exact oracle on the same
//! starts; `verify.csv` (one row per start and angle) and `verify.json`
//! (statistics, counts, worst starts, pass or fail).

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use kneeform::harness::{
    self, CompareOptions, Comparison, Fault, StartSelection, VerifySummary, VerifyTimings,
    WorstStart,
};
use kneeform::output::OutputDir;
use kneeform::{Footprint, GridFootprint, HeightGrid, KneeForm};
use kneeform_oracle::{KneeFormDims, OracleOptions, StartTrace};

use super::args::{Setup, VerifyArgs};

/// A spinner on stderr for work with no natural progress count.
pub fn spinner(message: &str) -> ProgressBar {
    let bar = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("static template"),
    );
    bar.set_message(message.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
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

/// The tie band's rule in words, for the summaries.
pub fn tie_band_rule(per_mm: f64) -> String {
    format!(
        "an exact contact is undecided when its deflection rate, widened by its rate_error, overlaps [sigma / (1 + m), sigma * (1 + m)] with m = {per_mm} x pitch (mm)"
    )
}

/// Runs the oracle on `starts` at `angles` with a spinner.
pub fn run_oracle(
    triangles: &[kneeform::mesh::Triangle],
    starts: &[[f64; 2]],
    angles: &[f64],
    options: &OracleOptions,
) -> anyhow::Result<(Vec<StartTrace>, f64)> {
    let bar = spinner(&format!(
        "exact oracle: {} starts x {} angles",
        starts.len(),
        angles.len()
    ));
    let t = Instant::now();
    let traces = harness::exact_traces(triangles, starts, angles, options)?;
    bar.finish_and_clear();
    Ok((traces, t.elapsed().as_secs_f64()))
}

/// Everything `verify` computes, before it is written.
pub struct VerifyResult {
    pub comparison: Comparison,
    pub summary: VerifySummary,
}

/// The library side of `verify`, with a test-only fault on the grid side.
pub fn verify(
    triangles: &[kneeform::mesh::Triangle],
    input_file: &str,
    setup: &Setup,
    selection: StartSelection,
    tie_band_per_mm: f64,
    tolerance: f64,
    fault: Option<Fault>,
) -> anyhow::Result<VerifyResult> {
    let t = Instant::now();
    let part =
        kneeform::Part::from_triangles(input_file, triangles.to_vec(), 1.0, kneeform::Side::Left)?;
    let spec = super::analyze::grid_spec(&part, &setup.knee, setup)?;
    spec.check_fits(setup.max_memory_bytes)?;
    let grid = HeightGrid::sample(&part.triangles, spec);
    let footprints: Vec<GridFootprint> = setup
        .angles
        .iter()
        .map(|&a| GridFootprint::new(&Footprint::new(&setup.knee, a), a, setup.pitch))
        .collect();
    let sample_s = t.elapsed().as_secs_f64();
    let nodes = harness::select_starts(&grid, &footprints, selection);
    anyhow::ensure!(
        !nodes.is_empty(),
        "no start is placed on this part: nothing to compare"
    );
    let starts: Vec<[f64; 2]> = nodes.iter().map(|&(i, j)| [spec.x(i), spec.z(j)]).collect();
    let options = oracle_options(&setup.knee, setup.pitch, spec.x(0));
    let (traces, oracle_s) = run_oracle(&part.triangles, &starts, &setup.angles, &options)?;
    let compare = CompareOptions {
        knee: setup.knee,
        rule: setup.rule,
        tie_band_per_mm,
        fault,
    };
    let comparison = harness::compare_grid(&grid, &footprints, &starts, &traces, &compare)?;
    let pass = comparison.passes(tolerance);
    let summary = VerifySummary {
        kneeform_version: env!("CARGO_PKG_VERSION").into(),
        input_file: input_file.into(),
        // The file's identity and units: set by `run`, which read the file.
        input_sha256: String::new(),
        scale: 1.0,
        side: kneeform::Side::Left,
        pitch_mm: setup.pitch,
        tolerance_mm: tolerance,
        pass,
        angles_deg: setup.angles.clone(),
        knee_form_mm: [
            setup.knee.triangle_side,
            setup.knee.radius,
            setup.knee.thickness,
        ],
        deflection_deg: setup.rule.deflection_deg(),
        sigma: setup.rule.sigma,
        e0_mm: setup.rule.e0,
        rate: setup.rule.rate.name().into(),
        tie_band: comparison.band,
        tie_band_rule: tie_band_rule(tie_band_per_mm),
        area_distance_decided_mm: Some(comparison.stat("area_distance_decided").max).filter(|_| {
            comparison
                .area
                .iter()
                .all(|a| a.miss_decided.is_finite() && a.false_alarm_decided.is_finite())
        }),
        area_distance_mm: Some(comparison.stat("area_distance").max).filter(|_| {
            comparison
                .area
                .iter()
                .all(|a| a.miss.is_finite() && a.false_alarm.is_finite())
        }),
        area_distance: comparison.area.clone(),
        starts: match selection {
            StartSelection::All => "all".into(),
            StartSelection::Sample { count, .. } => count.to_string(),
            StartSelection::Strip { z } => format!("strip:{}:{}", z[0], z[1]),
        },
        seed: match selection {
            StartSelection::Sample { seed, .. } => seed,
            _ => 0,
        },
        metrics: comparison.stats.iter().cloned().collect(),
        area_iou: comparison.area_iou,
        counts: comparison.counts,
        worst_starts: comparison
            .worst(10)
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
            .collect(),
        timings: VerifyTimings {
            sample_s,
            grid_s: comparison.grid_s,
            oracle_s,
        },
    };
    Ok(VerifyResult {
        comparison,
        summary,
    })
}

/// Writes `verify.csv` and `verify.json` into `dir`, atomically.
pub fn write(dir: &Path, result: &VerifyResult) -> anyhow::Result<()> {
    let out = OutputDir::stage(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut csv = csv::Writer::from_path(out.path("verify.csv"))?;
    for row in &result.comparison.rows {
        csv.serialize(row)?;
    }
    csv.flush()?;
    std::fs::write(
        out.path("verify.json"),
        serde_json::to_string_pretty(&result.summary)? + "\n",
    )?;
    out.commit()
        .with_context(|| format!("cannot move results into {}", dir.display()))?;
    Ok(())
}

pub fn run(args: &VerifyArgs) -> anyhow::Result<ExitCode> {
    args.part.validate()?;
    let setup = args.setup.validate()?;
    let selection = args.starts.validate()?;
    anyhow::ensure!(
        args.tolerance.is_finite() && args.tolerance > 0.0,
        "--tolerance must be > 0"
    );
    super::set_threads(setup.threads)?;
    let (part, sha256) = super::load_part(&args.part.part, args.part.scale, args.part.side)?;
    let mut result = verify(
        &part.triangles,
        &args.part.part.display().to_string(),
        &setup,
        selection,
        args.starts.tie_band,
        args.tolerance,
        None,
    )?;
    result.summary.input_sha256 = sha256;
    result.summary.scale = args.part.scale;
    result.summary.side = args.part.side;
    write(&args.out, &result)?;
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
