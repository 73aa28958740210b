//! Fan-out: `analyze --shard K/N` and `kneeform merge` give the unsharded
//! run's files byte for byte; `kneeform batch` resumes a killed batch
//! without redoing finished items.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::cli::kneeform;
use crate::util::{ok, scenario, scratch_dir};

/// Asserts exit 2 with one line on stderr naming `needle`.
fn refused(out: &Output, needle: &str, what: &str) {
    let text = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {text}");
    assert_eq!(text.lines().count(), 1, "{what}: not one line: {text}");
    assert!(text.starts_with("kneeform: error: "), "{what}: {text}");
    assert!(text.contains(needle), "{what}: no {needle:?} in {text}");
}

/// The keys of `summary.json` that hold a clock reading or describe the
/// machine (as `.ci/same-outputs` sets them aside).
const CLOCK_KEYS: [&str; 4] = ["timings", "run_unix_time", "peak_rss_mib", "threads"];

/// Asserts that the directories `a` and `b` hold the same files, byte for
/// byte, `summary.json`'s clock readings aside; returns how many.
fn assert_same_files(a: &Path, b: &Path) -> usize {
    let names = |d: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(names(a), names(b), "{} vs {}", a.display(), b.display());
    for name in names(a) {
        let (x, y) = (
            std::fs::read(a.join(&name)).unwrap(),
            std::fs::read(b.join(&name)).unwrap(),
        );
        if name == "summary.json" {
            let strip = |bytes: &[u8]| {
                let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
                for key in CLOCK_KEYS {
                    v.as_object_mut().unwrap().remove(key);
                }
                v
            };
            assert_eq!(strip(&x), strip(&y), "{name} differs");
        } else {
            assert!(
                x == y,
                "{name} differs between {} and {}",
                a.display(),
                b.display()
            );
        }
    }
    names(a).len()
}

const ANGLES: &str = "--angles=-30,-20,-10,0,10,20,30";

