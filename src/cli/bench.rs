//! `kneeform bench`: the paper-sized workload, built here so that anyone can
//! rerun it: the built-in console (`scenarios/console.toml`, the oracle's
//! benchmark part too) at 369,408+ triangles, a 1538 x 801 grid at 1.24 mm,
//! 61 angles. It times sampling and push-and-slide (median of
//! several runs), and the paper algorithm against the fast one on the same
//! sample of start rows and angles in the same run (the paper algorithm
//! scans every slide to the grid's end, so the full run is extrapolated and
//! labelled so).

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Context, ensure};
use kneeform::grid::GridSpec;
use kneeform::scenario::{self, PAPER_TRIANGLES};
use kneeform::setup::Sampled;
use kneeform::strike::{Level, RateEstimate};
use kneeform::{Algorithm, EngineOptions, GridFootprint, Setup, colliding_masks};

use super::args::BenchArgs;

/// The paper's workload (Inui, Gunji and Umezu): grid and pitch (its
/// triangle count is [`PAPER_TRIANGLES`]).
const PAPER_GRID: [usize; 2] = [1538, 801];
const PAPER_PITCH: f64 = 1.24;
/// The paper's reported time for one console (s).
const PAPER_SECONDS: f64 = 2519.92;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    ensure!(args.runs >= 1, "--runs must be at least 1");
    ensure!(
        args.paper_rows >= 1 && args.paper_angles >= 1,
        "--paper-rows and --paper-angles must be at least 1"
    );
    let angles = super::args::parse_angles(&args.angles.angles)?;
    let t = Instant::now();
    let console = scenario::builtin("console").context("the console is a built-in scenario")?;
    let triangles = console.triangulate(Some(PAPER_TRIANGLES));
    let build_s = t.elapsed().as_secs_f64();
    // The grid centred on the console.
    let [nx, nz] = PAPER_GRID;
    let centred =
        |[lo, hi]: [f64; 2], n: usize| lo + (hi - lo - (n - 1) as f64 * PAPER_PITCH) / 2.0;
    let origin = [centred(console.extent.x, nx), centred(console.extent.z, nz)];
    let spec = GridSpec::explicit(origin[0], origin[1], nx, nz, PAPER_PITCH);
    // The default knee-form at the angles asked for; the grid is `spec`,
    // handed to the sampling stage.
    let setup = Setup {
        pitch: PAPER_PITCH,
        angles,
        ..Setup::default()
    };
    let node = EngineOptions::default();
    let fast = EngineOptions {
        rule: node.rule.with_level(args.level),
        ..EngineOptions::default()
    };

    let mut sample_s = Vec::new();
    let mut blind_s = Vec::new();
    let mut blind_count = 0;
    let mut slide_s = Vec::new();
    // SPEC's former x-slope rule on the same grid in the same runs: what
    // the window rule costs, its load cancelling out; under the surface
    // level, the node level: what the surface level costs.
    let (other, other_name) = match args.level {
        Level::Node => (
            EngineOptions {
                rule: node.rule.with_rate(RateEstimate::XSlope),
                ..EngineOptions::default()
            },
            "`--rate x-slope`",
        ),
        Level::Surface => (node.clone(), "`--level node`"),
    };
    let mut x_slope_s = Vec::new();
    let mut grid = None;
    let mut footprints = Vec::new();
    let mut composite_nodes = 0;
    for run in 0..args.runs {
        // The sampling stage: the heights and the footprints.
        let Sampled {
            grid: g,
            footprints: laid,
            sample_s: s,
            ..
        } = setup.sample_on(spec, &triangles, None);
        footprints = laid;
        sample_s.push(s);
        let t = Instant::now();
        blind_count =
            kneeform::blind::blind_spots(&triangles, &g, Setup::DEFAULT_BLIND_DEPTH).len();
        blind_s.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let masks = colliding_masks(&g, &footprints, &fast, &|| {});
        slide_s.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        colliding_masks(&g, &footprints, &other, &|| {});
        x_slope_s.push(t.elapsed().as_secs_f64());
        composite_nodes = kneeform::composite(&masks)
            .iter()
            .filter(|&&c| c > 0)
            .count();
        eprintln!(
            "run {}/{}: sample {:.3} s, blind spots {:.3} s, push+slide {:.3} s ({:.3} s under {other_name})",
            run + 1,
            args.runs,
            sample_s[run],
            blind_s[run],
            slide_s[run],
            x_slope_s[run]
        );
        grid = Some(g);
    }
    let grid = grid.expect("at least one run");
    // The ratio of each run's pair, then its median: the two were timed
    // back to back, so a load on this shared machine cancels out.
    let blind_ratio = median(blind_s.iter().zip(&sample_s).map(|(b, s)| b / s).collect());
    let blind = median(blind_s);
    let window_ratio = median(slide_s.iter().zip(&x_slope_s).map(|(w, x)| w / x).collect());
    let x_slope = median(x_slope_s);
    let (sample, slide) = (median(sample_s), median(slide_s));
    let total = sample + slide;

    // The paper algorithm on a sample of start rows through the part and a
    // sample of angles, against the fast one on exactly the same sample.
    let rows: Vec<usize> = (0..args.paper_rows)
        .map(|k| (nz / 4) + k * (nz / 2) / args.paper_rows)
        .collect();
    let sampled: Vec<GridFootprint> = (0..args.paper_angles)
        .map(|k| footprints[k * (footprints.len() - 1) / (args.paper_angles - 1).max(1)].clone())
        .collect();
    let on_rows = |algorithm| EngineOptions {
        algorithm,
        start_rows: Some(rows.clone()),
        ..EngineOptions::default()
    };
    let t = Instant::now();
    let paper_masks = colliding_masks(&grid, &sampled, &on_rows(Algorithm::Paper), &|| {});
    let paper_sample_s = t.elapsed().as_secs_f64();
    let mut fast_runs = Vec::new();
    let mut fast_masks = Vec::new();
    for _ in 0..args.runs {
        let t = Instant::now();
        fast_masks = colliding_masks(&grid, &sampled, &on_rows(Algorithm::Fast), &|| {});
        fast_runs.push(t.elapsed().as_secs_f64());
    }
    let fast_sample_s = median(fast_runs);
    let identical = paper_masks == fast_masks;

    // The exact oracle on a few starts through the part: the "3D collision
    // detection" baseline the paper calls too costly, per start.
    let oracle_per_start_s = if args.oracle_starts > 0 {
        let part = kneeform_oracle::Part::from_triangles(&triangles)?;
        let j = nz / 2;
        let starts: Vec<[f64; 2]> = (0..args.oracle_starts)
            .map(|k| {
                [
                    spec.x(nx / 4 + k * (nx / 2) / args.oracle_starts),
                    spec.z(j),
                ]
            })
            .collect();
        let options = kneeform::harness::oracle_options(&setup.knee, PAPER_PITCH, spec.x(0));
        let t = Instant::now();
        kneeform_oracle::evaluate(&part, &starts, &[0.0], &options)?;
        Some(t.elapsed().as_secs_f64() / starts.len() as f64)
    } else {
        None
    };
    let scale_up =
        (nz as f64 / rows.len() as f64) * (footprints.len() as f64 / sampled.len() as f64);
    let paper_full_s = paper_sample_s * scale_up;

    let mut md = String::new();
    let threads = rayon::current_num_threads();
    writeln!(md, "| quantity | value |")?;
    writeln!(md, "| --- | --- |")?;
    writeln!(
        md,
        "| part | scenarios/console.toml, {} triangles (built in {build_s:.2} s) |",
        triangles.len()
    )?;
    writeln!(
        md,
        "| grid | {nx} x {nz} at {PAPER_PITCH} mm, {} nodes sampled |",
        grid.finite_count()
    )?;
    writeln!(
        md,
        "| angles | {} ({}) |",
        footprints.len(),
        args.angles.angles
    )?;
    writeln!(md, "| threads | {threads} |")?;
    writeln!(md, "| sampling (median of {}) | {sample:.3} s |", args.runs)?;
    writeln!(
        md,
        "| blind-spot sampling, conservative per cell (median) | {blind:.3} s, {blind_ratio:.1}x the node sampling in the same runs; {blind_count} blind spots at {} mm |",
        Setup::DEFAULT_BLIND_DEPTH
    )?;
    writeln!(md, "| level | {} |", args.level.name())?;
    writeln!(
        md,
        "| push + slide, {} angles (median) | {slide:.3} s |",
        footprints.len()
    )?;
    let what = match args.level {
        Level::Node => "the window rule",
        Level::Surface => "the surface level",
    };
    writeln!(
        md,
        "| push + slide under {other_name} in the same runs (median) | {x_slope:.3} s; {what} takes {window_ratio:.2}x that (median of the runs' ratios) |"
    )?;
    writeln!(
        md,
        "| per angle | {:.1} ms |",
        slide / footprints.len() as f64 * 1e3
    )?;
    writeln!(
        md,
        "| **total (sample + {} angles)** | **{total:.3} s** |",
        footprints.len()
    )?;
    writeln!(md, "| composite colliding nodes | {composite_nodes} |")?;
    if let Some(mib) = kneeform::memory::peak_rss_bytes().map(|b| b / (1024.0 * 1024.0)) {
        writeln!(md, "| peak memory (RSS) | {mib:.0} MiB |")?;
    }
    writeln!(
        md,
        "| paper algorithm, {} start rows x {} angles, node level | {paper_sample_s:.3} s (fast on the same: {fast_sample_s:.4} s) |",
        rows.len(),
        sampled.len()
    )?;
    writeln!(
        md,
        "| paper / fast on that sample (fast includes its fixed set-up: padded grid, window-minimum table) | {:.0}x |",
        paper_sample_s / fast_sample_s
    )?;
    writeln!(md, "| masks identical on that sample | {identical} |")?;
    if let Some(oracle) = oracle_per_start_s {
        let engine = slide / (footprints.len() as f64 * (nx * nz) as f64);
        writeln!(
            md,
            "| exact oracle, per start and angle ({} starts, {threads} threads) | {:.1} ms, against the engine's {:.0} ns: {:.1e}x |",
            args.oracle_starts,
            oracle * 1e3,
            engine * 1e9,
            oracle / engine
        )?;
    }
    writeln!(
        md,
        "| paper algorithm, full run (EXTRAPOLATED x{scale_up:.0} from the sample) | {paper_full_s:.0} s |"
    )?;
    writeln!(
        md,
        "| **paper (extrapolated) / fast (measured), full run** | **{:.0}x** |",
        paper_full_s / slide
    )?;
    writeln!(
        md,
        "| the paper's reported time (GPU + CPU) | {PAPER_SECONDS} s, {:.0}x ours |",
        PAPER_SECONDS / total
    )?;
    print!("{md}");
    if let Some(path) = &args.markdown {
        std::fs::write(path, &md)?;
    }
    ensure!(
        identical,
        "the paper and fast algorithms disagree on the sampled rows"
    );
    Ok(())
}
