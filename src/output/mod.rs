//! Result files: the composite as CSV (compressed unless asked plain; on
//! request the colliding points too), on request the colliding area as a
//! binary STL surface and a binary PLY mesh, and the height grid and the
//! composite as PNG images.
//!
//! * `write_composite`: a CSV table, one row per colliding node with its
//!   count and set of angles, in the part's own coordinates (mm, to 1 um);
//!   `write_colliding_points`: one row per node and angle (on request);
//! * `write_colliding_area`: the composite area as a triangle surface in
//!   the part's coordinates (mm), facing the knee (on request);
//! * `write_depth_png`, `write_composite_png`: images with mm axes, the
//!   vehicle front (-x) on the left and z up;
//! * [`OutputDir`]: every file of a run is written into a staging directory
//!   and moved under its final name only when the run succeeds, so a reader
//!   never sees a half-written result.
//!
//! **Invariant:** nothing here changes a result; writers only format what
//! the engine computed, mapping points back to the part with
//! [`Placement::to_part`].
//!
//! [`Placement::to_part`]: crate::frame::Placement::to_part

use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

mod csv;
#[cfg(feature = "harness")]
mod plot;
mod ply;
mod png;
mod record;
mod results;
mod stl;
#[cfg(feature = "harness")]
mod studies;
mod surface;

pub use self::csv::micrometres;
pub(crate) use self::csv::{write_colliding_points, write_composite};
#[cfg(feature = "harness")]
pub(crate) use self::plot::write_plot;
pub(crate) use self::ply::write_colliding_area_ply;
pub(crate) use self::png::count_colour;
#[cfg(feature = "harness")]
pub(crate) use self::png::register_font;
pub use self::png::{BLIND_COLOUR, NO_PART};
pub(crate) use self::png::{PngError, write_composite_png, write_depth_png};
pub(crate) use self::record::recorded;
pub use self::record::{RUN_RECORD, why_not_replaceable};
pub(crate) use self::results::{RunResults, write_results};
pub use self::results::{WriteOptions, write_analysis};
pub(crate) use self::stl::write_colliding_area;
pub use self::stl::write_stl;
#[cfg(feature = "harness")]
pub use self::studies::{write_study, write_study_files};
pub use crate::summary::{JSON_NOISE_ULPS, json_text, rounded_figure};

/// A run's record of everything it did (`summary.json`): the one name
/// every reader and writer uses.
pub const SUMMARY_JSON: &str = "summary.json";

/// The composite table as plain text (`analyze --csv`).
pub const COMPOSITE_CSV: &str = "composite.csv";

/// The composite table compressed (gzip), as an analysis writes it by
/// default: `composite.csv`'s bytes, some eight times smaller; `zcat`,
/// `gunzip -k` or pandas' `read_csv` read it as it is.
pub const COMPOSITE_CSV_GZ: &str = "composite.csv.gz";

/// A run directory's composite table: `composite.csv` where the run
/// wrote it plain (or an earlier version did), else `composite.csv.gz`.
pub fn composite_table(dir: &Path) -> PathBuf {
    let plain = dir.join(COMPOSITE_CSV);
    if plain.symlink_metadata().is_ok() {
        plain
    } else {
        dir.join(COMPOSITE_CSV_GZ)
    }
}

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
    staged_paths().push(tmp.clone());
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
    forget_staged(&tmp);
    written
}

/// Adds the files `names` of the committed result directory `dir` to its
/// record ([`RUN_RECORD`], rewritten whole or not at all): what kneeform
/// writes into a result directory after its commit (`analyze --report`'s
/// report, a batch item's fingerprint), so that `--force` may replace it
/// later. The caller holds the directory's lock.
pub fn add_to_record(dir: &Path, names: &[&str]) -> io::Result<()> {
    let text = record::record_adding(dir, names)?;
    write_file_atomically(&dir.join(RUN_RECORD), |w| {
        io::Write::write_all(w, text.as_bytes())
    })
}

