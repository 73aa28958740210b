//! The built-in scenarios: the synthetic parts the integration tests and
//! the README example were written against, each a closed-form surface
//! `y = g(x, z)` on a [`HeightField`]. Their names are the CLI's
//! `kneeform scenario NAME`. The scenario files in `scenarios/` (see
//! [`super::file`]) reproduce all but the console within rounding, and add
//! the parts these lack.

use super::lattice::{axis, cosine_bell, refined_step, sin_turns, tessellate};
use crate::mesh::Triangle;

/// A synthetic part. The names on the command line are kebab-case
/// (`flat-wall`, `growing-wave`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Scenario {
    /// `y = 0`: a flat wall; nothing collides.
    FlatWall,
    /// `y = 0.2 x`: tilted so that the surface comes closer to the knee as
    /// it slides to -x, which never lifts it off: every node of the part
    /// but the rearmost column (the largest x) is colliding at every angle.
    Ramp,
    /// `y = 5 sin(2 pi x / 100)`: crests 5 mm towards the knee every 100 mm.
    Wave,
    /// Crests only, growing towards the front:
    /// `y = -a(x) max(0, sin(2 pi x / 100))` with `a(x) = 2 + 0.01 (300 - x)`
    /// mm (2 mm at x = 300, 8 mm at x = -300). Each crest stands further out
    /// than the one behind it, so the knee, lifted by one crest, strikes the
    /// rising (+x) flank of the next; the flat hollows (y = 0) never collide.
    GrowingWave,
    /// A step 10 mm towards the knee at the front: `y = 0` for `x >= 0`,
    /// `y = -10` for `x <= -0.5`, a linear ramp between (steep but finite,
    /// so the surface is a function and its facets have area).
    Step,
    /// A smooth cosine bump, 10 mm towards the knee at the origin, radius
    /// 40 mm: `y = -5 (1 + cos(pi r / 40))` for `r < 40`, else 0.
    Bump,
    /// The paper's Figure 2b: a shallow dip 5 mm deep (away from the knee),
    /// radius 60 mm, centred at the origin, lying behind (for the sliding
    /// knee, after) a ridge across z that stands 10 mm towards the knee at
    /// x = 120 with half-width 40 mm. The knee rides over the ridge and runs
    /// straight over the dip, which never collides.
    Depression,
    /// The benchmark console side ([`crate::console`]): 1500 x 600 mm with
    /// a bulge, waves, a wavy ridge, switch-like bosses and a depression
    /// behind a protrusion, tessellated at 8 mm by default.
    Console,
}

/// Where and how finely to sample a scenario (mm, analysis frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightField {
    /// The part's extent in x (mm): `(low, high)`.
    pub x_range: (f64, f64),
    /// The part's extent in z (mm): `(low, high)`.
    pub z_range: (f64, f64),
    /// Lattice step (mm): vertices at multiples of it.
    pub step: f64,
}

impl Default for HeightField {
    /// A console-side-like panel, 600 mm long in x and 300 mm tall in z,
    /// centred on the origin where the features are, tessellated at 2 mm.
    fn default() -> Self {
        HeightField {
            x_range: (-300.0, 300.0),
            z_range: (-150.0, 150.0),
            step: 2.0,
        }
    }
}

impl Scenario {
    /// The field to sample this scenario on. Every scenario is laid out for
    /// the default panel ([`HeightField::default`]).
    pub fn default_field(self) -> HeightField {
        match self {
            Scenario::Console => HeightField {
                x_range: (0.0, crate::console::CONSOLE_SIZE[0]),
                z_range: (0.0, crate::console::CONSOLE_SIZE[1]),
                step: 8.0,
            },
            _ => HeightField::default(),
        }
    }

    /// [`Scenario::default_field`] with its step refined, when
    /// `min_triangles` is given, until [`triangulate`] makes at least that
    /// many triangles (the largest such step; see
    /// [`super::ScenarioFile::step_for`]).
    pub fn field_for(self, min_triangles: Option<usize>) -> HeightField {
        let mut field = self.default_field();
        if let Some(n) = min_triangles {
            field.step = refined_step(
                [field.x_range, field.z_range],
                field.step,
                [self.creases_x(), &[]],
                n,
            );
        }
        field
    }

