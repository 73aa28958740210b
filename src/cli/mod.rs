//! The subcommands of the `kneeform` binary.

pub mod analyze;
pub mod args;
pub mod batch;
pub mod bench;
pub mod converge;
pub mod diff;
pub mod merge;
pub mod progress;
pub mod report;
pub mod scenario;
pub mod study;
pub mod verify;

use std::path::Path;

use anyhow::Context;
use std::process::ExitCode;

use kneeform::harness::{self, HarnessError, StudyPart};
use kneeform::output::OutputDir;
use kneeform::partition::Shard;
use kneeform::report::ReportOptions;
use kneeform::{PartFile, Setup};

use args::StudyArgs;

/// Prints `line`, a line of the command's results (what it found, and
/// where it wrote them), on the standard output. Everything else a command
/// says (progress, notes on its work, warnings, errors) goes to the
/// standard error, so that `kneeform ... > results.txt` keeps the results
/// alone. A reader that went away (`| head`) is no error: the results are
/// in their files.
pub fn print_result(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{line}");
}

/// Writes the report of `options` to `out` and says so on stdout, naming
/// the file `shown_as` (where it will be once staged files are moved):
/// `report`'s work, and `analyze --report`'s.
pub fn write_report(options: &ReportOptions, out: &Path, shown_as: &Path) -> anyhow::Result<()> {
    let report = kneeform::report::write_report(options, out).with_context(|| {
        format!(
            "cannot write the report of {} to {}",
            options.run_dir.display(),
            shown_as.display()
        )
    })?;
    print_result(&format!(
        "kneeform: report of {} ({} triangles, views rendered in {:.2} s) written to {}",
        report.part_path.display(),
        report.triangles,
        report.render_s,
        shown_as.display()
    ));
    Ok(())
}

/// The start `verify` and `converge` share: every flag checked (the
/// command's own options by `check`), `out` checked, locked and staged
/// (before any work: the oracle may run for hours, as `analyze` does), the
/// thread pool sized, the part read.
pub fn study_inputs(
    study: &StudyArgs,
    check: anyhow::Result<()>,
    out: &Path,
) -> anyhow::Result<(PartFile, Setup, OutputDir)> {
    let (part, setup) = (&study.part, &study.setup);
    let source = part.validate(std::slice::from_ref(&study.path), &[])?;
    anyhow::ensure!(
        setup.pitch != args::PitchArg::Auto,
        "--pitch auto is for analyze: give verify and converge a pitch (mm)"
    );
    let (setup, threads) = setup.validate()?;
    check?;
    let inputs: Vec<&Path> = std::iter::once(study.path.as_path())
        .chain(part.frame_file())
        .collect();
    let staged = stage_output(out, study.force, &inputs)?;
    set_threads(threads)?;
    kneeform::analysis::check_reading(&source, setup.max_memory_bytes)?;
    let input = source.read()?;
    Ok((input, setup, staged))
}

/// `--shard K/N` of a study, parsed; `None` without one.
pub fn study_shard(study: &StudyArgs) -> anyhow::Result<Option<Shard>> {
    study
        .shard
        .as_deref()
        .map(Shard::parse)
        .transpose()
        .context("--shard")
}

/// Runs a study command (`verify`, `converge`): reads its part and setup
/// (its own options checked first), then its shard when `--shard` is
/// given (written to `out`), else the whole study, of the setup's
/// approach, written to `out` and printed as `kneeform merge` prints it.
pub fn run_study(
    study: &StudyArgs,
    out: &Path,
    options: harness::StudyOptions,
) -> anyhow::Result<ExitCode> {
    let shard = study_shard(study)?;
    // A convergence study's pitches are its --pitches.
    let pitch_flag = if matches!(options, harness::StudyOptions::Converge(_)) {
        "--pitches"
    } else {
        "--pitch"
    };
    let study_error = |e| harness_error_in(e, pitch_flag);
    let (input, setup, staged) = study_inputs(study, options.validate().map_err(study_error), out)?;
    let bars = progress::Bars::default();
    if let Some(shard) = shard {
        let part =
            harness::study_shard(&input, &setup, options, shard, &bars).map_err(study_error)?;
        return write_study_shard(staged, out, &part);
    }
    let result = harness::study(&input, &setup, options, &bars).map_err(study_error)?;
    // A convergence study says how long its one oracle run took (a merge
    // sums its shards').
    if let Some(line) = result.oracle_line(setup.angles.len()) {
        eprintln!("{line}");
    }
    kneeform::output::write_study_files(&staged, &result)?;
    staged
        .commit()
        .with_context(|| format!("cannot move results into {}", out.display()))?;
    Ok(study::print_study(&result, out))
}

