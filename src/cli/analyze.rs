//! `kneeform analyze`: STL in; colliding area per angle and composite out,
//! as CSV, STL, PNG and `summary.json`, all in one directory that appears
//! whole or not at all.

use std::io::BufWriter;
use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use kneeform::grid::GridSpec;
use kneeform::output::{self, OutputDir};
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
}

/// Reads the part, lays the grid and samples it.
pub fn prepare(path: &Path, scale: f64, side: Side, setup: &Setup) -> anyhow::Result<Prepared> {
    let t = Instant::now();
    let (part, sha256) = super::load_part(path, scale, side)?;
    let read_s = t.elapsed().as_secs_f64();

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

pub fn run(args: &AnalyzeArgs) -> anyhow::Result<()> {
    args.part.validate()?;
    let setup = args.setup.validate()?;
    super::set_threads(setup.threads)?;
    let started = Instant::now();
    let prepared = prepare(&args.part.part, args.part.scale, args.part.side, &setup)?;
    let t = Instant::now();
    let masks = run_engine(&prepared, &setup);
    let push_slide_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let counts = composite(&masks);
    let side = args.part.side;
    let grid = &prepared.grid;
    let out = OutputDir::stage(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
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
    output::write_depth_png(&out.path("depth.png"), grid)?;
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
    )?;
    let mut summary = summarize(args, &setup, &prepared, &masks, &counts);
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
    if args.report {
        // Written from the staged files, so report.html appears with them
        // or not at all.
        let options = kneeform::report::ReportOptions {
            part: Some(args.part.part.clone()),
            run_name: Some(args.out.clone()),
            ..kneeform::report::ReportOptions::new(out.path(""))
        };
        let shown_as = args.out.join("report.html");
        super::report::write(&options, &out.path("report.html"), &shown_as)?;
    }
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
    Ok(())
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
        rate: "x-slope".into(),
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
    }
}
