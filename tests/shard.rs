//! Fan-out: `analyze --shard K/N`, `verify --shard K/N` and `converge
//! --shard K/N` (with `--approach direct` too) with `kneeform merge` give
//! the unsharded command's files byte for byte (clock readings aside);
//! `kneeform batch` resumes a killed batch without redoing finished items.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use kneeform::output::DirLock;

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

/// The clock readings of a result file set aside: `summary.json`'s
/// [`CLOCK_KEYS`], `verify.json`'s timings (the direct approach's
/// `grid_s` and `oracle_s`), `converge.json`'s engine seconds and the time
/// predicted from them (the direct approach's `oracle_s`),
/// `converge.csv`'s `seconds` column where it has one; `None` for a file
/// that is a clock reading as a whole (the plot of the engine's time
/// against the pitch). Other files as they are.
fn without_clocks(name: &str, bytes: &[u8]) -> Option<Vec<u8>> {
    let json_keys: &[&str] = match name {
        "summary.json" => &CLOCK_KEYS,
        "verify.json" => &["timings", "grid_s", "oracle_s"],
        "converge.json" => &["seconds", "predicted_full_time_s", "oracle_s"],
        "time_vs_pitch.png" => return None,
        // The record of the files written: the digests of those holding
        // clock readings set aside (each is compared without them).
        "kneeform-run.json" => {
            let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
            let files = v["files"].as_object_mut().unwrap();
            for clocked in [
                "summary.json",
                "verify.json",
                "converge.json",
                "converge.csv",
                "time_vs_pitch.png",
            ] {
                files.remove(clocked);
            }
            return Some(serde_json::to_vec(&v).unwrap());
        }
        "converge.csv" => {
            let text = String::from_utf8(bytes.to_vec()).unwrap();
            let mut lines = text.lines();
            let header: Vec<&str> = lines.next().unwrap().split(',').collect();
            let Some(col) = header.iter().position(|h| *h == "seconds") else {
                // The direct approach's: no clock reading.
                return Some(bytes.to_vec());
            };
            let rows = lines.map(|l| {
                let mut cells: Vec<&str> = l.split(',').collect();
                cells[col] = "";
                cells.join(",")
            });
            let out: Vec<String> = std::iter::once(header.join(",")).chain(rows).collect();
            return Some(out.join("\n").into_bytes());
        }
        _ => return Some(bytes.to_vec()),
    };
    let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
    for key in json_keys {
        v.as_object_mut().unwrap().remove(*key);
    }
    Some(serde_json::to_vec(&v).unwrap())
}

