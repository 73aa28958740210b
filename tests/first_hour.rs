//! A new user's first hour (issue 13): the README's first command through
//! `analyze --report` and `report` at the default pitch and grid, every
//! third-party mesh (tests/data/meshes) and scenario reported at its default pitch, and each
//! natural mistake met with its warning or error, the documented exit
//! code, and nothing half written.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use kneeform::summary::Summary;
use serde_json::Value;

use crate::cli::kneeform_in as kneeform;
use crate::util::{Image, Rng, SEEDS, scratch_dir};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// What a run said: its results (stdout), then its messages (stderr).
fn stderr(out: &Output) -> String {
    crate::cli::said(out)
}

fn ok(out: Output, what: &str) -> Output {
    assert!(out.status.success(), "{what}: {}", stderr(&out));
    out
}

/// Asserts exit 2 with one line on stderr, an error naming `needle`.
fn refused(out: &Output, needle: &str, what: &str) {
    let text = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{what}: {text}");
    assert_eq!(text.lines().count(), 1, "{what}: not one line: {text}");
    assert!(text.starts_with("kneeform: error: "), "{what}: {text}");
    assert!(text.contains(needle), "{what}: no {needle:?} in {text}");
}

/// The `kneeform: warning:` lines of a run's stderr.
fn warnings(out: &Output) -> Vec<String> {
    stderr(out)
        .lines()
        .filter(|l| l.starts_with("kneeform: warning: "))
        .map(str::to_string)
        .collect()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The step scenario as STL in `dir` (its surface faces -y).
fn step_part(dir: &Path, name: &str) {
    ok(
        kneeform(dir, &["scenario", "step", "--out", name]),
        "scenario",
    );
}

/// A small, quick analysis of `part` into `out`.
fn quick<'a>(part: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "analyze",
        part,
        "--pitch",
        "4",
        "--angles=-30,0,30",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    args
}

/// Screenshots `page` in headless Chromium; the RGB pixels, or `None` when
/// Chromium is not installed.
fn screenshot(page: &Path, dir: &Path) -> Option<(usize, usize, Vec<[u8; 3]>)> {
    crate::util::screenshot(page, dir).map(|png| {
        let image = Image::decode(&png);
        (image.width, image.height, image.rgb())
    })
}

