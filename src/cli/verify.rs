//! `kneeform verify`: the grid engine and the exact oracle on the same
//! starts; `verify.csv` (one row per start and angle) and `verify.json`
//! (statistics, counts, worst starts, pass or fail).

use std::process::ExitCode;

use kneeform::harness::{self, VerifyOptions};

use super::args::VerifyArgs;

pub fn run(args: &VerifyArgs) -> anyhow::Result<ExitCode> {
    let options = VerifyOptions {
        selection: args.study.starts.validate()?,
        tie_band_per_mm: args.study.starts.tie_band,
        tolerance: args
            .tolerance
            .unwrap_or_else(|| sampling_tolerance(&args.study)),
        budget_s: args.budget_s,
    };
    super::run_study(
        &args.study,
        &args.out,
        harness::StudyOptions::Verify(&options),
    )
}

/// `verify`'s default tolerance ([`harness::sampling_tolerance`]). Under
/// `--pitch auto`, refused later, 1 mm.
fn sampling_tolerance(study: &super::args::StudyArgs) -> f64 {
    match study.setup.pitch {
        super::args::PitchArg::Mm(p) if p.is_finite() && p > 0.0 => harness::sampling_tolerance(p),
        _ => 1.0,
    }
}
