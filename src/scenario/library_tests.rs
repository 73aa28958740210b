//! Tests of the scenario library itself, `scenarios/*.toml` (as built in):
//! every file loads and tessellates exactly, each primitive's defining
//! values are where its parameters put them, and the files' "nothing
//! collides" and "a coarse grid misses it" claims hold.

use super::*;
use crate::mesh::Triangle;

/// The parts the library must hold (issue 4), by file stem.
const REQUIRED: [&str; 11] = [
    "flat-wall",
    "ramp",
    "wave",
    "growing-wave",
    "wavy-ridge",
    "depression",
    "groove",
    "thin-rib",
    "switch-boss",
    "angled-features",
    "console",
];

fn part(stem: &str) -> ScenarioFile {
    builtin(stem).unwrap_or_else(|| panic!("scenarios/{stem}.toml is not built in"))
}

/// Whether the mesh has a vertex at exactly `(x, y, z)`.
fn has_vertex(tris: &[Triangle], x: f64, y: f64, z: f64) -> bool {
    tris.iter().flatten().any(|v| *v == [x, y, z])
}

#[test]
fn every_file_loads_and_tessellates_exactly() {
    let stems: Vec<&str> = builtin_names().collect();
    for stem in REQUIRED {
        assert!(stems.contains(&stem), "scenarios/{stem}.toml is missing");
    }
    for stem in stems {
        // Lowercase-hyphen names.
        assert!(
            stem.chars().all(|c| c.is_ascii_lowercase() || c == '-'),
            "{stem}"
        );
        let f = part(stem);
        assert!(
            !f.features.is_empty(),
            "{stem}: a part says what it is made of"
        );
        let tris = f.triangulate(None);
        assert_eq!(tris.len(), f.triangle_count(None), "{stem}");
        assert!(tris.len() >= 2, "{stem}");
        let [x0, x1] = f.extent.x;
        let [z0, z1] = f.extent.z;
        for t in &tris {
            for v in t {
                assert_eq!(v[1], f.height(v[0], v[2]), "{stem} at {v:?}");
                assert!(v[1].is_finite());
                assert!(
                    (x0..=x1).contains(&v[0]) && (z0..=z1).contains(&v[2]),
                    "{stem}"
                );
            }
            // Each triangle has area in xz and faces the knee (-y), also
            // as binary STL stores it, in f32.
            let [a, b, c] = t;
            let (e1, e2) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
            assert!(e1[1] * e2[0] - e1[0] * e2[1] < 0.0, "{stem}: {t:?}");
            let [a, b, c] = t.map(|v| v.map(|x| f64::from(x as f32)));
            let (e1, e2) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
            assert!(e1[1] * e2[0] - e1[0] * e2[1] < 0.0, "{stem} in f32: {t:?}");
        }
        // The extent is covered exactly: the corners are vertices.
        for (x, z) in [(x0, z0), (x1, z0), (x0, z1), (x1, z1)] {
            assert!(
                has_vertex(&tris, x, f.height(x, z), z),
                "{stem} corner ({x}, {z})"
            );
        }
    }
}

#[test]
fn the_default_panel_is_600_by_300_at_2_mm() {
    // Every part but the console lies on the same panel, centred on the
    // origin where the features are.
    for stem in builtin_names().filter(|&s| s != "console") {
        let f = part(stem);
        assert_eq!(
            f.extent,
            Extent {
                x: [-300.0, 300.0],
                z: [-150.0, 150.0],
                step: 2.0
            },
            "{stem}"
        );
    }
    // The flat wall has no creases: exactly the 300 x 150 cells at 2 mm.
    let tris = part("flat-wall").triangulate(None);
    assert_eq!(tris.len(), 2 * 300 * 150);
    assert!(
        tris.iter()
            .flatten()
            .all(|v| v[0] % 2.0 == 0.0 && v[2] % 2.0 == 0.0)
    );
}