/// Asserts that the directories `a` and `b` hold the same files, byte for
/// byte, clock readings aside ([`without_clocks`]); returns how many.
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
        assert!(
            without_clocks(&name, &x) == without_clocks(&name, &y),
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
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
        "--stl".into(),
        "--ply".into(),
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
            "--stl",
            "--ply",
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
        // summary, composite, zones, points, STL, PLY, two images, blind
        // spots, and the record of them.
        assert_eq!(files, 10, "{files} files compared");
        let composite = crate::cli::table_text(&merged.join("composite.csv"));
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
    // The same run but for the level the knee-form follows (SPEC v4).
    let surface = dir.join("surface");
    std::fs::create_dir(&surface).unwrap();
    let by_surface = shard(&wave, &surface, 2, 3, &["--level", "surface"]);
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
        (
            vec![s[0], &by_surface, s[2]],
            "`level` differ",
            "another level",
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

/// The flags of the study tests: a coarse pitch, three angles, a small
/// start sample (seconds in a debug build).
const STUDY: [&str; 3] = ["--angles=-30,0,30", "--starts", "16"];

/// Runs `command` (`verify` or `converge`) on `part` with [`STUDY`] and
/// `extra` into `out`, `--shard K/N` when `shard` is given.
fn study(
    command: &str,
    part: &str,
    out: &Path,
    shard: Option<(usize, usize)>,
    extra: &[&str],
) -> Output {
    let spec = shard.map(|(k, n)| format!("{k}/{n}"));
    let mut args = vec![command, part];
    // `extra`'s own --starts replaces the sample.
    let own_starts = extra.contains(&"--starts");
    args.extend_from_slice(if own_starts { &STUDY[..1] } else { &STUDY[..] });
    args.extend_from_slice(extra);
    if let Some(spec) = &spec {
        args.extend(["--shard", spec.as_str()]);
    }
    args.extend(["--out", out.to_str().unwrap()]);
    kneeform(&args)
}

/// Shards 1 to `n` of a study into `dir/shard-K`.
fn study_shards(command: &str, part: &str, dir: &Path, n: usize, extra: &[&str]) -> Vec<PathBuf> {
    (1..=n)
        .map(|k| {
            let out = dir.join(format!("shard-{k}"));
            ok(study(command, part, &out, Some((k, n)), extra), "a shard");
            out
        })
        .collect()
}

fn merge_study(shards: &[&Path], out: &Path) -> Output {
    let mut args = vec!["merge".to_string()];
    args.extend(shards.iter().map(|s| s.display().to_string()));
    args.extend(["--out".into(), out.display().to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    kneeform(&args)
}

#[test]
fn four_verify_shards_merged_are_the_unsharded_verification_byte_for_byte() {
    // A bump, failing a tight tolerance; the thin rib, whose exact strikes
    // are all undecided at 4 mm (INCONCLUSIVE); the wave, which passes.
    // Three start rows through the bump (issue 39: scattered starts
    // measure no area).
    let mut codes = Vec::new();
    for (name, tolerance) in [("bump", "1"), ("thin-rib", "1"), ("wave", "4")] {
        let dir = scratch_dir(&format!("verify-shards-{name}"));
        let part = scenario(name);
        let extra = [
            "--pitch",
            "4",
            "--tolerance",
            tolerance,
            "--starts",
            "strip:-4:4",
        ];
        let whole = study("verify", &part, &dir.join("whole"), None, &extra);
        let code = whole.status.code();
        assert!(
            matches!(code, Some(0 | 1 | 3)),
            "{name}: {}",
            String::from_utf8_lossy(&whole.stderr)
        );
        let shards = study_shards("verify", &part, &dir, 4, &extra);
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(shards[1].join("shard.json")).unwrap()).unwrap();
        assert_eq!(record["shard"], serde_json::json!({"index": 2, "count": 4}));
        assert_eq!(record["study"]["kind"], "verify");
        // The part and every setting; no verdict of a part of the starts.
        let summary = &record["study"]["summary"];
        assert_eq!(summary["input_sha256"].as_str().unwrap().len(), 64);
        assert_eq!(summary["tolerance_mm"].as_f64(), tolerance.parse().ok());
        assert!(summary.get("pass").is_none() && summary.get("metrics").is_none());
        let starts = record["starts"].as_u64().unwrap() as usize;
        let mine: Vec<usize> = (1..starts).step_by(4).collect();
        assert_eq!(record["start_indices"], serde_json::json!(mine));
        let merged = dir.join("merged");
        let order: Vec<&Path> = [2, 0, 3, 1].iter().map(|&k| shards[k].as_path()).collect();
        let result = merge_study(&order, &merged);
        // The merge's verdict is verify's.
        assert_eq!(
            result.status.code(),
            code,
            "{name}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        // verify.csv, verify.json and the record of them.
        assert_eq!(assert_same_files(&dir.join("whole"), &merged), 3, "{name}");
        let rows = std::fs::read_to_string(merged.join("verify.csv")).unwrap();
        assert_eq!(
            rows.lines().count(),
            1 + 3 * starts,
            "{name}: a row per start and angle"
        );
        if name != "wave" {
            let summary: serde_json::Value =
                serde_json::from_slice(&std::fs::read(merged.join("verify.json")).unwrap())
                    .unwrap();
            assert!(
                summary["counts"]["exact_strikes"].as_u64().unwrap() > 0,
                "{name}: nothing struck"
            );
        }
        codes.push(code);
        std::fs::remove_dir_all(&dir).unwrap();
    }
    assert_eq!(
        codes,
        [Some(1), Some(3), Some(0)],
        "FAIL, INCONCLUSIVE, PASS"
    );
}

/// Issue 26: a strip's starts are traced in chains along their rows
/// (each start joins its -x neighbour's curve), and a chained trace is a
/// function of its block of the row alone, so shards that split every row
/// between them merge into the unsharded strip byte for byte.
#[test]
fn four_shards_of_a_chained_strip_merged_are_the_unsharded_strip_byte_for_byte() {
    let dir = scratch_dir("verify-shards-strip");
    let part = scenario("bump");
    // Three start rows of the 4 mm grid, every placed start of each.
    let strip = |out: &Path, shard: Option<&str>| {
        let mut args = vec![
            "verify",
            part.as_str(),
            "--angles=-30,0,30",
            "--pitch",
            "4",
            "--tolerance",
            "1",
            "--starts",
            "strip:-4:4",
            "--out",
            out.to_str().unwrap(),
        ];
        if let Some(shard) = shard {
            args.extend(["--shard", shard]);
        }
        kneeform(&args)
    };
    let whole = strip(&dir.join("whole"), None);
    let code = whole.status.code();
    assert!(
        matches!(code, Some(0 | 1 | 3)),
        "{}",
        String::from_utf8_lossy(&whole.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("whole/verify.json")).unwrap()).unwrap();
    assert_eq!(
        summary["oracle_chain"],
        serde_json::json!({"pitch": 4.0, "block": 64}),
        "a strip says how its traces were shared"
    );
    assert_eq!(summary["starts"], "strip:-4:4");
    let shards: Vec<PathBuf> = (1..=4)
        .map(|k| {
            let out = dir.join(format!("shard-{k}"));
            ok(strip(&out, Some(&format!("{k}/4"))), "a shard");
            out
        })
        .collect();
    let merged = dir.join("merged");
    let order: Vec<&Path> = [3, 1, 0, 2].iter().map(|&k| shards[k].as_path()).collect();
    let result = merge_study(&order, &merged);
    assert_eq!(
        result.status.code(),
        code,
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    // verify.csv, verify.json and the record of them.
    assert_eq!(assert_same_files(&dir.join("whole"), &merged), 3);
    let rows = std::fs::read_to_string(merged.join("verify.csv")).unwrap();
    assert!(
        rows.lines().count() > 3 * 3 * 20,
        "three whole rows at three angles"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn four_converge_shards_merged_are_the_unsharded_study_byte_for_byte() {
    let dir = scratch_dir("converge-shards");
    let part = scenario("bump");
    let extra = ["--pitches", "8,4", "--tolerance", "3"];
    ok(
        study("converge", &part, &dir.join("whole"), None, &extra),
        "the unsharded study",
    );
    let shards = study_shards("converge", &part, &dir, 4, &extra);
    let merged = dir.join("merged");
    let order: Vec<&Path> = [3, 1, 0, 2].iter().map(|&k| shards[k].as_path()).collect();
    ok(merge_study(&order, &merged), "merge");
    // converge.csv and .json, a verify_<pitch>mm.csv per pitch, two plots,
    // the record of them.
    assert_eq!(assert_same_files(&dir.join("whole"), &merged), 7);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_refuses_a_study_s_missing_repeated_foreign_or_damaged_shard() {
    let dir = scratch_dir("study-refusals");
    let wave = scenario("wave");
    let extra = ["--pitch", "4"];
    let shards = study_shards("verify", &wave, &dir, 3, &extra);
    let s: Vec<&Path> = shards.iter().map(PathBuf::as_path).collect();
    let other = dir.join("other");
    std::fs::create_dir(&other).unwrap();
    // Another part; another seed (the same part, other starts); another
    // tie band (the same starts); another kind of shard.
    let foreign = study_shards("verify", &scenario("bump"), &other, 3, &extra);
    let seed = dir.join("seed");
    ok(
        study(
            "verify",
            &wave,
            &seed,
            Some((2, 3)),
            &["--pitch", "4", "--seed", "4"],
        ),
        "seed",
    );
    let band = dir.join("band");
    ok(
        study(
            "verify",
            &wave,
            &band,
            Some((2, 3)),
            &["--pitch", "4", "--tie-band", "2"],
        ),
        "tie band",
    );
    let converge = dir.join("converge");
    ok(
        study(
            "converge",
            &wave,
            &converge,
            Some((2, 3)),
            &["--pitches", "8,4"],
        ),
        "a converge shard",
    );
    let analysis_dir = dir.join("analysis");
    std::fs::create_dir(&analysis_dir).unwrap();
    let analysis = shard(&wave, &analysis_dir, 2, 3, &[]);
    let out = dir.join("merged");
    for (given, needle, what) in [
        (vec![s[0], s[2]], "shard 2/3 is missing", "missing"),
        (
            vec![s[0], s[1], s[1], s[2]],
            "shard 2/3 is given twice",
            "twice",
        ),
        (
            vec![s[0], &foreign[1], s[2]],
            "shards of different studies",
            "foreign",
        ),
        (
            vec![s[0], &seed, s[2]],
            "shards of different studies",
            "seed",
        ),
        (vec![s[0], &converge, s[2]], "convergence study", "converge"),
        (vec![s[0], &analysis, s[2]], "an analysis", "analysis"),
    ] {
        refused(&merge_study(&given, &out), needle, what);
        assert!(!out.exists(), "{what}: output left behind");
    }
    let four = dir.join("four");
    ok(study("verify", &wave, &four, Some((1, 4)), &extra), "N = 4");
    refused(
        &merge_study(&[&four, s[1], s[2]], &out),
        "one N",
        "another N",
    );
    let bin = shards[0].join("shard.bin");
    let mut bytes = std::fs::read(&bin).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&bin, bytes).unwrap();
    refused(&merge_study(&s, &out), "SHA-256", "damaged");
    assert!(!out.exists());
    // Flags a study's shard cannot take.
    for (bad, needle, extra) in [
        ("0/3", "--shard", &extra[..]),
        ("x", "--shard", &extra[..]),
        ("1/999", "999 shards of 16 starts", &extra[..]),
    ] {
        let bad_out = dir.join("bad");
        refused(
            &study(
                "verify",
                &wave,
                &bad_out,
                None,
                &[extra, &["--shard", bad]].concat(),
            ),
            needle,
            bad,
        );
        assert!(!bad_out.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The flags of the direct approach's study tests: the part turned to
/// face the knee-form coming from +x, as `results/regenerate.sh
/// converge-direct` turns it.
const DIRECT: [&str; 3] = ["--frame=-y,x,z", "--approach", "direct"];

#[test]
fn four_direct_verify_shards_merged_are_the_unsharded_verification_byte_for_byte() {
    // The wave within a loose tolerance (its level errors at 4 mm reach
    // 7.4 mm where it is steep) and beyond a tight one.
    let part = scenario("wave");
    let mut codes = Vec::new();
    for tolerance in ["8", "1"] {
        let dir = scratch_dir(&format!("verify-direct-shards-{tolerance}"));
        let extra = [&DIRECT[..], &["--pitch", "4", "--tolerance", tolerance]].concat();
        let whole = study("verify", &part, &dir.join("whole"), None, &extra);
        let code = whole.status.code();
        assert!(
            matches!(code, Some(0 | 1 | 3)),
            "{tolerance}: {}",
            String::from_utf8_lossy(&whole.stderr)
        );
        let shards = study_shards("verify", &part, &dir, 4, &extra);
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(shards[1].join("shard.json")).unwrap()).unwrap();
        assert_eq!(record["shard"], serde_json::json!({"index": 2, "count": 4}));
        assert_eq!(record["study"]["kind"], "verify-direct");
        let summary = &record["study"]["summary"];
        assert_eq!(summary["approach"], "direct");
        assert!(summary.get("pass").is_none() && summary.get("metrics").is_none());
        let starts = record["starts"].as_u64().unwrap() as usize;
        let mine: Vec<usize> = (1..starts).step_by(4).collect();
        assert_eq!(record["start_indices"], serde_json::json!(mine));
        let merged = dir.join("merged");
        let order: Vec<&Path> = [1, 3, 0, 2].iter().map(|&k| shards[k].as_path()).collect();
        let result = merge_study(&order, &merged);
        assert_eq!(
            result.status.code(),
            code,
            "{tolerance}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        // verify.csv, verify.json and the record of them.
        assert_eq!(assert_same_files(&dir.join("whole"), &merged), 3);
        let rows = std::fs::read_to_string(merged.join("verify.csv")).unwrap();
        assert_eq!(
            rows.lines().count(),
            1 + 3 * starts,
            "a row per position and angle"
        );
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(merged.join("verify.json")).unwrap()).unwrap();
        assert!(
            summary["counts"]["both"].as_u64().unwrap() > 0,
            "{tolerance}: nothing touched on both sides"
        );
        codes.push(code);
        std::fs::remove_dir_all(&dir).unwrap();
    }
    assert_eq!(codes, [Some(0), Some(1)]);
}

#[test]
fn four_direct_converge_shards_merged_are_the_unsharded_study_byte_for_byte() {
    let dir = scratch_dir("converge-direct-shards");
    let part = scenario("tilted-wave");
    let extra = [&DIRECT[..], &["--pitches", "8,4", "--tolerance", "2"]].concat();
    ok(
        study("converge", &part, &dir.join("whole"), None, &extra),
        "the unsharded study",
    );
    let shards = study_shards("converge", &part, &dir, 4, &extra);
    let merged = dir.join("merged");
    let order: Vec<&Path> = [2, 3, 1, 0].iter().map(|&k| shards[k].as_path()).collect();
    ok(merge_study(&order, &merged), "merge");
    // converge.csv and .json, a verify_<pitch>mm.csv per pitch, the
    // record of them.
    assert_eq!(assert_same_files(&dir.join("whole"), &merged), 5);
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(merged.join("converge.json")).unwrap()).unwrap();
    assert_eq!(summary["approach"], "direct");
    // A slide study's shard, or a direct verification's, among them.
    let slide = dir.join("slide");
    ok(
        study(
            "converge",
            &part,
            &slide,
            Some((2, 4)),
            &["--pitches", "8,4"],
        ),
        "a slide shard",
    );
    let verify = dir.join("verify");
    ok(
        study(
            "verify",
            &part,
            &verify,
            Some((2, 4)),
            &[&DIRECT[..], &["--pitch", "8"]].concat(),
        ),
        "a direct verification's shard",
    );
    let out = dir.join("refused");
    for (other, needle) in [
        (&slide, "a convergence study (converge --shard)"),
        (&verify, "a direct-approach verification"),
    ] {
        let given = [shards[0].as_path(), other, &shards[2], &shards[3]];
        refused(&merge_study(&given, &out), needle, needle);
        assert!(!out.exists(), "{needle}: output left behind");
    }
    // Missing and repeated shards, and another study (another tolerance).
    let tight = dir.join("tight");
    ok(
        study(
            "converge",
            &part,
            &tight,
            Some((2, 4)),
            &[&DIRECT[..], &["--pitches", "8,4", "--tolerance", "1"]].concat(),
        ),
        "another study's shard",
    );
    let s: Vec<&Path> = shards.iter().map(PathBuf::as_path).collect();
    for (given, needle) in [
        (vec![s[0], s[2], s[3]], "shard 2/4 is missing"),
        (
            vec![s[0], s[1], s[1], s[2], s[3]],
            "shard 2/4 is given twice",
        ),
        (
            vec![s[0], &tight, s[2], s[3]],
            "shards of different studies",
        ),
    ] {
        refused(&merge_study(&given, &out), needle, needle);
        assert!(!out.exists(), "{needle}: output left behind");
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
    // Killed once the second item is done: its fingerprint written and
    // recorded in its run record (a kill between the two is the next
    // test's).
    let record = dir.join("runs/bump-right/kneeform-run.json");
    let recorded =
        || std::fs::read_to_string(&record).is_ok_and(|t| t.contains("\"batch-item.json\""));
    while !recorded() {
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
    // The batch is gone, but its item's run may not be yet: a process
    // killed inside a sync to disk dies when the sync returns, holding its
    // directory's lock until then (a CI run resumed too early and was
    // rightly refused). Wait for every item's lock to be free, as a
    // scheduler waits for a killed job's processes to end.
    for item in ["wave", "bump-right", "wave-fine"] {
        let run = dir.join("runs").join(item);
        loop {
            match DirLock::take(&run) {
                Ok(_released_at_once) => break,
                Err(e) if e.kind() == std::io::ErrorKind::ResourceBusy => {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                Err(e) => panic!("{}: {e}", run.display()),
            }
        }
    }
    let first = dir.join("runs/wave/summary.json");
    let inode = std::fs::metadata(&first).unwrap().ino();
    // Again: the finished items are skipped, the killed one is run whole.
    let again = ok(
        kneeform(&["batch", manifest.to_str().unwrap()]),
        "the batch again",
    );
    let text = crate::cli::said(&again);
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
    assert!(crate::cli::said(&third).contains("0 items run, 3 skipped"));
    // The same files as a batch never killed, and nothing staged left.
    let clean = batch_dir("batch-clean");
    ok(
        kneeform(&["batch", clean.join("manifest.toml").to_str().unwrap()]),
        "a clean batch",
    );
    for item in ["wave", "bump-right", "wave-fine"] {
        let files = assert_same_files(&dir.join("runs").join(item), &clean.join("runs").join(item));
        // summary, composite (compressed), zones, two images, blind
        // spots, batch-item.json and the record of the files.
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
    assert!(crate::cli::said(&changed).contains("1 items run, 2 skipped"));
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
            "the directory item 1 writes to",
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

/// Runs of adjacent starts (`--starts runs:N:L`, by default 20 runs of
/// 5): L starts one pitch apart on a row, from a chain block's first
/// start, traced in chains; the summary names them; an empty, over-long, half-written or unfitting run
/// (or a strip off the part) is refused in one line naming `--starts`.
#[test]
fn runs_of_starts_are_chained_and_bad_runs_are_refused() {
    let dir = scratch_dir("verify-runs");
    let part = scenario("bump");
    let verify_at = |pitch: &str, starts: &str, out: &str| {
        kneeform(&[
            "verify",
            part.as_str(),
            "--angles=-30,30",
            "--pitch",
            pitch,
            "--tolerance",
            "1",
            "--starts",
            starts,
            "--out",
            dir.join(out).to_str().unwrap(),
        ])
    };
    let run = verify_at("4", "runs:3:4", "runs");
    assert!(
        matches!(run.status.code(), Some(0 | 1 | 3)),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("runs/verify.json")).unwrap()).unwrap();
    assert_eq!(summary["starts"], "runs:3:4");
    assert_eq!(summary["seed"], 1);
    assert_eq!(
        summary["oracle_chain"],
        serde_json::json!({"pitch": 4.0, "block": 64})
    );
    let csv = std::fs::read_to_string(dir.join("runs/verify.csv")).unwrap();
    let rows: Vec<(i64, i64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().unwrap(), f[1].parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 2 * 3 * 4, "two angles of 3 runs of 4");
    for run in rows[..12].chunks(4) {
        assert!(
            run.windows(2).all(|w| w[1] == (w[0].0 + 1, w[0].1)),
            "{run:?}"
        );
    }
    // The default: 10 patches of 3 rows of 5 (issue 39: a place measured
    // in x and z).
    let default = kneeform(&[
        "verify",
        part.as_str(),
        "--angles=0",
        "--pitch",
        "4",
        "--tolerance",
        "1",
        "--out",
        dir.join("default").to_str().unwrap(),
    ]);
    assert!(matches!(default.status.code(), Some(0 | 1 | 3)));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("default/verify.json")).unwrap()).unwrap();
    assert_eq!(summary["starts"], "patches:10:5:3");
    assert_eq!(summary["counts"]["pairs"], 150);
    for (pitch, bad, says) in [
        ("4", "runs:0:4", "at least one start"),
        ("4", "runs:3:65", "1 to 64 starts"),
        ("4", "runs:3", "expected runs:N:L"),
        ("4", "patches:3:5", "expected patches:N:L:R"),
        ("4", "patches:3:5:0", "at least one start"),
        (
            "4",
            "all:3",
            "expected runs:N:L, strip:Z0:Z1, a number of starts or `all`",
        ),
        // No row of the bump at 16 mm holds 64 placed starts.
        ("16", "runs:3:64", "no 64 adjacent placed starts"),
        ("4", "strip:5000:6000", "no placed start lies in the strip"),
    ] {
        let out = verify_at(pitch, bad, "bad");
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = crate::cli::said(&out);
        assert!(
            err.contains("--starts") && err.contains(says),
            "{bad}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{bad}: {err}");
    }
    // A speck between the nodes places no start: the default runs say
    // so, not that shorter runs would fit.
    let speck = dir.join("speck.stl");
    std::fs::write(
        &speck,
        "solid s\nfacet normal 0 -1 0\nouter loop\nvertex 0.3 0 0.3\nvertex 0.5 0 0.3\nvertex 0.4 0 0.5\nendloop\nendfacet\nendsolid s\n",
    )
    .unwrap();
    let out = kneeform(&[
        "verify",
        speck.to_str().unwrap(),
        "--pitch",
        "4",
        "--out",
        dir.join("speck").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = crate::cli::said(&out);
    assert!(err.contains("no start is placed on this part"), "{err}");
    assert!(!err.contains("shorter runs"), "{err}");
}

/// A batch killed after writing an item's fingerprint and before recording
/// it in the item's run record: the item is not taken as complete; the
/// next batch runs it again, whole, and ends with a clean batch's files.
#[test]
fn a_fingerprint_written_but_not_recorded_runs_its_item_again() {
    let dir = batch_dir("batch-unrecorded");
    let manifest = dir.join("manifest.toml");
    ok(
        kneeform(&["batch", manifest.to_str().unwrap()]),
        "the batch",
    );
    // The state the kill leaves: the fingerprint on disk, not in the record.
    let run = dir.join("runs/bump-right");
    let record_path = run.join("kneeform-run.json");
    let mut record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&record_path).unwrap()).unwrap();
    let files = record["files"].as_object_mut().unwrap();
    assert!(files.remove("batch-item.json").is_some());
    std::fs::write(&record_path, serde_json::to_string_pretty(&record).unwrap()).unwrap();
    assert!(run.join("batch-item.json").is_file());
    let again = ok(
        kneeform(&["batch", manifest.to_str().unwrap()]),
        "the batch again",
    );
    let text = crate::cli::said(&again);
    assert!(text.contains("1 items run, 2 skipped"), "{text}");
    assert!(
        text.lines()
            .any(|l| l.contains("runs/bump-right") && !l.contains("skipped")),
        "{text}"
    );
    let clean = batch_dir("batch-unrecorded-clean");
    ok(
        kneeform(&["batch", clean.join("manifest.toml").to_str().unwrap()]),
        "a clean batch",
    );
    assert_same_files(&run, &clean.join("runs/bump-right"));
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&clean).unwrap();
}
