//! `kneeform converge`: the same starts compared with the exact oracle at
//! several pitches; `converge.csv`, `converge.json`, and log-log plots of
//! error and time against pitch.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, ensure};
use kneeform::grid::GridSpec;
use kneeform::harness::converge::{
    ConvergeSummary, PitchResult, fits, recommended_pitch, write_plots,
};
use kneeform::harness::{self, CompareOptions, StartSelection};
use kneeform::output::OutputDir;
use kneeform::{EngineOptions, Footprint, GridFootprint, HeightGrid, colliding_masks};

use super::args::{ConvergeArgs, Setup};
use super::verify::{oracle_options, run_oracle};

/// Parses and checks the pitch ladder: positive, coarsest first, each
/// dividing the coarsest (so that every grid holds the coarsest's nodes).
pub fn parse_pitches(s: &str) -> anyhow::Result<Vec<f64>> {
    let mut pitches: Vec<f64> = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .with_context(|| format!("--pitches: {t:?} is not a number"))
        })
        .collect::<anyhow::Result<_>>()?;
    ensure!(pitches.len() >= 2, "--pitches needs at least two pitches");
    ensure!(
        pitches.iter().all(|p| p.is_finite() && *p > 0.0),
        "--pitches must all be > 0"
    );
    pitches.sort_by(|a, b| b.total_cmp(a));
    pitches.dedup();
    let coarsest = pitches[0];
    for &p in &pitches {
        let ratio = coarsest / p;
        ensure!(
            (ratio - ratio.round()).abs() < 1e-9 * ratio,
            "--pitches: {p} mm does not divide {coarsest} mm, so the grids would not share the coarsest grid's starts"
        );
    }
    Ok(pitches)
}

/// The study's results at every pitch, coarsest first.
pub fn converge(
    triangles: &[kneeform::mesh::Triangle],
    input_file: &str,
    setup: &Setup,
    pitches: &[f64],
    selection: StartSelection,
    tie_band_per_mm: f64,
) -> anyhow::Result<Vec<PitchResult>> {
    let part =
        kneeform::Part::from_triangles(input_file, triangles.to_vec(), 1.0, kneeform::Side::Left)?;
    let coarse_setup = Setup {
        pitch: pitches[0],
        ..setup.clone()
    };
    let coarse = super::analyze::grid_spec(&part, &setup.knee, &coarse_setup)?;
    // Finer grids cover exactly the coarse grid's extent from its origin.
    let specs: Vec<GridSpec> = pitches
        .iter()
        .map(|&p| {
            let r = (pitches[0] / p).round() as usize;
            GridSpec::explicit(
                coarse.x(0),
                coarse.z(0),
                (coarse.nx - 1) * r + 1,
                (coarse.nz - 1) * r + 1,
                p,
            )
        })
        .collect();
    for spec in &specs {
        spec.check_fits(setup.max_memory_bytes)?;
    }
    let footprints_at = |p: f64| -> Vec<GridFootprint> {
        setup
            .angles
            .iter()
            .map(|&a| GridFootprint::new(&Footprint::new(&setup.knee, a), a, p))
            .collect()
    };
    let coarse_grid = HeightGrid::sample(&part.triangles, coarse);
    let nodes = harness::select_starts(&coarse_grid, &footprints_at(pitches[0]), selection);
    ensure!(
        !nodes.is_empty(),
        "no start is placed on this part: nothing to compare"
    );
    let starts: Vec<[f64; 2]> = nodes
        .iter()
        .map(|&(i, j)| [coarse.x(i), coarse.z(j)])
        .collect();
    let finest = pitches[pitches.len() - 1];
    let options = oracle_options(&setup.knee, finest, coarse.x(0));
    let (traces, oracle_s) = run_oracle(&part.triangles, &starts, &setup.angles, &options)?;
    eprintln!(
        "exact oracle: {} starts x {} angles in {oracle_s:.1} s",
        starts.len(),
        setup.angles.len()
    );
    let compare = CompareOptions {
        knee: setup.knee,
        rule: setup.rule,
        tie_band_per_mm,
        fault: None,
    };
    let mut results = Vec::new();
    for (&pitch, &spec) in pitches.iter().zip(&specs) {
        let bar =
            super::verify::spinner(&format!("pitch {pitch} mm: {} x {} grid", spec.nx, spec.nz));
        let grid = HeightGrid::sample(&part.triangles, spec);
        let footprints = footprints_at(pitch);
        let t = Instant::now();
        let masks = colliding_masks(
            &grid,
            &footprints,
            &EngineOptions {
                rule: setup.rule,
                ..EngineOptions::default()
            },
            &|| {},
        );
        let seconds = t.elapsed().as_secs_f64();
        drop(masks);
        let comparison = harness::compare_grid(&grid, &footprints, &starts, &traces, &compare)?;
        bar.finish_and_clear();
        results.push(PitchResult {
            pitch,
            comparison,
            seconds,
            nodes: spec.len(),
        });
    }
    Ok(results)
}

