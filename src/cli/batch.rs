//! `kneeform batch MANIFEST.toml`: many analyses (parts, variants) one
//! after the other, resumable. Each item of the manifest is one `kneeform
//! analyze`, run as a child process of this binary with `--force`; when it
//! has succeeded, its fingerprint (this kneeform's version, the item's
//! arguments and the SHA-256 of its part files) is written into its
//! output directory as `batch-item.json`. An item whose directory holds a
//! run (`summary.json`, or a shard's `shard.json`) with the same
//! fingerprint is skipped, so a batch
//! killed part way and started again loses only the item it was running:
//! `analyze` leaves no partial directory, and an item whose fingerprint
//! was not yet written runs again.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{Context, bail, ensure};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::args::BatchArgs;

/// The item's run in progress (its process id): a batch ended by a
/// signal ends it first ([`end_running_child`]), so that a resumed batch
/// does not find its lock held.
static RUNNING_CHILD: std::sync::Mutex<Option<u32>> = std::sync::Mutex::new(None);

/// Set by [`end_running_child`]: the batch is ending on a signal.
static STOPPING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn running_child() -> std::sync::MutexGuard<'static, Option<u32>> {
    RUNNING_CHILD
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Sends the running item's process SIGTERM and waits (up to a minute)
/// for it to end, having removed its staged results: for the batch's
/// signal handler. Nothing when no item runs.
pub fn end_running_child() {
    let Some(pid) = *running_child() else {
        return;
    };
    STOPPING.store(true, std::sync::atomic::Ordering::SeqCst);
    let _ = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .stderr(std::process::Stdio::null())
        .status();
    let proc_dir = PathBuf::from(format!("/proc/{pid}"));
    for _ in 0..600 {
        // The batch's main thread reaps it (it waits on it).
        if running_child().is_none() || !proc_dir.exists() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
}

/// `batch-item.json`: what an item's run was made from.
#[derive(Debug, Serialize, Deserialize, PartialEq)]
struct Fingerprint {
    /// SHA-256 over the version, the arguments and the parts' SHA-256.
    fingerprint: String,
    /// The `analyze` arguments (run in the manifest's directory).
    args: Vec<String>,
}

/// The file in an item's output directory holding its [`Fingerprint`].
const FINGERPRINT_FILE: &str = "batch-item.json";

pub fn run(args: &BatchArgs) -> anyhow::Result<ExitCode> {
    let text = kneeform::limits::read_text_bounded(&args.manifest)
        .with_context(|| format!("cannot read the manifest {}", args.manifest.display()))?;
    // Relative paths in the manifest are relative to its directory: the
    // items run there.
    let base = match args.manifest.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let switches = analyze_switches();
    let items = kneeform::manifest::plan(&text, &base, &|flag| switches.iter().any(|s| s == flag))
        .map_err(|e| anyhow::anyhow!("manifest {}: {e}", args.manifest.display()))?;
    // An item asking for help would print it and write no run.
    for (k, item) in items.iter().enumerate() {
        if let Some(flag) = item
            .argv
            .iter()
            .find(|a| matches!(a.as_str(), "--help" | "-h" | "--version" | "-V"))
        {
            bail!(
                "manifest {}: item {} asks for {flag}, which runs no analysis: remove it",
                args.manifest.display(),
                k + 1
            );
        }
    }
    // Every item's flags are checked before the first item runs: an item
    // further down with a flag of nonsense failed only once the items
    // before it had run.
    for (k, item) in items.iter().enumerate() {
        let argv = std::iter::once("kneeform").chain(item.argv.iter().map(String::as_str));
        let checked = match <super::args::Cli as clap::Parser>::try_parse_from(argv) {
            Ok(cli) => match &cli.command {
                super::args::Command::Analyze(analyze) => analyze.setup.validate().map(|_| ()),
                _ => Err(anyhow::anyhow!("not an analysis")),
            },
            Err(err) => Err(anyhow::anyhow!(super::clap_message(&err))),
        };
        checked.with_context(|| {
            format!(
                "manifest {}: item {} ({})",
                args.manifest.display(),
                k + 1,
                item.out.display()
            )
        })?;
    }
    let exe = std::env::current_exe().context("cannot find this kneeform binary")?;
    let total = items.len();
    let (mut ran, mut skipped) = (0, 0);
    for (k, item) in items.iter().enumerate() {
        let (parts, argv) = (&item.parts, &item.argv);
        let what = format!("batch item {}/{total}, {}", k + 1, item.out.display());
        let fingerprint = fingerprint(&base, parts, argv).with_context(|| what.clone())?;
        let out = base.join(&item.out);
        if is_done(&out, &fingerprint) {
            eprintln!("kneeform: {what}: skipped, its run is complete (same fingerprint)");
            skipped += 1;
            continue;
        }
        // A fingerprint written but not recorded: the batch was killed
        // between the two. The file is the batch's own (its name is fixed);
        // without it the folder is a complete run that --force replaces.
        let unrecorded = out.join(FINGERPRINT_FILE);
        if unrecorded.is_file() && !kneeform::output::is_recorded(&out, FINGERPRINT_FILE) {
            std::fs::remove_file(&unrecorded)
                .with_context(|| format!("{what}: cannot remove {}", unrecorded.display()))?;
        }
        eprintln!("kneeform: {what}: kneeform {}", argv.join(" "));
        // --force: an earlier run of another fingerprint is replaced whole
        // (never a directory of other files: analyze refuses those).
        let mut child = Command::new(&exe)
            .args(argv)
            .arg("--force")
            .current_dir(&base)
            .spawn()
            .with_context(|| format!("{what}: cannot start {}", exe.display()))?;
        *running_child() = Some(child.id());
        let status = child.wait();
        *running_child() = None;
        // Ended by the batch's own signal handler: it exits the batch (130)
        // once the item is gone; this thread must not report a failure.
        while STOPPING.load(std::sync::atomic::Ordering::SeqCst) {
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        let status = status.with_context(|| format!("{what}: lost its run"))?;
        if !status.success() {
            bail!(
                "{what} failed ({status}); the items before it are complete, and `kneeform batch` again resumes here"
            );
        }
        let record = Fingerprint {
            fingerprint: fingerprint.clone(),
            args: argv.clone(),
        };
        let text = serde_json::to_string_pretty(&record)? + "\n";
        // Under the directory's lock, and recorded as kneeform's in its
        // kneeform-run.json, so that the item's next run may replace it.
        let _lock = kneeform::output::DirLock::take(&out)
            .with_context(|| format!("{what}: cannot record its fingerprint"))?;
        kneeform::output::write_file_atomically(&out.join(FINGERPRINT_FILE), |w| {
            use std::io::Write;
            w.write_all(text.as_bytes())
        })
        .and_then(|()| kneeform::output::add_to_record(&out, &[FINGERPRINT_FILE]))
        .with_context(|| format!("{what}: cannot record its fingerprint"))?;
        ran += 1;
    }
    super::print_result(&format!(
        "kneeform: batch done: {ran} items run, {skipped} skipped (complete)"
    ));
    Ok(ExitCode::SUCCESS)
}

/// The `analyze` flags that take no value (`--report`), as the command
/// line defines them.
fn analyze_switches() -> Vec<String> {
    use clap::CommandFactory;
    let cli = super::args::Cli::command();
    cli.find_subcommand("analyze")
        .into_iter()
        .flat_map(|analyze| analyze.get_arguments())
        .filter(|a| !a.get_action().takes_values())
        .filter_map(|a| a.get_long().map(|long| format!("--{long}")))
        .collect()
}

/// Whether `out` holds a complete run (or shard: `--shard` in the item's
/// flags) of this fingerprint, its fingerprint recorded in the run's
/// record (a batch killed between writing and recording it is not done).
fn is_done(out: &Path, fingerprint: &str) -> bool {
    let recorded = kneeform::limits::read_text_bounded(&out.join(FINGERPRINT_FILE))
        .ok()
        .and_then(|t| serde_json::from_str::<Fingerprint>(&t).ok());
    let complete =
        out.join(kneeform::output::SUMMARY_JSON).is_file() || out.join("shard.json").is_file();
    complete
        && recorded.is_some_and(|r| r.fingerprint == fingerprint)
        && kneeform::output::is_recorded(out, FINGERPRINT_FILE)
}

/// SHA-256 over this kneeform's version, `argv` and the SHA-256 of every
/// input file of the item: its parts, and every file an argument names
/// (`--ignore FILE`, `--frame @FILE`, a part path among `args`; an
/// argument naming a regular file, relative to the manifest's directory,
/// counts whatever flag it belongs to). A part that is not a regular file
/// (a FIFO, a device) is refused: it would be read twice, or for ever.
fn fingerprint(base: &Path, parts: &[PathBuf], argv: &[String]) -> anyhow::Result<String> {
    let mut hash = Sha256::new();
    hash.update(env!("CARGO_PKG_VERSION").as_bytes());
    for a in argv {
        hash.update((a.len() as u64).to_le_bytes());
        hash.update(a.as_bytes());
    }
    let read = |path: &Path| -> anyhow::Result<String> {
        let bytes = kneeform::limits::read_bounded(path, kneeform::limits::MAX_PART_FILE_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Ok(kneeform::input::sha256_hex(&bytes))
    };
    for p in parts {
        let path = base.join(p);
        let meta = std::fs::metadata(&path)
            .with_context(|| format!("cannot read the part {}", path.display()))?;
        ensure!(
            meta.is_file(),
            "the part {} is not a regular file",
            path.display()
        );
        hash.update(read(&path)?.as_bytes());
    }
    // Every other file an argument names.
    for a in argv.iter().skip(1) {
        let value = a.split_once('=').map_or(a.as_str(), |(_, v)| v);
        let value = value.strip_prefix('@').unwrap_or(value);
        if value.is_empty() || parts.iter().any(|p| p.as_os_str() == value) {
            continue;
        }
        let path = base.join(value);
        if std::fs::metadata(&path).is_ok_and(|m| m.is_file()) {
            hash.update((value.len() as u64).to_le_bytes());
            hash.update(value.as_bytes());
            hash.update(read(&path)?.as_bytes());
        }
    }
    Ok(hash.finalize().iter().map(|b| format!("{b:02x}")).collect())
}
