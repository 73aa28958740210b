//! `kneeform merge`: the shards of one analysis (`analyze --shard K/N`)
//! into the run's result directory, as the unsharded `analyze` writes it.

use std::process::ExitCode;

use anyhow::Context;
use kneeform::output::WriteOptions;

use super::args::MergeArgs;

pub fn run(args: &MergeArgs) -> anyhow::Result<ExitCode> {
    let out = super::stage_output(&args.out, args.force)?;
    let merged = kneeform::shard::merge(&args.shards).context("cannot merge the shards")?;
    let options = WriteOptions {
        points_csv: args.points_csv,
    };
    let summary = kneeform::shard::write_merged(&out, &merged, &options)?;
    // The whole run's warnings: a shard's own were of its angles alone.
    for w in &summary.warnings {
        eprintln!("kneeform: warning: {w}");
    }
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    eprintln!(
        "kneeform: merged {} shards: {} angles, composite {} nodes ({:.0} mm^2); results in {}",
        args.shards.len(),
        summary.angles_deg.len(),
        summary.composite_nodes,
        summary.composite_area_mm2,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