#[test]
fn primitives_stand_where_their_parameters_put_them() {
    // Towards the knee is smaller y.
    let f = part("bump");
    assert_eq!(f.height(0.0, 0.0), -10.0);
    assert_eq!(f.height(0.0, 40.0), 0.0);
    assert!(has_vertex(&f.triangulate(None), 0.0, -10.0, 0.0));

    let f = part("ramp");
    assert_eq!(f.height(-100.0, 7.0), -20.0);
    assert_eq!(f.height(100.0, 7.0), 20.0);

    // y = 5 sin(2 pi x / 100): 5 mm proud at x = -25 and 75, 5 back at 25
    // and -75; exactly 0 at the lattice's zeros.
    let f = part("wave");
    assert_eq!(f.height(-25.0, 0.0), -5.0);
    assert_eq!(f.height(75.0, 9.0), -5.0);
    assert_eq!(f.height(25.0, 9.0), 5.0);
    assert_eq!(f.height(-75.0, 0.0), 5.0);
    for x in [-300.0, -250.0, 0.0, 50.0, 100.0] {
        assert_eq!(f.height(x, 0.0), 0.0, "x = {x}");
    }

    // Crests at x = 25 mod 100, amplitude 2 + 0.01 (300 - x): 4.75 mm at
    // x = 25, 7.75 at -275, each further out than the one behind it; the
    // hollows between are flat, and the zeros on the lattice exact.
    let f = part("growing-wave");
    assert!((f.height(25.0, 0.0) + 4.75).abs() < 1e-12);
    assert!((f.height(-275.0, 0.0) + 7.75).abs() < 1e-12);
    let crests: Vec<f64> = [225.0, 25.0, -175.0, -275.0]
        .iter()
        .map(|&x| f.height(x, 0.0))
        .collect();
    assert!(crests.windows(2).all(|w| w[1] < w[0]), "{crests:?}");
    assert_eq!(f.height(-25.0, 0.0), 0.0);
    assert_eq!(f.height(-40.0, 0.0), 0.0);
    for x in [-300.0, -250.0, 0.0, 50.0, 100.0] {
        assert_eq!(f.height(x, 0.0), 0.0, "x = {x}");
    }

    // Each boss's flat top, corners included, is exactly its height; the
    // shoulder ends 3 mm beyond it.
    let f = part("switch-boss");
    let tris = f.triangulate(None);
    for (cx, h) in [(150.0, 5.0), (0.0, 7.5), (-150.0, 10.0)] {
        for (dx, dz) in [(0.0, 0.0), (20.0, 12.0), (-20.0, -12.0), (-20.0, 12.0)] {
            assert_eq!(f.height(cx + dx, dz), -h, "boss at {cx}");
        }
        assert_eq!(f.height(cx + 23.0, 0.0), 0.0);
        assert_eq!(f.height(cx, -15.0), 0.0);
        assert!(has_vertex(&tris, cx + 20.0, -h, 12.0));
    }

    // The groove's flat bottom is `depth` behind the wall over its half
    // width; its walls end `shoulder` further out. The 10 mm groove's
    // edges (z = -63, -57) are off the 2 mm lattice: crease rows hold them.
    let f = part("groove");
    let tris = f.triangulate(None);
    for x in [-6.0, 0.0, 6.0] {
        assert_eq!(f.height(x, 50.0), 8.0);
    }
    assert_eq!(f.height(10.0, 50.0), 0.0);
    assert_eq!(f.height(-150.0, -63.0), 5.0);
    assert_eq!(f.height(-150.0, -65.0), 0.0);
    assert!(has_vertex(&tris, -150.0, 5.0, -63.0));
    assert!(has_vertex(&tris, -150.0, 5.0, -57.0));

    // The wavy ridge's top, measured from its `from` end at x = 250:
    // 12 + 3 = 15 mm proud a quarter wavelength (22.5 mm) in, 9 at three
    // quarters, over the whole 16 mm flat top; gone 18 mm off the axis.
    let f = part("wavy-ridge");
    for z in [-8.0, 0.0, 8.0] {
        assert_eq!(f.height(227.5, z), -15.0);
        assert_eq!(f.height(182.5, z), -9.0);
    }
    assert_eq!(f.height(0.0, 18.0), 0.0);

    // Figure 2b: the dip 5 mm deep at the origin, the ridge 10 mm proud at
    // x = 120 across the whole part.
    let f = part("depression");
    assert_eq!(f.height(0.0, 0.0), 5.0);
    assert_eq!(f.height(120.0, -150.0), -10.0);
    assert_eq!(f.height(120.0, 77.0), -10.0);
    assert_eq!(f.height(160.0, 0.0), 0.0);

    // The diagonal ridge is 8 mm proud on its axis whatever the z, and the
    // bosses staggered in z stand 6 and 9 mm proud.
    let f = part("angled-features");
    assert_eq!(f.height(0.0, 0.0), -8.0);
    assert!((f.height(100.0, 50.0) + 8.0).abs() < 1e-12);
    assert_eq!(f.height(-200.0, 90.0), -6.0);
    assert_eq!(f.height(-120.0, 40.0), -9.0);

    // The tilted wave fades to nothing at z = +-150 (its z envelope) and
    // varies along z on any line x = const.
    let f = part("tilted-wave");
    assert_eq!(f.height(37.0, 150.0), 0.0);
    assert_ne!(f.height(0.0, 10.0), f.height(0.0, 40.0));

    let f = part("step");
    assert_eq!(f.height(-0.5, 0.0), -10.0);
    assert_eq!(f.height(-0.25, 0.0), -5.0);
    assert_eq!(f.height(0.0, 0.0), 0.0);
}

