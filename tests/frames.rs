//! Parts in other coordinates (`--frame`) and assemblies (several files,
//! `--ignore`), end to end through the binary.
//!
//! The frames here are axis permutations with signs: rotating a part by one
//! and back is exact in floating point, so the framed run must give the
//! original's result node for node, to the bit, not within a tolerance.

use std::path::Path;

use kneeform::input::sha256_hex;
use kneeform::mesh::Triangle;
use kneeform::output::write_stl;
use kneeform::summary::Summary;
use kneeform::{HeightGrid, Side};

use crate::cli::{analyse_to, assert_clean_failure, asymmetric_part, csv_rows, kneeform, mirrored};
use crate::util::scratch_dir;

/// `triangles` mapped vertex by vertex.
fn mapped(triangles: &[Triangle], map: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<Triangle> {
    triangles.iter().map(|t| t.map(&map)).collect()
}

fn summary(dir: &Path) -> Summary {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Asserts that `framed`'s rows of `file` are `original`'s, row for row,
/// with the point in columns `xyz` mapped by `to_part` and every other
/// field the same text.
fn assert_same_nodes(
    original: &Path,
    framed: &Path,
    file: &str,
    xyz: [usize; 3],
    to_part: &dyn Fn([f64; 3]) -> [f64; 3],
) {
    let a = csv_rows(&original.join(file));
    let b = csv_rows(&framed.join(file));
    assert!(a.len() > 20, "{file}: too few rows to prove anything");
    assert_eq!(a.len(), b.len(), "{file}");
    let num = |r: &[String], k: usize| r[k].parse::<f64>().unwrap();
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!(ra.len(), rb.len(), "{file}");
        for k in (0..ra.len()).filter(|k| !xyz.contains(k)) {
            assert_eq!(ra[k], rb[k], "{file}: {ra:?} vs {rb:?}");
        }
        let p = to_part(xyz.map(|k| num(ra, k)));
        assert_eq!(p, xyz.map(|k| num(rb, k)), "{file}: {ra:?} vs {rb:?}");
    }
}

/// The colliding area's triangles, vertices as written (f32).
fn stl_triangles(path: &Path) -> Vec<[[f32; 3]; 3]> {
    let mut file = std::fs::File::open(path).unwrap();
    stl_io::create_stl_reader(&mut file)
        .unwrap()
        .map(|t| t.unwrap().vertices.map(|v| [v[0], v[1], v[2]]))
        .collect()
}

/// One door panel: `vehicle` (vehicle coordinates, analysed with `side`)
/// written as the CAD tool's file, `to_part` applied, and analysed with
/// the matching `frame`; the framed run must be the original's, mapped
/// back, node for node, in every table and the colliding area's surface.
fn door_panel(
    name: &str,
    vehicle: &[Triangle],
    side: &str,
    frame: &str,
    to_part: &dyn Fn([f64; 3]) -> [f64; 3],
) {
    let scratch = scratch_dir(name);
    let (v_path, p_path) = (scratch.join("vehicle.stl"), scratch.join("part.stl"));
    write_stl(&v_path, vehicle).unwrap();
    let part = mapped(vehicle, to_part);
    write_stl(&p_path, &part).unwrap();
    let (v_run, p_run) = (scratch.join("v"), scratch.join("p"));
    analyse_to(&v_path, &v_run, &["--side", side, "--points-csv", "--stl"]);
    analyse_to(
        &p_path,
        &p_run,
        &["--side", side, "--frame", frame, "--points-csv", "--stl"],
    );
    assert_same_nodes(&v_run, &p_run, "colliding_points.csv", [3, 4, 5], to_part);
    assert_same_nodes(&v_run, &p_run, "composite.csv", [2, 3, 4], to_part);
    let (a, b) = (
        stl_triangles(&v_run.join("colliding_area.stl")),
        stl_triangles(&p_run.join("colliding_area.stl")),
    );
    assert!(a.len() > 20);
    let to_part_f32 = |v: [f32; 3]| to_part(v.map(f64::from)).map(|c| c as f32);
    assert_eq!(a.iter().map(|t| t.map(to_part_f32)).collect::<Vec<_>>(), b);
    // The summary records the frame, and its bounding box is the file's.
    let (sv, sp) = (summary(&v_run), summary(&p_run));
    assert!(sv.frame.is_none());
    assert_eq!(sp.frame.as_ref().map(|f| f.given.as_str()), Some(frame));
    assert_eq!(sv.composite_nodes, sp.composite_nodes);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in part.iter().flatten() {
        for k in 0..3 {
            let c = v[k] as f32 as f64;
            lo[k] = lo[k].min(c);
            hi[k] = hi[k].max(c);
        }
    }
    // As summary.json writes its figures: without a double's noise.
    let written = |v: [f64; 3]| v.map(kneeform::output::rounded_figure);
    assert_eq!((sp.bbox_min, sp.bbox_max), (written(lo), written(hi)));
    // The report re-reads the file, finds every CSV node on the run's grid
    // through the frame, and draws the part in vehicle coordinates: the
    // same pictures as the vehicle file's.
    let page = |run: &Path| {
        let html = run.join("report.html");
        let result = kneeform(&[
            "report",
            run.to_str().unwrap(),
            "--out",
            html.to_str().unwrap(),
        ]);
        assert!(
            result.status.success(),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
        std::fs::read_to_string(html).unwrap()
    };
    let (pv, pp) = (page(&v_run), page(&p_run));
    assert!(pp.contains("Frame (--frame)") && !pv.contains("Frame (--frame)"));
    let views = |page: &str| -> Vec<String> {
        page.split("data:image/png;base64,")
            .skip(1)
            .take(2)
            .map(|s| s.split('"').next().unwrap().to_string())
            .collect()
    };
    assert_eq!(views(&pv).len(), 2);
    assert!(views(&pv) == views(&pp), "the report's views differ");
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// A door panel of the vehicle's left side faces +y, inwards, where the
/// driver's knee is: SPEC's `--side right`. Its CAD file is y-up (vehicle
/// z is the file's y, vehicle y its -z): `--frame x,-z,y`.
#[test]
fn a_left_door_panel_in_a_y_up_file_gives_the_vehicle_result_mapped_back() {
    let vehicle = mirrored(&asymmetric_part(), 1);
    // Vehicle (x, y, z) = part (x, -z, y), so part = (x, z, -y).
    door_panel("left-door", &vehicle, "right", "x,-z,y", &|[x, y, z]| {
        [x, z, -y]
    });
}

/// A right door panel faces -y, inwards: `--side left`. Its file's axes
/// are a cyclic turn of the vehicle's, given as a 4x4 matrix file.
#[test]
fn a_right_door_panel_with_a_matrix_frame_gives_the_vehicle_result_mapped_back() {
    let scratch = scratch_dir("right-door-matrix");
    let matrix = scratch.join("part_to_vehicle.txt");
    // Vehicle x = part y, vehicle y = part z, vehicle z = part x.
    std::fs::write(
        &matrix,
        "# part to vehicle\n0 1 0 0\n0 0 1 0\n1 0 0 0\n0 0 0 1\n",
    )
    .unwrap();
    let frame = format!("@{}", matrix.display());
    door_panel("right-door", &asymmetric_part(), "left", &frame, &|[
        x,
        y,
        z,
    ]| {
        [z, x, y]
    });
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// A frame that is no permutation: a part turned 30 degrees about the
/// vehicle's y axis and shifted, its matrix written to ten digits
/// (orthonormal within 1e-9 only) and the file in f32, so the framed
/// analysis sees the part moved by up to about 3e-5 mm. Node for node
/// equality cannot be asked here: on these extruded test parts many nodes
/// tie exactly, and a move of one f32 unit breaks the ties (measured: the
/// vehicle file itself with +-1e-5 mm of noise on its vertices changes 300
/// of its 1175 composite nodes). What must hold: every colliding node of
/// the framed run, mapped through the frame, is a node of the vehicle
/// run's grid at the vehicle file's height there (within the f32 moves),
/// most of the area is shared, and the report finds every node of the
/// run's CSV files on its grid through the frame.
#[test]
fn a_turned_part_with_a_ten_digit_matrix_lies_on_the_vehicle_result() {
    let scratch = scratch_dir("turned");
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let matrix = scratch.join("turn.txt");
    // Part to vehicle: a turn about y, and a shift (mm).
    std::fs::write(
        &matrix,
        format!(
            "{c:.10} 0 {s:.10} 250\n0 1 0 -700\n{:.10} 0 {c:.10} 410\n0 0 0 1\n",
            -s
        ),
    )
    .unwrap();
    let frame_arg = format!("@{}", matrix.display());
    let frame = kneeform::Frame::parse(&frame_arg).unwrap();
    let vehicle = asymmetric_part();
    let (v_path, p_path) = (scratch.join("vehicle.stl"), scratch.join("part.stl"));
    write_stl(&v_path, &vehicle).unwrap();
    write_stl(&p_path, &mapped(&vehicle, |v| frame.to_part(v))).unwrap();
    let (v_run, p_run) = (scratch.join("v"), scratch.join("p"));
    analyse_to(&v_path, &v_run, &[]);
    analyse_to(&p_path, &p_run, &["--frame", &frame_arg]);
    // Nodes by their vehicle x, z in pitches, with their vehicle y.
    let nodes = |run: &Path, to_vehicle: &dyn Fn([f64; 3]) -> [f64; 3]| {
        csv_rows(&run.join("composite.csv"))
            .into_iter()
            .map(|r| {
                let [x, y, z] = to_vehicle([2, 3, 4].map(|k| r[k].parse::<f64>().unwrap()));
                let key = [x, z].map(|c| (c / 2.5).round());
                // Rounded to 1 um in the part's frame, then rotated.
                assert!(
                    (x - 2.5 * key[0]).abs() < 1e-3 && (z - 2.5 * key[1]).abs() < 1e-3,
                    "({x}, {z}) is no grid node"
                );
                ((key[0] as i64, key[1] as i64), y)
            })
            .collect::<std::collections::BTreeMap<_, _>>()
    };
    let a = nodes(&v_run, &|v| v);
    let b = nodes(&p_run, &|p| frame.to_vehicle(p));
    let mut shared = 0;
    for (key, y) in &b {
        if let Some(y0) = a.get(key) {
            // 1e-3 between the two samplings, and composite.csv's rounding
            // to 1 um (up to 0.87 um through the rotation).
            assert!((y - y0).abs() < 2e-3, "node {key:?}: y {y} vs {y0}");
            shared += 1;
        }
    }
    assert!(a.len() > 100, "{}", a.len());
    assert!(
        shared * 4 >= a.len() * 3 && shared * 4 >= b.len() * 3,
        "{shared} shared of {} and {}",
        a.len(),
        b.len()
    );
    let html = scratch.join("report.html");
    let result = kneeform(&[
        "report",
        p_run.to_str().unwrap(),
        "--out",
        html.to_str().unwrap(),
    ]);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// `verify` takes `--frame` too: the framed part's comparison is the
/// original's, and verify.json records the frame.
#[test]
fn verify_of_a_framed_part_is_the_original_s() {
    let scratch = scratch_dir("verify-frame");
    let vehicle = asymmetric_part();
    let (v_path, p_path) = (scratch.join("vehicle.stl"), scratch.join("part.stl"));
    write_stl(&v_path, &vehicle).unwrap();
    write_stl(&p_path, &mapped(&vehicle, |[x, y, z]| [x, z, -y])).unwrap();
    let verify = |part: &Path, out: &str, extra: &[&str]| {
        let mut args = vec![
            "verify",
            part.to_str().unwrap(),
            "--pitch",
            "4",
            "--angles=-12,12",
            "--starts",
            "6",
            "--tolerance",
            "1000",
        ];
        args.extend_from_slice(extra);
        let out = scratch.join(out);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let result = kneeform(&args);
        // Six scattered starts measure no area: INCONCLUSIVE (exit 3), a
        // study written all the same.
        assert!(
            matches!(result.status.code(), Some(0 | 3)),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
        out
    };
    let a = verify(&v_path, "v", &[]);
    let b = verify(&p_path, "p", &["--frame", "x,-z,y"]);
    let rows = std::fs::read_to_string(a.join("verify.csv")).unwrap();
    assert!(rows.lines().count() > 6, "{rows}");
    assert_eq!(rows, std::fs::read_to_string(b.join("verify.csv")).unwrap());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(b.join("verify.json")).unwrap()).unwrap();
    assert_eq!(json["frame"]["given"], "x,-z,y");
    std::fs::remove_dir_all(&scratch).unwrap();
}

#[test]
fn bad_frames_get_one_line_and_exit_2() {
    let scratch = scratch_dir("bad-frame");
    let part = scratch.join("part.stl");
    write_stl(&part, &asymmetric_part()).unwrap();
    let shear = scratch.join("shear.txt");
    std::fs::write(&shear, "1 0.5 0 0\n0 1 0 0\n0 0 1 0\n").unwrap();
    let short = scratch.join("short.txt");
    std::fs::write(&short, "1 0 0\n0 1 0\n0 0 1\n").unwrap();
    let out = scratch.join("out");
    let (p, o) = (part.to_str().unwrap(), out.to_str().unwrap());
    let at = |path: &Path| format!("@{}", path.display());
    let missing = at(&scratch.join("missing.txt"));
    let (shear, short) = (at(&shear), at(&short));
    let cases: [(&str, &str); 7] = [
        ("a mirror", "x,y,-z"),
        ("a repeated axis", "x,-x,z"),
        ("not axes", "x,up,z"),
        ("two axes", "x,y"),
        ("an unreadable file", &missing),
        ("a shear", &shear),
        ("a 3x3 matrix", &short),
    ];
    for (what, frame) in cases {
        let result = kneeform(&["analyze", p, "--out", o, "--frame", frame]);
        assert_clean_failure(&result, &out, what);
        let stderr = crate::cli::said(&result);
        assert!(stderr.contains("--frame"), "{what}: {stderr}");
    }
    // verify and converge check it the same way, before any work.
    for command in ["verify", "converge"] {
        let result = kneeform(&[command, p, "--out", o, "--frame", "x,y,-z"]);
        assert_clean_failure(&result, &out, command);
    }
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// Two files: the asymmetric part, and a second part standing proud of a
/// band of it (so the knee strikes both), which also repeats a band of the
/// first exactly (ties, which the first file must win).
fn two_files() -> (Vec<Triangle>, Vec<Triangle>) {
    let a = asymmetric_part();
    let centre_x = |t: &Triangle| (t[0][0] + t[1][0] + t[2][0]) / 3.0;
    let proud = a
        .iter()
        .filter(|t| (-40.0..40.0).contains(&centre_x(t)))
        .map(|t| t.map(|[x, y, z]| [x, y - 3.0, z]));
    let same = a
        .iter()
        .filter(|t| (60.0..100.0).contains(&centre_x(t)))
        .copied();
    let b = proud.chain(same).collect();
    (a, b)
}

/// An assembly of two files gives the union area of one merged file, node
/// for node, and names for each node the file whose surface set its
/// height: checked against each file's own height grid.
#[test]
fn an_assembly_is_the_merged_part_with_each_node_attributed_to_its_file() {
    let scratch = scratch_dir("assembly");
    let (a, b) = two_files();
    let (a_path, b_path, merged) = (
        scratch.join("a.stl"),
        scratch.join("b.stl"),
        scratch.join("merged.stl"),
    );
    write_stl(&a_path, &a).unwrap();
    write_stl(&b_path, &b).unwrap();
    write_stl(&merged, &[a.clone(), b.clone()].concat()).unwrap();
    let (two, one) = (scratch.join("two"), scratch.join("one"));
    analyse_to(&a_path, &two, &[b_path.to_str().unwrap(), "--points-csv"]);
    analyse_to(&merged, &one, &["--points-csv"]);

    // The same nodes: the merged file's rows, and a last column `file`.
    for file in ["colliding_points.csv", "composite.csv"] {
        let (rows_two, rows_one) = (csv_rows(&two.join(file)), csv_rows(&one.join(file)));
        assert!(rows_one.len() > 20, "{file}");
        assert_eq!(rows_two.len(), rows_one.len(), "{file}");
        for (r2, r1) in rows_two.iter().zip(&rows_one) {
            assert_eq!(r2[..r2.len() - 1], r1[..], "{file}");
        }
    }
    let (s2, s1) = (summary(&two), summary(&one));
    assert_eq!(s2.composite_area_mm2, s1.composite_area_mm2);
    assert!(s1.files.is_empty());

    // Each node's file: the lower of the two files' own heights there,
    // the first file on a tie.
    let spec = kneeform::report::grid_spec(&s2).unwrap();
    let read = |p: &Path| {
        kneeform::read_part(p, 1.0, Side::Left)
            .unwrap()
            .part
            .triangles
    };
    let (ga, gb) = (
        HeightGrid::sample(&read(&a_path), spec),
        HeightGrid::sample(&read(&b_path), spec),
    );
    let mut per_file = [0usize; 2];
    let mut ties = 0;
    for r in csv_rows(&two.join("composite.csv")) {
        let (i, j): (usize, usize) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        let (ha, hb) = (ga.at(i, j), gb.at(i, j));
        let want = usize::from(hb < ha);
        assert_eq!(r[7], want.to_string(), "node ({i}, {j}): a {ha}, b {hb}");
        assert_eq!(r[3], kneeform::output::micrometres(ha.min(hb)));
        per_file[want] += 1;
        ties += usize::from(ha == hb);
    }
    assert!(per_file[0] > 0 && per_file[1] > 0, "{per_file:?}");
    assert!(
        ties > 0,
        "no tie among the colliding nodes: the rule is untested"
    );

    // The summary: every file's path, SHA-256 and its share of the area.
    assert_eq!(s2.files.len(), 2);
    for (k, (f, path)) in s2.files.iter().zip([&a_path, &b_path]).enumerate() {
        assert_eq!(f.path, path.display().to_string());
        assert_eq!(f.sha256, sha256_hex(&std::fs::read(path).unwrap()));
        assert!(!f.ignored);
        assert_eq!(f.colliding_nodes, per_file[k]);
        assert_eq!(f.colliding_area_mm2, per_file[k] as f64 * 2.5 * 2.5);
    }
    assert_eq!(per_file.iter().sum::<usize>(), s2.composite_nodes);

    // The report finds both files by their SHA-256 and lists their areas.
    let html = scratch.join("report.html");
    let result = kneeform(&[
        "report",
        two.to_str().unwrap(),
        "--out",
        html.to_str().unwrap(),
    ]);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let page = std::fs::read_to_string(&html).unwrap();
    for f in &s2.files {
        assert!(page.contains(&f.sha256), "{} not in the report", f.path);
    }
    assert!(page.contains("data-src=\"summary.json#/files/1/colliding_area_mm2\""));
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// A file the regulation disregards is identified but not analysed: the
/// result is the other file's alone.
#[test]
fn an_ignored_file_is_recorded_and_kept_out_of_the_grid() {
    let scratch = scratch_dir("ignore");
    let (a, b) = two_files();
    let (a_path, b_path) = (scratch.join("a.stl"), scratch.join("b.stl"));
    write_stl(&a_path, &a).unwrap();
    write_stl(&b_path, &b).unwrap();
    let (alone, ignoring) = (scratch.join("alone"), scratch.join("ignoring"));
    analyse_to(&a_path, &alone, &[]);
    let b_arg = b_path.to_str().unwrap();
    analyse_to(&a_path, &ignoring, &[b_arg, "--ignore", b_arg]);
    let (rows_alone, rows_ignoring) = (
        csv_rows(&alone.join("composite.csv")),
        csv_rows(&ignoring.join("composite.csv")),
    );
    assert!(rows_alone.len() > 20);
    assert_eq!(rows_alone.len(), rows_ignoring.len());
    for (r, s) in rows_alone.iter().zip(&rows_ignoring) {
        assert_eq!(s[..7], r[..]);
        assert_eq!(s[7], "0");
    }
    let s = summary(&ignoring);
    assert_eq!(s.files.len(), 2);
    assert!(!s.files[0].ignored && s.files[1].ignored);
    assert_eq!(
        s.files[1].sha256,
        sha256_hex(&std::fs::read(&b_path).unwrap())
    );
    assert_eq!(s.files[1].colliding_nodes, 0);
    assert_eq!(s.files[0].colliding_nodes, s.composite_nodes);

    // Nothing left to analyse, or a file given twice: refused.
    let out = scratch.join("out");
    let o = out.to_str().unwrap();
    let a_arg = a_path.to_str().unwrap();
    for (what, args) in [
        (
            "all ignored",
            vec!["analyze", a_arg, "--ignore", a_arg, "--out", o],
        ),
        (
            "given twice",
            vec!["analyze", a_arg, b_arg, a_arg, "--out", o],
        ),
    ] {
        assert_clean_failure(&kneeform(&args), &out, what);
    }
    std::fs::remove_dir_all(&scratch).unwrap();
}
