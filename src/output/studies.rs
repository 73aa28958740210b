//! A study's result files, for every study and approach ([`write_study`];
//! [`write_study_files`] into a staged directory, for a merge of its
//! shards): the files its approach describes, written here. Built with
//! the `harness` feature.

use std::path::Path;

use super::{OutputDir, WriteError};
use crate::harness::Study;
use crate::harness::approach::StudyFile;

/// Writes `study`'s files into `dir`, which appears with all of them or is
/// left as it was.
pub fn write_study(dir: &Path, study: &Study) -> Result<(), WriteError> {
    staged(dir, |out| write_study_files(out, study))
}

/// Writes [`write_study`]'s files into the staged directory `out`
/// (`kneeform merge` of a study's shards): each file its approach
/// describes, text or plot.
pub fn write_study_files(out: &OutputDir, study: &Study) -> Result<(), WriteError> {
    for file in study.files() {
        match file {
            StudyFile::Text(name, write) => {
                let path = out.path(&name);
                (|| -> std::io::Result<()> {
                    let mut file = std::fs::File::create(&path)?;
                    write(&mut file)
                })()
                .map_err(WriteError::at(&path))?;
            }
            StudyFile::Plot(plot) => super::write_plot(out.path(".").as_path(), &plot)?,
        }
    }
    Ok(())
}

/// Stages `dir`, has `write` fill it and commits it: `dir` appears with
/// every file or is left as it was.
fn staged(
    dir: &Path,
    write: impl FnOnce(&OutputDir) -> Result<(), WriteError>,
) -> Result<(), WriteError> {
    let commit_error = |source| WriteError::Commit {
        path: dir.to_path_buf(),
        source,
    };
    let out = OutputDir::stage(dir).map_err(commit_error)?;
    write(&out)?;
    out.commit().map(drop).map_err(commit_error)
}
