//! `kneeform analyze`: STL in; colliding area per angle and composite out,
//! as CSV, STL, PNG and `summary.json`, all in one directory that appears
//! whole or not at all.

use std::io::BufWriter;
use std::path::Path;
use std::time::Instant;

use std::process::ExitCode;

use anyhow::{Context, bail, ensure};
use indicatif::{ProgressBar, ProgressStyle};
use kneeform::grid::GridSpec;
use kneeform::output::{self, OutputDir};
use kneeform::sanity::{self, Warning};
use kneeform::summary::{AngleSummary, Summary, Timings};
use kneeform::{
    AngleMask, EngineOptions, Footprint, GridFootprint, HeightGrid, KneeForm, Part, Side,
    colliding_masks, composite,
};

use super::args::{AnalyzeArgs, GridPlacement, Setup};

/// A part read and sampled, ready for push and slide.
pub struct Prepared {
    pub part: Part,
    pub sha256: String,
    pub grid: HeightGrid,
    pub footprints: Vec<GridFootprint>,
    pub read_s: f64,
    pub sample_s: f64,
    /// The part's sanity warnings, printed once read, before sampling.
    pub warnings: Vec<Warning>,
}

/// Reads the part, lays the grid and samples it.
pub fn prepare(path: &Path, scale: f64, side: Side, setup: &Setup) -> anyhow::Result<Prepared> {
    let t = Instant::now();
    let (part, sha256) = super::load_part(path, scale, side)?;
    let read_s = t.elapsed().as_secs_f64();
    let warnings = sanity::part_warnings(&part, side, &setup.knee);
    warn(&warnings);

    let t = Instant::now();
    let footprints: Vec<Footprint> = setup
        .angles
        .iter()
        .map(|&a| Footprint::new(&setup.knee, a))
        .collect();
    let spec = grid_spec(&part, &setup.knee, setup)?;
    spec.check_fits(setup.max_memory_bytes)?;
    let grid = HeightGrid::sample(&part.triangles, spec);
    let footprints = footprints
        .iter()
        .zip(&setup.angles)
        .map(|(fp, &a)| GridFootprint::new(fp, a, setup.pitch))
        .collect();
    Ok(Prepared {
        part,
        sha256,
        grid,
        footprints,
        read_s,
        sample_s: t.elapsed().as_secs_f64(),
        warnings,
    })
}

/// SPEC's default extent covers every requested angle and its mirror, so
/// that a part mirrored in z gets the mirrored grid.
pub fn grid_spec(part: &Part, knee: &KneeForm, setup: &Setup) -> anyhow::Result<GridSpec> {
    Ok(match setup.grid {
        GridPlacement::AroundPart => {
            let extents: Vec<Footprint> = setup
                .angles
                .iter()
                .flat_map(|&a| [Footprint::new(knee, a), Footprint::new(knee, -a)])
                .collect();
            GridSpec::around(&part.bbox(), &extents, setup.pitch)
        }
        GridPlacement::Explicit { origin, size } => {
            GridSpec::explicit(origin[0], origin[1], size[0], size[1], setup.pitch)
        }
    })
}