/// Whether the run record of `dir` lists its file `name` (as
/// [`add_to_record`] adds it): a file written but not yet recorded was
/// cut short between the two.
pub fn is_recorded(dir: &Path, name: &str) -> bool {
    record::recorded(dir, name).is_some()
}

/// A result directory written atomically: files go into a hidden sibling
/// staging directory (`<parent>/.<name>.partial-<pid>-<n>`) and are renamed
/// into the final directory by [`OutputDir::commit`]. Dropped without a
/// commit, the staging directory and everything in it are removed; a
/// signal handler can remove it too ([`remove_staged`]).
///
/// Renames within one file system are atomic, and the staging directory is
/// a sibling of the final one, so each file appears complete or not at all.
/// One run at a time writes a final directory: staging takes an advisory
/// lock ([`DirLock`]) that a second run finds held and is refused.
#[derive(Debug)]
pub struct OutputDir {
    final_dir: PathBuf,
    staging: PathBuf,
    committed: bool,
    replace: bool,
    lock: Option<DirLock>,
}

/// The advisory lock of a result directory: `<parent>/.<name>.lock`, held
/// (an exclusive `flock`) from staging until the value is dropped, by one
/// run at a time, and removed when released.
///
/// Removing a lock file is safe because a lock counts only while its file
/// still has the lock's name: after locking, [`DirLock::take`] checks the
/// name still refers to the file it locked (a run releasing the lock may
/// have just removed it) and otherwise tries again, and a release removes
/// the name before it unlocks.
#[derive(Debug)]
pub struct DirLock {
    file: std::fs::File,
    path: PathBuf,
}

impl DirLock {
    /// Takes the lock of `final_dir`, or says that another run holds it
    /// (`ErrorKind::ResourceBusy`).
    pub fn take(final_dir: &Path) -> io::Result<DirLock> {
        let (parent, name) = parent_and_name(final_dir)?;
        std::fs::create_dir_all(&parent)?;
        let path = parent.join(hidden_name(&name, ".lock"));
        loop {
            let file = std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(io::Error::new(
                        io::ErrorKind::ResourceBusy,
                        format!(
                            "another kneeform run is writing it (it holds {}): wait for it to end, or choose another directory",
                            path.display()
                        ),
                    ));
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(e),
            }
            if still_named(&file, &path) {
                held_locks().push(path.clone());
                return Ok(DirLock { file, path });
            }
        }
    }
}

/// Whether `path` still names the open `file` (same device and inode).
#[cfg(unix)]
fn still_named(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Elsewhere a lock file's name cannot be compared: it is trusted.
#[cfg(not(unix))]
fn still_named(_file: &std::fs::File, path: &Path) -> bool {
    path.exists()
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // The name first, then the lock (when `file` closes).
        held_locks().retain(|p| p != &self.path);
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// The hidden sibling name `.<name><suffix>` (a lock, a staging).
fn hidden_name(name: &std::ffi::OsStr, suffix: &str) -> std::ffi::OsString {
    let mut hidden = std::ffi::OsString::from(".");
    hidden.push(name);
    hidden.push(suffix);
    hidden
}

/// The directory holding `dir` (`.` for a bare name) and `dir`'s name.
fn parent_and_name(dir: &Path) -> io::Result<(PathBuf, std::ffi::OsString)> {
    let name = dir.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} does not name a directory", dir.display()),
        )
    })?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((parent, name.to_os_string()))
}

/// Staging directories and temporary files of this process not yet
/// committed: what [`remove_staged`] removes.
static STAGED_PATHS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn staged_paths() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    STAGED_PATHS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn forget_staged(path: &Path) {
    staged_paths().retain(|p| p != path);
}