#[test]
fn the_readme_first_command_analyses_and_reports_the_bundled_console() {
    // The README's first command, from a checkout-like directory: the
    // bundled console at the default pitch, grid and angles, with
    // --report; then the report command a user runs next.
    let dir = scratch_dir("readme");
    std::fs::create_dir(dir.join("scenarios")).unwrap();
    std::fs::copy(
        repo().join("scenarios/console_side.stl"),
        dir.join("scenarios/console_side.stl"),
    )
    .unwrap();
    let out = ok(
        kneeform(
            &dir,
            &[
                "analyze",
                "scenarios/console_side.stl",
                "--out",
                "kneeform-out",
                "--report",
            ],
        ),
        "the README's first command with --report",
    );
    assert!(warnings(&out).is_empty(), "{}", stderr(&out));
    let summary = read_json(&dir.join("kneeform-out/summary.json"));
    assert_eq!(summary["pitch_mm"], 1.24);
    assert_eq!(summary["angles_deg"].as_array().unwrap().len(), 61);
    // The grid whose origin broke the report (z0 = 1.24 x -189, written
    // -234.35999999999999).
    let z0 = summary["grid_origin"][1].as_f64().unwrap();
    assert_eq!((z0 / 1.24).round(), -189.0, "the grid moved: {summary}");
    assert!(summary["composite_nodes"].as_u64().unwrap() > 100_000);
    assert!(dir.join("kneeform-out/report.html").is_file());
    // Issue 39, item 5: a run a user keeps. The default analysis of the
    // console wrote 50 MB (the area as STL 21.6 MB, as ASCII PLY 16.9 MB,
    // composite.csv 11 MB); the large files are now asked for (--stl,
    // --ply, --csv) and the composite is compressed: at most 10 MB, the
    // report --report adds included.
    let mut files = Vec::new();
    let mut total = 0;
    for entry in std::fs::read_dir(dir.join("kneeform-out")).unwrap() {
        let entry = entry.unwrap();
        let len = entry.metadata().unwrap().len();
        total += len;
        files.push(format!("{} {len}", entry.file_name().to_string_lossy()));
    }
    assert!(total <= 10_000_000, "{total} bytes: {files:?}");
    for large in ["colliding_area.stl", "colliding_area.ply", "composite.csv"] {
        assert!(
            !dir.join("kneeform-out").join(large).exists(),
            "{large} written by default"
        );
    }
    assert!(
        dir.join("kneeform-out/composite.csv.gz").is_file(),
        "{files:?}"
    );

    ok(
        kneeform(&dir, &["report", "kneeform-out", "--out", "r.html"]),
        "report after the README's command",
    );
    let html = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(html.contains("id=\"main-view\""));

    // Then the README's evidence, one step after another in the same
    // directory as the first command (issue 39, item 4: none collides with
    // kneeform-out): the analysis with its report, the default
    // verification, a convergence study and the report of all three (issue
    // 24, item 2): the worst rows only, under 5 MB with the 3D view, at
    // most 15 printed pages.
    let analyze = [
        "analyze",
        "scenarios/console_side.stl",
        "--out",
        "console",
        "--report",
    ];
    ok(kneeform(&dir, &analyze), "the evidence's analysis");
    let verify = [
        "verify",
        "scenarios/console_side.stl",
        "--out",
        "console-verify",
    ];
    // The default verification gives a verdict, PASS or FAIL, never
    // INCONCLUSIVE: its starts measure an area.
    let verified = kneeform(&dir, &verify);
    assert!(
        matches!(verified.status.code(), Some(0 | 1)),
        "the default verify: {}",
        stderr(&verified)
    );
    let converge = [
        "converge",
        "scenarios/console_side.stl",
        "--pitches",
        "4.96,2.48,1.24",
        "--angles=-30,0,30",
        "--tolerance",
        "1.754",
        "--out",
        "console-converge",
    ];
    ok(
        kneeform(&dir, &converge),
        "the evidence's convergence study",
    );
    let report = [
        "report",
        "console",
        "console-verify",
        "console-converge",
        "--out",
        "console.html",
    ];
    ok(
        kneeform(&dir, &report),
        "report with the verification and the study",
    );
    // These are the README's evidence commands, word for word
    // (tests/readme.rs accounts for that block by this test).
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    assert!(
        readme.contains("cargo install --path ."),
        "README lacks PATH"
    );
    for args in [&analyze[..], &verify, &converge, &report] {
        let line = format!("kneeform {}", args.join(" "));
        assert!(readme.contains(&line), "README lacks: {line}");
    }
    let size = std::fs::metadata(dir.join("console.html")).unwrap().len();
    assert!(size < 5_000_000, "the report is {size} bytes");
    // 16 since issue 39, item 5: the tables wider than the page (the
    // per-start and convergence tables) made Chromium shrink the whole
    // printout to fit them (13 pages of smaller print, their last columns
    // still cut off); every table now fits, and the report prints at full
    // size.
    if let Some(pages) = crate::util::pdf_pages(&dir.join("console.html"), &dir) {
        assert!(
            (3..=16).contains(&pages),
            "the report prints to {pages} pages"
        );
    }

    // composite.png is cropped to the part: the pale of "no part" is a
    // small share of the image, where the whole grid made it most.
    let pixels =
        Image::decode(&std::fs::read(dir.join("kneeform-out/composite.png")).unwrap()).rgb();
    let no_part = kneeform::output::NO_PART;
    let pale = pixels
        .iter()
        .filter(|p| **p == [no_part.0, no_part.1, no_part.2])
        .count();
    assert!(
        pale * 10 < pixels.len(),
        "{pale} of {} pixels",
        pixels.len()
    );

    if let Some((w, h, shot)) = screenshot(&dir.join("r.html"), &dir) {
        assert_eq!((w, h), (1200, 1600));
        // The main image's border frames a large box holding the grey part
        // and the ramp's colours.
        let [br, bg, bb] = kneeform::report::MAIN_BORDER;
        let near = |a: u8, b: u8| a.abs_diff(b) <= 3;
        let border: Vec<usize> = (0..shot.len())
            .filter(|&k| {
                let [r, g, b] = shot[k];
                near(r, br) && near(g, bg) && near(b, bb)
            })
            .collect();
        assert!(border.len() > 1000, "main image border not found");
        let rows = border.iter().map(|k| k / w);
        let (r0, r1) = (rows.clone().min().unwrap(), rows.max().unwrap());
        let cols = border.iter().map(|k| k % w);
        let (c0, c1) = (cols.clone().min().unwrap(), cols.max().unwrap());
        assert!(
            c1 - c0 > 800 && r1 - r0 > 250,
            "box {c0}..{c1} x {r0}..{r1}"
        );
        let inside: Vec<[u8; 3]> = (r0 + 8..r1 - 8)
            .flat_map(|r| (c0 + 8..c1 - 8).map(move |c| r * w + c))
            .map(|k| shot[k])
            .collect();
        let grey = inside
            .iter()
            .filter(|p| p[0] == p[1] && p[1] == p[2] && p[0] > 60 && p[0] < 250)
            .count();
        let coloured = inside
            .iter()
            .filter(|p| p[0].abs_diff(p[1]) > 30 || p[1].abs_diff(p[2]) > 30)
            .count();
        assert!(grey > inside.len() / 10, "the part is not visible");
        assert!(
            coloured > inside.len() / 10,
            "the struck area is not visible"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn every_real_mesh_and_scenario_analyses_and_reports_at_its_default_pitch() {
    // Default pitch and grid; the angles are cut to -30, 0, 30, which give
    // the same default grid as all 61 (the footprint's extent over
    // -30..30 is reached at the ends).
    let mut parts: Vec<PathBuf> = std::fs::read_dir(repo().join("scenarios"))
        .unwrap()
        .chain(std::fs::read_dir(repo().join("tests/data/meshes")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let ext = p.extension().map(|e| e.to_ascii_lowercase());
            ext.is_some_and(|e| e == "stl" || e == "toml")
        })
        .filter(|p| {
            !p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("empty")
        })
        .collect();
    parts.sort();
    assert!(parts.len() >= 20, "{parts:?}");
    let dir = scratch_dir("every-part");
    for (k, part) in parts.iter().enumerate() {
        let name = part.file_name().unwrap().to_string_lossy().into_owned();
        let out_dir = format!("run-{k}");
        let out = kneeform(
            &dir,
            &[
                "analyze",
                part.to_str().unwrap(),
                "--angles=-30,0,30",
                "--out",
                &out_dir,
                "--report",
            ],
        );
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let summary = read_json(&dir.join(&out_dir).join("summary.json"));
        assert_eq!(summary["pitch_mm"], 1.24, "{name}");
        let html = std::fs::read_to_string(dir.join(&out_dir).join("report.html"))
            .unwrap_or_else(|e| panic!("{name}: no report: {e}"));
        assert!(html.contains("id=\"main-view\""), "{name}");
        // The scenarios are surfaces facing the knee at the right scale:
        // no warning about units or side.
        if part.extension().is_some_and(|e| e == "toml") {
            let w = warnings(&out);
            assert!(
                w.iter().all(|l| !l.contains("--scale 1000")
                    && !l.contains("--side left")
                    && !l.contains("--side right")),
                "{name}: {w:?}"
            );
        }
        std::fs::remove_dir_all(dir.join(&out_dir)).unwrap();
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_summary_written_and_read_back_describes_the_same_grid() {
    // Random pitches (0.05..10 mm) and node indices (+-1e5), seeded: the
    // origin the summary holds, written and parsed as analyze and report
    // do, and a last place off as a less careful parser would read it.
    let dir = scratch_dir("grid-roundtrip");
    step_part(&dir, "part.stl");
    ok(kneeform(&dir, &quick("part.stl", "run", &[])), "analyze");
    let template: Summary =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/summary.json")).unwrap())
            .unwrap();
    for &seed in &SEEDS {
        let mut rng = Rng::new(seed);
        for _ in 0..2000 {
            let pitch = 0.05 + 10.0 * rng.unit();
            let pitch = (pitch * 1000.0).round() / 1000.0;
            let index = |rng: &mut Rng| (rng.unit() * 2e5 - 1e5).round() as i64;
            let spec = kneeform::GridSpec {
                pitch,
                i_origin: index(&mut rng),
                j_origin: index(&mut rng),
                nx: 1 + (rng.unit() * 2000.0) as usize,
                nz: 1 + (rng.unit() * 2000.0) as usize,
            };
            let summary = Summary {
                pitch_mm: spec.pitch,
                grid_origin: [spec.x(0), spec.z(0)],
                grid_size: [spec.nx, spec.nz],
                ..template.clone()
            };
            let text = serde_json::to_string_pretty(&summary).unwrap();
            let back: Summary = serde_json::from_str(&text).unwrap();
            assert_eq!(back.grid_origin, summary.grid_origin, "{spec:?}");
            assert_eq!(kneeform::report::grid_spec(&back), Some(spec), "{spec:?}");
            let sloppy = Summary {
                grid_origin: back.grid_origin.map(|v| f64::from_bits(v.to_bits() ^ 1)),
                ..back
            };
            assert_eq!(kneeform::report::grid_spec(&sloppy), Some(spec), "{spec:?}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_existing_out_is_refused_without_force_and_replaced_whole_with_it() {
    let dir = scratch_dir("force");
    step_part(&dir, "part.stl");
    // A file of an earlier run that this one does not write: it was run
    // with --points-csv.
    ok(
        kneeform(&dir, &quick("part.stl", "run", &["--points-csv"])),
        "first run",
    );
    assert!(dir.join("run/colliding_points.csv").is_file());
    let before = std::fs::read(dir.join("run/summary.json")).unwrap();

    let out = kneeform(&dir, &quick("part.stl", "run", &[]));
    refused(&out, "--force", "second run without --force");
    assert_eq!(std::fs::read(dir.join("run/summary.json")).unwrap(), before);

    ok(
        kneeform(&dir, &quick("part.stl", "run", &["--force"])),
        "--force",
    );
    let files = entries(&dir.join("run"));
    assert!(
        !files.contains(&"colliding_points.csv".to_string()),
        "{files:?}"
    );
    assert!(files.contains(&"summary.json".to_string()), "{files:?}");
    // Nothing staged or set aside is left beside it.
    assert_eq!(entries(&dir), ["part.stl", "run"]);

    // --force never removes a directory that is not a run's.
    std::fs::create_dir(dir.join("photos")).unwrap();
    std::fs::write(dir.join("photos/holiday.jpg"), "jpeg").unwrap();
    let out = kneeform(&dir, &quick("part.stl", "photos", &["--force"]));
    refused(&out, "not a kneeform run directory", "--force on photos");
    assert_eq!(entries(&dir.join("photos")), ["holiday.jpg"]);
    // Nor a run directory holding a file kneeform did not write.
    std::fs::write(dir.join("run/notes.txt"), "mine").unwrap();
    let out = kneeform(&dir, &quick("part.stl", "run", &["--force"]));
    refused(
        &out,
        "notes.txt, which kneeform did not write",
        "--force on notes",
    );
    assert!(dir.join("run/notes.txt").is_file());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_unwritable_out_is_reported_before_the_part_is_even_read() {
    let dir = scratch_dir("unwritable");
    std::fs::write(dir.join("a-file"), "not a directory").unwrap();
    // The part does not exist either: the error is about --out, so --out
    // was checked first.
    let out = kneeform(&dir, &["analyze", "missing.stl", "--out", "a-file/run"]);
    refused(&out, "a-file/run", "--out under a file");
    let out = kneeform(&dir, &["analyze", "missing.stl", "--out", "a-file"]);
    refused(&out, "is a file", "--out is a file");
    assert_eq!(entries(&dir), ["a-file"]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_os_error_is_said_once() {
    let dir = scratch_dir("os-error");
    let out = kneeform(&dir, &["analyze", "missing.stl", "--out", "run"]);
    refused(&out, "missing.stl", "a missing part");
    let text = stderr(&out);
    assert_eq!(text.matches("os error").count(), 1, "{text}");
    let out = kneeform(&dir, &["report", "no-run", "--out", "r.html"]);
    refused(&out, "no-run", "a missing run");
    let text = stderr(&out);
    assert_eq!(text.matches("os error").count(), 1, "{text}");
    assert_eq!(entries(&dir), Vec::<String>::new());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_part_in_metres_is_warned_of_and_its_empty_result_too() {
    let dir = scratch_dir("metres");
    let mm = kneeform::read_part(
        &repo().join("scenarios/console_side.stl"),
        0.001,
        kneeform::Side::Left,
    )
    .unwrap();
    kneeform::output::write_stl(&dir.join("console_m.stl"), &mm.part.triangles).unwrap();
    let out = ok(
        kneeform(&dir, &["analyze", "console_m.stl", "--out", "run"]),
        "a part in metres",
    );
    let w = warnings(&out);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].contains("--scale 1000"), "{w:?}");
    assert!(w[1].contains("no grid node is struck"), "{w:?}");
    let summary = read_json(&dir.join("run/summary.json"));
    assert_eq!(summary["composite_nodes"], 0);
    assert_eq!(summary["warnings"].as_array().unwrap().len(), 2);

    // Read with --scale 1000: no warning, and struck.
    let out = ok(
        kneeform(
            &dir,
            &[
                "analyze",
                "console_m.stl",
                "--scale",
                "1000",
                "--pitch",
                "4",
                "--angles=0",
                "--out",
                "run-mm",
            ],
        ),
        "--scale 1000",
    );
    assert!(warnings(&out).is_empty(), "{}", stderr(&out));
    let summary = read_json(&dir.join("run-mm/summary.json"));
    assert!(summary["composite_nodes"].as_u64().unwrap() > 0);
    assert_eq!(summary["warnings"], Value::Array(Vec::new()));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_surface_facing_plus_y_is_warned_of_unless_side_right() {
    let dir = scratch_dir("facing");
    step_part(&dir, "step.stl");
    // The same part on the vehicle's right, as CAD would export it: mirrored
    // in y, its triangles wound to face +y.
    let part = kneeform::read_part(&dir.join("step.stl"), 1.0, kneeform::Side::Right).unwrap();
    let rewound: Vec<_> = part
        .part
        .triangles
        .iter()
        .map(|&[a, b, c]| [a, c, b])
        .collect();
    kneeform::output::write_stl(&dir.join("right.stl"), &rewound).unwrap();
    let out = ok(kneeform(&dir, &quick("right.stl", "as-left", &[])), "left");
    let w = warnings(&out);
    // Its back face, seen from -y, is a flat plate: nothing struck either.
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("faces +y") && w[0].contains("--side right"),
        "{w:?}"
    );
    assert!(w[1].contains("no grid node is struck"), "{w:?}");
    let out = ok(
        kneeform(&dir, &quick("right.stl", "as-right", &["--side", "right"])),
        "right",
    );
    assert!(warnings(&out).is_empty(), "{}", stderr(&out));
    // And the other way round.
    let out = ok(
        kneeform(&dir, &quick("step.stl", "wrong", &["--side", "right"])),
        "left part read as right",
    );
    assert!(warnings(&out).iter().any(|l| l.contains("--side left")));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn angles_beyond_the_regulation_are_warned_of() {
    let dir = scratch_dir("angles");
    step_part(&dir, "part.stl");
    let out = ok(
        kneeform(
            &dir,
            &[
                "analyze",
                "part.stl",
                "--pitch",
                "4",
                "--angles=-45,0,30,31",
                "--out",
                "run",
            ],
        ),
        "angles",
    );
    let w = warnings(&out);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("-45, 31") && w[0].contains("-30..+30"),
        "{w:?}"
    );
    let out = ok(
        kneeform(&dir, &quick("part.stl", "run-ok", &[])),
        "angles within",
    );
    assert!(warnings(&out).is_empty(), "{}", stderr(&out));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_report_failure_keeps_the_analysis_and_exits_3() {
    // A part piped on stdin is read once by the analysis; the report reads
    // the path again, finds the pipe empty, and cannot draw the part.
    let dir = scratch_dir("report-fails");
    step_part(&dir, "part.stl");
    let bytes = std::fs::read(dir.join("part.stl")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .current_dir(&dir)
        .args(quick("/dev/stdin", "run", &["--report"]))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(&bytes).unwrap();
    let out = child.wait_with_output().unwrap();
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(3), "{text}");
    let errors: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("kneeform: error: "))
        .collect();
    assert_eq!(errors.len(), 1, "{text}");
    assert!(errors[0].contains("kept in run"), "{text}");
    // Every result is there and whole; no report, nothing staged.
    let files = entries(&dir.join("run"));
    for f in [
        "summary.json",
        "composite.csv.gz",
        "depth.png",
        "composite.png",
    ] {
        assert!(files.contains(&f.to_string()), "{f} missing: {files:?}");
    }
    assert!(!files.iter().any(|f| f.contains("report")), "{files:?}");
    assert_eq!(entries(&dir), ["part.stl", "run"]);
    read_json(&dir.join("run/summary.json"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn report_refuses_a_verification_of_another_part_or_setup() {
    let dir = scratch_dir("mismatch");
    step_part(&dir, "part.stl");
    ok(
        kneeform(&dir, &["scenario", "ramp", "--out", "other.stl"]),
        "scenario",
    );
    ok(kneeform(&dir, &quick("part.stl", "run", &[])), "analyze");
    let verify = |part: &str, pitch: &str, out: &str| {
        let args = [
            "verify",
            part,
            "--pitch",
            pitch,
            "--angles=0",
            "--starts",
            "4",
            "--out",
            out,
        ];
        let out = kneeform(&dir, &args);
        // 0 within the tolerance, 1 beyond: both write the files.
        assert!(
            matches!(out.status.code(), Some(0 | 1 | 3)),
            "{}",
            stderr(&out)
        );
    };
    verify("part.stl", "4", "same");
    verify("other.stl", "4", "other-part");
    verify("part.stl", "2", "other-pitch");
    let v = read_json(&dir.join("same/verify.json"));
    let run = read_json(&dir.join("run/summary.json"));
    assert_eq!(v["input_sha256"], run["sha256"]);

    // The matching one is accepted.
    ok(
        kneeform(&dir, &["report", "run", "same", "--out", "ok.html"]),
        "a matching verification",
    );
    // Each mismatch: one line, exit 2, no report written.
    let check = |verify_dir: &str, needle: &str| {
        let out = kneeform(&dir, &["report", "run", verify_dir, "--out", "bad.html"]);
        refused(&out, needle, verify_dir);
        assert!(!dir.join("bad.html").exists(), "{verify_dir}");
    };
    check("other-part", "another part");
    check("other-pitch", "pitch");
    // A different knee-form or strike rule, as if run with other flags.
    for (name, pointer, value, needle) in [
        (
            "other-knee",
            "/knee_form_mm/0",
            Value::from(190.0),
            "knee-form",
        ),
        ("other-side", "/side", Value::from("right"), "side"),
    ] {
        std::fs::create_dir(dir.join(name)).unwrap();
        let mut changed = v.clone();
        *changed.pointer_mut(pointer).unwrap() = value;
        std::fs::write(dir.join(name).join("verify.json"), changed.to_string()).unwrap();
        check(name, needle);
    }
    // The strike rule, whichever keys it has.
    let key = kneeform::report::STRIKE_RULE_KEYS
        .iter()
        .find(|k| v.get(**k).is_some_and(Value::is_number))
        .expect("verify.json records its strike rule");
    std::fs::create_dir(dir.join("other-rule")).unwrap();
    let mut changed = v.clone();
    changed[*key] = Value::from(v[*key].as_f64().unwrap() * 2.0 + 0.25);
    std::fs::write(dir.join("other-rule/verify.json"), changed.to_string()).unwrap();
    check("other-rule", key);
    // A converge study whose ladder misses the run's pitch.
    let converge = kneeform(
        &dir,
        &[
            "converge",
            "part.stl",
            "--pitches",
            "16,8",
            "--angles=0",
            "--starts",
            "3",
            "--out",
            "ladder",
        ],
    );
    assert!(converge.status.success(), "{}", stderr(&converge));
    // Each pitch's per-start rows: a header and one row per start and
    // angle (3 starts, one angle).
    for pitch in [16, 8] {
        let rows = std::fs::read_to_string(dir.join(format!("ladder/verify_{pitch}mm.csv")))
            .expect("the pitch's per-start rows");
        assert_eq!(rows.lines().count(), 1 + 3, "{rows}");
        assert!(rows.starts_with("i,j,angle_deg,status"), "{rows}");
    }
    check("ladder", "pitch ladder");
    std::fs::remove_dir_all(dir).unwrap();
}
