//! `kneeform converge`: the same starts compared with the exact oracle at
//! several pitches; `converge.csv`, `converge.json`, and log-log plots of
//! error and time against pitch.

use std::process::ExitCode;

use anyhow::Context;
use kneeform::harness::{self, ConvergeOptions};
use kneeform::output;

use super::args::ConvergeArgs;
use super::progress::Bars;

/// Parses the pitch ladder, coarsest first, repeats removed; the library
/// checks that the pitches nest.
pub fn parse_pitches(s: &str) -> anyhow::Result<Vec<f64>> {
    let mut pitches: Vec<f64> = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .with_context(|| format!("--pitches: {t:?} is not a number"))
        })
        .collect::<anyhow::Result<_>>()?;
    pitches.sort_by(|a, b| b.total_cmp(a));
    pitches.dedup();
    Ok(pitches)
}

pub fn run(args: &ConvergeArgs) -> anyhow::Result<ExitCode> {
    let options = ConvergeOptions {
        pitches: parse_pitches(&args.pitches)?,
        selection: args.study.starts.validate()?,
        tie_band_per_mm: args.study.starts.tie_band,
        tolerance: args.tolerance,
        budget_s: args.budget_s,
    };
    let command = super::StudyCommand {
        options: &options,
        check: options.validate(),
        budget_s: args.budget_s,
        slide_shard: harness::converge_shard,
        direct_shard: harness::converge_direct_shard,
        slide: &|input, setup| {
            let study = harness::converge(input, setup, &options, &Bars::default())
                .map_err(super::harness_error)?;
            eprintln!(
                "exact oracle: {} starts x {} angles in {:.1} s",
                study.summary.starts,
                setup.angles.len(),
                study.oracle_s
            );
            output::write_convergence(&args.out, &study)?;
            super::study::print_convergence(&study, &args.out);
            Ok(ExitCode::SUCCESS)
        },
        direct: &|input, setup| run_direct(args, input, setup, &options),
    };
    super::run_study(&args.study, &args.out, command)
}

/// `converge --approach direct`: the grid's first contacts against the
/// exact casts along -x at every pitch, and the fitted order.
fn run_direct(
    args: &ConvergeArgs,
    input: &kneeform::PartFile,
    setup: &kneeform::Setup,
    options: &ConvergeOptions,
) -> anyhow::Result<ExitCode> {
    let study = harness::converge_direct(input, setup, options, &Bars::default())
        .map_err(super::harness_error)?;
    eprintln!(
        "exact oracle (direct): {} positions x {} angles in {:.1} s",
        study.summary.starts,
        setup.angles.len(),
        study.summary.oracle_s
    );
    output::write_direct_convergence(&args.out, &study)?;
    super::study::print_direct_convergence(&study, &args.out);
    Ok(ExitCode::SUCCESS)
}
