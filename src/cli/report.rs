//! `kneeform report`: the evidence report of an `analyze` run, with any
//! `verify` and `converge` directories, as one self-contained HTML file.

use kneeform::report::ReportOptions;

use super::args::ReportArgs;

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    let options = ReportOptions {
        verify_dirs: args.verify_dirs.clone(),
        part: args.part.clone(),
        ..ReportOptions::new(&args.run_dir)
    };
    super::write_report(&options, &args.out, &args.out)
}
