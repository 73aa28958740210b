//! The repository stands on its own (issue 40): a clone with nothing
//! beside it builds and passes its tests, so no file of the project names
//! a folder outside it, and no tracked file is too large for a clone to
//! carry.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The tracked files, as `git ls-files` lists them (the tests run in a
/// clone); `None` where the tree is not a git checkout (a source archive),
/// where these checks have nothing to judge.
fn tracked_files(root: &Path) -> Option<Vec<PathBuf>> {
    let out = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z"])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let names = String::from_utf8(out.stdout).expect("UTF-8 paths");
    Some(
        names
            .split('\0')
            .filter(|n| !n.is_empty())
            .map(PathBuf::from)
            .collect(),
    )
}

/// The tracked files of `root` (relative paths) whose text holds
/// `needle`, but for the changelog, whose history may name old layouts.
fn files_naming(root: &Path, needle: &str) -> Vec<PathBuf> {
    let Some(files) = tracked_files(root) else {
        return Vec::new();
    };
    files
        .into_iter()
        .filter(|f| f != Path::new("CHANGELOG.md"))
        .filter(|f| {
            std::fs::read(root.join(f))
                .is_ok_and(|bytes| bytes.windows(needle.len()).any(|w| w == needle.as_bytes()))
        })
        .collect()
}

/// The tracked files of `root` larger than `limit` bytes.
fn files_over(root: &Path, limit: u64) -> Vec<(PathBuf, u64)> {
    let Some(files) = tracked_files(root) else {
        return Vec::new();
    };
    files
        .into_iter()
        .filter_map(|f| {
            let len = std::fs::metadata(root.join(&f)).ok()?.len();
            (len > limit).then_some((f, len))
        })
        .collect()
}

/// The bytes of the tracked files of `root` under its folder `folder`.
fn tracked_bytes_under(root: &Path, folder: &str) -> u64 {
    let Some(files) = tracked_files(root) else {
        return 0;
    };
    files
        .into_iter()
        .filter(|f| f.starts_with(folder))
        .filter_map(|f| std::fs::metadata(root.join(f)).ok())
        .map(|m| m.len())
        .sum()
}

/// Five megabytes: the largest file a clone should carry (issue 40).
const MAX_TRACKED_BYTES: u64 = 5_000_000;
/// Twenty megabytes: the most the committed evidence, `results/`, may
/// hold (issue 40); the per-pair CSVs that `results/regenerate.sh` makes
/// again are not committed.
const MAX_RESULTS_BYTES: u64 = 20_000_000;

// The parent folder's name, spelled in two pieces so that this file does
// not name it itself.
fn outside() -> String {
    format!("..{}shared", '/')
}

#[test]
fn no_file_of_the_project_names_a_folder_beside_it() {
    let found = files_naming(repo(), &outside());
    assert!(
        found.is_empty(),
        "tracked files naming {}: {found:?}",
        outside()
    );
}

#[test]
fn no_tracked_file_is_over_five_megabytes() {
    let found = files_over(repo(), MAX_TRACKED_BYTES);
    assert!(found.is_empty(), "tracked files over 5 MB: {found:?}");
}

#[test]
fn the_committed_evidence_is_at_most_twenty_megabytes() {
    let bytes = tracked_bytes_under(repo(), "results");
    assert!(
        bytes <= MAX_RESULTS_BYTES,
        "results/ holds {bytes} bytes of tracked files, over {MAX_RESULTS_BYTES}"
    );
}

