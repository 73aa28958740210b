//! Every code block of README.md runs here, or is skipped by name with its
//! reason (issue 24, item 11: the pandas snippet failed on pandas 2 and 3
//! alike, `>>` on a Series, and nothing ran it). A block that no entry of [`ENTRIES`] names
//! fails the test, so a new snippet cannot go untested silently; an entry
//! whose block is gone fails it too.
//!
//! Shell blocks run under `bash -ex` in a scratch directory, with the
//! binary under test first on `PATH` as `kneeform` and the parts they name
//! prepared (small synthetic parts, so that each command takes seconds in
//! the unoptimised test build). Where a README setting would take minutes
//! here, the test runs the block with a named edit (its reason printed);
//! every edit must still match the README's text, so a changed block fails
//! until the test is updated with it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

use kneeform::mesh::Triangle;
use kneeform::output::write_stl;
use kneeform::scenario::{Extent, ScenarioFile, builtin};

use crate::util::scratch_dir;

/// A fenced code block of README.md.
struct Block {
    /// 1-based line of its opening fence.
    line: usize,
    /// The fence's info string (`sh`, `python`, ...).
    lang: String,
    /// The lines between the fences.
    text: String,
}

/// The fenced code blocks of `readme`, in order.
fn blocks(readme: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (n, line) in readme.lines().enumerate() {
        let fence = line.trim_start().strip_prefix("```");
        match (open.take(), fence) {
            (None, Some(lang)) => {
                open = Some(Block {
                    line: n + 1,
                    lang: lang.trim().to_string(),
                    text: String::new(),
                })
            }
            (Some(b), Some(rest)) if rest.trim().is_empty() => out.push(b),
            (Some(mut b), _) => {
                b.text.push_str(line);
                b.text.push('\n');
                open = Some(b);
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "README.md: a code block is never closed");
    out
}

/// How the test accounts for a README block.
enum How {
    /// Run by this function; an error is a reason it could not run here
    /// (a missing interpreter), printed as a skip.
    Run(fn(&Ctx) -> Result<(), String>),
    /// Not run here, for this reason.
    Skip(&'static str),
    /// Written to a file and run by the named entry's block.
    RunBy(&'static str),
}

/// One README block, named by text only it contains.
struct Entry {
    name: &'static str,
    key: &'static str,
    how: How,
}

/// An edit of a block before it runs: `(from, to, why)`; `from` must occur
/// in the block exactly once.
type Edit = (&'static str, &'static str, &'static str);

/// Every README block, each either run or skipped with its reason.
const ENTRIES: &[Entry] = &[
    Entry {
        name: "quick start",
        key: "cargo run --release -- analyze scenarios/console_side.stl",
        how: How::Run(quick_start),
    },
    Entry {
        name: "the evidence",
        key: "kneeform report console console-verify console-converge --out console.html",
        how: How::Skip(
            "run as written, its report printed to PDF (at most 15 pages) and weighed (under \
             5 MB), by tests/first_hour.rs's \
             the_readme_first_command_analyses_and_reports_the_bundled_console",
        ),
    },
    Entry {
        name: "knee-form dimensions",
        key: "--triangle-side 190 --radius 60 --thickness 120",
        how: How::Run(knee_form_dimensions),
    },
    Entry {
        name: "--frame",
        key: "door_left.stl --frame x,-z,y --side right",
        how: How::Run(frames),
    },
    Entry {
        name: "assembly",
        key: "trim.stl bezel.stl switch.stl --ignore seal.stl",
        how: How::Run(assembly),
    },
    Entry {
        name: "--pitch auto",
        key: "--pitch auto --tolerance 1",
        how: How::Run(pitch_auto),
    },
    Entry {
        name: "slide against direct",
        key: "kneeform report slide --compare direct",
        how: How::Run(slide_against_direct),
    },
    Entry {
        name: "direct convergence",
        key: "kneeform converge scenarios/tilted-wave.toml",
        how: How::Run(direct_convergence),
    },
    Entry {
        name: "reading the angle sets",
        key: "import json, pandas as pd",
        how: How::Run(angle_sets),
    },
    Entry {
        name: "analyze --shard",
        key: "--shard 2/4 --out shards/2",
        how: How::Run(analysis_shards),
    },
    Entry {
        name: "verify --shard",
        key: "--starts runs:80:5 --shard 2/4 --out vshards/2",
        how: How::Run(verify_shards),
    },
    Entry {
        name: "converge --shard",
        key: "--shard 3/4 --out dshards/3",
        how: How::Run(converge_shards),
    },
    Entry {
        name: "Slurm script",
        key: "#SBATCH --job-name=kneeform",
        how: How::RunBy("Slurm test-run"),
    },
    Entry {
        name: "Kubernetes Job",
        key: "completionMode: Indexed",
        how: How::Skip(
            "a Kubernetes Indexed Job needs kubectl and a cluster; its container runs \
             the Slurm script's `kneeform analyze --shard` line, which runs here (Slurm test-run)",
        ),
    },
    Entry {
        name: "Slurm test-run",
        key: "SLURM_ARRAY_TASK_ID=$i",
        how: How::Run(slurm_test_run),
    },
    Entry {
        name: "batch manifest",
        key: "[[item]]",
        how: How::Run(batch_manifest),
    },
    Entry {
        name: "fuzzing",
        key: ".ci/fuzz 3600",
        how: How::Skip(
            "cargo-fuzz on a nightly toolchain, minutes to hours per target; its entry \
             points run on stable in tests/fuzz_seeded.rs",
        ),
    },
];

/// What a running block sees: its text, its scratch directory, the other
/// blocks.
struct Ctx<'a> {
    label: String,
    block: &'a Block,
    all: &'a [(&'a Block, &'static Entry)],
    dir: PathBuf,
    bin: &'a Path,
}

impl Ctx<'_> {
    /// The block's text with `edits` applied, each announced with its reason.
    fn edited(&self, edits: &[Edit]) -> String {
        let mut text = self.block.text.clone();
        for &(from, to, why) in edits {
            assert_eq!(
                self.block.text.matches(from).count(),
                1,
                "{}: the test edits `{from}`, which the block no longer holds once: \
                 update tests/readme.rs with the README",
                self.label
            );
            text = text.replacen(from, to, 1);
            eprintln!("{}: ran with `{from}` -> `{to}`: {why}", self.label);
        }
        text
    }

    /// Runs `script` under `bash -ex` in the block's directory with the
    /// binary under test on `PATH`, asserting that it succeeds.
    fn sh(&self, script: &str) -> Output {
        for line in script.lines() {
            assert!(
                !line.trim_start().starts_with("cargo "),
                "{}: would run cargo from a test: {line}",
                self.label
            );
        }
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![self.bin.to_path_buf()];
        paths.extend(std::env::split_paths(&path));
        let out = Command::new("bash")
            .args(["-ex", "-c", script])
            .current_dir(&self.dir)
            .env("PATH", std::env::join_paths(paths).unwrap())
            .env_remove("RUST_BACKTRACE")
            .output()
            .expect("bash runs");
        assert!(
            out.status.success(),
            "{}: {script}\nexit {:?}\nstdout: {}\nstderr: {}",
            self.label,
            out.status.code(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }

    /// The text of the block the entry `name` accounts for.
    fn block_of(&self, name: &str) -> &str {
        let (b, _) = self
            .all
            .iter()
            .find(|(_, e)| e.name == name)
            .unwrap_or_else(|| panic!("no README block is {name:?}"));
        &b.text
    }

    /// Writes `tris` as the STL file `name` in the block's directory.
    fn part(&self, name: &str, tris: &[Triangle]) {
        write_stl(&self.dir.join(name), tris).unwrap();
    }

    /// Links the repository's `scenarios/` into the block's directory, for
    /// the commands that name its files.
    fn scenarios(&self) {
        std::os::unix::fs::symlink(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios"),
            self.dir.join("scenarios"),
        )
        .unwrap();
    }

    /// The JSON file at `path`, relative to the block's directory.
    fn json(&self, path: &str) -> serde_json::Value {
        let text = std::fs::read_to_string(self.dir.join(path))
            .unwrap_or_else(|e| panic!("{}: {path}: {e}", self.label));
        serde_json::from_str(&text).unwrap()
    }
}

/// A built-in scenario cut down to 160 x 100 mm at a 5 mm step: every
/// analysis of it takes a second or two in the test build.
fn small(name: &str) -> Vec<Triangle> {
    ScenarioFile {
        extent: Extent {
            x: [-80.0, 80.0],
            z: [-50.0, 50.0],
            step: 5.0,
        },
        ..builtin(name).unwrap()
    }
    .triangulate(None)
}

/// `tris` under the improper map `f` (a mirror or an axis swap), with the
/// winding reversed so that each triangle still faces the same way.
fn reflected(tris: &[Triangle], f: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<Triangle> {
    tris.iter().map(|t| [f(t[0]), f(t[2]), f(t[1])]).collect()
}

/// The composite's node count in a run's summary.
fn composite_nodes(s: &serde_json::Value) -> u64 {
    s["composite_nodes"].as_u64().expect("composite_nodes")
}

/// Each of `blocks` with the one entry naming it; an error listing every
/// block no entry names, a block two entries name, an entry naming no
/// block or several, or one run by an entry that runs nothing.
fn accounted(blocks: &[Block]) -> Result<Vec<(&Block, &'static Entry)>, String> {
    let mut all = Vec::new();
    let mut wrong = Vec::new();
    for b in blocks {
        let named: Vec<&Entry> = ENTRIES.iter().filter(|e| b.text.contains(e.key)).collect();
        match named[..] {
            [e] => all.push((b, e)),
            [] => wrong.push(format!(
                "README line {} ({}): neither run nor skipped by tests/readme.rs \
                 (add an entry to ENTRIES):\n{}",
                b.line, b.lang, b.text
            )),
            _ => wrong.push(format!(
                "README line {}: named by several entries: {:?}",
                b.line,
                named.iter().map(|e| e.name).collect::<Vec<_>>()
            )),
        }
    }
    for e in ENTRIES {
        let n = blocks.iter().filter(|b| b.text.contains(e.key)).count();
        if n != 1 {
            wrong.push(format!("entry {:?} names {n} README blocks, not 1", e.name));
        }
        if let How::RunBy(by) = e.how
            && !ENTRIES
                .iter()
                .any(|f| f.name == by && matches!(f.how, How::Run(_)))
        {
            wrong.push(format!("{:?} is run by {by:?}, which runs nothing", e.name));
        }
    }
    if wrong.is_empty() {
        Ok(all)
    } else {
        Err(wrong.join("\n"))
    }
}

/// The accounting fails a README with a block no entry names (a new
/// snippet), and one that lost a block an entry names (a stale entry).
#[test]
fn a_readme_block_no_entry_names_fails_the_accounting() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    assert!(accounted(&blocks(&readme)).is_ok());
    let added = format!("{readme}\n```sh\nkneeform frobnicate part.stl\n```\n");
    let err = accounted(&blocks(&added)).err().expect("a new block fails");
    assert!(err.contains("kneeform frobnicate part.stl"), "{err}");
    let fuzz = blocks(&readme)
        .into_iter()
        .find(|b| b.text.contains(".ci/fuzz 3600"))
        .expect("the fuzzing block");
    let dropped = readme.replacen(&fuzz.text, "", 1);
    let err = accounted(&blocks(&dropped))
        .err()
        .expect("a stale entry fails");
    assert!(err.contains("\"fuzzing\" names 0 README blocks"), "{err}");
}

/// Every README block is accounted for ([`accounted`]): run (and its
/// results checked), or skipped by an entry naming it, with the reason
/// printed.
#[test]
fn every_readme_block_runs_or_is_skipped_with_a_reason() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let blocks = blocks(&readme);
    let all = accounted(&blocks).unwrap_or_else(|e| panic!("{e}"));

    let bin = scratch_dir("readme-bin");
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_kneeform"), bin.join("kneeform")).unwrap();
    let start = Instant::now();
    let mut ran = 0;
    for &(block, entry) in &all {
        let label = format!(
            "README block {:?} (line {}, {})",
            entry.name, block.line, block.lang
        );
        match entry.how {
            How::Skip(why) => eprintln!("{label}: skipped: {why}"),
            How::RunBy(by) => eprintln!("{label}: run by the block {by:?}"),
            How::Run(run) => {
                let t = Instant::now();
                let ctx = Ctx {
                    label: label.clone(),
                    block,
                    all: &all,
                    dir: scratch_dir("readme"),
                    bin: &bin,
                };
                let result = run(&ctx);
                std::fs::remove_dir_all(&ctx.dir).unwrap();
                match result {
                    Ok(()) => {
                        ran += 1;
                        eprintln!("{label}: ran in {:.1} s", t.elapsed().as_secs_f64());
                    }
                    Err(why) => eprintln!("{label}: skipped: {why}"),
                }
            }
        }
    }
    std::fs::remove_dir_all(&bin).unwrap();
    eprintln!(
        "README: {} blocks, {ran} run in {:.1} s",
        blocks.len(),
        start.elapsed().as_secs_f64()
    );
}

/// The quick start: the bundled console side at its 61 angles, results in
/// kneeform-out/. (The other line is the test suite itself.)
fn quick_start(ctx: &Ctx) -> Result<(), String> {
    ctx.scenarios();
    ctx.sh(&ctx.edited(&[
        (
            "cargo run --release --",
            "kneeform",
            "the binary under test, built by this `cargo test`",
        ),
        (
            "--out kneeform-out",
            "--out kneeform-out --pitch 4",
            "at 1.24 mm the console takes about 20 s in the unoptimised test build",
        ),
        (
            "cargo test --workspace",
            ": cargo test --workspace",
            "skipped: the test suite itself, this test among it",
        ),
    ]));
    let s = ctx.json("kneeform-out/summary.json");
    assert_eq!(s["angles_deg"].as_array().unwrap().len(), 61, "{s}");
    assert!(composite_nodes(&s) > 0, "{s}");
    for f in ["composite.csv.gz", "depth.png", "composite.png"] {
        assert!(ctx.dir.join("kneeform-out").join(f).is_file(), "{f}");
    }
    Ok(())
}

/// The knee-form's dimensions set on the command line are the ones used
/// and recorded, no longer marked assumed.
fn knee_form_dimensions(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("bump"));
    ctx.sh(&ctx.block.text);
    let s = ctx.json("kneeform-out/summary.json");
    assert_eq!(s["triangle_side_mm"], 190.0, "{s}");
    assert_eq!(s["triangle_side_assumed"], false, "{s}");
    Ok(())
}

/// `--frame`: a y-up file (the bump with y and z swapped, a right-hand
/// part once mirrored) analysed with the README's axes gives the bump's
/// own composite, as the bump through an identity matrix file does.
fn frames(ctx: &Ctx) -> Result<(), String> {
    let bump = small("bump");
    // Vehicle (x, y, z) = (x, -z, y) of the file, then --side right
    // mirrors y: the file's (x, z, y) is the bump's (x, y, z).
    ctx.part("door_left.stl", &reflected(&bump, |[x, y, z]| [x, z, y]));
    ctx.part("bezel.stl", &bump);
    std::fs::write(
        ctx.dir.join("bezel_to_vehicle.txt"),
        "# the identity\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n",
    )
    .unwrap();
    ctx.sh(&ctx.edited(&[(
        "bezel.stl --frame @bezel_to_vehicle.txt --out run ",
        "bezel.stl --frame @bezel_to_vehicle.txt --out run2 ",
        "the two lines are alternatives writing the same --out: the second writes beside",
    )]));
    let (door, bezel) = (ctx.json("run/summary.json"), ctx.json("run2/summary.json"));
    assert!(composite_nodes(&door) > 0, "{door}");
    assert_eq!(
        composite_nodes(&door),
        composite_nodes(&bezel),
        "the y-up file is not analysed as the part it is"
    );
    Ok(())
}

/// An assembly of three files with a fourth ignored: all four are
/// identified in summary.json, the ignored one marked so.
fn assembly(ctx: &Ctx) -> Result<(), String> {
    ctx.part("trim.stl", &small("wave"));
    ctx.part("bezel.stl", &small("bump"));
    ctx.part("switch.stl", &small("switch-boss"));
    // A flat seal 20 mm proud of the others: struck everywhere if it
    // were not ignored.
    let seal: Vec<Triangle> = small("flat-wall")
        .iter()
        .map(|t| t.map(|[x, y, z]| [x, y - 20.0, z]))
        .collect();
    ctx.part("seal.stl", &seal);
    ctx.sh(&ctx.block.text);
    let s = ctx.json("run/summary.json");
    let files = s["files"].as_array().expect("files");
    assert_eq!(files.len(), 4, "{s}");
    let ignored: Vec<_> = files.iter().filter(|f| f["ignored"] == true).collect();
    assert_eq!(ignored.len(), 1, "{s}");
    assert!(
        ignored[0]["path"].as_str().unwrap().ends_with("seal.stl"),
        "{s}"
    );
    Ok(())
}

/// `--pitch auto` at the README's tolerance, on a 10 mm step (the bump's
/// study takes 15-30 s in the test build, the step's a few): the study is
/// recorded and the pitch chosen is one it judged within the tolerance;
/// its message says what it judged and what it only showed (issue 24,
/// item 6: it said "meets the tolerance" beside an 8 mm whole-part change).
fn pitch_auto(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("step"));
    let out = ctx.sh(&ctx.block.text);
    let said = crate::cli::said(&out);
    assert!(
        said.contains("decided exact strike away from flagged blind spots")
            && said.contains("the whole-part change from the coarser pitch is shown, not judged"),
        "{said}"
    );
    let s = ctx.json("run/summary.json");
    let study = s["pitch_study"]["study"].as_array().expect("pitch_study");
    let chosen = study
        .iter()
        .find(|p| p["pitch_mm"] == s["pitch_mm"])
        .unwrap_or_else(|| panic!("the pitch chosen is not in the study: {s}"));
    assert_eq!(chosen["meets"], true, "{s}");
    Ok(())
}

/// Both approaches on the pocket behind a ridge and their comparison, with
/// the README's figures: 675 nodes (10800 mm^2) for push-and-slide, 975
/// (15600 mm^2) for the direct approach.
fn slide_against_direct(ctx: &Ctx) -> Result<(), String> {
    ctx.scenarios();
    ctx.sh(&ctx.block.text);
    for (run, nodes, area) in [("slide", 675, 10800.0), ("direct", 975, 15600.0)] {
        let s = ctx.json(&format!("{run}/summary.json"));
        assert_eq!(composite_nodes(&s), nodes, "{run}");
        assert_eq!(s["composite_area_mm2"].as_f64(), Some(area), "{run}");
    }
    assert!(ctx.dir.join("both.html").is_file());
    Ok(())
}

/// The direct approach's convergence study on the tilted wave, at the
/// README's settings.
fn direct_convergence(ctx: &Ctx) -> Result<(), String> {
    ctx.scenarios();
    ctx.sh(&ctx.block.text);
    let c = ctx.json("tw-direct/converge.json");
    assert!(c.is_object(), "{c}");
    Ok(())
}

/// The pandas snippet, with checks appended: `at_0` is the 0-degree rows
/// of colliding_points.csv, `long` all of them. It runs on the README's
/// console at 61 angles (masks within 64 bits) and on a part at 81 angles
/// (masks past 64 bits, an object column in pandas). Skipped, saying so,
/// where python3 or pandas is missing.
fn angle_sets(ctx: &Ctx) -> Result<(), String> {
    let probe = Command::new("python3")
        .args(["-c", "import pandas; print(pandas.__version__)"])
        .output();
    let version = match probe {
        Err(e) => return Err(format!("python3 does not run: {e}")),
        Ok(o) if !o.status.success() => {
            let err = crate::cli::said(&o);
            let last = err.lines().last().unwrap_or("").to_string();
            return Err(format!("pandas is not importable: {last}"));
        }
        Ok(o) => String::from_utf8_lossy(&o.stdout).trim().to_string(),
    };
    let checks = r#"
pts = pd.read_csv(f"{run}/colliding_points.csv")
assert len(at_0) > 0, "no node struck at 0 deg"
want_0 = pts[pts["angle_deg"] == 0.0]
assert sorted(zip(at_0["i"], at_0["j"])) == sorted(zip(want_0["i"], want_0["j"])), "at_0"
assert len(long) == nodes["angles"].sum() == len(pts), (len(long), len(pts))
got = sorted(zip(long["angle_deg"].astype(float), long["i"], long["j"]))
assert got == sorted(zip(pts["angle_deg"].astype(float), pts["i"], pts["j"])), "long"
print(f"{len(angles)} angles, {len(nodes)} nodes, {len(at_0)} at 0 deg, {len(long)} rows")
"#;
    let script = format!("{}{checks}", ctx.block.text);
    ctx.part("part.stl", &small("bump"));
    ctx.scenarios();
    for (what, args) in [
        (
            "the README's console at 16 mm, 61 angles",
            "scenarios/console_side.stl --pitch 16",
        ),
        (
            "a bump at 81 angles, masks past 64 bits",
            "part.stl --angles=-40:40:1 --force",
        ),
    ] {
        ctx.sh(&format!(
            "kneeform analyze {args} --points-csv --out kneeform-out"
        ));
        let out = Command::new("python3")
            .args(["-c", &script])
            .current_dir(&ctx.dir)
            .output()
            .expect("python3 runs");
        assert!(
            out.status.success(),
            "{}: on {what}, pandas {version}:\n{}",
            ctx.label,
            String::from_utf8_lossy(&out.stderr)
        );
        eprintln!(
            "{}: pandas {version}, {what}: {}",
            ctx.label,
            String::from_utf8_lossy(&out.stdout).trim()
        );
    }
    Ok(())
}

/// Why a shard line runs in a loop.
const EVERY_SHARD: &str =
    "the merge needs all four shards: the README's shard line runs for K = 1..4";

/// `analyze --shard` and `merge`: the merged run has every angle.
fn analysis_shards(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("bump"));
    ctx.sh(&ctx.edited(&[(
        "kneeform analyze part.stl --shard 2/4 --out shards/2",
        "for k in 1 2 3 4; do kneeform analyze part.stl --shard $k/4 --out shards/$k; done",
        EVERY_SHARD,
    )]));
    let s = ctx.json("run/summary.json");
    assert_eq!(s["angles_deg"].as_array().unwrap().len(), 61, "{s}");
    Ok(())
}

/// `verify --shard` and `merge`: the bump passes (exit 0, `pass` in
/// verify.json) on all 8 starts.
fn verify_shards(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("bump"));
    ctx.sh(&ctx.edited(&[
        (
            "kneeform verify",
            "for k in 1 2 3 4; do kneeform verify",
            EVERY_SHARD,
        ),
        (
            "--shard 2/4 --out vshards/2",
            "--shard $k/4 --out vshards/$k; done",
            "(the loop's end)",
        ),
        (
            "--starts runs:80:5",
            "--starts runs:8:5 --angles=-30,0,30",
            "80 runs at 61 angles take minutes per shard in the test build",
        ),
    ]));
    let v = ctx.json("verify/verify.json");
    assert_eq!(
        v["outcome"], "PASS",
        "{}: {}",
        v["verdict"], v["outcome_reason"]
    );
    assert_eq!(v["pass"], true, "{}", v["verdict"]);
    assert_eq!(v["starts"], "runs:8:5", "{}", v["starts"]);
    Ok(())
}

