//! Result files: the colliding points and the composite as CSV, the
//! colliding area as a binary STL surface, and the height grid and the
//! composite as PNG images.
//!
//! * [`write_colliding_points`], [`write_composite`]: CSV tables, one row
//!   per node, in the part's own coordinates (mm);
//! * [`write_colliding_area`]: the composite area as a triangle surface in
//!   the part's coordinates (mm), facing the knee;
//! * [`write_depth_png`], [`write_composite_png`]: images with mm axes, the
//!   vehicle front (-x) on the left and z up;
//! * [`OutputDir`]: every file of a run is written into a staging directory
//!   and moved under its final name only when the run succeeds, so a reader
//!   never sees a half-written result.
//!
//! **Invariant:** nothing here changes a result; writers only format what
//! the engine computed, mapping y back to the part with [`Side::to_part`].
//!
//! [`Side::to_part`]: crate::mesh::Side::to_part

use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

mod csv;
mod plot;
mod ply;
mod png;
mod results;
mod stl;
mod surface;

pub use self::csv::{write_colliding_points, write_composite};
pub use self::plot::write_plots;
pub use self::ply::write_colliding_area_ply;
pub(crate) use self::png::count_colour;
pub(crate) use self::png::register_font;
pub use self::png::{
    BLIND_COLOUR, CROP_MARGIN, NO_PART, PngError, RING_BELOW, RING_COLOUR, Window, composite_key,
    crop_window, depth_bar_ends, view_line, write_composite_png, write_depth_png,
};
pub use self::results::{write_analysis, write_convergence, write_verification};
pub(crate) use self::stl::to_stl_triangle;
pub use self::stl::write_colliding_area;

/// Why a result could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// A file could not be created or written.
    #[error("cannot write {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: io::Error,
    },
    /// A result directory could not be staged or moved into place.
    #[error("cannot move results into {}", path.display())]
    Commit {
        /// The final directory.
        path: PathBuf,
        /// The cause.
        source: io::Error,
    },
    /// An image could not be drawn.
    #[error(transparent)]
    Png(#[from] PngError),
    /// A plot could not be drawn.
    #[error("cannot draw the convergence plot: {0}")]
    Plot(String),
}

impl WriteError {
    /// A closure wrapping an I/O-ish error with the file it concerns.
    pub(crate) fn at<E: Into<io::Error>>(path: &Path) -> impl FnOnce(E) -> WriteError + '_ {
        move |e| WriteError::Io {
            path: path.to_path_buf(),
            source: e.into(),
        }
    }
}

/// Writes the file `path` whole or not at all: `write` fills a temporary
/// file in the same directory, which is synced and then renamed into
/// place; on any failure the temporary file is removed and `path` is left
/// as it was.
pub fn write_file_atomically(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<std::fs::File>) -> io::Result<()>,
) -> io::Result<()> {
    let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    tmp_name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = path.with_file_name(tmp_name);
    let written = (|| {
        let mut file = io::BufWriter::new(std::fs::File::create(&tmp)?);
        write(&mut file)?;
        let file = file.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// A result directory written atomically: files go into a hidden sibling
/// staging directory (`<parent>/.<name>.partial-<pid>-<n>`) and are renamed
/// into the final directory by [`OutputDir::commit`]. Dropped without a
/// commit, the staging directory and everything in it are removed.
///
/// Renames within one file system are atomic, and the staging directory is
/// a sibling of the final one, so each file appears complete or not at all.
#[derive(Debug)]
pub struct OutputDir {
    final_dir: PathBuf,
    staging: PathBuf,
    committed: bool,
    replace: bool,
}

impl OutputDir {
    /// Creates the staging directory next to `final_dir` (which need not
    /// exist yet). `<n>` counts the stagings of this process, so two of them
    /// never share a staging directory; a stale one of the same name, left
    /// by a crashed process that had the same id, is cleared first.
    pub fn stage(final_dir: &Path) -> io::Result<OutputDir> {
        let name = final_dir.file_name().ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{} does not name a directory", final_dir.display()),
            )
        })?;
        let parent = match final_dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)?;
        let mut staged_name = std::ffi::OsString::from(".");
        staged_name.push(name);
        static STAGED: AtomicUsize = AtomicUsize::new(0);
        let n = STAGED.fetch_add(1, Ordering::Relaxed);
        staged_name.push(format!(".partial-{}-{n}", std::process::id()));
        let staging = parent.join(staged_name);
        if staging.exists() {
            std::fs::remove_dir_all(&staging)?;
        }
        std::fs::create_dir(&staging)?;
        Ok(OutputDir {
            final_dir: final_dir.to_path_buf(),
            staging,
            committed: false,
            replace: false,
        })
    }

    /// As [`OutputDir::stage`], but [`OutputDir::commit`] replaces the
    /// final directory whole: the staging directory is renamed to the final
    /// name, and a directory already there (an earlier run, which the
    /// caller has agreed to replace) is moved aside first and removed
    /// after, so no file of it survives beside the new results. A fresh
    /// final directory thus appears complete, in one rename.
    pub fn stage_replacing(final_dir: &Path) -> io::Result<OutputDir> {
        let mut out = OutputDir::stage(final_dir)?;
        out.replace = true;
        Ok(out)
    }

    /// Where to write the file `file_name`: inside the staging directory.
    pub fn path(&self, file_name: impl AsRef<Path>) -> PathBuf {
        self.staging.join(file_name)
    }

    /// The directory the files will be in after [`OutputDir::commit`].
    pub fn final_dir(&self) -> &Path {
        &self.final_dir
    }

    /// Moves every staged entry into the final directory (created if
    /// missing; files of the same name are replaced), then removes the
    /// staging directory. Entries are moved in name order, so a failure
    /// part way leaves a predictable prefix.
    pub fn commit(mut self) -> io::Result<()> {
        if self.replace {
            self.replace_final()?;
            self.committed = true;
            return Ok(());
        }
        std::fs::create_dir_all(&self.final_dir)?;
        let mut names: Vec<_> = std::fs::read_dir(&self.staging)?
            .map(|entry| entry.map(|e| e.file_name()))
            .collect::<io::Result<_>>()?;
        names.sort();
        for name in names {
            std::fs::rename(self.staging.join(&name), self.final_dir.join(&name))?;
        }
        std::fs::remove_dir(&self.staging)?;
        self.committed = true;
        Ok(())
    }
}