/// The sample check's line, and its warning where it found the grid beyond
/// its tolerance.
pub fn print_check(check: &kneeform::summary::SampleCheck) {
    print_result(&format!("kneeform: {}", check.line()));
    if check.exceeds_tolerance {
        eprintln!(
            "kneeform: warning: the sample check found the grid's colliding area further than sqrt 2 pitches ({} mm, `verify`'s default tolerance) from the exact knee-form's; run `kneeform verify` on this part with the same flags for the evidence, or choose a finer pitch (`--pitch auto --tolerance MM`)",
            kneeform::limits::short(check.tolerance_mm)
        );
    }
}

/// Writes a study's shard into `staged`, the staged `out` (it appears
/// whole or not at all), and says so.
pub fn write_study_shard(
    staged: OutputDir,
    out: &Path,
    part: &StudyPart,
) -> anyhow::Result<ExitCode> {
    kneeform::shard::study::write_study_shard(&staged, part)?;
    staged
        .commit()
        .with_context(|| format!("cannot move the shard into {}", out.display()))?;
    let shard = part.shard;
    print_result(&format!(
        "kneeform: shard {shard}: {} of {} starts written to {}; `kneeform merge` puts the {} shards together",
        shard.indices(part.starts.len()).len(),
        part.starts.len(),
        out.display(),
        shard.count
    ));
    Ok(ExitCode::SUCCESS)
}

/// A harness error with the flag it concerns in front, where one does.
pub fn harness_error(err: HarnessError) -> anyhow::Error {
    harness_error_in(err, "--pitch")
}

/// [`harness_error`] of a command whose pitches are given by `pitch_flag`
/// (`converge`'s `--pitches`).
pub fn harness_error_in(err: HarnessError, pitch_flag: &str) -> anyhow::Error {
    let flag = match &err {
        HarnessError::Setup(e) if e.field() == "pitch" => Some(pitch_flag.to_string()),
        HarnessError::Setup(e) => Some(format!("--{}", e.field().replace('_', "-"))),
        HarnessError::Tolerance(_) => Some("--tolerance".into()),
        HarnessError::TieBand(_) => Some("--tie-band".into()),
        HarnessError::Pitches(_) => Some("--pitches".into()),
        HarnessError::EmptySample
        | HarnessError::Strip(_)
        | HarnessError::RunLength { .. }
        | HarnessError::NoneChosen(_) => Some("--starts".into()),
        HarnessError::DirectApproach => Some("--approach".into()),
        HarnessError::TooManyShards { .. } => Some("--shard".into()),
        _ => None,
    };
    match flag {
        Some(flag) => anyhow::Error::new(err).context(flag),
        None => err.into(),
    }
}

/// The error and its causes as one line, `outer: inner: ...`, each cause
/// said once: a layer that already quotes its cause (`{path}: {source}`,
/// as thiserror messages often do) is not followed by the cause again, so
/// an OS error never reads `(os error 2): No such file or directory (os
/// error 2)`. Line breaks inside a message become spaces.
pub fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
        if text.is_empty() || line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    cap(line, MAX_LINE_CHARS)
}

/// The longest error line said whole (characters): a message listing
/// thousands of indices (a damaged shard's) was 11 KB.
const MAX_LINE_CHARS: usize = 600;

/// `line` cut to `max` characters at a word, saying how many were left
/// out.
fn cap(line: String, max: usize) -> String {
    let count = line.chars().count();
    if count <= max {
        return line;
    }
    let cut: String = line.chars().take(max).collect();
    let cut = cut.rsplit_once(' ').map_or(cut.as_str(), |(head, _)| head);
    let left = count - cut.chars().count();
    format!("{cut} ... ({left} more characters left out)")
}

