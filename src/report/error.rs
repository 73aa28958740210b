//! Why a report could not be written: the error of every part of the
//! report, in a leaf of its own so that the parts and the page
//! (`report/mod.rs`) do not import each other.

use std::path::PathBuf;

/// Why a report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A JSON file does not parse (or lacks a field the report needs).
    #[error("{} is not a readable run file: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// What serde said.
        source: serde_json::Error,
    },
    /// A buffer the run's files call for cannot be allocated.
    #[error("{what}: {source}")]
    Memory {
        /// What needed it.
        what: String,
        /// The refused allocation.
        source: crate::limits::OutOfMemory,
    },
    /// A run file contradicts the run's summary.
    #[error("{}: {reason}", path.display())]
    Inconsistent {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The part file is not the one the run analysed.
    #[error(
        "{} has changed since the run: its SHA-256 is {found}, the run analysed {expected}; pass the analysed file with --part",
        path.display()
    )]
    PartChanged {
        /// The file found.
        path: PathBuf,
        /// The run's SHA-256.
        expected: String,
        /// The file's.
        found: String,
    },
    /// The part file is nowhere to be found.
    #[error(
        "cannot find the analysed part {input_file:?} (tried {}); pass it with --part",
        tried.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    PartMissing {
        /// The file as the run named it.
        input_file: String,
        /// Where it was looked for.
        tried: Vec<PathBuf>,
    },
    /// The part file does not read.
    #[error("cannot read the part {}: {reason}", path.display())]
    Part {
        /// The file.
        path: PathBuf,
        /// What the reader said.
        reason: String,
    },
    /// A verification directory holds neither `verify.json` nor
    /// `converge.json`.
    #[error("{} holds neither verify.json nor converge.json", dir.display())]
    NotAVerification {
        /// The directory.
        dir: PathBuf,
    },
    /// A verification directory is not of the run reported on.
    #[error("{} is not a verification of this run ({file}): {reason}", dir.display())]
    Mismatch {
        /// The directory.
        dir: PathBuf,
        /// The file that says so.
        file: String,
        /// What differs.
        reason: String,
    },
    /// An image could not be encoded.
    #[error("cannot encode a PNG: {0}")]
    Png(#[from] png::EncodingError),
}
