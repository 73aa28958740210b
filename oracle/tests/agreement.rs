//! Issue 26, item 2: the faster tracer gives today's answers. Every cast
//! skips the triangles it cannot meet ([`OracleOptions::prune`], on by
//! default); with the skip off the oracle casts every triangle its BVH
//! traversal hands over, as it did before the skip existed. On every
//! scenario of `scenarios/` and every third-party mesh of
//! `tests/data/meshes/` that loads, the two give the same traces to the bit:
//! `yr*`, every contact (travel, level, witness, rate and its error), the
//! end, the status and the cast count.

use std::path::{Path, PathBuf};

use kneeform_oracle::{Chain, ContactPoint, OracleOptions, Part, Side, StartTrace, evaluate};

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

/// Every scenario of `scenarios/` but the paper-sized console (370,448
/// triangles, the benchmark's), and the console side (the same design),
/// by name.
fn scenario_parts() -> Vec<(String, Part)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "{files:?}");
    let mut parts = Vec::new();
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if name == "console" {
            continue;
        }
        let read = kneeform::read_part(path, 1.0, kneeform::Side::Left).unwrap();
        parts.push((name, Part::from_triangles(&read.part.triangles).unwrap()));
    }
    let console =
        Part::from_stl_path(&repo().join("scenarios/console_side.stl"), 1.0, Side::Left).unwrap();
    parts.push(("console_side".into(), console));
    parts
}

/// Every third-party mesh of `tests/data/meshes/` that loads, scaled to about
/// 600 mm as a user's part (`tests/real_meshes.rs`; an empty or broken one
/// is refused, as that file checks), by path.
fn real_mesh_parts() -> Vec<(String, Part)> {
    let dir = repo().join("tests/data/meshes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl")))
        .collect();
    files.sort();
    let parts: Vec<(String, Part)> = files
        .iter()
        .filter_map(|path| {
            let part = util::stl_at_size(path, 600.0, Side::Left).ok()?;
            Some((path.display().to_string(), part))
        })
        .collect();
    assert!(parts.len() >= 5, "{} meshes load", parts.len());
    parts
}

#[test]
fn the_skip_changes_no_trace_on_any_scenario() {
    let contacts: usize = scenario_parts()
        .iter()
        .map(|(name, part)| agree(name, part))
        .sum();
    assert!(contacts > 1000, "{contacts} contacts compared");
}

#[test]
fn the_skip_changes_no_trace_on_the_real_meshes() {
    for (name, part) in real_mesh_parts() {
        agree(&name, &part);
    }
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

/// Starts of two rows of `part` on a lattice of `pitch` (x = `pitch * c`
/// exactly, as a grid's nodes): 3 blocks of 8 consecutive columns each
/// across the middle of the part.
fn rows_over(part: &Part, pitch: f64) -> Vec<[f64; 2]> {
    let (mins, maxs) = part.bounds();
    let first = ((mins[0] + maxs[0]) / 2.0 / pitch).round() as i64 - 12;
    let rows = [0.4, 0.6].map(|t| mins[2] + (maxs[2] - mins[2]) * t);
    rows.iter()
        .flat_map(|&z| (0..24).map(move |k| [pitch * (first + k) as f64, z]))
        .collect()
}

/// How chained traces ([`Chain`]) compare with each start traced alone:
/// the push identical; every contact of either within the witness
/// tolerance (travel and witness) of a contact of the other; and a
/// contact decided on one side (its rate beyond `sigma` by more than its
/// stated error) not decided the other way by a contact within the
/// tolerance. Returns (contacts, casts alone, casts chained).
fn chained_agree(name: &str, part: &Part) -> (usize, usize, usize) {
    let (mins, _) = part.bounds();
    let pitch = 2.0;
    let starts = rows_over(part, pitch);
    let angles = [-30.0, 0.0, 30.0];
    let alone = OracleOptions {
        witness_tolerance: pitch / 10.0,
        x_min: mins[0],
        ..OracleOptions::default()
    };
    let chained = OracleOptions {
        chain: Some(Chain { pitch, block: 8 }),
        ..alone
    };
    let a = evaluate(part, &starts, &angles, &alone).unwrap();
    let b = evaluate(part, &starts, &angles, &chained).unwrap();
    let tol = alone.witness_tolerance + 1e-9;
    let sigma = 0.5f64.to_radians().tan();
    let near = |c: &ContactPoint, e: &ContactPoint| {
        let w: f64 = (0..3).map(|k| (c.witness[k] - e.witness[k]).powi(2)).sum();
        w.sqrt() <= tol && (c.travel - e.travel).abs() <= tol
    };
    let decided = |c: &ContactPoint| (c.rate - sigma).abs() > c.rate_error;
    // A run the tracer does not bisect further: levels (or travels)
    // within its jump tolerance; along a graze (a vertex or edge sliding
    // on the knee-form's flat face), within the oracle's grazing
    // tolerance, a tenth of `eps` (trace.rs): where a graze ends is
    // resolved to no better.
    let run = 0.1 * alone.eps;
    let mut contacts = 0;
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        let at = format!(
            "{name}: start {:?} at {} degrees",
            starts[k % starts.len()],
            angles[k / starts.len()]
        );
        assert_eq!(
            (x.status, x.yr_star, x.push_witness, x.slide_end),
            (y.status, y.yr_star, y.push_witness, y.slide_end),
            "{at}"
        );
        for (p, q) in [(x, y), (y, x)] {
            for c in &p.contacts {
                let close: Vec<&ContactPoint> = q.contacts.iter().filter(|e| near(c, e)).collect();
                if close.is_empty() {
                    // Where the curve runs flat (or rises straight), the
                    // tracer samples only the ends of the run (its levels
                    // or travels closer than `jump_tolerance`: a face or
                    // edge grazing the knee-form's face), so either trace
                    // may hold points along it that the other brackets.
                    let along_run = q.contacts.windows(2).any(|w| {
                        let (lo, hi) = (&w[0], &w[1]);
                        let flat = (lo.face_level - hi.face_level).abs() <= run
                            && (lo.travel - tol..=hi.travel + tol).contains(&c.travel)
                            && (c.face_level - lo.face_level).abs() <= tol;
                        let riser = (hi.travel - lo.travel).abs() <= run
                            && (c.travel - lo.travel).abs() <= tol
                            && (hi.face_level - tol..=lo.face_level + tol).contains(&c.face_level);
                        flat || riser
                    });
                    // The same past the last contact: a graze along a
                    // flat face that either trace may end at a different
                    // point of (the next cast clears it).
                    let past_end = q.contacts.last().is_some_and(|l| {
                        c.travel >= l.travel - tol && (c.face_level - l.face_level).abs() <= run
                    });
                    let before = q.contacts.iter().rev().find(|e| e.travel <= c.travel);
                    let after = q.contacts.iter().find(|e| e.travel > c.travel);
                    assert!(
                        along_run || past_end,
                        "{at}: contact {c:?} of the trace {} is on its curve only (the other's before it: {before:?}, after: {after:?}, end {:?})",
                        if std::ptr::eq(p, x) {
                            "alone"
                        } else {
                            "chained"
                        },
                        q.slide_end
                    );
                    continue;
                }
                if decided(c) {
                    assert!(
                        close
                            .iter()
                            .any(|e| !decided(e) || (e.rate > sigma) == (c.rate > sigma)),
                        "{at}: contact {c:?} decided otherwise by every contact near it: {close:?}"
                    );
                }
            }
        }
        contacts += y.contacts.len();
    }
    let casts = |v: &[StartTrace]| v.iter().map(|t| t.casts).sum::<usize>();
    (contacts, casts(&a), casts(&b))
}

