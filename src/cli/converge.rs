//! `kneeform converge`: the same starts compared with the exact oracle at
//! several pitches; `converge.csv`, `converge.json`, and log-log plots of
//! error and time against pitch.

use std::process::ExitCode;

use anyhow::Context;
use kneeform::harness::{self, ConvergeOptions};

use super::args::ConvergeArgs;

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
    super::run_study(
        &args.study,
        &args.out,
        harness::StudyOptions::Converge(&options),
    )
}