    /// The x of the lines where the surface has a crease that the lattice
    /// might step over; [`triangulate`] puts vertices on them, so the
    /// tessellation is exact there at any step.
    fn creases_x(self) -> &'static [f64] {
        match self {
            Scenario::Step => &[STEP_RAMP_START, 0.0],
            Scenario::Depression => &[
                RIDGE_X - RIDGE_HALF_WIDTH,
                RIDGE_X,
                RIDGE_X + RIDGE_HALF_WIDTH,
            ],
            _ => &[],
        }
    }
}

const WAVE_AMPLITUDE: f64 = 5.0;
const WAVE_LENGTH: f64 = 100.0;
/// GrowingWave: crest height at `GROWTH_REF_X`, and its growth per mm
/// towards -x.
const GROWTH_BASE: f64 = 2.0;
const GROWTH_PER_MM: f64 = 0.01;
const GROWTH_REF_X: f64 = 300.0;
const STEP_HEIGHT: f64 = 10.0;
const STEP_RAMP_START: f64 = -0.5;
const BUMP_HEIGHT: f64 = 10.0;
const BUMP_RADIUS: f64 = 40.0;
const DIP_DEPTH: f64 = 5.0;
const DIP_RADIUS: f64 = 60.0;
const RIDGE_HEIGHT: f64 = 10.0;
const RIDGE_X: f64 = 120.0;
const RIDGE_HALF_WIDTH: f64 = 40.0;

/// The surface's y (mm, analysis frame) at `(x, z)` (mm).
pub fn height(scenario: Scenario, x: f64, z: f64) -> f64 {
    match scenario {
        Scenario::FlatWall => 0.0,
        Scenario::Ramp => 0.2 * x,
        Scenario::Wave => WAVE_AMPLITUDE * sin_turns(x / WAVE_LENGTH),
        Scenario::GrowingWave => {
            let amplitude = (GROWTH_BASE + GROWTH_PER_MM * (GROWTH_REF_X - x)).max(0.0);
            -amplitude * sin_turns(x / WAVE_LENGTH).max(0.0)
        }
        Scenario::Step => {
            if x >= 0.0 {
                0.0
            } else if x <= STEP_RAMP_START {
                -STEP_HEIGHT
            } else {
                -STEP_HEIGHT * x / STEP_RAMP_START
            }
        }
        Scenario::Bump => -BUMP_HEIGHT * cosine_bell(x.hypot(z) / BUMP_RADIUS),
        Scenario::Console => crate::console::console_height(x, z),
        Scenario::Depression => {
            DIP_DEPTH * cosine_bell(x.hypot(z) / DIP_RADIUS)
                - RIDGE_HEIGHT * cosine_bell((x - RIDGE_X) / RIDGE_HALF_WIDTH)
        }
    }
}