/// `converge --approach direct --shard` and `merge`.
fn converge_shards(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("bump"));
    ctx.sh(&ctx.edited(&[
        (
            "kneeform converge",
            "for k in 1 2 3 4; do kneeform converge",
            EVERY_SHARD,
        ),
        (
            "--shard 3/4 --out dshards/3",
            "--starts 8 --angles=-30,0,30 --shard $k/4 --out dshards/$k; done",
            "(the loop's end) with 8 starts at 3 angles: the defaults take about 15 s \
             for the four shards in the test build",
        ),
    ]));
    let c = ctx.json("converge-direct/converge.json");
    assert!(c.is_object(), "{c}");
    Ok(())
}

/// The README's Slurm script, test-run as the README says: four local
/// processes with the array index set by hand, then the merge.
fn slurm_test_run(ctx: &Ctx) -> Result<(), String> {
    ctx.part("part.stl", &small("bump"));
    std::fs::write(ctx.dir.join("shard.sh"), ctx.block_of("Slurm script")).unwrap();
    ctx.sh(&ctx.block.text);
    let s = ctx.json("run/summary.json");
    assert_eq!(s["angles_deg"].as_array().unwrap().len(), 61, "{s}");
    Ok(())
}

/// The batch manifest, as manifest.toml beside its parts, run by
/// `kneeform batch manifest.toml` (the README's inline command); run
/// again, it skips both items, whose fingerprints match.
fn batch_manifest(ctx: &Ctx) -> Result<(), String> {
    // door_left is a right-hand part (`side = "right"`): the bump mirrored.
    ctx.part(
        "door_left.stl",
        &reflected(&small("bump"), |[x, y, z]| [x, -y, z]),
    );
    ctx.part("trim.stl", &small("wave"));
    ctx.part("bezel.stl", &small("bump"));
    ctx.part("seal.stl", &small("flat-wall"));
    std::fs::write(ctx.dir.join("manifest.toml"), &ctx.block.text).unwrap();
    ctx.sh("kneeform batch manifest.toml");
    for item in ["runs/door_left", "runs/console-d05"] {
        assert!(
            ctx.dir.join(item).join("batch-item.json").is_file(),
            "{item}"
        );
    }
    let door = ctx.json("runs/door_left/summary.json");
    assert!(composite_nodes(&door) > 0, "{door}");
    let again = ctx.sh("kneeform batch manifest.toml");
    let said = crate::cli::said(&again);
    assert!(
        said.contains("skip"),
        "a second batch redid its items: {said}"
    );
    Ok(())
}