impl OutputDir {
    /// The replacing commit: old directory aside, staging in, old removed;
    /// on failure the old directory is put back.
    fn replace_final(&self) -> io::Result<()> {
        let mut aside_name = self.staging.file_name().unwrap_or_default().to_os_string();
        aside_name.push(".old");
        let aside = self.staging.with_file_name(aside_name);
        let moved = match std::fs::rename(&self.final_dir, &aside) {
            Ok(()) => true,
            Err(e) if e.kind() == io::ErrorKind::NotFound => false,
            Err(e) => return Err(e),
        };
        if let Err(e) = std::fs::rename(&self.staging, &self.final_dir) {
            if moved {
                let _ = std::fs::rename(&aside, &self.final_dir);
            }
            return Err(e);
        }
        if moved {
            std::fs::remove_dir_all(&aside)?;
        }
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: a failure to clean up must not hide the error
            // that caused the drop.
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// A fresh, empty directory under the system's temporary directory.
#[cfg(test)]
pub(crate) fn temp_dir(tag: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "kneeform-test-{}-{tag}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn commit_moves_files_under_their_final_names() {
        let root = temp_dir("commit");
        let final_dir = root.join("run");
        let out = OutputDir::stage(&final_dir).unwrap();
        std::fs::write(out.path("a.csv"), "angle_deg\n").unwrap();
        std::fs::write(out.path("b.stl"), [1u8, 2, 3]).unwrap();
        // Nothing is visible under the final name before the commit.
        assert!(!final_dir.exists());
        let staged = entries(&root);
        let prefix = format!(".run.partial-{}-", std::process::id());
        assert!(
            staged.len() == 1 && staged[0].starts_with(&prefix),
            "{staged:?}"
        );
        out.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", "b.stl"]);
        assert_eq!(
            std::fs::read_to_string(final_dir.join("a.csv")).unwrap(),
            "angle_deg\n"
        );
        // The staging directory is gone.
        assert_eq!(entries(&root), ["run"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn commit_replaces_files_of_an_earlier_run() {
        let root = temp_dir("replace");
        let final_dir = root.join("run");
        std::fs::create_dir(&final_dir).unwrap();
        std::fs::write(final_dir.join("a.csv"), "old").unwrap();
        std::fs::write(final_dir.join("keep.txt"), "kept").unwrap();
        let out = OutputDir::stage(&final_dir).unwrap();
        std::fs::write(out.path("a.csv"), "new").unwrap();
        out.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(final_dir.join("a.csv")).unwrap(),
            "new"
        );
        assert_eq!(entries(&final_dir), ["a.csv", "keep.txt"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn a_replacing_commit_leaves_no_file_of_the_earlier_run() {
        let root = temp_dir("replace-whole");
        let final_dir = root.join("run");
        // Fresh: the directory appears with its files.
        let out = OutputDir::stage_replacing(&final_dir).unwrap();
        std::fs::write(out.path("a.csv"), "first").unwrap();
        std::fs::write(out.path("report.html"), "old report").unwrap();
        assert!(!final_dir.exists());
        out.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", "report.html"]);
        // Replaced: only the new run's files, nothing staged or aside left.
        let out = OutputDir::stage_replacing(&final_dir).unwrap();
        std::fs::write(out.path("a.csv"), "second").unwrap();
        out.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv"]);
        assert_eq!(
            std::fs::read_to_string(final_dir.join("a.csv")).unwrap(),
            "second"
        );
        assert_eq!(entries(&root), ["run"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn two_stagings_of_one_directory_do_not_collide() {
        let root = temp_dir("twice");
        let final_dir = root.join("run");
        let first = OutputDir::stage(&final_dir).unwrap();
        let second = OutputDir::stage(&final_dir).unwrap();
        std::fs::write(first.path("a.csv"), "first").unwrap();
        std::fs::write(second.path("b.csv"), "second").unwrap();
        first.commit().unwrap();
        second.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", "b.csv"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn drop_without_commit_leaves_nothing() {
        let root = temp_dir("drop");
        let final_dir = root.join("run");
        {
            let out = OutputDir::stage(&final_dir).unwrap();
            std::fs::write(out.path("half.csv"), "angle_deg,i").unwrap();
            assert!(out.path("half.csv").exists());
        }
        assert!(entries(&root).is_empty());
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn a_bare_name_stages_in_the_current_directory() {
        let out = OutputDir::stage(Path::new("kneeform-unit-test-out")).unwrap();
        assert_eq!(
            out.path("x").parent().unwrap().parent().unwrap(),
            Path::new(".")
        );
        assert!(OutputDir::stage(Path::new("/")).is_err());
    }
}