/// The lock files this process holds ([`DirLock`]): a signal handler
/// removes their names as a release does (the locks themselves end with
/// the process).
static HELD_LOCKS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn held_locks() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    HELD_LOCKS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Result directories this process has committed: what an interrupted
/// process may say it finished.
static COMMITTED: AtomicUsize = AtomicUsize::new(0);

/// What [`remove_staged`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interrupted {
    /// Staged results were removed.
    PartialRemoved,
    /// Nothing was staged, and some result was committed whole before.
    AfterCommit,
    /// Nothing was staged or committed.
    BeforeAnyResult,
}

/// Removes every staging directory and temporary file this process has
/// not committed: for a signal handler (SIGINT, SIGTERM) before it exits,
/// so that an interrupted run leaves nothing behind. A commit in progress
/// finishes first (it holds the same lock), so a directory is either
/// committed whole or removed.
pub fn remove_staged() -> Interrupted {
    let mut paths = staged_paths();
    let removed = !paths.is_empty();
    for path in paths.drain(..) {
        let _ = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
    }
    // The lock files' names go too (the locks end with the process): an
    // interrupted run left `.NAME.lock` behind.
    for lock in held_locks().drain(..) {
        let _ = std::fs::remove_file(&lock);
    }
    // Held until the process exits: no commit may start after this.
    std::mem::forget(paths);
    if removed {
        Interrupted::PartialRemoved
    } else if COMMITTED.load(Ordering::SeqCst) > 0 {
        Interrupted::AfterCommit
    } else {
        Interrupted::BeforeAnyResult
    }
}

