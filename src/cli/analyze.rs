//! `kneeform analyze`: STL in; colliding area per angle and composite out,
//! as CSV, STL, PNG and `summary.json`, all in one directory that appears
//! whole or not at all.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail, ensure};
use kneeform::Analysis;
use kneeform::harness::{self, AutoPitch};
use kneeform::output::{self, OutputDir};

use super::args::{AnalyzeArgs, PitchArg};
use super::progress::Bars;

/// Exit code of `analyze --report` when the analysis is written but its
/// report is not.
pub const REPORT_FAILED: u8 = 3;

pub fn run(args: &AnalyzeArgs) -> anyhow::Result<ExitCode> {
    args.part.validate()?;
    let (mut setup, threads) = args.setup.validate()?;
    let auto = args.setup.pitch == PitchArg::Auto;
    let auto_pitch = match (auto, args.tolerance) {
        (true, Some(tolerance)) => Some(AutoPitch {
            tolerance,
            budget_s: args.budget_s,
            starts: AutoPitch::DEFAULT_STARTS,
        }),
        (true, None) => bail!("--pitch auto needs --tolerance MM: the error it must meet"),
        (false, Some(_)) => bail!(
            "--tolerance is for --pitch auto; with a pitch given, `kneeform verify` measures the error"
        ),
        (false, None) => None,
    };
    // Before any work: where the results go, so that an unwritable or
    // occupied --out is said now, not after the computation.
    let out = stage_output(&args.out, args.force)?;
    super::set_threads(threads)?;
    let bars = Bars::default();
    let mut choice = None;
    if let Some(auto) = &auto_pitch {
        let input = kneeform::read_part(&args.part.part, args.part.scale, args.part.side)?;
        let chosen =
            harness::choose_pitch(&input, &setup, auto, &bars).map_err(super::harness_error)?;
        for row in &chosen.study {
            let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
            eprintln!(
                "kneeform: pitch study: {:>6} mm: exact area distance {} mm, change from the coarser grid {} mm, analysis about {:.1} s, {:.2} GiB{}",
                row.pitch_mm,
                mm(row.exact_area_distance_mm),
                mm(row.grid_change_mm),
                row.predicted_s,
                row.memory_gib,
                if row.meets {
                    ": meets the tolerance"
                } else {
                    ""
                }
            );
        }
        eprintln!(
            "kneeform: --pitch auto chose {} mm: {}; the analysis should take about {:.1} s (study {:.1} s)",
            chosen.pitch_mm, chosen.reason, chosen.predicted_s, chosen.study_s
        );
        setup.pitch = chosen.pitch_mm;
        choice = Some(chosen);
    }
    let mut analysis = Analysis::of_file(
        &args.part.part,
        args.part.scale,
        args.part.side,
        &setup,
        &bars,
    )?;
    analysis.pitch_choice = choice;
    let summary = output::write_analysis(&out, &analysis)?;
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
    eprintln!(
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
    );
    if args.report {
        // From the committed run, so the analysis stands whatever the
        // report meets; report.html itself appears whole or not at all.
        let options = kneeform::report::ReportOptions {
            part: Some(args.part.part.clone()),
            ..kneeform::report::ReportOptions::new(&args.out)
        };
        let report = args.out.join("report.html");
        if let Err(err) = super::write_report(&options, &report, &report) {
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