/// Samples the surface on the lattice of `field` (plus vertex lines at the
/// scenario's creases) and splits each lattice cell into two triangles,
/// wound so their normals face -y (towards the knee). Vertices are exact
/// multiples of the step except at the range ends and creases.
///
/// # Panics
///
/// If the step is not positive or a range is empty or reversed.
pub fn triangulate(scenario: Scenario, field: &HeightField) -> Vec<Triangle> {
    assert!(
        field.step > 0.0,
        "the lattice step must be positive, got {}",
        field.step
    );
    assert!(
        field.x_range.0 < field.x_range.1 && field.z_range.0 < field.z_range.1,
        "empty field: x {:?}, z {:?}",
        field.x_range,
        field.z_range
    );
    let xs = axis(field.x_range, field.step, scenario.creases_x());
    let zs = axis(field.z_range, field.step, &[]);
    tessellate(&xs, &zs, |i, k| height(scenario, xs[i], zs[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    const ALL: [Scenario; 8] = [
        Scenario::FlatWall,
        Scenario::Ramp,
        Scenario::Wave,
        Scenario::GrowingWave,
        Scenario::Step,
        Scenario::Bump,
        Scenario::Depression,
        Scenario::Console,
    ];

    fn small() -> HeightField {
        HeightField {
            x_range: (-300.0, 300.0),
            z_range: (-20.0, 20.0),
            step: 5.0,
        }
    }

    #[test]
    fn vertex_heights_are_the_surface_and_cells_are_two_triangles() {
        for s in ALL {
            let f = small();
            let tris = triangulate(s, &f);
            let creases = s.creases_x().iter().filter(|&&c| c % f.step != 0.0).count();
            let cells = (120 + creases) * 8;
            assert_eq!(tris.len(), 2 * cells, "{s:?}");
            for v in tris.iter().flatten() {
                assert_eq!(v[1], height(s, v[0], v[2]), "{s:?} at {v:?}");
            }
        }
    }

    #[test]
    fn default_panel_is_600_by_300_at_2_mm() {
        let f = Scenario::Bump.default_field();
        let tris = triangulate(Scenario::FlatWall, &f);
        assert_eq!(tris.len(), 2 * 300 * 150);
        let xs: Vec<f64> = tris.iter().flatten().map(|v| v[0]).collect();
        assert!(xs.iter().all(|x| x % 2.0 == 0.0));
        assert_eq!(xs.iter().copied().fold(f64::INFINITY, f64::min), -300.0);
    }

    #[test]
    fn field_for_reaches_the_requested_count() {
        let f = Scenario::Console.field_for(Some(369_408));
        assert!(f.step < 8.0);
        assert!(triangulate(Scenario::Console, &f).len() >= 369_408);
        assert_eq!(Scenario::Bump.field_for(None), HeightField::default());
    }

    #[test]
    fn triangles_face_the_knee() {
        for t in triangulate(Scenario::Wave, &small()) {
            let [a, b, c] = t;
            let (e1, e2) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
            // y of the normal: e1.z e2.x - e1.x e2.z.
            assert!(e1[1] * e2[0] - e1[0] * e2[1] < 0.0);
        }
    }

    #[test]
    fn features_stand_where_documented() {
        // Towards the knee is smaller y.
        assert_eq!(height(Scenario::Bump, 0.0, 0.0), -10.0);
        assert_eq!(height(Scenario::Bump, 40.0, 0.0), 0.0);
        assert_eq!(height(Scenario::Depression, 0.0, 0.0), 5.0);
        assert_eq!(height(Scenario::Depression, RIDGE_X, 77.0), -10.0);
        assert_eq!(height(Scenario::Step, -0.5, 0.0), -10.0);
        assert_eq!(height(Scenario::Step, -0.25, 0.0), -5.0);
        assert!(height(Scenario::Ramp, -100.0, 0.0) < height(Scenario::Ramp, 100.0, 0.0));
        // GrowingWave: crests (x = 25 mod 100) stand further out towards
        // the front, hollows stay at 0.
        let crests: Vec<f64> = [225.0, 25.0, -175.0, -275.0]
            .iter()
            .map(|&x| height(Scenario::GrowingWave, x, 0.0))
            .collect();
        assert!(crests.windows(2).all(|w| w[1] < w[0]), "{crests:?}");
        assert!((crests[3] + 7.75).abs() < 1e-9);
        assert_eq!(height(Scenario::GrowingWave, -40.0, 0.0), 0.0);
        // Zeros on the lattice are exact.
        for x in [-300.0, -250.0, 0.0, 50.0, 100.0] {
            assert_eq!(height(Scenario::GrowingWave, x, 0.0), 0.0, "x = {x}");
            assert_eq!(height(Scenario::Wave, x, 0.0), 0.0, "x = {x}");
        }
        assert_eq!(height(Scenario::Wave, -75.0, 0.0), 5.0);
    }

    #[test]
    fn command_line_names_are_kebab_case() {
        let names: Vec<String> = Scenario::value_variants()
            .iter()
            .map(|s| s.to_possible_value().unwrap().get_name().to_string())
            .collect();
        assert_eq!(
            names,
            [
                "flat-wall",
                "ramp",
                "wave",
                "growing-wave",
                "step",
                "bump",
                "depression",
                "console"
            ]
        );
    }
}