/// Runs shard `k` of `n` of `part` into `dir/shard-k`.
fn shard(part: &str, dir: &Path, k: usize, n: usize, extra: &[&str]) -> PathBuf {
    let out = dir.join(format!("shard-{k}"));
    let spec = format!("{k}/{n}");
    let mut args = vec![
        "analyze",
        part,
        "--pitch",
        "4",
        ANGLES,
        "--shard",
        &spec,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ok(kneeform(&args), "a shard");
    out
}

fn merge(shards: &[&Path], out: &Path) -> Output {
    let mut args = vec!["merge".to_string()];
    args.extend(shards.iter().map(|s| s.display().to_string()));
    args.extend([
        "--out".into(),
        out.display().to_string(),
        "--points-csv".into(),
    ]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    kneeform(&args)
}

#[test]
fn four_shards_merged_are_the_unsharded_run_byte_for_byte() {
    // A smooth wave; a thin rib the grid misses (blind spots met and
    // nothing struck, with their warnings); an assembly of two files
    // (each node's file) turned by a frame (mapped back by the merge); the
    // pocket behind a ridge by the direct approach (its own frame).
    let bump = scenario("bump");
    let assembly = [bump.as_str(), "--frame", "-x,y,-z"];
    for (case, (name, extra)) in [
        ("wave", &[][..]),
        ("thin-rib", &[][..]),
        ("wave", &assembly[..]),
        ("pocket-behind-ridge", &["--approach", "direct"][..]),
    ]
    .into_iter()
    .enumerate()
    {
        let dir = scratch_dir(&format!("shard-{case}-{name}"));
        let part = scenario(name);
        let whole = dir.join("whole");
        let mut args = vec![
            "analyze",
            part.as_str(),
            "--pitch",
            "4",
            ANGLES,
            "--points-csv",
            "--out",
            whole.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        ok(kneeform(&args), "the unsharded run");
        let shards: Vec<PathBuf> = (1..=4).map(|k| shard(&part, &dir, k, 4, extra)).collect();
        // Each shard describes itself.
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(shards[1].join("shard.json")).unwrap()).unwrap();
        assert_eq!(record["shard"], serde_json::json!({"index": 2, "count": 4}));
        assert_eq!(record["angle_indices"], serde_json::json!([1, 5]));
        assert_eq!(record["summary"]["angles_deg"].as_array().unwrap().len(), 7);
        // In any order.
        let merged = dir.join("merged");
        let order: Vec<&Path> = [3, 0, 2, 1].iter().map(|&k| shards[k].as_path()).collect();
        ok(merge(&order, &merged), "merge");
        let files = assert_same_files(&whole, &merged);
        // summary, composite, points, STL, PLY, two images, blind spots.
        assert_eq!(files, 8, "{files} files compared");
        let composite = std::fs::read_to_string(merged.join("composite.csv")).unwrap();
        if name != "thin-rib" {
            assert!(
                composite.lines().count() > 20,
                "too little struck to prove anything"
            );
        } else {
            // Both warnings a merge recomputes from the masks.
            let summary = std::fs::read_to_string(merged.join("summary.json")).unwrap();
            assert!(
                summary.contains("blind spots the knee-form meets"),
                "{summary}"
            );
            assert!(summary.contains("no grid node is struck"), "{summary}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn merge_refuses_a_missing_a_repeated_or_a_foreign_shard() {
    let dir = scratch_dir("shard-refusals");
    let wave = scenario("wave");
    let shards: Vec<PathBuf> = (1..=3).map(|k| shard(&wave, &dir, k, 3, &[])).collect();
    let other = dir.join("other");
    std::fs::create_dir(&other).unwrap();
    let foreign = shard(&scenario("bump"), &other, 2, 3, &[]);
    let out = dir.join("merged");
    let s: Vec<&Path> = shards.iter().map(PathBuf::as_path).collect();
    for (given, needle, what) in [
        (vec![s[0], s[2]], "shard 2/3 is missing", "missing"),
        (
            vec![s[0], s[1], s[1], s[2]],
            "shard 2/3 is given twice",
            "twice",
        ),
        (
            vec![s[0], &foreign, s[2]],
            "shards of different runs",
            "foreign",
        ),
    ] {
        let result = merge(&given, &out);
        refused(&result, needle, what);
        assert!(!out.exists(), "{what}: output left behind");
    }
    // Another N, and a damaged shard.
    let four = dir.join("four");
    std::fs::create_dir(&four).unwrap();
    let n4 = shard(&wave, &four, 1, 4, &[]);
    refused(&merge(&[&n4, s[1], s[2]], &out), "one N", "another N");
    let bin = shards[0].join("shard.bin");
    let mut bytes = std::fs::read(&bin).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&bin, bytes).unwrap();
    refused(&merge(&s, &out), "SHA-256", "damaged");
    assert!(!out.exists());
    // Flags a shard cannot take.
    for (bad, needle) in [
        ("0/4", "--shard"),
        ("5/4", "--shard"),
        ("x", "--shard"),
        ("1/9", "9 shards of 7 angles"),
    ] {
        let result = kneeform(&[
            "analyze",
            &wave,
            "--pitch",
            "4",
            ANGLES,
            "--shard",
            bad,
            "--out",
            dir.join("bad").to_str().unwrap(),
        ]);
        refused(&result, needle, bad);
        assert!(!dir.join("bad").exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Sets up a batch directory: the part and a manifest of three items, the
/// last one slow enough to be killed in.
fn batch_dir(name: &str) -> PathBuf {
    let dir = scratch_dir(name);
    std::fs::copy(scenario("wave"), dir.join("wave.toml")).unwrap();
    std::fs::copy(scenario("bump"), dir.join("bump.toml")).unwrap();
    std::fs::write(
        dir.join("manifest.toml"),
        r#"# Three analyses; paths relative to this file.
[defaults]
pitch = 4
angles = "-30,0,30"

[[item]]
part = "wave.toml"
out = "runs/wave"

[[item]]
part = "bump.toml"
out = "runs/bump-right"
side = "right"
args = ["--deflection", "1"]

[[item]]
part = "wave.toml"
out = "runs/wave-fine"
pitch = 1
angles = "-30:30:5"
"#,
    )
    .unwrap();
    dir
}

#[cfg(unix)]
#[test]
fn a_killed_batch_resumes_and_ends_with_a_clean_batch_s_outputs() {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::process::CommandExt;
    let dir = batch_dir("batch-killed");
    let manifest = dir.join("manifest.toml");
    // Its own process group, so that the kill takes its child too (as a
    // scheduler ending a job does).
    let mut child = Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .args(["batch", manifest.to_str().unwrap()])
        .stderr(std::process::Stdio::null())
        .process_group(0)
        .spawn()
        .unwrap();
    let done = dir.join("runs/bump-right/batch-item.json");
    while !done.exists() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the batch ended ({status}) before it could be killed");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let killed = Command::new("kill")
        .args(["-KILL", "--", &format!("-{}", child.id())])
        .status()
        .unwrap();
    assert!(killed.success());
    child.wait().unwrap();
    let first = dir.join("runs/wave/summary.json");
    let inode = std::fs::metadata(&first).unwrap().ino();
    // Again: the finished items are skipped, the killed one is run whole.
    let again = ok(
        kneeform(&["batch", manifest.to_str().unwrap()]),
        "the batch again",
    );
    let text = String::from_utf8_lossy(&again.stderr);
    let skipped: Vec<&str> = text.lines().filter(|l| l.contains(": skipped")).collect();
    assert_eq!(skipped.len(), 2, "{text}");
    assert!(skipped[0].contains("runs/wave"), "{text}");
    assert!(text.contains("1 items run, 2 skipped"), "{text}");
    assert_eq!(std::fs::metadata(&first).unwrap().ino(), inode);
    // A third time: nothing to do.
    let third = ok(
        kneeform(&["batch", manifest.to_str().unwrap()]),
        "a third time",
    );
    assert!(String::from_utf8_lossy(&third.stderr).contains("0 items run, 3 skipped"));
    // The same files as a batch never killed, and nothing staged left.
    let clean = batch_dir("batch-clean");
    ok(
        kneeform(&["batch", clean.join("manifest.toml").to_str().unwrap()]),
        "a clean batch",
    );
    for item in ["wave", "bump-right", "wave-fine"] {
        let files = assert_same_files(&dir.join("runs").join(item), &clean.join("runs").join(item));
        assert_eq!(files, 8, "{item}: {files} files");
    }
    let runs: Vec<String> = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(runs.len(), 3, "{runs:?}");
    // A changed item runs again; the others are kept.
    let text = std::fs::read_to_string(&manifest)
        .unwrap()
        .replace("--deflection\", \"1\"", "--deflection\", \"2\"");
    std::fs::write(&manifest, text).unwrap();
    let changed = ok(kneeform(&["batch", manifest.to_str().unwrap()]), "changed");
    assert!(String::from_utf8_lossy(&changed.stderr).contains("1 items run, 2 skipped"));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&clean).unwrap();
}

#[test]
fn a_bad_manifest_is_one_line() {
    let dir = scratch_dir("batch-bad");
    let manifest = dir.join("m.toml");
    for (text, needle) in [
        ("[[item]]\npart = \"a.stl\"\n", "out"),
        (
            "[[item]]\npart = \"a.stl\"\nout = \"r\"\npich = 2\n",
            "pich",
        ),
        ("", "no [[item]]"),
        (
            "[[item]]\npart = \"a.stl\"\nout = \"r\"\n[[item]]\npart = \"b.stl\"\nout = \"r\"\n",
            "as an earlier item",
        ),
        (
            "[[item]]\npart = \"missing.stl\"\nout = \"r\"\n",
            "missing.stl",
        ),
    ] {
        std::fs::write(&manifest, text).unwrap();
        refused(
            &kneeform(&["batch", manifest.to_str().unwrap()]),
            needle,
            text,
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
