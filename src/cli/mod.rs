//! The subcommands of the `kneeform` binary.

pub mod analyze;
pub mod args;
pub mod bench;
pub mod converge;
pub mod report;
pub mod scenario;
pub mod verify;

use std::path::Path;

use anyhow::Context;
use kneeform::{Part, Side};
use sha2::Digest;

/// Reads a part, from an STL file or a scenario file (`.toml`, generated
/// on the fly), into the analysis frame; returns it with the SHA-256 of
/// the file's bytes.
pub fn load_part(path: &Path, scale: f64, side: Side) -> anyhow::Result<(Part, String)> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let sha256 = sha2::Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let name = path.display().to_string();
    let part = if kneeform::scenario::is_scenario_file(path) {
        let triangles = kneeform::scenario::triangles_from_file(path, None)?;
        Part::from_triangles(&name, triangles, scale, side)?
    } else {
        Part::from_stl_bytes(&name, &bytes, scale, side)?
    };
    Ok((part, sha256))
}

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
