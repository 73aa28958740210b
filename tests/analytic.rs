//! Parts whose colliding areas follow from their geometry alone: each
//! expectation is derived in its comment from SPEC's rules, not read off
//! the program.

use kneeform::KneeForm;
use kneeform::scenario::{Extent, ScenarioFile, builtin};

use crate::util::{analyse, brute_force, mask_diff};

const ANGLES: [f64; 5] = [-30.0, -7.0, 0.0, 12.0, 30.0];

/// The built-in scenario `name` on `extent` instead of its own panel.
fn on(name: &str, extent: Extent) -> ScenarioFile {
    ScenarioFile {
        extent,
        ..builtin(name).expect("a built-in scenario")
    }
}

/// The built-in scenario `name` on a smaller panel than its own, so the
/// tests stay quick: x in [-200, 200], z in [-60, 60] (mm).
fn part(name: &str, step: f64) -> ScenarioFile {
    on(
        name,
        Extent {
            x: [-200.0, 200.0],
            z: [-60.0, 60.0],
            step,
        },
    )
}

#[test]
fn sampled_heights_equal_the_surface_at_lattice_nodes() {
    for scenario in ["wave", "bump", "depression", "growing-wave"] {
        let part = part(scenario, 2.0);
        // Nodes on lattice vertices get the vertex height exactly; nodes
        // between them the linear interpolation, within its error bound
        // (curvature x step^2 / 8; 0.05 mm is generous for these surfaces).
        for (pitch, bound) in [(2.0, 1e-9), (1.0, 0.05)] {
            let tris = part.triangulate(None);
            let (grid, _) = analyse(&tris, pitch, &KneeForm::default(), &[0.0]);
            let mut checked = 0;
            for j in 0..grid.spec.nz {
                for i in 0..grid.spec.nx {
                    let (x, z) = (grid.spec.x(i), grid.spec.z(j));
                    let inside = x > -200.0 && x < 200.0 && z > -60.0 && z < 60.0;
                    if !inside {
                        continue;
                    }
                    let want = part.height(x, z);
                    assert!(
                        (grid.at(i, j) - want).abs() <= bound,
                        "{scenario} p={pitch} at ({x}, {z}): {} vs {want}",
                        grid.at(i, j)
                    );
                    checked += 1;
                }
            }
            assert!(checked > 1000);
        }
    }
}

#[test]
fn flat_wall_strikes_nothing() {
    // Every height equals the face level after the push: nothing is below it.
    let (_, masks) = analyse(
        &part("flat-wall", 4.0).triangulate(None),
        2.0,
        &KneeForm::default(),
        &ANGLES,
    );
    for m in &masks {
        assert!(m.placed > 0);
        assert_eq!(m.colliding, 0, "angle {}", m.angle_deg);
    }
}

#[test]
fn ramp_strikes_every_node_with_a_finite_right_neighbour() {
    // y = 0.2 x. Take a node N with a finite neighbour at x + p, and the
    // start S for which N is the first node in front in S's footprint row
    // reaching furthest to -x (the first such row in slide order). S's
    // footprint holds N's neighbour, so S is placed, and every node inside
    // it lies at x >= x_N + p: yr >= h_N + 0.2 p. Every node S judges before
    // N's group lies at x > x_N, so the level is still above h_N + 0.2 p
    // > h_N + eps when N is judged: N collides. The rearmost column has no
    // finite right neighbour, and no start is placed beyond it.
    let p = 2.0;
    let (grid, masks) = analyse(
        &part("ramp", 4.0).triangulate(None),
        p,
        &KneeForm::default(),
        &ANGLES,
    );
    for m in &masks {
        for j in 0..grid.spec.nz {
            for i in 0..grid.spec.nx {
                let want = grid.at(i, j).is_finite()
                    && i + 1 < grid.spec.nx
                    && grid.at(i + 1, j).is_finite();
                assert_eq!(
                    m.mask[j * grid.spec.nx + i] == 1,
                    want,
                    "angle {} node ({i}, {j})",
                    m.angle_deg
                );
            }
        }
    }
}

