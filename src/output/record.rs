//! `kneeform-run.json`: the record, in every result directory kneeform
//! writes (an analysis, a study, a shard, a merge), of the files it wrote
//! there with their size and SHA-256. `--force` replaces a directory only
//! when this record proves every file in it kneeform's, unchanged
//! ([`why_not_replaceable`]); the report checks the study tables it shows
//! against it ([`recorded`]).
//!
//! The record is written by [`super::OutputDir::commit`] over the staged
//! files; a file added after the commit (`analyze --report`'s
//! `report.html`, a batch item's fingerprint) is added with
//! [`super::add_to_record`] while the directory's lock is held.

use std::collections::BTreeMap;
use std::io;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::Digest;

/// The record's file name.
pub const RUN_RECORD: &str = "kneeform-run.json";

/// The largest record read (bytes): a few hundred files' names and digests
/// at most.
const MAX_RECORD_BYTES: u64 = 1 << 20;

/// What a record says of one file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub(crate) struct RecordedFile {
    /// Its size (bytes).
    pub(crate) bytes: u64,
    /// Its SHA-256, lowercase hex.
    pub(crate) sha256: String,
}

/// `kneeform-run.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RunRecord {
    /// The kneeform version that wrote the directory.
    kneeform: String,
    /// Every file it wrote there, by name.
    files: BTreeMap<String, RecordedFile>,
}

/// The size and SHA-256 of the regular file `path`, read in pieces.
pub(crate) fn digest_file(path: &Path) -> io::Result<RecordedFile> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(not_regular());
    }
    let mut file = std::fs::File::open(path)?;
    let mut hash = sha2::Sha256::new();
    let bytes = io::copy(&mut file, &mut hash)?;
    Ok(RecordedFile {
        bytes,
        sha256: hash.finalize().iter().map(|b| format!("{b:02x}")).collect(),
    })
}

fn not_regular() -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, "not a regular file")
}

/// Whether `name` is a temporary file of [`super::write_file_atomically`]
/// (`NAME.tmp-PID-N`), which a process killed while writing leaves behind:
/// kneeform's own, never a user's result.
pub(crate) fn is_temporary_name(name: &str) -> bool {
    name.rsplit_once(".tmp-").is_some_and(|(stem, tail)| {
        !stem.is_empty()
            && tail.split_once('-').is_some_and(|(pid, n)| {
                [pid, n]
                    .iter()
                    .all(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
            })
    })
}

/// Writes the record of every regular file in `dir` (the staging
/// directory of a run, before its commit): plain, as the staged files are.
pub(crate) fn write_record(dir: &Path) -> io::Result<()> {
    let mut files = BTreeMap::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let Some(name) = entry.file_name().to_str().map(str::to_string) else {
            continue;
        };
        if name == RUN_RECORD || !entry.file_type()?.is_file() {
            continue;
        }
        files.insert(name, digest_file(&entry.path())?);
    }
    let text = record_text(files)?;
    std::fs::write(dir.join(RUN_RECORD), text)
}

fn record_text(files: BTreeMap<String, RecordedFile>) -> io::Result<String> {
    let record = RunRecord {
        kneeform: env!("CARGO_PKG_VERSION").to_string(),
        files,
    };
    Ok(serde_json::to_string_pretty(&record).map_err(io::Error::other)? + "\n")
}

/// The text of `dir`'s record with the files `names` of the committed
/// directory added ([`super::add_to_record`] writes it).
pub(crate) fn record_adding(dir: &Path, names: &[&str]) -> io::Result<String> {
    let mut record = read_record(dir)?;
    for name in names {
        record
            .files
            .insert(name.to_string(), digest_file(&dir.join(name))?);
    }
    record_text(record.files)
}

