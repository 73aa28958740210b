//! What `verify` and `converge` print of their results (with `--approach
//! direct` too), and `kneeform merge` of their shards alike: the lines the
//! study says of itself, and `verify`'s exit status.

use std::path::Path;
use std::process::ExitCode;

use kneeform::harness::Study;

/// Prints what `study` found (its results are in `out`: on stdout, its
/// warnings on stderr) and returns the command's exit status: a
/// verification's 0 on PASS, 1 on FAIL, 3 when INCONCLUSIVE; a
/// convergence study's 0.
pub fn print_study(study: &Study, out: &Path) -> ExitCode {
    let said = study.said(out);
    for line in &said.lines {
        if line.starts_with("kneeform: warning") {
            eprintln!("{line}");
        } else {
            super::print_result(line);
        }
    }
    ExitCode::from(said.outcome.map_or(0, |o| o.exit_code()))
}
