//! The `kneeform` binary end to end: real third-party meshes, bad input,
//! determinism across thread counts, the side and z symmetries, and the
//! built-in scenario names.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use kneeform::mesh::Triangle;
use kneeform::output::write_stl;
use kneeform::scenario::{Extent, ScenarioFile, builtin};

use crate::util::scratch_dir;

/// Runs the binary with `args`, without the caller's RUST_BACKTRACE (its
/// errors must be one line whatever the environment).
pub(crate) fn kneeform(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the binary runs")
}

/// What a run said: its results (stdout), then its messages (stderr).
pub(crate) fn said(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
}

/// [`kneeform`] run in the directory `dir`.
pub(crate) fn kneeform_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .current_dir(dir)
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the binary runs")
}

fn real_meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes")
}

const OUTPUTS: [&str; 5] = [
    "summary.json",
    "composite.csv.gz",
    "zones.csv",
    "depth.png",
    "composite.png",
];

/// Asserts a run failed cleanly: exit 2, one line on stderr, no output
/// directory and no staging directory left beside it.
pub(crate) fn assert_clean_failure(out: &Output, dir: &Path, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{what}: not one line: {stderr}");
    assert!(stderr.starts_with("kneeform: error: "), "{what}: {stderr}");
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    assert!(!dir.exists(), "{what}: output directory left behind");
    let parent = dir.parent().expect("a parent");
    let leftovers: Vec<_> = std::fs::read_dir(parent)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(
        leftovers.is_empty(),
        "{what}: staging left behind: {leftovers:?}"
    );
}

#[test]
fn every_real_mesh_analyses_or_fails_cleanly() {
    let mut analysed = 0;
    let mut refused = 0;
    let mut files: Vec<PathBuf> = std::fs::read_dir(real_meshes())
        .expect("tests/data/meshes in the repository")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl")))
        .collect();
    files.sort();
    assert!(
        files.len() >= 10,
        "expected the third-party meshes, found {files:?}"
    );
    for file in &files {
        let scratch = scratch_dir("mesh");
        let dir = scratch.join("out");
        let out = kneeform(&[
            "analyze",
            file.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--pitch",
            "2",
            "--angles=-30,0,30",
        ]);
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        if out.status.success() {
            for f in OUTPUTS {
                let len = std::fs::metadata(dir.join(f)).map(|m| m.len()).unwrap_or(0);
                assert!(
                    len > 0 || f.ends_with(".csv"),
                    "{name}: {f} missing or empty"
                );
            }
            let summary: serde_json::Value =
                serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
            let triangles = summary["triangles"].as_u64().unwrap();
            assert!(
                triangles > 0 && summary["degenerate_triangles"].as_u64().unwrap() < triangles,
                "{name}"
            );
            assert_eq!(summary["sha256"].as_str().unwrap().len(), 64, "{name}");
            assert_eq!(summary["triangle_side_mm"], 200.0);
            assert_eq!(summary["triangle_side_assumed"], true);
            analysed += 1;
        } else {
            assert_clean_failure(&out, &dir, &name);
            refused += 1;
        }
        std::fs::remove_dir_all(&scratch).unwrap();
    }
    // The three empty files must be refused; the real parts must analyse.
    assert_eq!(refused, 3, "analysed {analysed}, refused {refused}");
    assert_eq!(analysed, files.len() - 3);
}

