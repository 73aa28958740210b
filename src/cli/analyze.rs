//! `kneeform analyze`: STL in; colliding area per angle and composite out,
//! as CSV, STL, PNG and `summary.json`, all in one directory that appears
//! whole or not at all.

use std::process::ExitCode;

use anyhow::{Context, bail, ensure};
use kneeform::Analysis;
use kneeform::harness::{self, AutoPitch};
use kneeform::output;
use kneeform::partition::Shard;
use kneeform::shard::ShardError;
use kneeform::summary::{CheckStatus, SampleCheck};

use super::args::{AnalyzeArgs, PitchArg};
use super::progress::Bars;

/// Exit code of `analyze --report` when the analysis is written but its
/// report is not.
pub const REPORT_FAILED: u8 = 3;

pub fn run(args: &AnalyzeArgs) -> anyhow::Result<ExitCode> {
    let source = args.part.validate(&args.parts, &args.ignore)?;
    let (mut setup, threads) = args.setup.validate()?;
    let auto = args.setup.pitch == PitchArg::Auto;
    let auto_pitch = match (auto, args.tolerance) {
        (true, Some(tolerance)) => Some(AutoPitch {
            tolerance,
            budget_s: args.budget_s,
            selection: kneeform::harness::StartSelection::default_for(1),
        }),
        (true, None) => bail!("--pitch auto needs --tolerance MM: the error it must meet"),
        (false, Some(_)) => bail!(
            "--tolerance is for --pitch auto; with a pitch given, `kneeform verify` measures the error"
        ),
        (false, None) => None,
    };
    let shard = args
        .shard
        .as_deref()
        .map(Shard::parse)
        .transpose()
        .context("--shard")?;
    if let Some(shard) = shard {
        ensure!(
            !auto,
            "--shard needs a pitch in mm: every shard must sample the same grid, and --pitch auto chooses one per run"
        );
        ensure!(
            !args.report && !args.points_csv && !args.files.any(),
            "--report, --points-csv, --csv, --stl and --ply are for the merged run: pass them to `kneeform merge`"
        );
        let angles = setup.angles.len();
        if shard.count > angles {
            return Err(ShardError::TooMany {
                shards: shard.count,
                angles,
            })
            .context("--shard");
        }
    }
    // Before any work: where the results go, so that an unwritable or
    // occupied --out is said now, not after the computation.
    let inputs: Vec<&std::path::Path> = args
        .parts
        .iter()
        .chain(&args.ignore)
        .map(|p| p.as_path())
        .chain(args.part.frame_file())
        .collect();
    let out = super::stage_output(&args.out, args.force, &inputs)?;
    super::set_threads(threads)?;
    let bars = Bars::default();
    let mut choice = None;
    if let Some(auto) = &auto_pitch {
        let input = source.read()?;
        let chosen =
            harness::choose_pitch(&input, &setup, auto, &bars).map_err(super::harness_error)?;
        for row in &chosen.study {
            let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
            super::print_result(&format!(
                "kneeform: pitch study: {:>6} mm: judged area distance to the exact knee-form {} mm (the level error's false alarms, safe side, shown: {} mm; change from the coarser grid, shown: {} mm), analysis about {:.1} s, {:.2} GiB{}",
                row.pitch_mm,
                mm(row.exact_area_distance_mm),
                mm(row.level_error_area_mm),
                mm(row.grid_change_mm),
                row.predicted_s,
                row.memory_gib,
                if row.meets {
                    ": the judged distance meets the tolerance"
                } else {
                    ""
                }
            ));
        }
        super::print_result(&format!(
            "kneeform: --pitch auto chose {} mm: {}; the analysis should take about {:.1} s (study {:.1} s)",
            chosen.pitch_mm, chosen.reason, chosen.predicted_s, chosen.study_s
        ));
        setup.pitch = chosen.pitch_mm;
        choice = Some(chosen);
    }
    let angles = shard.unwrap_or(Shard::WHOLE);
    let mut analysis = Analysis::of_source_at(&source, &setup, angles, &bars)?;
    analysis.pitch_choice = choice;
    // The sample check (a shard checks its own angles: the merge puts the
    // checks together as the whole run's).
    let t = std::time::Instant::now();
    analysis.sample_check = Some(if args.no_check {
        SampleCheck::not_run(
            CheckStatus::Skipped,
            "skipped (--no-check): this analysis carries no measured accuracy; `kneeform verify` measures it",
        )
    } else {
        let triangles = analysis.input.part.triangles.len();
        analysis.memory.add_sample_check(triangles);
        harness::check_analysis(&analysis, &bars).map_err(super::harness_error)?
    });
    analysis.timings.check_s = t.elapsed().as_secs_f64();
    if let Some(shard) = shard {
        kneeform::shard::write_shard(&out, &analysis)?;
        out.commit()
            .with_context(|| format!("cannot move the shard into {}", args.out.display()))?;
        super::print_result(&format!(
            "kneeform: shard {shard}: {} of {} angles written to {}; `kneeform merge` puts the {} shards together",
            angles.indices(setup.angles.len()).len(),
            setup.angles.len(),
            args.out.display(),
            shard.count
        ));
        return Ok(ExitCode::SUCCESS);
    }
    let options = output::WriteOptions {
        points_csv: args.points_csv,
        plain_csv: args.files.csv,
        stl: args.files.stl,
        ply: args.files.ply,
    };
    let summary = output::write_analysis(&out, &analysis, &options)?;
    // Held until the report is written: no other run replaces the
    // directory under it.
    let _lock = out
        .commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    if let Some(chosen) = &analysis.pitch_choice {
        let t = &analysis.timings;
        eprintln!(
            "kneeform: at {} mm the analysis took {:.1} s (predicted {:.1} s)",
            chosen.pitch_mm,
            t.sample_s + t.blind_s + t.push_slide_s,
            chosen.predicted_s
        );
    }
    super::print_result(&format!(
        "kneeform: {} angles, composite {} nodes ({:.0} mm^2); knee-form L = {} mm{}, R = {} mm; results in {}",
        analysis.masks.len(),
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
    ));
    for (k, f) in summary.files.iter().enumerate() {
        super::print_result(&format!(
            "kneeform: file {k}, {}: {}",
            f.path,
            if f.ignored {
                "ignored (--ignore)".to_string()
            } else {
                format!(
                    "{} colliding nodes ({:.0} mm^2)",
                    f.colliding_nodes, f.colliding_area_mm2
                )
            }
        ));
    }
    print_zones(&summary.zones);
    if let Some(check) = &analysis.sample_check {
        super::print_check(check);
    }
    if args.report {
        // From the committed run, so the analysis stands whatever the
        // report meets; report.html itself appears whole or not at all.
        let options = kneeform::report::ReportOptions {
            // One file: the one just analysed; an assembly's files are
            // found from summary.json.
            part: source.is_single().then(|| args.parts[0].clone()),
            ..kneeform::report::ReportOptions::new(&args.out)
        };
        let report = args.out.join("report.html");
        // Recorded as kneeform's, so that --force may replace it later.
        let written = super::write_report(&options, &report, &report).and_then(|()| {
            output::add_to_record(&args.out, &["report.html"])
                .with_context(|| format!("cannot record report.html in {}", output::RUN_RECORD))
        });
        if let Err(err) = written {
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

/// The five largest struck zones, one line each (all of them in
/// `zones.csv`), and how many more there are.
fn print_zones(zones: &[kneeform::zones::Zone]) {
    const SHOWN: usize = 5;
    if zones.is_empty() {
        return;
    }
    let specks = zones.iter().filter(|z| z.speck).count();
    super::print_result(&format!(
        "kneeform: {} struck zones ({specks} of them specks under {} nodes), largest first (zones.csv lists them all):",
        zones.len(),
        kneeform::zones::SPECK_NODES
    ));
    for z in zones.iter().take(SHOWN) {
        let c = z.centroid;
        super::print_result(&format!(
            "kneeform:   zone {}: {:.0} mm^2 around ({:.1}, {:.1}, {:.1}) mm, angles {}{}",
            z.id,
            z.area_mm2,
            c[0],
            c[1],
            c[2],
            z.angle_runs,
            if z.touches_blind_spot {
                "; a blind spot touches it"
            } else {
                ""
            }
        ));
    }
    if zones.len() > SHOWN {
        super::print_result(&format!("kneeform:   ... and {} more", zones.len() - SHOWN));
    }
}