/// What clap found wrong with a command line, in one line: its message,
/// without the usage and the tip that follow it (a list of missing
/// arguments runs on to a second line, joined).
pub fn clap_message(err: &clap::Error) -> String {
    let text = err.render().to_string();
    let message: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("tip:"))
        .collect();
    let message = message.join(" ");
    let first = message.strip_prefix("error: ").unwrap_or(&message);
    if first.is_empty() {
        "the command line is not understood".into()
    } else {
        first.into()
    }
}

/// Sizes rayon's global pool (default: one thread per CPU) and starts it
/// now, so that a system that gives no threads (`ulimit -v` leaves no
/// room for their stacks) is said in a line, not in rayon's panic at its
/// first use.
pub fn set_threads(threads: Option<usize>) -> anyhow::Result<()> {
    if let Some(n) = threads {
        args::check_threads(n)?;
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build_global()
        .context("cannot start the worker threads")?;
    Ok(())
}

/// Checks `out` before any work and stages the run's files beside it
/// (the directory's lock taken: one run at a time writes it). An existing
/// directory is replaced only with `force`, and only when it is empty or
/// its record (`kneeform-run.json`) proves every file in it kneeform's,
/// unchanged, and it holds none of this run's `inputs` (a part, a shard):
/// --force must not remove a directory of someone else's files. Staging
/// creates a directory beside `out`, so an unwritable place fails here.
pub fn stage_output(out: &Path, force: bool, inputs: &[&Path]) -> anyhow::Result<OutputDir> {
    use anyhow::{bail, ensure};
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
            if let Some(input) = input_inside(out, inputs) {
                bail!(
                    "--out {} holds {}, an input of this run, so --force will not replace it: choose another --out",
                    out.display(),
                    input.display()
                );
            }
            if let Some(why) = kneeform::output::why_not_replaceable(out)
                .with_context(|| format!("cannot read --out {}", out.display()))?
            {
                bail!(
                    "--out {} {why}, so --force will not replace it: move its files out or choose another --out",
                    out.display()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("cannot use --out {}", out.display())),
    }
    OutputDir::stage_replacing(out)
        .with_context(|| format!("cannot write the results to {}", out.display()))
}

/// The first of `inputs` inside the directory `out` (or `out` itself),
/// by their canonical paths; inputs that cannot be resolved (a stream)
/// are not inside.
fn input_inside<'a>(out: &Path, inputs: &[&'a Path]) -> Option<&'a Path> {
    let out = std::fs::canonicalize(out).ok()?;
    inputs
        .iter()
        .copied()
        .find(|input| std::fs::canonicalize(input).is_ok_and(|p| p.starts_with(&out)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("{path}: {source}")]
    struct Quoting {
        path: String,
        source: std::io::Error,
    }

    #[test]
    fn a_long_line_is_cut_saying_how_much_is_left_out() {
        assert_eq!(cap("short".into(), 600), "short");
        let long = (0..3000)
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        let line = cap(format!("shard 1/4 does not hold starts [{long}]"), 600);
        assert!(line.len() < 700, "{}", line.len());
        assert!(line.ends_with("more characters left out)"), "{line}");
        let left: usize = line
            .rsplit_once(" ... (")
            .and_then(|(_, t)| t.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap();
        assert_eq!(
            line.chars().count()
                - " ... ( more characters left out)".len()
                - left.to_string().len()
                + left,
            format!("shard 1/4 does not hold starts [{long}]")
                .chars()
                .count()
        );
    }

    #[test]
    fn a_cause_already_quoted_is_said_once() {
        let io = std::io::Error::from_raw_os_error(2);
        let io_text = io.to_string();
        let err = anyhow::Error::new(Quoting {
            path: "run/summary.json".into(),
            source: io,
        })
        .context("cannot write the report");
        let line = one_line(&err);
        assert_eq!(line.matches(&io_text).count(), 1, "{line}");
        assert_eq!(
            line,
            format!("cannot write the report: run/summary.json: {io_text}")
        );
    }

    #[test]
    fn causes_not_quoted_are_chained_on_one_line() {
        let err = anyhow::anyhow!("no such\nfile").context("cannot read part.stl");
        assert_eq!(one_line(&err), "cannot read part.stl: no such file");
    }
}