#[test]
fn thin_ribs_are_in_the_mesh_though_narrower_than_the_step() {
    let f = part("thin-rib");
    assert!(f.extent.step > 0.6);
    for min_triangles in [None, Some(100_000)] {
        let tris = f.triangulate(min_triangles);
        // The crest across the slide, x = 10.3, 5 mm proud along z in
        // [-100, 100]: on every lattice row there, plus its ends.
        let mut crest: Vec<f64> = tris
            .iter()
            .flatten()
            .filter(|v| v[0] == 10.3 && v[1] == -5.0)
            .map(|v| v[2])
            .collect();
        crest.sort_by(f64::total_cmp);
        crest.dedup();
        let rows = (200.0 / f.step_for(min_triangles)).floor() as usize;
        assert!(
            crest.len() > rows,
            "{} crest vertices, {rows} rows",
            crest.len()
        );
        assert_eq!((crest[0], crest[crest.len() - 1]), (-100.0, 100.0));
        // Its feet (0.3 mm either side) are vertices on the wall.
        for foot in [10.0, 10.6] {
            assert!(
                tris.iter()
                    .flatten()
                    .any(|v| (v[0] - foot).abs() < 1e-9 && v[2] == 0.0 && v[1].abs() < 1e-9),
                "foot {foot}"
            );
        }
        // The crest along the slide, z = 40.3, x in [-250, -50].
        let along: Vec<f64> = tris
            .iter()
            .flatten()
            .filter(|v| v[2] == 40.3 && v[1] == -5.0)
            .map(|v| v[0])
            .collect();
        assert!(along.contains(&-250.0) && along.contains(&-50.0));
        assert!(along.iter().any(|&x| -151.0 < x && x < -149.0));
    }
}

#[test]
fn a_coarse_grid_misses_the_thin_rib_a_fine_one_does_not() {
    use crate::grid::{GridSpec, HeightGrid};
    let tris = part("thin-rib").triangulate(None);
    // The grid's heights over the part, at pitch p: nodes at multiples of
    // p over x in [-300, 300], z in [-150, 150].
    let lowest = |p: f64| {
        let n = |len: f64| (len / p) as usize + 1;
        let spec = GridSpec::explicit(-300.0, -150.0, n(600.0), n(300.0), p);
        let grid = HeightGrid::sample(&tris, spec);
        (0..grid.spec.nz)
            .flat_map(|j| (0..grid.spec.nx).map(move |i| (i, j)))
            .map(|(i, j)| grid.at(i, j))
            .fold(f64::INFINITY, f64::min)
    };
    // At 2 mm the nodes either side of the crests (x = 10, 12; z = 40,
    // 42) are on the wall or on a foot: the grid sees a flat wall.
    assert!(lowest(2.0).abs() < 1e-9, "{}", lowest(2.0));
    // At 0.5 mm the node x = 10.5 is 0.2 mm from the crest on a 0.3 mm
    // flank: 5 (1 - 0.2 / 0.3) = 5/3 mm proud (z = 40.5 likewise).
    assert!((lowest(0.5) + 5.0 / 3.0).abs() < 1e-9, "{}", lowest(0.5));
}

