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

/// The error and its causes as one line, `outer: inner: ...`, each cause
/// said once: a layer that already quotes its cause (`{path}: {source}`,
/// as thiserror messages often do) is not followed by the cause again, so
/// an OS error never reads `(os error 2): No such file or directory (os
/// error 2)`. Line breaks inside a message become spaces.
pub fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
        if text.is_empty() || line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
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

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("{path}: {source}")]
    struct Quoting {
        path: String,
        source: std::io::Error,
    }

    #[test]
    fn a_cause_already_quoted_is_said_once() {
        let io = std::io::Error::from_raw_os_error(2);
        let io_text = io.to_string();
        let err = anyhow::Error::new(Quoting {
            path: "run/summary.json".into(),
            source: io,
        })
        .context("cannot write the report");
        let line = one_line(&err);
        assert_eq!(line.matches(&io_text).count(), 1, "{line}");
        assert_eq!(
            line,
            format!("cannot write the report: run/summary.json: {io_text}")
        );
    }

    #[test]
    fn causes_not_quoted_are_chained_on_one_line() {
        let err = anyhow::anyhow!("no such\nfile").context("cannot read part.stl");
        assert_eq!(one_line(&err), "cannot read part.stl: no such file");
    }
}
