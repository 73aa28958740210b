//! `kneeform verify`: the grid engine and the exact oracle on the same
//! starts; `verify.csv` (one row per start and angle) and `verify.json`
//! (statistics, counts, worst starts, pass or fail).

use std::process::ExitCode;

use kneeform::harness::{self, VerifyOptions};
use kneeform::output;

use super::args::VerifyArgs;
use super::progress::Bars;

pub fn run(args: &VerifyArgs) -> anyhow::Result<ExitCode> {
    let options = VerifyOptions {
        selection: args.study.starts.validate()?,
        tie_band_per_mm: args.study.starts.tie_band,
        tolerance: args
            .tolerance
            .unwrap_or_else(|| sampling_tolerance(&args.study)),
        budget_s: args.budget_s,
    };
    let command = super::StudyCommand {
        options: &options,
        check: options.validate(),
        budget_s: args.budget_s,
        slide_shard: harness::verify_shard,
        direct_shard: harness::verify_direct_shard,
        slide: &|input, setup| {
            let result = harness::verify(input, setup, &options, &Bars::default())
                .map_err(super::harness_error)?;
            output::write_verification(&args.out, &result)?;
            Ok(super::study::print_verification(&result, &args.out))
        },
        direct: &|input, setup| run_direct(args, input, setup, &options),
    };
    super::run_study(&args.study, &args.out, command)
}

/// `verify`'s default tolerance ([`harness::sampling_tolerance`]). Under
/// `--pitch auto`, refused later, 1 mm.
fn sampling_tolerance(study: &super::args::StudyArgs) -> f64 {
    match study.setup.pitch {
        super::args::PitchArg::Mm(p) if p.is_finite() && p > 0.0 => harness::sampling_tolerance(p),
        _ => 1.0,
    }
}

/// `verify --approach direct`: the grid's first contacts against the exact
/// casts along -x.
fn run_direct(
    args: &VerifyArgs,
    input: &kneeform::PartFile,
    setup: &kneeform::Setup,
    options: &VerifyOptions,
) -> anyhow::Result<ExitCode> {
    let result = harness::verify_direct(input, setup, options, &Bars::default())
        .map_err(super::harness_error)?;
    output::write_direct_verification(&args.out, &result)?;
    Ok(super::study::print_direct_verification(&result, &args.out))
}
