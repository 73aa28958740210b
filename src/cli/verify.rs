//! `kneeform verify`: the grid engine and the exact oracle on the same
//! starts; `verify.csv` (one row per start and angle) and `verify.json`
//! (statistics, counts, worst starts, pass or fail).

use std::process::ExitCode;

use kneeform::Approach;
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
    let shard = super::study_shard(&args.study)?;
    let (input, setup) = super::study_inputs(&args.study, options.validate())?;
    if setup.approach == Approach::Direct {
        if args.budget_s.is_some() {
            // The direct study casts once per position: no sample predicts it.
            eprintln!(
                "kneeform: warning: --budget-s is not applied with --approach direct (one cast per knee position; --shard fans it out)"
            );
        }
        if let Some(shard) = shard {
            let part =
                harness::verify_direct_shard(&input, &setup, &options, shard, &Bars::default())
                    .map_err(super::harness_error)?;
            return super::write_study_shard(&args.out, &part);
        }
        return run_direct(args, &input, &setup, &options);
    }
    if let Some(shard) = shard {
        let part = harness::verify_shard(&input, &setup, &options, shard, &Bars::default())
            .map_err(super::harness_error)?;
        return super::write_study_shard(&args.out, &part);
    }
    let result = harness::verify(&input, &setup, &options, &Bars::default())
        .map_err(super::harness_error)?;
    output::write_verification(&args.out, &result)?;
    Ok(super::study::print_verification(&result, &args.out))
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
