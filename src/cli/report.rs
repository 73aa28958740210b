//! `kneeform report`: the evidence report of an `analyze` run, with any
//! `verify` and `converge` directories, as one self-contained HTML file.

use std::path::Path;

use anyhow::Context;
use kneeform::report::{ReportOptions, write_report};

use super::args::ReportArgs;

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    let options = ReportOptions {
        verify_dirs: args.verify_dirs.clone(),
        part: args.part.clone(),
        ..ReportOptions::new(&args.run_dir)
    };
    write(&options, &args.out, &args.out)
}

/// Writes the report of `options` to `out` and says so on stderr, naming
/// the file `shown_as` (where it will be once staged files are moved).
pub fn write(options: &ReportOptions, out: &Path, shown_as: &Path) -> anyhow::Result<()> {
    let report = write_report(options, out).with_context(|| {
        format!(
            "cannot write the report of {} to {}",
            options.run_dir.display(),
            shown_as.display()
        )
    })?;
    eprintln!(
        "kneeform: report of {} ({} triangles, views rendered in {:.2} s) written to {}",
        report.part_path.display(),
        report.triangles,
        report.render_s,
        shown_as.display()
    );
    Ok(())
}