/// Runs push and slide with a progress bar over angles.
pub fn run_engine(prepared: &Prepared, setup: &Setup) -> Vec<AngleMask> {
    let bar = ProgressBar::new(prepared.footprints.len() as u64).with_style(
        ProgressStyle::with_template(
            "{prefix} [{bar:30}] {pos}/{len} angles, {elapsed} ({eta} left)",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_prefix("push and slide");
    let options = EngineOptions {
        rule: setup.rule,
        algorithm: setup.algorithm,
        start_rows: None,
    };
    let masks = colliding_masks(&prepared.grid, &prepared.footprints, &options, &|| {
        bar.inc(1)
    });
    bar.finish_and_clear();
    masks
}

/// Exit code of `analyze --report` when the analysis is written but its
/// report is not.
pub const REPORT_FAILED: u8 = 3;

pub fn run(args: &AnalyzeArgs) -> anyhow::Result<ExitCode> {
    args.part.validate()?;
    let setup = args.setup.validate()?;
    // Before any work: where the results go, so that an unwritable or
    // occupied --out is said now, not after the computation.
    let out = stage_output(&args.out, args.force)?;
    let mut warnings = sanity::angle_warnings(&setup.angles);
    warn(&warnings);
    super::set_threads(setup.threads)?;
    let started = Instant::now();
    let prepared = prepare(&args.part.part, args.part.scale, args.part.side, &setup)?;
    warnings.extend(prepared.warnings.iter().cloned());
    let t = Instant::now();
    let masks = run_engine(&prepared, &setup);
    let push_slide_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let counts = composite(&masks);
    let composite_nodes = counts.iter().filter(|&&c| c > 0).count();
    let nothing = sanity::result_warnings(composite_nodes);
    warn(&nothing);
    warnings.extend(nothing);
    let side = args.part.side;
    let grid = &prepared.grid;
    let create = |name: &str| -> anyhow::Result<BufWriter<std::fs::File>> {
        Ok(BufWriter::new(std::fs::File::create(out.path(name))?))
    };
    output::write_colliding_points(create("colliding_points.csv")?, grid, &masks, side)?;
    output::write_composite(create("composite.csv")?, grid, &counts, side)?;
    output::write_colliding_area(create("colliding_area.stl")?, grid, &counts, side)?;
    output::write_colliding_area_ply(
        create("colliding_area.ply")?,
        grid,
        &counts,
        masks.len(),
        side,
    )?;
    output::write_depth_png(&out.path("depth.png"), grid, side)?;
    let title = format!(
        "Composite colliding area, {} angles (L = {} mm)",
        masks.len(),
        setup.knee.triangle_side
    );
    output::write_composite_png(
        &out.path("composite.png"),
        grid,
        &counts,
        masks.len(),
        &title,
        side,
    )?;
    let mut summary = summarize(args, &setup, &prepared, &masks, &counts);
    summary.warnings = warnings.iter().map(ToString::to_string).collect();
    summary.timings = Timings {
        read_s: prepared.read_s,
        sample_s: prepared.sample_s,
        push_slide_s,
        write_s: t.elapsed().as_secs_f64(),
        total_s: started.elapsed().as_secs_f64(),
    };
    std::fs::write(
        out.path("summary.json"),
        serde_json::to_string_pretty(&summary)? + "\n",
    )?;
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    eprintln!(
        "kneeform: {} angles, composite {} nodes ({:.0} mm^2); knee-form L = {} mm{}, R = {} mm; results in {}",
        masks.len(),
        summary.composite_nodes,
        summary.composite_area_mm2,
        setup.knee.triangle_side,
        if summary.triangle_side_assumed {
            " (assumed)"
        } else {
            ""
        },
        setup.knee.radius,
        args.out.display()
    );
    if args.report {
        // From the committed run, so the analysis stands whatever the
        // report meets; report.html itself appears whole or not at all.
        let options = kneeform::report::ReportOptions {
            part: Some(args.part.part.clone()),
            ..kneeform::report::ReportOptions::new(&args.out)
        };
        let report = args.out.join("report.html");
        if let Err(err) = super::report::write(&options, &report, &report) {
            eprintln!(
                "kneeform: error: {}; the analysis is complete and kept in {}, only its report is missing",
                super::one_line(&err),
                args.out.display()
            );
            return Ok(ExitCode::from(REPORT_FAILED));
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Prints each warning as one line on stderr.
pub fn warn(warnings: &[Warning]) {
    for w in warnings {
        eprintln!("kneeform: warning: {w}");
    }
}

/// Checks `out` before any work and stages the run's files beside it. An
/// existing directory is replaced only with `force`, and only when it is
/// an earlier run's (it holds `summary.json`) or empty: --force must not
/// remove a directory of someone else's files. Staging creates a directory
/// beside `out`, so an unwritable place fails here.
pub fn stage_output(out: &Path, force: bool) -> anyhow::Result<OutputDir> {
    match std::fs::metadata(out) {
        Ok(meta) if !meta.is_dir() => {
            bail!("--out {} is a file, not a directory", out.display())
        }
        Ok(_) => {
            ensure!(
                force,
                "--out {} already exists: pass --force to replace it, or choose another --out",
                out.display()
            );
            let is_run = out.join("summary.json").is_file();
            let is_empty = std::fs::read_dir(out)
                .with_context(|| format!("cannot read --out {}", out.display()))?
                .next()
                .is_none();
            ensure!(
                is_run || is_empty,
                "--out {} is not a kneeform run directory (no summary.json), so --force will not replace it: choose another --out",
                out.display()
            );
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("cannot use --out {}", out.display())),
    }
    OutputDir::stage_replacing(out)
        .with_context(|| format!("cannot write the results to {}", out.display()))
}

fn summarize(
    args: &AnalyzeArgs,
    setup: &Setup,
    prepared: &Prepared,
    masks: &[AngleMask],
    counts: &[u16],
) -> Summary {
    let spec = prepared.grid.spec;
    let area = spec.pitch * spec.pitch;
    let bbox = prepared.part.bbox();
    // Back to the part's frame: a mirrored side swaps the y bounds.
    let side = args.part.side;
    let (y0, y1) = (side.to_part(bbox.min[1]), side.to_part(bbox.max[1]));
    let composite_nodes = counts.iter().filter(|&&c| c > 0).count();
    Summary {
        kneeform_version: env!("CARGO_PKG_VERSION").into(),
        run_unix_time: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs()),
        input_file: args.part.part.display().to_string(),
        sha256: prepared.sha256.clone(),
        triangles: prepared.part.file_triangles,
        degenerate_triangles: prepared.part.degenerate,
        bbox_min: [bbox.min[0], y0.min(y1), bbox.min[2]],
        bbox_max: [bbox.max[0], y0.max(y1), bbox.max[2]],
        scale: args.part.scale,
        side,
        triangle_side_mm: setup.knee.triangle_side,
        triangle_side_assumed: setup.knee.triangle_side == KneeForm::default().triangle_side,
        radius_mm: setup.knee.radius,
        thickness_mm: setup.knee.thickness,
        pitch_mm: spec.pitch,
        grid_origin: [spec.x(0), spec.z(0)],
        grid_size: [spec.nx, spec.nz],
        sampled_nodes: prepared.grid.finite_count(),
        angles_deg: setup.angles.clone(),
        deflection_deg: setup.rule.deflection_deg(),
        sigma: setup.rule.sigma,
        e0_mm: setup.rule.e0,
        rate: setup.rule.rate.name().into(),
        algorithm: setup.algorithm,
        threads: rayon::current_num_threads(),
        per_angle: masks
            .iter()
            .map(|m| AngleSummary {
                angle_deg: m.angle_deg,
                placed_starts: m.placed,
                colliding_nodes: m.colliding,
                colliding_area_mm2: m.colliding as f64 * area,
            })
            .collect(),
        composite_nodes,
        composite_area_mm2: composite_nodes as f64 * area,
        timings: Timings::default(),
        warnings: Vec::new(),
    }
}