/// The three checks find what they look for: a scratch repository with a
/// file naming the folder beside it, a 6 MB file, and a `results/` of
/// five 4.5 MB files (each under the file limit, 22.5 MB together) fails
/// them.
#[test]
fn the_checks_find_a_reference_and_a_large_file() {
    let dir = std::env::temp_dir().join(format!("kneeform-standalone-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let git = |args: &[&str]| {
        let ok = Command::new("git")
            .arg("-C")
            .arg(&dir)
            .args(args)
            .output()
            .is_ok_and(|o| o.status.success());
        assert!(ok, "git {args:?}");
    };
    git(&["init", "-q"]);
    std::fs::write(dir.join("a.md"), format!("see {}/SPEC.md", outside())).unwrap();
    std::fs::write(dir.join("CHANGELOG.md"), outside()).unwrap();
    std::fs::write(dir.join("big.csv"), vec![b'0'; 6_000_000]).unwrap();
    std::fs::write(dir.join("small.csv"), b"0\n").unwrap();
    std::fs::create_dir_all(dir.join("results")).unwrap();
    for k in 0..5 {
        std::fs::write(
            dir.join(format!("results/part_{k}.csv")),
            vec![b'0'; 4_500_000],
        )
        .unwrap();
    }
    git(&["add", "."]);
    assert_eq!(files_naming(&dir, &outside()), vec![PathBuf::from("a.md")]);
    assert_eq!(
        files_over(&dir, MAX_TRACKED_BYTES),
        vec![(PathBuf::from("big.csv"), 6_000_000)]
    );
    assert_eq!(tracked_bytes_under(&dir, "results"), 22_500_000);
    assert!(tracked_bytes_under(&dir, "results") > MAX_RESULTS_BYTES);
    // Files beside `results/` do not count towards it.
    assert_eq!(tracked_bytes_under(&dir, "result"), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The method document (issue 40, item 1) defines every column that
/// `verify.csv` and `converge.csv` write and every metric `converge.csv`
/// names, read from a verification and a convergence study run here; the
/// README, `results/README.md`, `--help` and the report's verdict cite it.
#[test]
fn the_method_document_defines_every_figure_and_is_cited() {
    let method = std::fs::read_to_string(repo().join("docs/method.md")).expect("docs/method.md");
    let dir = crate::util::scratch_dir("method-document");
    let part = crate::util::scenario("bump");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_kneeform"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            matches!(out.status.code(), Some(0 | 1 | 3)),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    let at = |name: &str| dir.join(name).display().to_string();
    run(&[
        "analyze",
        &part,
        "--pitch",
        "8",
        "--angles=-30,0,30",
        "--no-check",
        "--out",
        &at("run"),
    ]);
    run(&[
        "verify",
        &part,
        "--pitch",
        "8",
        "--angles=0",
        "--starts",
        "runs:2:3",
        "--out",
        &at("v"),
    ]);
    run(&[
        "converge",
        &part,
        "--pitches",
        "16,8",
        "--angles=0",
        "--starts",
        "4",
        "--out",
        &at("c"),
    ]);
    let header = |file: &str| -> Vec<String> {
        let mut csv = csv::Reader::from_path(dir.join(file)).unwrap();
        csv.headers().unwrap().iter().map(String::from).collect()
    };
    let mut names = header("v/verify.csv");
    names.extend(header("c/converge.csv"));
    let mut csv = csv::Reader::from_path(dir.join("c/converge.csv")).unwrap();
    let metric = csv
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "metric")
        .unwrap();
    names.extend(csv.records().map(|r| r.unwrap()[metric].to_string()));
    names.sort();
    names.dedup();
    let undefined: Vec<&String> = names
        .iter()
        .filter(|n| !method.contains(&format!("`{n}`")))
        .collect();
    assert!(undefined.is_empty(), "not in docs/method.md: {undefined:?}");

    for file in ["README.md", "results/README.md"] {
        let text = std::fs::read_to_string(repo().join(file)).unwrap();
        assert!(text.contains("docs/method.md"), "{file} does not cite it");
    }
    let help = run(&["--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("docs/method.md"));
    run(&["report", &at("run"), &at("v"), "--out", &at("report.html")]);
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let verdict = page.find("id=\"verdict-first-0\"").expect("the verdict");
    let paragraph = &page[verdict..verdict + page[verdict..].find("</p>").unwrap()];
    assert!(
        paragraph.contains("docs/method.md") && paragraph.contains(env!("CARGO_PKG_VERSION")),
        "{paragraph}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