#[test]
fn step_strikes_exactly_the_column_below_its_face() {
    // y = 0 for x >= 0, -10 for x <= -0.5. Nodes sit at multiples of 2 mm,
    // so the column x = -2 is the first below the step. A node N there
    // collides for the start S whose furthest-forward row meets N first
    // (S's footprint lies on x >= 0: yr = 0, and everything judged before
    // N is at level 0). Any node at x <= -4 is met after the node at x = -2
    // of its own row, when the level is already -10; and a start whose
    // footprint reaches the lower part has yr = -10 and strikes nothing.
    let (grid, masks) = analyse(
        &part("step", 4.0).triangulate(None),
        2.0,
        &KneeForm::default(),
        &ANGLES,
    );
    for m in &masks {
        for j in 0..grid.spec.nz {
            for i in 0..grid.spec.nx {
                let want = grid.spec.x(i) == -2.0 && grid.at(i, j).is_finite();
                assert_eq!(
                    m.mask[j * grid.spec.nx + i] == 1,
                    want,
                    "angle {} node ({i}, {j})",
                    m.angle_deg
                );
            }
        }
    }
}

#[test]
fn growing_wave_strikes_rising_flanks_never_hollows() {
    // y <= 0 everywhere, so every placed start has yr <= 0 and the level
    // never exceeds 0: hollows (y = 0) never collide. A colliding node N was
    // met after its neighbour at x + p in the same row had been inside the
    // footprint or passed, so the level was at most h(x + p): N lies where
    // the surface comes closer to the knee towards -x (h(x + p) > h(x)).
    // Every crest is struck: a start whose footprint lies on the hollow
    // behind a crest (or, for the rearmost, on the flat strip x in
    // [150, 200] behind it) has yr = 0 and strikes the crest's +x flank.
    let p = 2.0;
    let (grid, masks) = analyse(
        &part("growing-wave", 2.0).triangulate(None),
        p,
        &KneeForm::default(),
        &ANGLES,
    );
    for m in &masks {
        let mut crests_struck = std::collections::BTreeSet::new();
        for j in 0..grid.spec.nz {
            for i in 0..grid.spec.nx {
                if m.mask[j * grid.spec.nx + i] == 0 {
                    continue;
                }
                let h = grid.at(i, j);
                assert!(
                    h < 0.0,
                    "angle {}: a hollow node collides at x = {}",
                    m.angle_deg,
                    grid.spec.x(i)
                );
                assert!(
                    grid.at(i + 1, j) > h,
                    "angle {}: node at x = {} is not on a rising flank",
                    m.angle_deg,
                    grid.spec.x(i)
                );
                crests_struck.insert((grid.spec.x(i) / 100.0).floor() as i64);
            }
        }
        // Crests at x in [-200, -150], [-100, -50], [0, 50], [100, 150].
        assert_eq!(
            crests_struck.into_iter().collect::<Vec<_>>(),
            vec![-2, -1, 0, 1],
            "angle {}",
            m.angle_deg
        );
    }
}

#[test]
fn scenario_grids_agree_with_brute_force() {
    // The engine on sampled parts, against SPEC's transcription, with a
    // small knee-form so the brute force stays quick.
    let knee = KneeForm {
        triangle_side: 40.0,
        radius: 12.0,
        thickness: 120.0,
    };
    let small = Extent {
        x: [-60.0, 60.0],
        z: [-30.0, 30.0],
        step: 3.0,
    };
    for scenario in ["wave", "bump", "step", "depression"] {
        let tris = on(scenario, small).triangulate(None);
        let (grid, masks) = analyse(&tris, 3.0, &knee, &ANGLES);
        for m in &masks {
            let rule = kneeform::StrikeRule::default();
            let (want, placed) = brute_force(
                &grid,
                &knee,
                m.angle_deg,
                (rule.e0, rule.sigma, rule.window_mm()),
            );
            assert_eq!(
                m.mask,
                want,
                "{scenario} angle {}: {}",
                m.angle_deg,
                mask_diff(&grid, &m.mask, &want)
            );
            assert_eq!(m.placed, placed);
        }
    }
}