/// Removes the stagings of `name` in `parent` left by processes that no
/// longer run (killed with SIGKILL, or by a power cut): entries
/// `.<name>.partial-<pid>-<n>` (and their `.old` asides) whose `<pid>` is
/// not a running process (none, or a zombie). Where the system cannot say (no `/proc`),
/// nothing is removed.
fn clear_stale_stagings(parent: &Path, name: &std::ffi::OsStr) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let prefix = format!(".{}.partial-", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(rest) = file_name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if !process_runs(pid) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Whether process `pid` runs: `/proc/<pid>` exists and is not a zombie
/// (a process killed whose parent died too waits as a zombie until
/// something reaps it, which in a container may be never).
fn process_runs(pid: u32) -> bool {
    let Ok(stat) = std::fs::read_to_string(Path::new("/proc").join(pid.to_string()).join("stat"))
    else {
        return Path::new("/proc").join(pid.to_string()).exists();
    };
    // `pid (name) state ...`: the name may hold spaces and parentheses.
    let state = stat
        .rfind(')')
        .and_then(|end| stat[end + 1..].split_whitespace().next());
    !matches!(state, Some("Z" | "X"))
}

/// Syncs the file or directory at `path` to disk.
fn sync_path(path: &Path) -> io::Result<()> {
    std::fs::File::open(path)?.sync_all()
}

impl OutputDir {
    /// Creates the staging directory next to `final_dir` (which need not
    /// exist yet), after taking `final_dir`'s lock ([`DirLock`]) and
    /// removing stagings of it left by dead processes. `<n>` counts the
    /// stagings of this process.
    pub fn stage(final_dir: &Path) -> io::Result<OutputDir> {
        let lock = DirLock::take(final_dir)?;
        let (parent, name) = parent_and_name(final_dir)?;
        clear_stale_stagings(&parent, &name);
        static STAGED: AtomicUsize = AtomicUsize::new(0);
        let n = STAGED.fetch_add(1, Ordering::Relaxed);
        let staging = parent.join(hidden_name(
            &name,
            &format!(".partial-{}-{n}", std::process::id()),
        ));
        if staging.exists() {
            std::fs::remove_dir_all(&staging)?;
        }
        staged_paths().push(staging.clone());
        if let Err(e) = std::fs::create_dir(&staging) {
            forget_staged(&staging);
            return Err(e);
        }
        Ok(OutputDir {
            final_dir: final_dir.to_path_buf(),
            staging,
            committed: false,
            replace: false,
            lock: Some(lock),
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

    /// Writes the record of the staged files ([`RUN_RECORD`]: what
    /// `--force` may later replace), syncs every staged file and the
    /// staging directory to disk, then moves every staged entry into the final directory (created if
    /// missing; files of the same name are replaced), removes the staging
    /// directory and syncs the final directory and its parent. Entries are
    /// moved in name order, so a failure part way leaves a predictable
    /// prefix. Returns the directory's lock, for a caller that writes more
    /// into it (a report) before another run may.
    pub fn commit(mut self) -> io::Result<DirLock> {
        // Held through the renames: a signal handler waits for them.
        let mut staged = staged_paths();
        let mut names: Vec<_> = std::fs::read_dir(&self.staging)?
            .map(|entry| entry.map(|e| e.file_name()))
            .collect::<io::Result<_>>()?;
        // The record of what this run wrote, over the staged files.
        record::write_record(&self.staging)?;
        if !names.iter().any(|n| n == RUN_RECORD) {
            names.push(RUN_RECORD.into());
        }
        names.sort();
        for name in &names {
            let path = self.staging.join(name);
            if path.is_file() {
                sync_path(&path)?;
            }
        }
        sync_path(&self.staging)?;
        if self.replace {
            self.replace_final()?;
        } else {
            std::fs::create_dir_all(&self.final_dir)?;
            for name in names {
                std::fs::rename(self.staging.join(&name), self.final_dir.join(&name))?;
            }
            std::fs::remove_dir(&self.staging)?;
        }
        self.committed = true;
        COMMITTED.fetch_add(1, Ordering::SeqCst);
        staged.retain(|p| p != &self.staging);
        drop(staged);
        sync_path(&self.final_dir)?;
        let (parent, _) = parent_and_name(&self.final_dir)?;
        sync_path(&parent)?;
        Ok(self.lock.take().expect("a staged directory holds its lock"))
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
            forget_staged(&self.staging);
        }
    }
}

/// Decodes a PNG written here (RGB or RGBA, 8 bits): width, height and
/// its pixels' RGB.
#[cfg(test)]
pub(crate) fn decode_png(path: &Path) -> (usize, usize, Vec<[u8; 3]>) {
    let decoder = ::png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.line_size / info.width as usize;
    let pixels = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width as usize, info.height as usize, pixels)
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
            staged.len() == 2 && staged[0] == ".run.lock" && staged[1].starts_with(&prefix),
            "{staged:?}"
        );
        out.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", "b.stl", RUN_RECORD]);
        assert_eq!(
            std::fs::read_to_string(final_dir.join("a.csv")).unwrap(),
            "angle_deg\n"
        );
        // The staging directory is gone, the lock released.
        assert_eq!(entries(&root), ["run"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    /// The interrupt handler's account of what was left, in a process of
    /// its own (the staged and committed directories are the process's):
    /// this test binary run again on [`interrupt_child`] with
    /// `KNEEFORM_INTERRUPT_CHILD` naming a scratch directory.
    fn interrupt_account(root: &Path, step: &str) -> String {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "output::tests::interrupt_child", "--nocapture"])
            .env("KNEEFORM_INTERRUPT_CHILD", root)
            .env("KNEEFORM_INTERRUPT_STEP", step)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.lines()
            .find_map(|l| l.strip_prefix("account: "))
            .unwrap_or_else(|| panic!("no account in {text}"))
            .to_string()
    }

    /// Issue 25, item 16: SIGTERM during merge's final commit exited
    /// saying "partial results removed" while the result was whole. What
    /// [`remove_staged`] reports after each step of a run: nothing yet, a
    /// staged directory, its commit (before the process could exit).
    #[test]
    fn an_interrupt_reports_what_is_true() {
        let root = temp_dir("interrupt");
        for (step, expected) in [
            ("none", Interrupted::BeforeAnyResult),
            ("staged", Interrupted::PartialRemoved),
            ("committed", Interrupted::AfterCommit),
        ] {
            let dir = root.join(step);
            std::fs::create_dir(&dir).unwrap();
            assert_eq!(
                interrupt_account(&dir, step),
                format!("{expected:?}"),
                "{step}"
            );
            let run = dir.join("run");
            match expected {
                Interrupted::AfterCommit => {
                    assert!(run.join("a.csv").is_file(), "the committed run is whole");
                }
                _ => assert!(!run.exists(), "{step}: a result directory"),
            }
            assert_eq!(
                entries(&dir),
                if expected == Interrupted::AfterCommit {
                    vec!["run".to_string()]
                } else {
                    vec![]
                },
                "{step}: what is left"
            );
        }
        std::fs::remove_dir_all(root).unwrap();
    }

    /// The child of [`an_interrupt_reports_what_is_true`]; nothing when
    /// run by the test harness itself.
    #[test]
    fn interrupt_child() {
        let (Some(root), Ok(step)) = (
            std::env::var_os("KNEEFORM_INTERRUPT_CHILD"),
            std::env::var("KNEEFORM_INTERRUPT_STEP"),
        ) else {
            return;
        };
        let final_dir = Path::new(&root).join("run");
        if step != "none" {
            let out = OutputDir::stage(&final_dir).unwrap();
            std::fs::write(out.path("a.csv"), "angle_deg\n").unwrap();
            if step == "committed" {
                // The lock is held until the process ends, as a merge's
                // is while it writes its report.
                std::mem::forget(out.commit().unwrap());
            } else {
                std::mem::forget(out);
            }
        }
        println!("account: {:?}", remove_staged());
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
        assert_eq!(entries(&final_dir), ["a.csv", "keep.txt", RUN_RECORD]);
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
        assert_eq!(entries(&final_dir), ["a.csv", RUN_RECORD, "report.html"]);
        // Replaced: only the new run's files, nothing staged or aside left.
        let out = OutputDir::stage_replacing(&final_dir).unwrap();
        std::fs::write(out.path("a.csv"), "second").unwrap();
        out.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", RUN_RECORD]);
        assert_eq!(
            std::fs::read_to_string(final_dir.join("a.csv")).unwrap(),
            "second"
        );
        assert_eq!(entries(&root), ["run"]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn one_run_at_a_time_writes_a_directory() {
        let root = temp_dir("twice");
        let final_dir = root.join("run");
        let first = OutputDir::stage(&final_dir).unwrap();
        let err = OutputDir::stage(&final_dir).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::ResourceBusy, "{err}");
        assert!(err.to_string().contains("another kneeform run"), "{err}");
        std::fs::write(first.path("a.csv"), "first").unwrap();
        let lock = first.commit().unwrap();
        // Still held after the commit, until the lock is dropped.
        assert!(OutputDir::stage(&final_dir).is_err());
        drop(lock);
        let second = OutputDir::stage(&final_dir).unwrap();
        std::fs::write(second.path("b.csv"), "second").unwrap();
        second.commit().unwrap();
        assert_eq!(entries(&final_dir), ["a.csv", "b.csv", RUN_RECORD]);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn stagings_of_dead_processes_are_cleared() {
        let root = temp_dir("stale");
        // No process has pid 4294967295.
        let stale = root.join(".run.partial-4294967295-0");
        std::fs::create_dir(&stale).unwrap();
        std::fs::write(stale.join("half.csv"), "x").unwrap();
        let ours = OutputDir::stage(&root.join("run")).unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!stale.exists());
        }
        drop(ours);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn this_process_runs_and_no_process_has_the_largest_pid() {
        if Path::new("/proc/self").exists() {
            assert!(process_runs(std::process::id()));
            assert!(!process_runs(u32::MAX));
        }
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