/// Issue 26, items 1 and 2: the starts of a row traced in chains sample
/// the same curves as each start traced alone, within the tolerance, on
/// every scenario and on the console side, for far fewer casts.
#[test]
fn chained_rows_trace_the_curves_of_starts_traced_alone() {
    let (mut contacts, mut alone, mut chained) = (0, 0, 0);
    for (name, part) in scenario_parts() {
        let (n, a, b) = chained_agree(&name, &part);
        contacts += n;
        alone += a;
        chained += b;
    }
    assert!(contacts > 10_000, "{contacts} contacts compared");
    // Shared, not recomputed: blocks of 8 starts cost about one start's
    // casts and seven joins.
    assert!(
        3 * chained < alone,
        "{chained} casts chained, {alone} alone"
    );
}

/// The same on the third-party meshes (open sheets, facets, thin walls).
#[test]
fn chained_rows_trace_the_curves_of_starts_traced_alone_on_real_meshes() {
    for (name, part) in real_mesh_parts() {
        chained_agree(&name, &part);
    }
}

/// A chained start's trace is a function of its block alone: any subset
/// of the pairs (a shard's, or `verify`'s sample that predicts its time)
/// traces each start as the whole does, to the bit.
#[test]
fn chained_traces_do_not_depend_on_the_other_starts_asked_for() {
    let read = kneeform::read_part(
        &repo().join("scenarios/wave.toml"),
        1.0,
        kneeform::Side::Left,
    )
    .unwrap();
    let part = Part::from_triangles(&read.part.triangles).unwrap();
    let starts = rows_over(&part, 2.0);
    let angles = [-30.0, 0.0, 30.0];
    let options = OracleOptions {
        witness_tolerance: 0.2,
        chain: Some(Chain {
            pitch: 2.0,
            block: 8,
        }),
        ..OracleOptions::default()
    };
    let all = evaluate(&part, &starts, &angles, &options).unwrap();
    let pairs = [(30, 2), (5, 0), (13, 1), (47, 2), (8, 0), (9, 0), (23, 1)];
    let some =
        kneeform_oracle::evaluate_pairs(&part, &starts, &angles, &pairs, &options, &|| {}).unwrap();
    for (trace, &(s, a)) in some.iter().zip(&pairs) {
        assert!(
            same(trace, &all[a * starts.len() + s]),
            "start {s}, angle {a}"
        );
    }
    // And a start off the lattice is traced alone.
    let off = [[starts[3][0] + 0.5, starts[3][1]]];
    let alone = OracleOptions {
        chain: None,
        ..options
    };
    assert!(same(
        &evaluate(&part, &off, &[0.0], &options).unwrap()[0],
        &evaluate(&part, &off, &[0.0], &alone).unwrap()[0]
    ));
}
