//! `kneeform report`: the evidence report of an `analyze` run, with any
//! `verify` and `converge` directories, as one self-contained HTML file.

use kneeform::report::ReportOptions;

use super::args::ReportArgs;

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    // A report replaces an earlier report, never a part or a run file
    // (`--out part.stl`, `--out run/summary.json`).
    let is_html = args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
    anyhow::ensure!(
        is_html || !args.out.exists(),
        "--out {} exists and is not an .html file: it will not be overwritten; name the report something.html",
        args.out.display()
    );
    // An earlier report (another run's, perhaps) is replaced only when
    // asked, as `analyze` replaces a run directory.
    anyhow::ensure!(
        args.force || !args.out.exists(),
        "--out {} exists: pass --force to replace it, or name another file",
        args.out.display()
    );
    let options = ReportOptions {
        verify_dirs: args.verify_dirs.clone(),
        part: args.part.clone(),
        compare: args.compare.clone(),
        ..ReportOptions::new(&args.run_dir)
    };
    super::write_report(&options, &args.out, &args.out)
}
