//! The subcommands of the `kneeform` binary.

pub mod analyze;
pub mod args;
pub mod bench;
pub mod scenario;

/// Sizes rayon's global pool (default: one thread per CPU).
pub fn set_threads(threads: Option<usize>) -> anyhow::Result<()> {
    if let Some(n) = threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()?;
    }
    Ok(())
}