pub fn run(args: &ConvergeArgs) -> anyhow::Result<ExitCode> {
    args.part.validate()?;
    let setup = args.setup.validate()?;
    let selection = args.starts.validate()?;
    let pitches = parse_pitches(&args.pitches)?;
    if let Some(t) = args.tolerance {
        ensure!(t.is_finite() && t > 0.0, "--tolerance must be > 0");
    }
    super::set_threads(setup.threads)?;
    let (part, sha256) = super::load_part(&args.part.part, args.part.scale, args.part.side)?;
    let input = args.part.part.display().to_string();
    let results = converge(
        &part.triangles,
        &input,
        &setup,
        &pitches,
        selection,
        args.starts.tie_band,
    )?;
    let fitted = fits(&results);
    let recommended = args.tolerance.and_then(|t| recommended_pitch(&results, t));
    let full_angles = 61.0 / setup.angles.len() as f64;
    let summary = ConvergeSummary {
        kneeform_version: env!("CARGO_PKG_VERSION").into(),
        input_file: input,
        input_sha256: sha256,
        scale: args.part.scale,
        side: args.part.side,
        knee_form_mm: [
            setup.knee.triangle_side,
            setup.knee.radius,
            setup.knee.thickness,
        ],
        sigma: setup.rule.sigma,
        rate: setup.rule.rate.name().into(),
        pitches_mm: pitches.clone(),
        fits: fitted
            .iter()
            .filter_map(|(m, f)| f.map(|f| (m.clone(), f)))
            .collect(),
        tolerance_mm: args.tolerance,
        recommended_pitch_mm: recommended.map(|r| r.pitch),
        predicted_full_time_s: recommended.map(|r| r.seconds * full_angles),
        angles_deg: setup.angles.clone(),
        deflection_deg: setup.rule.deflection_deg(),
        e0_mm: setup.rule.e0,
        tie_band_rule: super::verify::tie_band_rule(args.starts.tie_band),
        starts: results
            .first()
            .map_or(0, |r| r.comparison.rows.len() / setup.angles.len().max(1)),
        seconds: results.iter().map(|r| r.seconds).collect(),
    };

    let out = OutputDir::stage(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut csv = csv::Writer::from_path(out.path("converge.csv"))?;
    csv.write_record([
        "pitch_mm", "metric", "max", "p95", "mean", "n", "seconds", "area_iou", "pass",
    ])?;
    for r in &results {
        let pass = args
            .tolerance
            .map_or(String::new(), |t| r.comparison.passes(t).to_string());
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
    csv.flush()?;
    // Every pitch's per-start rows, as `verify.csv` has them: where each
    // figure of converge.csv comes from.
    for r in &results {
        let mut rows = csv::Writer::from_path(out.path(format!("verify_{}mm.csv", r.pitch)))?;
        for row in &r.comparison.rows {
            rows.serialize(row)?;
        }
        rows.flush()?;
    }
    std::fs::write(
        out.path("converge.json"),
        serde_json::to_string_pretty(&summary)? + "\n",
    )?;
    write_plots(out.path(".").as_path(), &results, &fitted)?;
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;

    for r in &results {
        let maxes: Vec<String> = r
            .comparison
            .stats
            .iter()
            .filter(|(m, _)| kneeform::harness::DECIDED_METRICS.contains(&m.as_str()))
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
    for (m, f) in &fitted {
        if !kneeform::harness::DECIDED_METRICS.contains(&m.as_str()) {
            continue;
        }
        match f {
            Some(f) => eprintln!("{m:>22}: error ~ {:.3} p^{:.2}", f.c, f.alpha),
            None => eprintln!("{m:>22}: no fit (zero or too few errors)"),
        }
    }
    match (args.tolerance, recommended) {
        (Some(t), Some(r)) => eprintln!(
            "kneeform: the coarsest pitch within {t} mm is {} mm; a full 61-angle analysis at it takes about {:.1} s",
            r.pitch,
            r.seconds * full_angles
        ),
        (Some(t), None) => eprintln!("kneeform: no pitch tried is within {t} mm"),
        _ => {}
    }
    eprintln!("kneeform: results in {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}
