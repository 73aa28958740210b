//! The oracle on real-world STL files (tests/data/meshes): they load and
//! answer, or are refused with a clear error.

use std::path::{Path, PathBuf};

use kneeform_oracle::{
    KneeForm, OracleError, OracleOptions, Part, Side, StartStatus, StartTrace, evaluate,
};

mod util;

fn mesh(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/meshes")).join(name)
}

/// Distance from `(x, z)` to the footprint of `knee` placed at `start`
/// (the distance to the rotated triangle minus R, <= 0 inside),
/// by brute force.
fn footprint_gap(knee: &KneeForm, start: [f64; 2], x: f64, z: f64) -> f64 {
    let p = [x - start[0], z - start[1]];
    let t = knee.triangle();
    let cross =
        |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let s = [cross(t[0], t[1]), cross(t[1], t[2]), cross(t[2], t[0])];
    if s.iter().all(|v| *v >= 0.0) || s.iter().all(|v| *v <= 0.0) {
        return -knee.dims().radius;
    }
    let d = (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let ap = [p[0] - a[0], p[1] - a[1]];
            let u =
                ((ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1])).clamp(0.0, 1.0);
            (ap[0] - u * ab[0]).hypot(ap[1] - u * ab[1])
        })
        .fold(f64::INFINITY, f64::min);
    d - knee.dims().radius
}

/// Whether `(x, z)` lies in the closed footprint.
fn in_footprint(knee: &KneeForm, start: [f64; 2], x: f64, z: f64) -> bool {
    footprint_gap(knee, start, x, z) <= 0.0
}

/// Scales the file to about 600 mm, evaluates a 5 x 4 grid of starts over
/// its xz-extent at three angles, and checks each answer.
fn check(name: &str, side: Side) -> Vec<StartTrace> {
    let part = util::stl_at_size(&mesh(name), 600.0, side).unwrap();
    let (mins, _) = part.bounds();
    let starts = util::starts_over(&part, 5, 4);
    let options = OracleOptions {
        witness_tolerance: 1.0,
        level_step: 5.0,
        x_min: mins[0] - 10.0,
        ..OracleOptions::default()
    };
    let angles = [-30.0, 0.0, 30.0];
    let traces = evaluate(&part, &starts, &angles, &options).unwrap();
    let vertices = part.mesh().vertices();
    for trace in &traces {
        let knee = KneeForm::new(options.knee_form, trace.angle_deg);
        match trace.status {
            StartStatus::Placed => {
                // SPEC's invariant, against the mesh's own vertices: no
                // vertex in the footprint lies below yr*, and one vertex
                // (or a point of a triangle) in it is at yr*.
                let yr = trace.yr_star.unwrap();
                for v in vertices {
                    if in_footprint(&knee, trace.start, v.x, v.z) {
                        assert!(
                            v.y >= yr - 1e-6,
                            "{name}: vertex {v:?} below yr* in {trace:?}"
                        );
                    }
                }
                // The push witness is at yr* (to 1e-5 mm: parry's error grows
                // with coordinates of hundreds of mm; seen 1.4e-6 mm) and in
                // the footprint (to 1e-3 mm along its boundary).
                let w = trace.push_witness.unwrap();
                assert!((w[1] - yr).abs() < 1e-5, "{name}: {trace:?}");
                assert!(
                    footprint_gap(&knee, trace.start, w[0], w[2]) < 1e-3,
                    "{name}: {trace:?}"
                );
                let mut last = (0.0, yr);
                for c in &trace.contacts {
                    assert!(
                        c.travel >= last.0 - 1e-6 && c.face_level <= last.1,
                        "{name}: {c:?} after {last:?} in {:?}",
                        trace.start
                    );
                    assert!(c.witness[0] >= options.x_min, "{name}: {c:?}");
                    last = (c.travel, c.face_level);
                }
            }
            StartStatus::NotPlaced => {
                // Not placed: no vertex at all in the footprint.
                assert!(
                    vertices
                        .iter()
                        .all(|v| !in_footprint(&knee, trace.start, v.x, v.z)),
                    "{name}: {trace:?}"
                );
            }
            StartStatus::Failed { reason } => panic!("{name}: failed ({reason}): {trace:?}"),
        }
    }
    traces
}

#[test]
fn real_meshes_load_and_answer_on_both_sides() {
    for name in [
        "1002_tray_bottom.STL",
        "octagonal_pocket.stl",
        "featuretype.STL",
        "DC-DC_case.stl",
        "busted.STL",
        "soup.stl",
        "multibody.stl",
    ] {
        for side in [Side::Left, Side::Right] {
            let traces = check(name, side);
            let placed = traces
                .iter()
                .filter(|t| t.status == StartStatus::Placed)
                .count();
            assert!(placed > 0, "{name} {side:?}: no start placed");
        }
    }
}

#[test]
fn empty_files_are_refused_with_a_clear_error() {
    for name in ["empty.stl", "empty_ascii.stl", "empty_bin.stl"] {
        let err = Part::from_stl_path(&mesh(name), 1.0, Side::Left).unwrap_err();
        assert!(
            matches!(err, OracleError::NoTriangles { dropped: 0 }),
            "{name}: {err:?}"
        );
        assert_eq!(
            err.to_string(),
            "the part has no triangles (0 degenerate ones dropped)"
        );
    }
}
