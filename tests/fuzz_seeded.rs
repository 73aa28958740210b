//! The fuzz targets on stable: the entry points of `tests/fuzz/entry.rs`
//! (what the libFuzzer targets call) on a fixed-seed mutation loop over
//! the scenario files, a few third-party meshes (tests/data/meshes), a summary.json written here,
//! and every committed reproducer in `tests/fuzz/regressions/`. Asserts
//! that nothing panics, not that inputs are accepted; a failure names the
//! target, seed and iteration and writes the input beside the test's
//! scratch files. The long runs are cargo-fuzz's (`.ci/fuzz`).

use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use kneeform::{Analysis, Setup, Side};

use crate::util::{Rng, SEEDS, scratch_dir};

#[path = "fuzz/entry.rs"]
mod entry;

/// Mutated inputs per target and seed: with the four seeds of
/// `util::SEEDS`, 4000 per target: under a second for all three in the
/// test profile.
const ITERATIONS: usize = 1000;

/// The most triangles a mutated scenario is tessellated into here: the
/// test profile is some 10 times slower than the fuzzer's release build,
/// so the seeds are coarsened ([`coarsened`]) to stay below it.
const MAX_TRIANGLES: usize = 20_000;

/// Shared meshes small enough to mutate thousands of times (kB each).
const SHARED_MESHES: [&str; 5] = [
    "soup.stl",
    "multibody.stl",
    "empty_ascii.stl",
    "empty_bin.stl",
    "DC-DC_case.stl",
];

/// Numbers a text mutation writes over a number: the edges of f64 and of
/// the integer types serde reads.
const TEXT_NUMBERS: [&str; 14] = [
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "-0",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "0",
    "-1",
    "4294967295",
    "18446744073709551615",
    "18446744073709551616",
];

/// Values a mutation writes into a binary STL's triangle count (bytes
/// 80..84); `None` stands for the count that matches the file's length.
const STL_COUNTS: [Option<u32>; 6] = [
    Some(0),
    Some(1),
    Some(0xff),
    Some(u32::MAX),
    Some(u32::MAX / 50),
    None,
];

/// f32 bit patterns a mutation writes over a binary STL's coordinate.
const STL_FLOATS: [u32; 5] = [
    0x7f80_0000, // inf
    0xff80_0000, // -inf
    0x7fc0_0000, // NaN
    0x7f7f_ffff, // f32::MAX
    0x0000_0001, // the smallest subnormal
];

/// A target's entry point: whether the library accepted the input.
type Entry = fn(&[u8]) -> bool;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The files of `dir` (none when it is missing), sorted.
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// The committed reproducers of `target`.
fn regressions(target: &str) -> Vec<Vec<u8>> {
    files_in(&repo().join("tests/fuzz/regressions").join(target))
        .iter()
        .map(|p| read(p))
        .collect()
}