#[test]
fn bad_input_gets_one_line_and_exit_2() {
    let scratch = scratch_dir("bad");
    let dir = scratch.join("out");
    let garbage = scratch.join("garbage.stl");
    std::fs::write(&garbage, vec![7u8; 300]).unwrap();
    let truncated = scratch.join("truncated.stl");
    let mut bytes = std::fs::read(real_meshes().join("featuretype.STL")).unwrap();
    bytes.truncate(bytes.len() / 2);
    std::fs::write(&truncated, bytes).unwrap();
    let nan = scratch.join("nan.stl");
    write_stl(
        &nan,
        &[[[0.0, f64::NAN, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]],
    )
    .unwrap();
    let part = scratch.join("part.stl");
    write_stl(&part, &builtin("bump").unwrap().triangulate(None)).unwrap();
    let (g, t, n, p, d) = (
        garbage.to_str().unwrap(),
        truncated.to_str().unwrap(),
        nan.to_str().unwrap(),
        part.to_str().unwrap(),
        dir.to_str().unwrap(),
    );
    let cases: Vec<(&str, Vec<&str>)> = vec![
        (
            "missing file",
            vec!["analyze", "/nonexistent/part.stl", "--out", d],
        ),
        ("garbage", vec!["analyze", g, "--out", d]),
        ("truncated", vec!["analyze", t, "--out", d]),
        ("NaN vertex", vec!["analyze", n, "--out", d]),
        ("zero pitch", vec!["analyze", p, "--out", d, "--pitch", "0"]),
        (
            "grid too large",
            vec!["analyze", p, "--out", d, "--pitch", "0.05"],
        ),
        (
            "bad angles",
            vec!["analyze", p, "--out", d, "--angles", "0:10"],
        ),
        (
            "bad grid origin",
            vec![
                "analyze",
                p,
                "--out",
                d,
                "--grid-origin",
                "x,1",
                "--grid-size",
                "10,10",
            ],
        ),
    ];
    for (what, args) in cases {
        let out = kneeform(&args);
        assert_clean_failure(&out, &dir, what);
    }
    // The memory refusal names what it would need.
    let out = kneeform(&["analyze", p, "--out", d, "--pitch", "0.05"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("GiB"));
    std::fs::remove_dir_all(&scratch).unwrap();
}

pub(crate) fn analyse_to(part: &Path, dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "analyze",
        part.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--pitch",
        "2.5",
        "--angles=-30,-12,0,12,30",
    ];
    args.extend_from_slice(extra);
    let out = kneeform(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn thread_count_does_not_change_any_byte() {
    let scratch = scratch_dir("threads");
    let part = scratch.join("part.stl");
    write_stl(&part, &builtin("depression").unwrap().triangulate(None)).unwrap();
    analyse_to(
        &part,
        &scratch.join("one"),
        &["--threads", "1", "--points-csv", "--stl", "--ply"],
    );
    analyse_to(
        &part,
        &scratch.join("many"),
        &["--points-csv", "--stl", "--ply"],
    );
    for f in [
        "colliding_points.csv",
        "composite.csv.gz",
        "colliding_area.stl",
        "colliding_area.ply",
    ] {
        let a = std::fs::read(scratch.join("one").join(f)).unwrap();
        let b = std::fs::read(scratch.join("many").join(f)).unwrap();
        assert!(
            a.len() > 100,
            "{f} is nearly empty: the comparison would prove nothing"
        );
        assert!(a == b, "{f} differs between --threads 1 and the default");
    }
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// The text of a run's table: `path` itself, or where it is missing its
/// compressed form, `path` with `.gz` (as `composite.csv.gz`, written by
/// default) decompressed.
pub(crate) fn table_text(path: &Path) -> String {
    if path.exists() {
        return std::fs::read_to_string(path).unwrap();
    }
    let mut gz = path.as_os_str().to_owned();
    gz.push(".gz");
    let file = std::fs::File::open(&gz)
        .unwrap_or_else(|e| panic!("neither {} nor its .gz: {e}", path.display()));
    let mut text = String::new();
    std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(file), &mut text).unwrap();
    text
}

/// Rows of a CSV file (or its `.gz`, [`table_text`]) as text fields,
/// header dropped.
pub(crate) fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let text = table_text(path);
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    reader
        .records()
        .map(|r| r.unwrap().iter().map(str::to_string).collect())
        .collect()
}

pub(crate) fn mirrored(tris: &[Triangle], axis: usize) -> Vec<Triangle> {
    tris.iter()
        .map(|t| {
            // Mirroring flips the winding; swap two vertices to keep it.
            let m = t.map(|mut v| {
                v[axis] = -v[axis];
                v
            });
            [m[0], m[2], m[1]]
        })
        .collect()
}

/// A part with features varying along z, so that the angle matters.
pub(crate) fn asymmetric_part() -> Vec<Triangle> {
    let bump = ScenarioFile {
        extent: Extent {
            x: [-150.0, 150.0],
            z: [-40.0, 90.0],
            step: 2.5,
        },
        ..builtin("bump").unwrap()
    };
    bump.triangulate(None)
        .into_iter()
        .map(|t| t.map(|[x, y, z]| [x, y - 0.05 * z * (x / 50.0).sin(), z]))
        .collect()
}

#[test]
fn right_side_of_a_mirrored_part_gives_the_mirrored_result() {
    let scratch = scratch_dir("side");
    let tris = asymmetric_part();
    let (left, right) = (scratch.join("left.stl"), scratch.join("right.stl"));
    write_stl(&left, &tris).unwrap();
    write_stl(&right, &mirrored(&tris, 1)).unwrap();
    analyse_to(
        &left,
        &scratch.join("l"),
        &["--side", "left", "--points-csv"],
    );
    analyse_to(
        &right,
        &scratch.join("r"),
        &["--side", "right", "--points-csv"],
    );
    // y is column 4 of colliding_points (angle_deg,i,j,x,y,z) and column 3
    // of composite (i,j,x,y,z,angles).
    for (f, y_col) in [("colliding_points.csv", 4), ("composite.csv", 3)] {
        let l = csv_rows(&scratch.join("l").join(f));
        let r = csv_rows(&scratch.join("r").join(f));
        assert!(l.len() > 20, "{f}: too few rows to prove anything");
        assert_eq!(l.len(), r.len(), "{f}");
        // Same nodes, y negated.
        for (a, b) in l.iter().zip(&r) {
            for (k, (u, v)) in a.iter().zip(b).enumerate() {
                if k == y_col {
                    assert_eq!(
                        u.parse::<f64>().unwrap(),
                        -v.parse::<f64>().unwrap(),
                        "{f}: {a:?} vs {b:?}"
                    );
                } else {
                    assert_eq!(u, v, "{f}: {a:?} vs {b:?}");
                }
            }
        }
    }
    std::fs::remove_dir_all(&scratch).unwrap();
}

#[test]
fn composite_masks_hold_exactly_the_colliding_points() {
    // composite.csv's angle_mask is colliding_points.csv's rows, packed:
    // bit a for summary.json's angles_deg[a]; angles in the run's order,
    // not sorted.
    let scratch = scratch_dir("masks");
    let part = scratch.join("part.stl");
    write_stl(&part, &asymmetric_part()).unwrap();
    let run = scratch.join("run");
    let out = kneeform(&[
        "analyze",
        part.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--pitch",
        "2.5",
        "--angles=30,-30,0,-12,12",
        "--points-csv",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(run.join("summary.json")).unwrap()).unwrap();
    let angles: Vec<f64> = summary["angles_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_f64().unwrap())
        .collect();
    assert_eq!(angles, [30.0, -30.0, 0.0, -12.0, 12.0]);
    let mut from_points: Vec<(String, String, u64)> = csv_rows(&run.join("colliding_points.csv"))
        .into_iter()
        .map(|r| {
            let a = angles
                .iter()
                .position(|&a| a == r[0].parse::<f64>().unwrap());
            (r[1].clone(), r[2].clone(), a.unwrap() as u64)
        })
        .collect();
    let mut from_masks = Vec::new();
    for r in csv_rows(&run.join("composite.csv")) {
        let hex = r[6].strip_prefix("0x").expect("0x");
        assert_eq!(hex.len(), 2, "one digit per four angles: {r:?}");
        let bits = u64::from_str_radix(hex, 16).unwrap();
        assert_eq!(
            bits.count_ones().to_string(),
            r[5],
            "the count is the set's: {r:?}"
        );
        for a in (0..angles.len() as u64).filter(|a| bits >> a & 1 == 1) {
            from_masks.push((r[0].clone(), r[1].clone(), a));
        }
    }
    from_points.sort();
    from_masks.sort();
    assert!(from_points.len() > 100, "too few points to prove anything");
    assert_eq!(from_points, from_masks);
    std::fs::remove_dir_all(&scratch).unwrap();
}

#[test]
fn part_mirrored_in_z_gives_the_composite_mirrored_with_angles_swapped() {
    let scratch = scratch_dir("zmirror");
    let tris = asymmetric_part();
    let (a, b) = (scratch.join("a.stl"), scratch.join("b.stl"));
    write_stl(&a, &tris).unwrap();
    write_stl(&b, &mirrored(&tris, 2)).unwrap();
    analyse_to(&a, &scratch.join("a"), &["--points-csv"]);
    analyse_to(&b, &scratch.join("b"), &["--points-csv"]);
    // colliding_points: angle_deg,i,j,x,y,z -> key (angle, x, z).
    let key = |rows: Vec<Vec<String>>, flip: f64| {
        let mut keys: Vec<(i64, i64, i64)> = rows
            .iter()
            .map(|r| {
                let f = |k: usize| r[k].parse::<f64>().unwrap();
                (
                    (flip * f(0)).round() as i64,
                    (f(3) * 1000.0).round() as i64,
                    (flip * f(5) * 1000.0).round() as i64,
                )
            })
            .collect();
        keys.sort();
        keys
    };
    let ka = key(
        csv_rows(&scratch.join("a").join("colliding_points.csv")),
        1.0,
    );
    let kb = key(
        csv_rows(&scratch.join("b").join("colliding_points.csv")),
        -1.0,
    );
    assert!(ka.len() > 20, "too few colliding points to prove anything");
    assert_eq!(ka, kb);
    // And the angle does matter here: the masks at -30 and +30 differ.
    let at = |angle: i64| {
        ka.iter()
            .filter(|k| k.0 == angle)
            .map(|k| (k.1, k.2))
            .collect::<Vec<_>>()
    };
    assert_ne!(at(-30), at(30));
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// A verification where neither side strikes anything is INCONCLUSIVE
/// (exit 3; issue 39: it passed, saying so) and says why: a pass on
/// nothing is no evidence. The ramp, where everything in front strikes,
/// has no such warning.
#[test]
fn verify_warns_when_nothing_is_struck_on_either_side() {
    let dir = scratch_dir("verify-nothing");
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let run = |part: &str, out: &str| {
        kneeform(&[
            "verify",
            scenarios.join(part).to_str().unwrap(),
            "--pitch",
            "4",
            "--angles=0",
            "--starts",
            "10",
            "--tolerance",
            "10",
            "--out",
            dir.join(out).to_str().unwrap(),
        ])
    };
    let flat = run("flat-wall.toml", "flat");
    let stderr = crate::cli::said(&flat);
    assert_eq!(flat.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("strikes nothing on these starts"),
        "{stderr}"
    );
    let ramp = run("ramp.toml", "ramp");
    let stderr = crate::cli::said(&ramp);
    assert!(!stderr.contains("strikes nothing"), "{stderr}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Every scenario file's stem is a built-in name that works from any
/// directory and writes exactly what the file writes; any other name is
/// refused in one line that lists them all.
#[test]
fn built_in_names_are_the_scenario_files_from_any_directory() {
    let dir = scratch_dir("builtin-names");
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    // Run from the scratch directory, where no `scenarios/` lies.
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_kneeform"))
            .current_dir(&dir)
            .args(args)
            .output()
            .expect("the binary runs")
    };
    let mut stems: Vec<String> = std::fs::read_dir(&scenarios)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| kneeform::scenario::is_scenario_file(p))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    stems.sort();
    assert!(stems.len() >= 14, "{stems:?}");
    for stem in &stems {
        let by_name = format!("{stem}-by-name.stl");
        let by_file = format!("{stem}-by-file.stl");
        let file = scenarios.join(format!("{stem}.toml"));
        for args in [
            vec!["scenario", stem, "--out", &by_name],
            vec!["scenario", file.to_str().unwrap(), "--out", &by_file],
        ] {
            let out = run(&args);
            assert!(
                out.status.success(),
                "{args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let written = std::fs::read(dir.join(&by_name)).unwrap();
        assert!(
            written == std::fs::read(dir.join(&by_file)).unwrap(),
            "{stem}: the name and the file write different parts"
        );
        // 84 bytes of header and count, 50 per triangle.
        let count = builtin(stem).unwrap().triangle_count(None);
        assert_eq!(written.len(), 84 + 50 * count, "{stem}");
    }
    let out = run(&["scenario", "no-such-part", "--out", "x.stl"]);
    let stderr = crate::cli::said(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    for stem in &stems {
        assert!(
            stderr.contains(stem.as_str()),
            "{stem} not listed: {stderr}"
        );
    }
    assert!(!dir.join("x.stl").exists());
    std::fs::remove_dir_all(dir).unwrap();
}

/// Issue 39, item 6: every command's results (what it found and where it
/// wrote them) on stdout, every message (progress with the time left,
/// notes, warnings) on stderr: `analyze`, `verify` and `report` of a
/// small run, with a progress line forced every 50 ms off a terminal.
#[test]
fn results_go_to_stdout_and_messages_to_stderr() {
    let dir = scratch_dir("stdout-stderr");
    let part = crate::util::scenario("bump");
    let run = |args: &[&str]| -> (Option<i32>, String, String) {
        let out = Command::new(env!("CARGO_BIN_EXE_kneeform"))
            .current_dir(&dir)
            .args(args)
            .env_remove("RUST_BACKTRACE")
            .env("KNEEFORM_PROGRESS_EVERY", "0.05")
            .output()
            .expect("the binary runs");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // What only a message says: progress (elapsed, left), a warning, the
    // memory note, an error.
    let is_message = |line: &str| {
        line.contains(" elapsed")
            || line.starts_with("kneeform: warning")
            || line.starts_with("kneeform: error")
            || line.contains("needs about")
    };
    let check = |what: &str, stdout: &str, stderr: &str, results: &[&str]| {
        assert!(
            !stdout.is_empty(),
            "{what}: nothing on stdout; stderr:\n{stderr}"
        );
        for line in stdout.lines() {
            assert!(!is_message(line), "{what}: a message on stdout: {line}");
        }
        for needle in results {
            assert!(
                stdout.contains(needle),
                "{what}: {needle:?} not on stdout:\n{stdout}"
            );
            assert!(
                !stderr.contains(needle),
                "{what}: {needle:?} on stderr:\n{stderr}"
            );
        }
    };
    let (code, stdout, stderr) = run(&[
        "analyze",
        &part,
        "--pitch",
        "2",
        "--angles=-30:30:2",
        "--out",
        "run",
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    check(
        "analyze",
        &stdout,
        &stderr,
        &[
            "composite",
            "results in run",
            "struck zones",
            "sample check against",
        ],
    );
    // The push and slide's progress, with the time left, on stderr.
    assert!(
        stderr
            .lines()
            .any(|l| l.starts_with("kneeform: push and slide: ") && l.contains(" left")),
        "no progress with the time left on stderr:\n{stderr}"
    );
    let (code, stdout, stderr) = run(&[
        "verify",
        &part,
        "--pitch",
        "2",
        "--angles=-30,0,30",
        "--out",
        "v",
    ]);
    assert!(matches!(code, Some(0 | 1 | 3)), "{stderr}");
    check(
        "verify",
        &stdout,
        &stderr,
        &["at tolerance", "results in v"],
    );
    // The oracle's pairs and the comparison, counted with the time left.
    for stage in ["kneeform: exact oracle: ", "kneeform: grid against exact: "] {
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with(stage) && l.contains('/')),
            "no counted progress of {stage:?}:\n{stderr}"
        );
    }
    let (code, stdout, stderr) = run(&["report", "run", "v", "--out", "r.html"]);
    assert_eq!(code, Some(0), "{stderr}");
    check("report", &stdout, &stderr, &["written to r.html"]);
    // An error: one line on stderr, nothing on stdout.
    let (code, stdout, stderr) = run(&["analyze", "missing.stl", "--out", "x"]);
    assert_eq!(code, Some(2));
    assert_eq!(stdout, "");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
