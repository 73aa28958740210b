//! The direct approach (`--approach direct`, issue 12): its fast form
//! against a brute-force transcription of its definition (README, "Two
//! approaches"; `src/direct.rs`), and on the pocket behind a ridge, the
//! area it cannot reach and push-and-slide strikes.

use kneeform::direct::{DirectFootprint, contact_levels, direct_mask};
use kneeform::{Analysis, Approach, HeightGrid, KneeForm, Setup, Side};

use crate::cli::kneeform_in as kneeform_cli;
use crate::util::{SEEDS, ok, random_grid_quantised, row_start, scenario_file, triangle};

/// The definition, per position and per footprint node, with the test's
/// own footprint geometry (`util::row_start`): `Y*` per position (`+inf`
/// where not placed) and the union of the contacts.
fn brute_force(grid: &HeightGrid, knee: &KneeForm, angle: f64, e0: f64) -> (Vec<f64>, Vec<u8>) {
    let s = grid.spec;
    let (nx, nz, p) = (s.nx, s.nz, s.pitch);
    let tri = triangle(knee, angle);
    let mut levels = vec![f64::INFINITY; nx * nz];
    let mut mask = vec![0u8; nx * nz];
    for j0 in 0..nz {
        for i0 in 0..nx {
            // The footprint's nodes on the grid, each with h + a(dz).
            let mut nodes = Vec::new();
            for j in 0..nz {
                let Some(a) = row_start(&tri, knee.radius, (j as f64 - j0 as f64) * p) else {
                    continue;
                };
                for i in 0..nx {
                    let h = grid.at(i, j);
                    let dx = (i as f64 - i0 as f64).abs() * p;
                    if dx <= knee.thickness / 2.0 + 1e-9 && h.is_finite() {
                        nodes.push((j * nx + i, h + a));
                    }
                }
            }
            let first = nodes.iter().map(|n| n.1).fold(f64::INFINITY, f64::min);
            levels[j0 * nx + i0] = first;
            for &(k, level) in &nodes {
                if level <= first + e0 {
                    mask[k] = 1;
                }
            }
        }
    }
    (levels, mask)
}

#[test]
fn fast_equals_brute_force_on_seeded_random_grids() {
    // Coarse heights (0.5 mm: exact ties within a row, and between rows
    // wherever a(dz) agrees) and fine ones, with holes (+inf) and blocks
    // standing proud; two knee-forms, so the width and the z-range cut
    // the grid differently; angles at the regulation's ends, 0 and off
    // the pitch.
    let knees = [
        KneeForm {
            triangle_side: 80.0,
            radius: 20.0,
            thickness: 50.0,
        },
        KneeForm {
            triangle_side: 50.0,
            radius: 12.0,
            thickness: 23.0,
        },
    ];
    let (mut checked, mut contacts, mut placed) = (0, 0, 0);
    for (n, &seed) in SEEDS.iter().enumerate() {
        for quantum in [0.5, 0.001] {
            let knee = &knees[n % 2];
            let grid = random_grid_quantised(seed, 48, 56, 4.1 - 0.3 * n as f64, quantum);
            for angle in [-30.0, -13.5, 0.0, 17.0, 30.0] {
                for e0 in [1e-6, 0.01] {
                    let fp = DirectFootprint::new(knee, angle, grid.spec.pitch);
                    let (want_levels, want) = brute_force(&grid, knee, angle, e0);
                    let got_levels = contact_levels(&grid, &fp);
                    for (k, (g, w)) in got_levels.iter().zip(&want_levels).enumerate() {
                        // Both are minima of h + a(dz); a(dz) is computed
                        // by two geometries, which agree to rounding.
                        assert!(
                            g == w || (g - w).abs() <= 1e-9,
                            "seed {seed:#x}, angle {angle}: Y* at node {k}: fast {g}, brute force {w}"
                        );
                    }
                    let got = direct_mask(&grid, &fp, e0, &[]);
                    assert_eq!(
                        got.mask,
                        want,
                        "seed {seed:#x}, quantum {quantum}, angle {angle}, e0 {e0}: {}",
                        crate::util::mask_diff(&grid, &got.mask, &want)
                    );
                    assert_eq!(
                        got.placed,
                        want_levels.iter().filter(|y| y.is_finite()).count()
                    );
                    checked += 1;
                    contacts += got.colliding;
                    placed += got.placed;
                    // Not everything: the comparison can fail both ways.
                    let finite = grid.finite_count();
                    assert!(got.colliding > 0 && got.colliding < finite);
                }
            }
        }
    }
    assert_eq!(checked, SEEDS.len() * 2 * 5 * 2);
    assert!(contacts > 1000 && placed > 10_000, "{contacts} {placed}");
}

