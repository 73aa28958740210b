//! `kneeform merge`: the shards of one analysis (`analyze --shard K/N`)
//! into the run's result directory, as the unsharded `analyze` writes it;
//! or the shards of one verification or convergence study (`verify` or
//! `converge --shard K/N`) into the study's, as the unsharded command
//! writes it, printing and exiting as it does.

use std::process::ExitCode;

use anyhow::{Context, ensure};
use kneeform::output::{self, OutputDir, WriteOptions};
use kneeform::shard::study::{ShardKind, shard_kind};

use super::args::MergeArgs;

pub fn run(args: &MergeArgs) -> anyhow::Result<ExitCode> {
    let kinds = args
        .shards
        .iter()
        .map(|d| shard_kind(d))
        .collect::<Result<Vec<_>, _>>()
        .context("cannot merge the shards")?;
    let kind = kinds[0];
    if let Some(k) = kinds.iter().position(|&k| k != kind) {
        anyhow::bail!(
            "cannot merge the shards: {} is a shard of {}, {} of {}",
            args.shards[0].display(),
            kind,
            args.shards[k].display(),
            kinds[k]
        );
    }
    ensure!(
        kind == ShardKind::Analysis || !(args.points_csv || args.files.any()),
        "--points-csv, --csv, --stl and --ply are for an analysis's shards: a study writes no composite"
    );
    let shards: Vec<&std::path::Path> = args.shards.iter().map(|p| p.as_path()).collect();
    let out = super::stage_output(&args.out, args.force, &shards)?;
    if kind == ShardKind::Analysis {
        return merge_analysis(args, out);
    }
    let merged =
        kneeform::shard::study::merge_study(&args.shards).context("cannot merge the shards")?;
    output::write_study_files(&out, &merged)?;
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    super::print_result(&format!(
        "kneeform: merged {} shards of {kind}",
        args.shards.len()
    ));
    Ok(super::study::print_study(&merged, &args.out))
}

fn merge_analysis(args: &MergeArgs, out: OutputDir) -> anyhow::Result<ExitCode> {
    let merged = kneeform::shard::merge(&args.shards).context("cannot merge the shards")?;
    let options = WriteOptions {
        points_csv: args.points_csv,
        plain_csv: args.files.csv,
        stl: args.files.stl,
        ply: args.files.ply,
    };
    let summary = kneeform::shard::write_merged(&out, &merged, &options)?;
    // The whole run's warnings: a shard's own were of its angles alone.
    for w in &summary.warnings {
        eprintln!("kneeform: warning: {w}");
    }
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    super::print_result(&format!(
        "kneeform: merged {} shards: {} angles, composite {} nodes ({:.0} mm^2); results in {}",
        args.shards.len(),
        summary.angles_deg.len(),
        summary.composite_nodes,
        summary.composite_area_mm2,
        args.out.display()
    ));
    if let Some(check) = &summary.sample_check {
        super::print_check(check);
    }
    Ok(ExitCode::SUCCESS)
}
