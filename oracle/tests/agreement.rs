//! Issue 26, item 2: the faster tracer gives today's answers. Every cast
//! skips the triangles it cannot meet ([`OracleOptions::prune`], on by
//! default); with the skip off the oracle casts every triangle its BVH
//! traversal hands over, as it did before the skip existed. On every
//! scenario of `scenarios/` and every third-party mesh of
//! `shared/meshes/` that loads, the two give the same traces to the bit:
//! `yr*`, every contact (travel, level, witness, rate and its error), the
//! end, the status and the cast count.

use std::path::{Path, PathBuf};

use kneeform_oracle::{OracleOptions, Part, Side, StartTrace, evaluate};

mod util;

/// The repository's root.
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// 3 x 2 starts over the part's xz-extent, at -30, 0 and 30 degrees, with
/// and without the skip; the traces must be equal.
fn agree(name: &str, part: &Part) -> usize {
    let (mins, _) = part.bounds();
    let starts = util::starts_over(part, 3, 2);
    let angles = [-30.0, 0.0, 30.0];
    // A 4 mm study's bisection: coarse enough to keep the test short,
    // fine enough for hundreds of casts per start.
    let options = OracleOptions {
        witness_tolerance: 0.4,
        x_min: mins[0],
        ..OracleOptions::default()
    };
    let fast = evaluate(part, &starts, &angles, &options).unwrap();
    let all = OracleOptions {
        prune: false,
        ..options
    };
    let slow = evaluate(part, &starts, &angles, &all).unwrap();
    assert_eq!(fast.len(), slow.len());
    for (k, (a, b)) in fast.iter().zip(&slow).enumerate() {
        assert!(
            same(a, b),
            "{name}: start {:?} at {} degrees differs with the skip",
            starts[k % starts.len()],
            angles[k / starts.len()]
        );
    }
    fast.iter().map(|t| t.contacts.len()).sum()
}

/// Equal to the bit: the traces print alike (every float in its shortest
/// round-trip form, `-0.0` apart from `0.0`).
fn same(a: &StartTrace, b: &StartTrace) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

#[test]
fn the_skip_changes_no_trace_on_any_scenario() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "{files:?}");
    let mut contacts = 0;
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if name == "console" {
            // The paper-sized console (370,448 triangles) is the
            // benchmark's; console_side.stl below is the same design.
            continue;
        }
        let read = kneeform::read_part(path, 1.0, kneeform::Side::Left).unwrap();
        let part = Part::from_triangles(&read.part.triangles).unwrap();
        contacts += agree(&name, &part);
    }
    let console =
        Part::from_stl_path(&repo().join("scenarios/console_side.stl"), 1.0, Side::Left).unwrap();
    contacts += agree("console_side", &console);
    assert!(contacts > 1000, "{contacts} contacts compared");
}

#[test]
fn the_skip_changes_no_trace_on_the_real_meshes() {
    let dir = repo().join("../shared/meshes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl")))
        .collect();
    files.sort();
    let mut compared = 0;
    for path in &files {
        // Scaled to about 600 mm, as a user's part (tests/real_meshes.rs).
        let Ok(part) = util::stl_at_size(path, 600.0, Side::Left) else {
            continue; // empty or broken: refused, as real_meshes.rs checks
        };
        agree(&path.display().to_string(), &part);
        compared += 1;
    }
    assert!(compared >= 5, "{compared} meshes compared");
}

/// `evaluate_pairs` traces any subset of `evaluate`'s pairs, in the order
/// asked, each trace the same to the bit (`verify` predicts its time from
/// such a subset, then traces the rest).
#[test]
fn any_pairs_trace_as_the_whole_product_does() {
    let read = kneeform::read_part(
        &repo().join("scenarios/bump.toml"),
        1.0,
        kneeform::Side::Left,
    )
    .unwrap();
    let part = Part::from_triangles(&read.part.triangles).unwrap();
    let starts = util::starts_over(&part, 3, 2);
    let angles = [-30.0, 0.0, 30.0];
    let options = OracleOptions {
        witness_tolerance: 0.4,
        ..OracleOptions::default()
    };
    let all = evaluate(&part, &starts, &angles, &options).unwrap();
    let pairs = [(5, 2), (0, 0), (3, 1), (2, 2), (1, 0)];
    let some =
        kneeform_oracle::evaluate_pairs(&part, &starts, &angles, &pairs, &options, &|| {}).unwrap();
    assert_eq!(some.len(), pairs.len());
    for (trace, &(s, a)) in some.iter().zip(&pairs) {
        assert!(
            same(trace, &all[a * starts.len() + s]),
            "start {s}, angle {a}"
        );
    }
    assert!(some.iter().any(|t| !t.contacts.is_empty()));
    let bad = kneeform_oracle::evaluate_pairs(&part, &starts, &angles, &[(6, 0)], &options, &|| {});
    assert!(bad.is_err(), "a start index beyond the starts given");
}