#[test]
fn parts_that_strike_nothing_strike_nothing() {
    use crate::grid::HeightGrid;
    use crate::{EngineOptions, Footprint, GridFootprint, KneeForm, colliding_masks};
    // The flat wall and the grooved wall: every node's height is at least
    // the face level after any push (the wall's 0), so nothing is more
    // than eps below it. The depression: the dip (y > 0 within 60 mm of
    // the origin) lies behind the ridge and below the level any knee over
    // the ridge or the flat wall holds, so none of its nodes collide.
    let (pitch, angles) = (4.0, [-30.0, 0.0, 30.0]);
    let knee = KneeForm::default();
    let shapes: Vec<Footprint> = angles.iter().map(|&a| Footprint::new(&knee, a)).collect();
    for stem in ["flat-wall", "groove", "depression"] {
        let part =
            crate::Part::from_triangles(stem, part(stem).triangulate(None), 1.0, crate::Side::Left)
                .unwrap();
        let spec = Footprint::grid_around(&part.bbox(), &shapes, pitch);
        let grid = HeightGrid::sample(&part.triangles, spec);
        let footprints: Vec<GridFootprint> = angles
            .iter()
            .zip(&shapes)
            .map(|(&a, _)| GridFootprint::new(&knee, a, &spec))
            .collect();
        let masks = colliding_masks(&grid, &footprints, &EngineOptions::default(), &|| {});
        for m in &masks {
            assert!(m.placed > 0, "{stem}");
            if stem == "depression" {
                for (k, _) in m.mask.iter().enumerate().filter(|(_, c)| **c != 0) {
                    let (i, j) = (k % grid.spec.nx, k / grid.spec.nx);
                    let r = grid.spec.x(i).hypot(grid.spec.z(j));
                    assert!(
                        r >= 60.0,
                        "{stem} angle {}: dip node at r = {r}",
                        m.angle_deg
                    );
                }
            } else {
                assert_eq!(m.colliding, 0, "{stem} angle {}", m.angle_deg);
            }
        }
    }
}

#[test]
fn the_console_reaches_the_paper_triangle_count() {
    let f = part("console");
    assert_eq!((f.extent.x, f.extent.z), ([0.0, 1500.0], [0.0, 600.0]));
    let tris = f.triangulate(Some(369_408));
    // At least the paper's count, and less than one more row of cells
    // along x over (two triangles per lattice column: the step is about
    // 2.2 mm, so under 2 x 1500 / 2 = 1500).
    assert!(
        (369_408..369_408 + 1500).contains(&tris.len()),
        "{}",
        tris.len()
    );
    for v in tris.iter().flatten() {
        assert_eq!(v[1], f.height(v[0], v[2]));
    }
    // No triangle loses its area when written as f32 (binary STL): lattice
    // lines closer than f32's spacing at 1500 mm are merged.
    for t in &tris {
        let [a, b, c] = t.map(|v| v.map(|x| f64::from(x as f32)));
        let (e1, e2) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
        assert!(
            e1[1] * e2[0] - e1[0] * e2[1] < 0.0,
            "zero area in f32: {t:?}"
        );
    }
    // It is the benchmark console plus its extra features: the rib's crest
    // stands 5 mm proud of the console there, the far corner is untouched.
    let console = super::console::console_height;
    assert_eq!(f.height(1000.3, 200.0), console(1000.3, 200.0) - 5.0);
    assert_eq!(f.height(1500.0, 0.0), console(1500.0, 0.0));
    assert!(
        tris.iter()
            .flatten()
            .any(|v| v[0] == 1000.3 && v[2] > 60.0 && v[2] < 330.0)
    );
}