fn read_record(dir: &Path) -> io::Result<RunRecord> {
    let bytes = crate::limits::read_bounded(&dir.join(RUN_RECORD), MAX_RECORD_BYTES)?;
    serde_json::from_slice(&bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

/// What the record of `dir` says of its file `name`: `None` where the
/// directory has no readable record or the record does not list it.
pub(crate) fn recorded(dir: &Path, name: &str) -> Option<RecordedFile> {
    read_record(dir).ok()?.files.remove(name)
}

/// Why `--force` must not replace the existing directory `dir`, in words
/// that follow its name (`holds notes.txt, which kneeform did not write`);
/// `None` when it may: it is empty, or every entry in it is a file its
/// record lists, unchanged, or a temporary file of kneeform's
/// (`is_temporary_name`).
pub fn why_not_replaceable(dir: &Path) -> io::Result<Option<String>> {
    let mut entries: Vec<(std::ffi::OsString, std::fs::FileType)> = std::fs::read_dir(dir)?
        .map(|e| e.and_then(|e| Ok((e.file_name(), e.file_type()?))))
        .collect::<io::Result<_>>()?;
    if entries.is_empty() {
        return Ok(None);
    }
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    let record = match read_record(dir) {
        Ok(record) => record,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Ok(Some(format!(
                "is not a kneeform run directory: it holds {} and no {RUN_RECORD} (kneeform's record of the files it wrote; results of kneeform before this version have none, and are not replaced)",
                entries[0].0.to_string_lossy()
            )));
        }
        Err(e) => {
            return Ok(Some(format!(
                "holds a {RUN_RECORD} that cannot be read ({e})"
            )));
        }
    };
    for (name, kind) in entries {
        let shown = name.to_string_lossy().into_owned();
        let foreign = || Some(format!("holds {shown}, which kneeform did not write"));
        let Some(name) = name.to_str() else {
            return Ok(foreign());
        };
        if !kind.is_file() {
            return Ok(foreign());
        }
        if name == RUN_RECORD || is_temporary_name(name) {
            continue;
        }
        let Some(expected) = record.files.get(name) else {
            return Ok(foreign());
        };
        let path = dir.join(name);
        let same =
            std::fs::metadata(&path)?.len() == expected.bytes && digest_file(&path)? == *expected;
        if !same {
            return Ok(Some(format!(
                "holds {name}, changed since kneeform wrote it"
            )));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_recognised() {
        for name in ["report.html.tmp-123-0", "batch-item.json.tmp-9-12"] {
            assert!(is_temporary_name(name), "{name}");
        }
        for name in [
            "report.html",
            ".tmp-1-2",
            "notes.tmp-1",
            "notes.tmp-a-1",
            "notes.tmp-1-",
            "notes.tmp-1-2x",
        ] {
            assert!(!is_temporary_name(name), "{name}");
        }
    }

    #[test]
    fn a_directory_is_replaceable_only_as_its_record_proves() {
        let dir = std::env::temp_dir().join(format!("kneeform-record-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(why_not_replaceable(&dir).unwrap(), None, "empty");
        std::fs::write(dir.join("summary.json"), "{\"mine\": true}").unwrap();
        let why = why_not_replaceable(&dir).unwrap().unwrap();
        assert!(
            why.contains("summary.json and no kneeform-run.json"),
            "{why}"
        );
        write_record(&dir).unwrap();
        assert_eq!(why_not_replaceable(&dir).unwrap(), None, "recorded");
        std::fs::write(dir.join("report.html.tmp-4-0"), "half").unwrap();
        assert_eq!(why_not_replaceable(&dir).unwrap(), None, "a temporary");
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        let why = why_not_replaceable(&dir).unwrap().unwrap();
        assert!(why.contains("holds notes.txt"), "{why}");
        let text = record_adding(&dir, &["notes.txt"]).unwrap();
        std::fs::write(dir.join(RUN_RECORD), text).unwrap();
        assert_eq!(why_not_replaceable(&dir).unwrap(), None, "added");
        std::fs::write(dir.join("summary.json"), "{\"mine\": false}").unwrap();
        let why = why_not_replaceable(&dir).unwrap().unwrap();
        assert!(why.contains("summary.json, changed"), "{why}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
