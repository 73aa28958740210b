//! `kneeform report`: the evidence report of an `analyze` run, with any
//! `verify` and `converge` directories, as one self-contained HTML file.

use anyhow::{Context, bail, ensure};
use kneeform::report::ReportOptions;

use super::args::ReportArgs;

/// The bytes of a page's head searched for [`GENERATOR`].
const HEAD_BYTES: u64 = 4096;

/// What every report kneeform writes says in its head.
const GENERATOR: &str = "<meta name=\"generator\" content=\"kneeform ";

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    // A report replaces an earlier report, never a part or a run file
    // (`--out part.stl`, `--out run/summary.json`).
    let is_html = args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
    ensure!(
        is_html || !args.out.exists(),
        "--out {} exists and is not an .html file: it will not be overwritten; name the report something.html",
        args.out.display()
    );
    // One report at a time writes --out, from here to its rename.
    let _lock = kneeform::output::DirLock::take(&args.out)
        .with_context(|| format!("cannot write the report to {}", args.out.display()))?;
    // An earlier report (another run's, perhaps) is replaced only when
    // asked, as `analyze` replaces a run directory, and only when kneeform
    // wrote it.
    if args.out.exists() {
        ensure!(
            args.force,
            "--out {} exists: pass --force to replace it, or name another file",
            args.out.display()
        );
        ensure!(
            is_kneeform_report(&args.out),
            "--out {} is not a report kneeform wrote (its head names no kneeform generator), so --force will not replace it: name another file",
            args.out.display()
        );
    }
    // Each verification once: the same directory given twice would be
    // shown twice, as two studies.
    let mut seen = Vec::new();
    for dir in &args.verify_dirs {
        let same = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.clone());
        if let Some(first) = seen.iter().position(|s| *s == same) {
            bail!(
                "{} is given twice (as {} before): name each verification directory once",
                dir.display(),
                args.verify_dirs[first].display()
            );
        }
        seen.push(same);
    }
    let options = ReportOptions {
        verify_dirs: args.verify_dirs.clone(),
        part: args.part.clone(),
        compare: args.compare.clone(),
        ..ReportOptions::new(&args.run_dir)
    };
    super::write_report(&options, &args.out, &args.out)
}

/// Whether the file at `path` is a report kneeform wrote: a regular file
/// whose head names kneeform as its generator.
fn is_kneeform_report(path: &std::path::Path) -> bool {
    use std::io::Read;
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return false;
    }
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(HEAD_BYTES).read_to_end(&mut head))
        .is_ok_and(|_| String::from_utf8_lossy(&head).contains(GENERATOR))
}