/// A scenario file with its lattice step raised to 25 mm, so that its
/// mutants tessellate in the test profile's time.
fn coarsened(text: &str) -> String {
    text.lines()
        .map(|line| match line.trim_start().strip_prefix("step") {
            Some(rest) if rest.trim_start().starts_with('=') => "step = 25".to_string(),
            _ => line.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The seeds of `target`.
fn seeds(target: &str) -> Vec<Vec<u8>> {
    let mut seeds = match target {
        "stl" => {
            let meshes = repo().join("tests/data/meshes");
            let mut seeds: Vec<Vec<u8>> = SHARED_MESHES
                .iter()
                .map(|name| meshes.join(name))
                .filter_map(|path| match std::fs::read(&path) {
                    Ok(bytes) => Some(bytes),
                    Err(e) => {
                        eprintln!("note: seed {} skipped: {e}", path.display());
                        None
                    }
                })
                .collect();
            seeds.push(tiny_binary_stl());
            seeds
        }
        "scenario" => files_in(&repo().join("scenarios"))
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .map(|p| coarsened(&String::from_utf8(read(p)).expect("UTF-8")).into_bytes())
            .collect(),
        "summary" => vec![summary_json()],
        "frame" => [
            "# part to vehicle\n0 1 0 0\n0 0 1 0\n1 0 0 0\n0 0 0 1\n",
            "0.8660254038 0 0.5 250\n0 1 0 -700\n-0.5 0 0.8660254038 410\n",
            "1,0,0,0\n0,-1,0,0\n0,0,-1,0\n0,0,0,1\n",
        ]
        .iter()
        .map(|t| t.as_bytes().to_vec())
        .collect(),
        "shard_json" => vec![shard_json()],
        "study_shard" => study_shards(),
        "manifest" => [
            "[defaults]\npitch = 2\nargs = [\"--report\"]\n\n[[item]]\npart = \"a.stl\"\nout = \"a\"\n\n\
             [[item]]\npart = [\"b.stl\", \"c.stl\"]\nout = \"bc\"\nangles = \"-30:30:10\"\n\
             side = \"right\"\nargs = [\"--frame\", \"@m.txt\"]\n",
            "[[item]]\npart = \"console.stl\"\nout = \"./dd/x\"\npitch = 0.5\n",
        ]
        .iter()
        .map(|t| t.as_bytes().to_vec())
        .collect(),
        _ => unreachable!("no target {target}"),
    };
    seeds.extend(regressions(target));
    seeds
}

/// A binary STL of two triangles: the smallest input that reaches the
/// binary reader's triangle loop.
fn tiny_binary_stl() -> Vec<u8> {
    let triangle: [[f32; 3]; 3] = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 1.0]];
    let mut bytes = vec![0u8; 80];
    bytes.extend(2u32.to_le_bytes());
    for _ in 0..2 {
        bytes.extend([0u8; 12]);
        bytes.extend(triangle.iter().flatten().flat_map(|c| c.to_le_bytes()));
        bytes.extend([0u8; 2]);
    }
    bytes
}

/// The summary.json of a small real run: bump.toml at an 8 mm pitch and
/// three angles.
fn summary_json() -> Vec<u8> {
    let setup = Setup {
        pitch: 8.0,
        angles: vec![-30.0, 0.0, 30.0],
        ..Setup::default()
    };
    let analysis = Analysis::of_file(
        &repo().join("scenarios/bump.toml"),
        1.0,
        Side::Left,
        &setup,
        &(),
    )
    .expect("bump.toml analyses");
    serde_json::to_vec_pretty(&analysis.summary()).expect("a summary serialises")
}

/// The `shard.json` of shard 1 of 2 of a small real run: bump.toml at an
/// 8 mm pitch and three angles.
fn shard_json() -> Vec<u8> {
    let out = scratch_dir("fuzz-shard-seed").join("shard");
    let o = crate::cli::kneeform(&[
        "analyze",
        repo().join("scenarios/bump.toml").to_str().unwrap(),
        "--pitch",
        "8",
        "--angles=-30,0,30",
        "--shard",
        "1/2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    read(&out.join("shard.json"))
}

/// Study shards as `entry::study_shard` reads them (`shard.json`, a NUL
/// byte, `shard.bin`): shard 1 of 2 of a small verification (bump.toml,
/// 8 mm, three angles, 4 starts) and of a small convergence study
/// (step.toml, 8 and 4 mm, one angle, 3 starts).
fn study_shards() -> Vec<Vec<u8>> {
    let dir = scratch_dir("fuzz-study-seed");
    let runs: [(&str, &str, &[&str]); 2] = [
        (
            "verify",
            "bump",
            &["--pitch", "8", "--angles=-30,0,30", "--starts", "4"],
        ),
        (
            "converge",
            "step",
            &["--pitches", "8,4", "--angles=0", "--starts", "3"],
        ),
    ];
    runs.iter()
        .map(|(command, part, extra)| {
            let out = dir.join(command);
            let part = repo().join(format!("scenarios/{part}.toml"));
            let mut args = vec![*command, part.to_str().unwrap()];
            args.extend_from_slice(extra);
            args.extend(["--shard", "1/2", "--out", out.to_str().unwrap()]);
            let o = crate::cli::kneeform(&args);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let mut input = read(&out.join("shard.json"));
            input.push(entry::STUDY_SHARD_SEPARATOR);
            input.extend(read(&out.join("shard.bin")));
            // Unmutated, the seed is a shard merge accepts.
            assert!(entry::study_shard(&input), "{command}'s shard is refused");
            input
        })
        .collect()
}

/// A small random number below `n` (`n > 0`).
fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

/// One random edit of `input`; `seeds` are what a splice takes from.
fn mutate(rng: &mut Rng, input: &mut Vec<u8>, seeds: &[Vec<u8>]) {
    match below(rng, 8) {
        // A bit flip.
        0 if !input.is_empty() => {
            let at = below(rng, input.len());
            input[at] ^= 1 << below(rng, 8);
        }
        // A byte inserted: random, or one of 0x00, 0xff, newline, quote.
        1 => {
            let at = below(rng, input.len() + 1);
            let byte = [0x00, 0xff, b'\n', b'"', rng.next_u64() as u8][below(rng, 5)];
            input.insert(at, byte);
        }
        // A run of up to 16 bytes deleted.
        2 if !input.is_empty() => {
            let at = below(rng, input.len());
            let end = (at + 1 + below(rng, 16)).min(input.len());
            input.drain(at..end);
        }
        // A splice: this input's head on another seed's tail.
        3 => {
            let other = &seeds[below(rng, seeds.len())];
            let head = below(rng, input.len() + 1);
            let tail = below(rng, other.len() + 1);
            input.truncate(head);
            input.extend_from_slice(&other[tail..]);
        }
        // A number in text replaced by an extreme one.
        4 | 5 => replace_number(rng, input),
        // A binary STL's triangle count.
        6 if input.len() >= 84 => {
            let count = STL_COUNTS[below(rng, STL_COUNTS.len())]
                .unwrap_or(((input.len() - 84) / 50) as u32);
            input[80..84].copy_from_slice(&count.to_le_bytes());
        }
        // A binary STL's coordinate (any aligned f32 after the header).
        7 if input.len() >= 88 => {
            let at = 84 + 4 * below(rng, (input.len() - 84) / 4);
            let bits = STL_FLOATS[below(rng, STL_FLOATS.len())];
            input[at..at + 4].copy_from_slice(&bits.to_le_bytes());
        }
        _ => {
            let at = below(rng, input.len() + 1);
            input.truncate(at);
        }
    }
}

/// Replaces the number (a run of digits, signs, dots and exponents)
/// starting at or after a random place in `input` by one of
/// [`TEXT_NUMBERS`]; leaves `input` alone when no number follows.
fn replace_number(rng: &mut Rng, input: &mut Vec<u8>) {
    let from = below(rng, input.len() + 1);
    let Some(start) = input[from..]
        .iter()
        .position(u8::is_ascii_digit)
        .map(|i| from + i)
    else {
        return;
    };
    let number = |b: &u8| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-');
    let start = input[..start]
        .iter()
        .rposition(|b| !number(b))
        .map_or(0, |i| i + 1);
    let end = input[start..]
        .iter()
        .position(|b| !number(b))
        .map_or(input.len(), |i| start + i);
    let replacement = TEXT_NUMBERS[below(rng, TEXT_NUMBERS.len())].as_bytes();
    input.splice(start..end, replacement.iter().copied());
}

/// Runs `entry` on [`ITERATIONS`] mutants of `seeds` per seed of
/// `util::SEEDS`; panics naming the target, seed and iteration of the
/// first input that panicked, written to a scratch file. Also fails when
/// the mutants were all refused or all accepted: the loop must reach both
/// the library's checks and what lies past them.
fn mutation_loop(target: &str, seeds: &[Vec<u8>], entry: impl Fn(&[u8]) -> bool) {
    assert!(!seeds.is_empty(), "{target}: no seeds");
    let mut accepted = 0;
    for seed in SEEDS {
        let mut rng = Rng::new(seed);
        for iteration in 0..ITERATIONS {
            let mut input = seeds[below(&mut rng, seeds.len())].clone();
            for _ in 0..1 + below(&mut rng, 4) {
                mutate(&mut rng, &mut input, seeds);
            }
            match panic::catch_unwind(AssertUnwindSafe(|| entry(&input))) {
                Ok(true) => accepted += 1,
                Ok(false) => {}
                Err(_) => {
                    let path = scratch_dir("fuzz").join(format!("{target}-{seed:#x}-{iteration}"));
                    std::fs::write(&path, &input).expect("the input is written");
                    panic!(
                        "{target}: seed {seed:#x}, iteration {iteration} panicked; input in {}",
                        path.display()
                    );
                }
            }
        }
    }
    let total = SEEDS.len() * ITERATIONS;
    eprintln!("{target}: {accepted} of {total} mutants accepted");
    assert!(
        0 < accepted && accepted < total,
        "{target}: {accepted} of {total} mutants accepted"
    );
}

#[test]
fn stl_mutants_do_not_panic() {
    mutation_loop("stl", &seeds("stl"), entry::stl);
}

#[test]
fn scenario_mutants_do_not_panic() {
    mutation_loop("scenario", &seeds("scenario"), |data| {
        entry::scenario(data, MAX_TRIANGLES)
    });
}

#[test]
fn summary_mutants_do_not_panic() {
    mutation_loop("summary", &seeds("summary"), entry::summary);
}

#[test]
fn frame_mutants_do_not_panic() {
    mutation_loop("frame", &seeds("frame"), entry::frame);
}

#[test]
fn shard_json_mutants_do_not_panic() {
    mutation_loop("shard_json", &seeds("shard_json"), entry::shard_json);
}

#[test]
fn study_shard_mutants_do_not_panic() {
    mutation_loop("study_shard", &seeds("study_shard"), entry::study_shard);
}

#[test]
fn manifest_mutants_do_not_panic() {
    mutation_loop("manifest", &seeds("manifest"), entry::manifest);
}

/// Every committed reproducer, as it was found (unmutated), through the
/// target that found it, at the fuzzer's own triangle bound; issue 14's
/// hostile inputs (`issue14-*`) must also be refused.
#[test]
fn regressions_do_not_panic() {
    let targets: [(&str, Entry); 3] = [
        ("stl", entry::stl),
        ("scenario", |data| {
            entry::scenario(data, entry::FUZZ_MAX_TRIANGLES)
        }),
        ("summary", entry::summary),
    ];
    for (target, entry) in targets {
        let files = files_in(&repo().join("tests/fuzz/regressions").join(target));
        assert!(!files.is_empty(), "{target}: no regressions");
        for file in files {
            let accepted = entry(&read(&file));
            let hostile = file
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("issue14-"));
            assert!(!(hostile && accepted), "{} was accepted", file.display());
        }
    }
}