/// The composite's nodes of `analysis` as points of the part (mm).
fn composite_points(analysis: &Analysis) -> Vec<[f64; 3]> {
    let placement = analysis.placement();
    let s = analysis.grid.spec;
    (0..s.len())
        .filter(|&k| analysis.composite[k] > 0)
        .map(|k| {
            let (i, j) = (k % s.nx, k / s.nx);
            placement.to_part([s.x(i), analysis.grid.h[k], s.z(j)])
        })
        .collect()
}

#[test]
fn the_direct_approach_cannot_reach_the_pocket_behind_the_ridge() {
    // scenarios/pocket-behind-ridge.toml: a ridge across z, 20 mm proud,
    // its front (+x) flank at x in [110, 130]; directly behind it a pocket
    // 30 mm deep, floor x in [-280, 60], far wall x in [-290, -280] facing
    // +x; z in [-150, 150]. Behind x = -200 lie only the floor and the far
    // wall: the depression. The slide's footprint (at most 320 mm long)
    // fits the 340 mm floor, so a knee-form pushed onto it slides into the
    // far wall in every row: at a 4 mm pitch, at least one node in each of
    // the 75 rows (z = -148..148). The direct approach's knee-form, moving
    // in -x, meets the ridge's front flank first in every row: every line
    // along x that reaches the far wall crosses the near wall (x in
    // [60, 70]) first, so nothing behind x = -200 is a first contact.
    let pitch = 4.0;
    let rows = 2 * (150.0 / pitch) as usize + 1;
    let run = |approach| {
        let setup = Setup {
            pitch,
            angles: vec![-30.0, 0.0, 30.0],
            approach,
            ..Setup::default()
        };
        let path = scenario_file("pocket-behind-ridge");
        Analysis::of_file(&path, 1.0, Side::Left, &setup, &()).unwrap()
    };
    let (slide, direct) = (run(Approach::Slide), run(Approach::Direct));
    assert_eq!(direct.summary().approach, Approach::Direct);
    let in_pocket = |p: &[f64; 3]| p[0] < -200.0;
    let on_front_flank = |p: &[f64; 3]| (110.0 - 1e-9..=130.0 + 1e-9).contains(&p[0]);
    let slide_points = composite_points(&slide);
    let direct_points = composite_points(&direct);
    let slide_pocket = slide_points.iter().filter(|p| in_pocket(p)).count();
    let direct_pocket = direct_points.iter().filter(|p| in_pocket(p)).count();
    // In each row, a slide from the floor (face level 30) meets the wall's
    // nodes x = -284 and -288 below its level, each rising from the node
    // behind it far more steeply than tan 0.5 degrees, then x = -292 on
    // the flat (y = 0), below the level -288 left; x = -280 is the floor's
    // edge (y = 30, no contact) and -296 is level with -292. So three
    // nodes per row.
    assert_eq!(
        slide_pocket,
        3 * rows,
        "push-and-slide strikes the far wall in every row"
    );
    // Every struck node behind x = -200 is on the far wall, or the first
    // node past its top (SPEC's grid strikes the node a slide meets
    // first, as on the step).
    assert!(
        slide_points
            .iter()
            .filter(|p| in_pocket(p))
            .all(|p| (-290.0 - pitch - 1e-9..=-280.0 + 1e-9).contains(&p[0]))
    );
    assert_eq!(direct_pocket, 0, "the direct approach reaches the pocket");
    // Both meet the ridge's front flank, in every row.
    for (name, points) in [("slide", &slide_points), ("direct", &direct_points)] {
        let front = points.iter().filter(|p| on_front_flank(p)).count();
        assert!(front >= rows, "{name}: {front} nodes on the front flank");
    }
}

#[test]
fn the_report_compares_a_direct_run_with_a_slide_run_of_the_same_part() {
    let dir = crate::util::scratch_dir("direct-compare");
    let scenario = scenario_file("pocket-behind-ridge");
    let part = scenario.to_str().unwrap();
    let common = ["--pitch", "8", "--angles=-30,0,30"];
    for (approach, out) in [("slide", "slide"), ("direct", "direct")] {
        let mut args = vec!["analyze", part, "--approach", approach, "--out", out];
        args.extend(common);
        ok(kneeform_cli(&dir, &args), approach);
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(summary["approach"], approach);
    }
    // A direct run reports on its own, and beside the slide run.
    ok(
        kneeform_cli(&dir, &["report", "direct", "--out", "direct.html"]),
        "report direct",
    );
    let html = std::fs::read_to_string(dir.join("direct.html")).unwrap();
    assert!(html.contains("direct approach (the knee-form moved in -x"));
    ok(
        kneeform_cli(
            &dir,
            &[
                "report",
                "slide",
                "--compare",
                "direct",
                "--out",
                "both.html",
            ],
        ),
        "report --compare",
    );
    let html = std::fs::read_to_string(dir.join("both.html")).unwrap();
    assert!(html.contains("<section id=\"compare\">"));
    assert!(html.contains("id=\"compare-view-0\"") && html.contains("id=\"compare-view-1\""));
    assert!(html.contains("data-src=\"compare/summary.json#/composite_area_mm2\""));
    // The far wall (x in [-290, -280], every row of z in [-150, 150]: 37
    // rows at 8 mm) is struck by the slide only: at least one node per
    // row is what the direct approach misses.
    let row = &html[html
        .find("<tr id=\"slide-only\">")
        .expect("the slide-only row")..];
    let cells: Vec<&str> = row
        .split("<td class=\"num\">")
        .skip(1)
        .take(2)
        .map(|c| &c[..c.find('<').unwrap()])
        .collect();
    let nodes: usize = cells[0].parse().unwrap();
    let area: f64 = cells[1].parse().unwrap();
    assert!(nodes >= 37, "{nodes} nodes only push-and-slide strikes");
    assert_eq!(area, nodes as f64 * 64.0);
    // A run is not compared with itself (two runs of one approach are two
    // revisions of a part: tests/diff.rs): one line, exit 2.
    let out = kneeform_cli(
        &dir,
        &["report", "slide", "--compare", "slide", "--out", "x.html"],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = crate::cli::said(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("the report's run itself"), "{err}");
}

#[test]
fn the_right_side_of_a_mirrored_part_gives_the_mirrored_direct_result() {
    // The pocket behind the ridge, and the same part mirrored in y read for
    // the right side: the same analysis, so the same contacts with y
    // negated, in the part's own coordinates.
    use kneeform::{Part, PartFile};
    let file = kneeform::scenario::load(&scenario_file("pocket-behind-ridge")).unwrap();
    let left = file.triangulate(None);
    // (The winding kept: read for the right side, these are the left
    // part's triangles to the bit, so any difference is the mapping back.)
    let right: Vec<_> = left.iter().map(|t| t.map(|[x, y, z]| [x, -y, z])).collect();
    let setup = Setup {
        pitch: 8.0,
        angles: vec![-30.0, 0.0, 30.0],
        approach: Approach::Direct,
        ..Setup::default()
    };
    let run = |tris: Vec<_>, side| {
        let part = Part::from_triangles("pocket", tris, 1.0, side).unwrap();
        let mut input = PartFile::in_memory("pocket", part);
        input.side = side;
        let analysis = Analysis::run(input, &setup, &()).unwrap();
        let mut points: Vec<[i64; 3]> = composite_points(&analysis)
            .iter()
            .map(|p| p.map(|c| (c * 1e6).round() as i64))
            .collect();
        points.sort_unstable();
        points
    };
    let l = run(left, Side::Left);
    let mut r: Vec<[i64; 3]> = run(right, Side::Right)
        .into_iter()
        .map(|[x, y, z]| [x, -y, z])
        .collect();
    r.sort_unstable();
    assert!(l.len() > 100, "{} contacts", l.len());
    assert_eq!(l, r);
}

#[test]
fn verify_compares_the_direct_approach_with_its_exact_oracle() {
    let dir = crate::util::scratch_dir("direct-verify");
    let part = scenario_file("pocket-behind-ridge");
    let args = [
        "verify",
        part.to_str().unwrap(),
        "--pitch",
        "8",
        "--angles=0",
        "--starts",
        "5",
        "--approach",
        "direct",
        "--out",
        "v",
    ];
    let out = kneeform_cli(&dir, &args);
    let err = crate::cli::said(&out);
    // PASS or FAIL at the default 1 mm tolerance, never an error.
    assert!(matches!(out.status.code(), Some(0 | 1 | 3)), "{err}");
    let json = std::fs::read_to_string(dir.join("v/verify.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(summary["approach"], "direct", "{json}");
    assert_eq!(summary["counts"]["compared"], 5, "{json}");
    assert_eq!(summary["counts"]["engine_mismatch"], 0, "{json}");
    assert_eq!(summary["counts"]["oracle_failed"], 0, "{json}");
    assert!(dir.join("v/verify.csv").exists());
    // No sample predicts the direct approach's casts: a budget is said
    // not to apply, and only when one is given.
    let warning = "--budget-s is not applied with --approach direct";
    assert!(!err.contains(warning), "{err}");
    let mut budget = args.to_vec();
    *budget.last_mut().unwrap() = "with-budget";
    budget.extend(["--budget-s", "1000"]);
    let out = kneeform_cli(&dir, &budget);
    let err = crate::cli::said(&out);
    assert!(matches!(out.status.code(), Some(0 | 1 | 3)), "{err}");
    assert!(
        err.contains(&format!("kneeform: warning: {warning}")),
        "{err}"
    );
}
