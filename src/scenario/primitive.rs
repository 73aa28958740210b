//! The named primitives a scenario file sums into its height field
//! `y(x, z)`, each with its parameters as written in the file (`kind =
//! "..."`), its contribution to y, the crease lines the lattice must carry
//! so that thin features and flat tops are tessellated exactly, and its
//! parameter checks.
//!
//! Analysis frame, mm: the surface faces -y and the knee comes from -y, so
//! a `height` (how far a feature **stands proud towards the knee**) lowers
//! y, and a `depth` raises it. Points `[x, z]` are in mm; angles
//! (`phase`, `tilt`) in degrees.

use serde::Deserialize;

use super::console::console_height;
use super::lattice::{cos2_bell, plateau, sin_turns};
use crate::grid::NODE_TOL;

/// One primitive of a scenario file; the file's surface is the sum of its
/// primitives' contributions.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Feature {
    /// `y += offset + slope_x x + slope_z z`.
    Plane(Plane),
    /// A sine wave along x (or along a tilted direction), optionally
    /// growing towards the front, crests only, or modulated along z.
    Wave(Wave),
    /// A round bump with a `cos^2` falloff.
    Bump(Bump),
    /// A smoothed block: a flat top with `cos^2` shoulders.
    Boss(Boss),
    /// A strip standing proud along a segment, optionally with a wavy top
    /// (the paper's Figure 6).
    Ridge(Ridge),
    /// A channel sunk along a segment, with a flat bottom.
    Groove(Groove),
    /// A thin rib with a sharp crest (a tent profile) along an axis-parallel
    /// segment.
    Rib(Rib),
    /// A step across x: the part in front stands proud.
    Step(Step),
    /// The benchmark console side, 1500 x 600 mm: a bulge, waves, a wavy
    /// ridge, switch-like bosses and a dip behind a protrusion.
    Console(Console),
}

/// `kind = "plane"`: `y += offset + slope_x x + slope_z z` (mm, slopes
/// dimensionless). A positive `slope_x` brings the surface closer to the
/// knee as it slides to -x.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plane {
    /// y at the origin (mm); default 0.
    #[serde(default)]
    pub offset: f64,
    /// dy/dx; default 0.
    #[serde(default)]
    pub slope_x: f64,
    /// dy/dz; default 0.
    #[serde(default)]
    pub slope_z: f64,
}

/// `kind = "wave"`: `y += a(x) e(z) sin(2 pi u / wavelength + phase)`, with
/// `u = x cos(tilt) + z sin(tilt)` (`u = x` untilted),
/// `a(x) = max(0, amplitude + growth (growth_from - x))` and
/// `e(z) = 0.5 (1 + cos(2 pi z / z_wavelength))` (1 without
/// `z_wavelength`). With `crests_only`, only the half-waves standing
/// towards the knee (y < 0) are kept and the rest is flat.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wave {
    /// Amplitude (mm) at `x = growth_from`.
    pub amplitude: f64,
    /// Wavelength (mm), > 0.
    pub wavelength: f64,
    /// Phase (degrees) added to the sine's argument; default 0.
    #[serde(default)]
    pub phase: f64,
    /// Amplitude gained per mm travelled towards -x (the front); default 0.
    #[serde(default)]
    pub growth: f64,
    /// The x (mm) where the amplitude is `amplitude`; default 0.
    #[serde(default)]
    pub growth_from: f64,
    /// Keep only the crests towards the knee; default false.
    #[serde(default)]
    pub crests_only: bool,
    /// Angle (degrees) of the wave's direction from +x towards +z: its
    /// crest lines are tilted by it from the z axis, so the knee-form's
    /// angle matters; default 0.
    #[serde(default)]
    pub tilt: f64,
    /// Period (mm) of the amplitude's modulation along z; none by default.
    pub z_wavelength: Option<f64>,
}

/// `kind = "bump"`: `y -= height cos^2(pi r / (2 radius))` for
/// `r = |(x, z) - center| < radius`, 0 beyond. The peak is exactly
/// `-height` at the centre.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bump {
    /// Centre `[x, z]` (mm).
    pub center: [f64; 2],
    /// Radius (mm), > 0.
    pub radius: f64,
    /// How far the peak stands proud towards the knee (mm); negative for a
    /// dip.
    pub height: f64,
}

/// `kind = "boss"`: a smoothed block, `y -= height p_x p_z`, where `p_x`
/// is 1 for `|x - cx| <= half_size[0]` and falls as `cos^2` to 0 over
/// `shoulder`, and `p_z` likewise in z. The top is exactly `-height`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Boss {
    /// Centre `[x, z]` (mm).
    pub center: [f64; 2],
    /// Half sizes of the flat top `[x, z]` (mm), >= 0.
    pub half_size: [f64; 2],
    /// Width of the `cos^2` shoulders (mm), > 0.
    pub shoulder: f64,
    /// How far the top stands proud towards the knee (mm).
    pub height: f64,
}

/// `kind = "ridge"`: a strip along the segment `from`-`to` with rounded
/// ends, `y -= (height + top_amplitude sin(2 pi s / top_wavelength)) p(d)`,
/// where `d` is the distance to the segment, `s` the distance along it from
/// `from`, and `p` is 1 for `d <= half_width` with a `cos^2` shoulder.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ridge {
    /// One end of the centre line `[x, z]` (mm).
    pub from: [f64; 2],
    /// The other end `[x, z]` (mm), not `from`.
    pub to: [f64; 2],
    /// Half width of the flat top (mm), >= 0.
    pub half_width: f64,
    /// Width of the `cos^2` shoulders (mm), > 0.
    pub shoulder: f64,
    /// How far the top stands proud towards the knee (mm).
    pub height: f64,
    /// Amplitude of the wavy top (mm); default 0 (a flat top).
    #[serde(default)]
    pub top_amplitude: f64,
    /// Wavelength of the wavy top along the ridge (mm), > 0; required when
    /// `top_amplitude` is not 0.
    pub top_wavelength: Option<f64>,
}

/// `kind = "groove"`: a channel along the segment `from`-`to` with rounded
/// ends, `y += depth p(d)`, with `d` and `p` as for a [`Ridge`]: a flat
/// bottom exactly `depth` behind the surface.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Groove {
    /// One end of the centre line `[x, z]` (mm).
    pub from: [f64; 2],
    /// The other end `[x, z]` (mm), not `from`.
    pub to: [f64; 2],
    /// Half width of the flat bottom (mm), >= 0.
    pub half_width: f64,
    /// Width of the `cos^2` walls (mm), > 0.
    pub shoulder: f64,
    /// How far the bottom lies behind the surface, away from the knee (mm).
    pub depth: f64,
}

/// `kind = "rib"`: a thin rib with a sharp crest, `y -= height max(0, 1 -
/// 2 d / width)`, `d` the distance to the segment `from`-`to`, which must
/// run along x or along z (and 0 within 1e-9 mm of the foot). The crest line and both feet get lattice lines,
/// so the mesh holds the rib exactly however coarse the step.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rib {
    /// One end of the crest line `[x, z]` (mm).
    pub from: [f64; 2],
    /// The other end `[x, z]` (mm): the same x or the same z as `from`.
    pub to: [f64; 2],
    /// Width at the foot (mm), > 0.
    pub width: f64,
    /// How far the crest stands proud towards the knee (mm).
    pub height: f64,
}

/// `kind = "step"`: a step across x, `y -= height clamp((at - x) / width,
/// 0, 1)`: unchanged for `x >= at`, `height` proud for `x <= at - width`,
/// a plane between (steep but finite, so the surface stays a function).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// The x (mm) where the step starts rising towards the front.
    pub at: f64,
    /// Width of the rise in x (mm), > 0.
    pub width: f64,
    /// How far the front stands proud towards the knee (mm).
    pub height: f64,
}

/// `kind = "console"`: the benchmark console side, a closed-form height
/// field 1500 x 600 mm (`src/scenario/console.rs`: a bulge towards the
/// knee, waves growing towards the front, a narrow ridge with a wavy top,
/// switch-like bosses 5-10 mm proud, a shallow dip behind a protrusion),
/// with its `(0, 0)` at `origin`; it covers x in `[0, 1500]` and z in
/// `[0, 600]` from there.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Console {
    /// Where the console's `(x, z) = (0, 0)` lies (mm); default the origin.
    #[serde(default)]
    pub origin: [f64; 2],
}

/// A segment's frame: its unit direction and length, for distances that
/// are exact when the segment runs along an axis (the direction is then
/// exactly `(0, +-1)` or `(+-1, 0)`).
struct Segment {
    from: [f64; 2],
    unit: [f64; 2],
    length: f64,
}

impl Segment {
    fn new(from: [f64; 2], to: [f64; 2]) -> Segment {
        let (dx, dz) = (to[0] - from[0], to[1] - from[1]);
        let length = dx.hypot(dz);
        Segment {
            from,
            unit: [dx / length, dz / length],
            length,
        }
    }

    /// `(d, s)`: the distance of `(x, z)` to the segment and the distance
    /// along it from `from` of its nearest point.
    fn locate(&self, x: f64, z: f64) -> (f64, f64) {
        let (px, pz) = (x - self.from[0], z - self.from[1]);
        let along = px * self.unit[0] + pz * self.unit[1];
        let across = pz * self.unit[0] - px * self.unit[1];
        let s = along.clamp(0.0, self.length);
        if s == along {
            (across.abs(), s)
        } else {
            (across.hypot(along - s), s)
        }
    }

    /// The lattice lines along a segment that runs along an axis: `[xs,
    /// zs]` at the given offsets across it from the centre line, and at its
    /// ends. None for a diagonal segment, which no lattice line can follow.
    fn creases(&self, to: [f64; 2], across: &[f64]) -> Option<[Vec<f64>; 2]> {
        let ends = |k: usize| vec![self.from[k], to[k]];
        let offsets = |c: f64| across.iter().map(|o| c + o).collect::<Vec<_>>();
        if self.from[0] == to[0] {
            Some([offsets(self.from[0]), ends(1)])
        } else if self.from[1] == to[1] {
            Some([ends(0), offsets(self.from[1])])
        } else {
            None
        }
    }
}

/// `+-a` and `+-(a + b)`, and 0: the offsets of a plateau's creases.
fn plateau_offsets(half: f64, shoulder: f64) -> [f64; 5] {
    [-half - shoulder, -half, 0.0, half, half + shoulder]
}

impl Feature {
    /// The primitive's name as written after `kind =`.
    pub fn kind(&self) -> &'static str {
        match self {
            Feature::Plane(_) => "plane",
            Feature::Wave(_) => "wave",
            Feature::Bump(_) => "bump",
            Feature::Boss(_) => "boss",
            Feature::Ridge(_) => "ridge",
            Feature::Groove(_) => "groove",
            Feature::Rib(_) => "rib",
            Feature::Step(_) => "step",
            Feature::Console(_) => "console",
        }
    }

    /// This primitive's contribution to y (mm) at `(x, z)` (mm).
    pub fn height(&self, x: f64, z: f64) -> f64 {
        match self {
            Feature::Plane(p) => p.offset + p.slope_x * x + p.slope_z * z,
            Feature::Wave(w) => w.height(x, z),
            Feature::Bump(b) => {
                -b.height * cos2_bell((x - b.center[0]).hypot(z - b.center[1]) / b.radius)
            }
            Feature::Boss(b) => {
                let px = plateau((x - b.center[0]).abs(), b.half_size[0], b.shoulder);
                let pz = plateau((z - b.center[1]).abs(), b.half_size[1], b.shoulder);
                -b.height * px * pz
            }
            Feature::Ridge(r) => {
                let (d, s) = Segment::new(r.from, r.to).locate(x, z);
                let top = match r.top_wavelength {
                    Some(wl) if r.top_amplitude != 0.0 => {
                        r.height + r.top_amplitude * sin_turns(s / wl)
                    }
                    _ => r.height,
                };
                -top * plateau(d, r.half_width, r.shoulder)
            }
            Feature::Groove(g) => {
                let (d, _) = Segment::new(g.from, g.to).locate(x, z);
                g.depth * plateau(d, g.half_width, g.shoulder)
            }
            Feature::Rib(r) => {
                let (d, _) = Segment::new(r.from, r.to).locate(x, z);
                let half = 0.5 * r.width;
                // A foot vertex is a rounding error (1e-14 mm) off the foot
                // (`10.3 - 0.3`), which the thin rib's steep flank would
                // turn into a height of 1e-13 mm: within SPEC's node
                // tolerance of the foot is on it.
                if d >= half - NODE_TOL {
                    0.0
                } else {
                    -r.height * (1.0 - d / half)
                }
            }
            Feature::Step(s) => -s.height * ((s.at - x) / s.width).clamp(0.0, 1.0),
            Feature::Console(c) => console_height(x - c.origin[0], z - c.origin[1]),
        }
    }

    /// `[xs, zs]`: the x of lines along z and the z of lines along x where
    /// this primitive has a crease, a flat top's edge, a crest or a peak
    /// that the lattice might step over; the tessellation puts vertices on
    /// those inside `x_range` (waves are enumerated only there). Diagonal
    /// ridges and grooves and tilted waves have none: no lattice line can
    /// follow them, so they are sampled like any smooth surface.
    pub fn creases(&self, x_range: (f64, f64)) -> [Vec<f64>; 2] {
        match self {
            Feature::Plane(_) | Feature::Console(_) => [vec![], vec![]],
            Feature::Wave(w) => [w.creases_x(x_range), vec![]],
            Feature::Bump(b) => [vec![b.center[0]], vec![b.center[1]]],
            Feature::Boss(b) => [0, 1].map(|k| {
                plateau_offsets(b.half_size[k], b.shoulder)
                    .iter()
                    .map(|o| b.center[k] + o)
                    .collect()
            }),
            Feature::Ridge(r) => Segment::new(r.from, r.to)
                .creases(r.to, &plateau_offsets(r.half_width, r.shoulder))
                .unwrap_or_default(),
            Feature::Groove(g) => Segment::new(g.from, g.to)
                .creases(g.to, &plateau_offsets(g.half_width, g.shoulder))
                .unwrap_or_default(),
            Feature::Rib(r) => {
                let h = 0.5 * r.width;
                let seg = Segment::new(r.from, r.to);
                let mut c = seg.creases(r.to, &[-h, 0.0, h]).unwrap_or_default();
                // The feet of the rounded ends.
                let k = if r.from[0] == r.to[0] { 1 } else { 0 };
                let (lo, hi) = (r.from[k].min(r.to[k]), r.from[k].max(r.to[k]));
                c[k].extend([lo - h, hi + h]);
                c
            }
            Feature::Step(s) => [vec![s.at - s.width, s.at], vec![]],
        }
    }

    /// The first parameter that makes no surface (a non-positive radius,
    /// wavelength, width or shoulder, a degenerate segment, a diagonal rib,
    /// a non-finite number), as a sentence naming it.
    pub fn check(&self) -> Result<(), String> {
        let mut numbers: Vec<(&str, f64)> = Vec::new();
        let mut positive: Vec<(&str, f64)> = Vec::new();
        let mut non_negative: Vec<(&str, f64)> = Vec::new();
        let mut segment = None;
        match self {
            Feature::Plane(p) => numbers.extend([
                ("offset", p.offset),
                ("slope_x", p.slope_x),
                ("slope_z", p.slope_z),
            ]),
            Feature::Wave(w) => {
                numbers.extend([
                    ("amplitude", w.amplitude),
                    ("phase", w.phase),
                    ("growth", w.growth),
                    ("growth_from", w.growth_from),
                    ("tilt", w.tilt),
                ]);
                positive.push(("wavelength", w.wavelength));
                positive.extend(w.z_wavelength.map(|v| ("z_wavelength", v)));
            }
            Feature::Bump(b) => {
                numbers.extend([
                    ("center", b.center[0]),
                    ("center", b.center[1]),
                    ("height", b.height),
                ]);
                positive.push(("radius", b.radius));
            }
            Feature::Boss(b) => {
                numbers.extend([
                    ("center", b.center[0]),
                    ("center", b.center[1]),
                    ("height", b.height),
                ]);
                non_negative.extend([("half_size", b.half_size[0]), ("half_size", b.half_size[1])]);
                positive.push(("shoulder", b.shoulder));
            }
            Feature::Ridge(r) => {
                numbers.extend([("height", r.height), ("top_amplitude", r.top_amplitude)]);
                non_negative.push(("half_width", r.half_width));
                positive.push(("shoulder", r.shoulder));
                match r.top_wavelength {
                    Some(wl) => positive.push(("top_wavelength", wl)),
                    None if r.top_amplitude != 0.0 => {
                        return Err("a ridge with a top_amplitude needs a top_wavelength".into());
                    }
                    None => {}
                }
                segment = Some((r.from, r.to));
            }
            Feature::Groove(g) => {
                numbers.push(("depth", g.depth));
                non_negative.push(("half_width", g.half_width));
                positive.push(("shoulder", g.shoulder));
                segment = Some((g.from, g.to));
            }
            Feature::Rib(r) => {
                numbers.push(("height", r.height));
                positive.push(("width", r.width));
                segment = Some((r.from, r.to));
                if r.from[0] != r.to[0] && r.from[1] != r.to[1] {
                    return Err(format!(
                        "a rib must run along x or along z (from {:?} to {:?}): the lattice \
                         puts vertices on its crest only then; use a ridge for a diagonal one",
                        r.from, r.to
                    ));
                }
            }
            Feature::Step(s) => {
                numbers.extend([("at", s.at), ("height", s.height)]);
                positive.push(("width", s.width));
            }
            Feature::Console(c) => {
                numbers.extend([("origin", c.origin[0]), ("origin", c.origin[1])])
            }
        }
        if let Some((from, to)) = segment {
            numbers.extend([
                ("from", from[0]),
                ("from", from[1]),
                ("to", to[0]),
                ("to", to[1]),
            ]);
            if from == to {
                return Err(format!("`from` and `to` are the same point {from:?}"));
            }
        }
        let all = numbers.iter().chain(&positive).chain(&non_negative);
        if let Some((name, v)) = all.into_iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("`{name}` must be a finite number, got {v}"));
        }
        if let Some((name, v)) = positive.iter().find(|(_, v)| *v <= 0.0) {
            return Err(format!("`{name}` must be positive, got {v}"));
        }
        if let Some((name, v)) = non_negative.iter().find(|(_, v)| *v < 0.0) {
            return Err(format!("`{name}` must not be negative, got {v}"));
        }
        Ok(())
    }
}

/// The most crease lines a wave reports: one per two triangles of
/// [`super::MAX_TRIANGLES`] (a lattice line makes at least two).
const MAX_CREASES: i64 = (super::lattice::MAX_TRIANGLES / 2) as i64;

impl Wave {
    /// The amplitude at x: grows by `growth` per mm towards -x, never below
    /// 0.
    fn amplitude_at(&self, x: f64) -> f64 {
        if self.growth == 0.0 {
            self.amplitude
        } else {
            (self.amplitude + self.growth * (self.growth_from - x)).max(0.0)
        }
    }

    /// The sine's argument in turns at `(x, z)`.
    fn turns(&self, x: f64, z: f64) -> f64 {
        let u = if self.tilt == 0.0 {
            x
        } else {
            let t = self.tilt.to_radians();
            x * t.cos() + z * t.sin()
        };
        let t = u / self.wavelength;
        if self.phase == 0.0 {
            t
        } else {
            t + self.phase / 360.0
        }
    }

    fn height(&self, x: f64, z: f64) -> f64 {
        let envelope = match self.z_wavelength {
            Some(zw) => 0.5 * (1.0 + sin_turns(z / zw + 0.25)),
            None => 1.0,
        };
        let y = self.amplitude_at(x) * envelope * sin_turns(self.turns(x, z));
        if self.crests_only { y.min(0.0) } else { y }
    }

    /// With `crests_only` and no tilt, the x of the zeros of the sine in
    /// `x_range` (where a crest meets the flat; none if there are more than
    /// [`MAX_CREASES`]); with `growth`, the x where the amplitude reaches 0.
    fn creases_x(&self, (lo, hi): (f64, f64)) -> Vec<f64> {
        let mut out = Vec::new();
        if self.crests_only && self.tilt == 0.0 {
            // Zeros where x / wavelength + phase / 360 = k / 2.
            let shift = self.phase / 360.0;
            let first = ((lo / self.wavelength + shift) * 2.0).floor() as i64;
            let last = ((hi / self.wavelength + shift) * 2.0).ceil() as i64;
            // More zeros than a lattice within `MAX_TRIANGLES` could hold
            // lines for would only exhaust memory: such a wave is sampled.
            // A wavelength tiny against the extent saturates the casts to
            // i64::MIN and i64::MAX, whose difference overflows: checked,
            // so that too is "more zeros" (found by the fuzzer's seeded
            // run, tests/fuzz/regressions/scenario).
            if last.checked_sub(first).is_some_and(|n| n <= MAX_CREASES) {
                out.extend((first..=last).map(|k| (k as f64 * 0.5 - shift) * self.wavelength));
            }
        }
        if self.growth != 0.0 {
            out.push(self.growth_from + self.amplitude / self.growth);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rib_along_z() -> Feature {
        Feature::Rib(Rib {
            from: [10.3, -50.0],
            to: [10.3, 50.0],
            width: 0.6,
            height: 5.0,
        })
    }

    #[test]
    fn thin_rib_is_a_tent_with_creases_on_its_crest_and_feet() {
        let rib = rib_along_z();
        assert_eq!(rib.height(10.3, 0.0), -5.0);
        assert_eq!(rib.height(10.3, 50.0), -5.0);
        assert_eq!(rib.height(10.0, 0.0), 0.0);
        assert_eq!(rib.height(10.9, 0.0), 0.0);
        // Half way down the flank: 0.15 mm from the crest of a 0.3 mm flank.
        assert!((rib.height(10.45, 3.0) + 2.5).abs() < 1e-9);
        // Beyond the end, the rounded end falls off with the distance.
        assert_eq!(rib.height(10.3, 50.3), 0.0);
        let [xs, zs] = rib.creases((-100.0, 100.0));
        assert!(xs.contains(&10.3));
        assert!(xs.iter().any(|&x| (x - 10.0).abs() < 1e-12));
        assert!(xs.iter().any(|&x| (x - 10.6).abs() < 1e-12));
        assert!(zs.contains(&-50.0) && zs.contains(&50.0));
    }

    #[test]
    fn segments_along_an_axis_give_exact_distances() {
        let seg = Segment::new([0.0, -7.0], [0.0, 13.0]);
        assert_eq!(seg.locate(0.7, 3.1), (0.7, 10.1));
        assert_eq!(seg.locate(-3.0, 17.0), (5.0, 20.0));
        let diag = Segment::new([0.0, 0.0], [3.0, 4.0]);
        let (d, s) = diag.locate(4.0, -3.0);
        assert!((d - 5.0).abs() < 1e-12 && s == 0.0);
    }

    #[test]
    fn checks_name_the_bad_parameter() {
        let bad = Feature::Bump(Bump {
            center: [0.0, 0.0],
            radius: 0.0,
            height: 1.0,
        });
        assert_eq!(bad.check().unwrap_err(), "`radius` must be positive, got 0");
        let diagonal = Feature::Rib(Rib {
            from: [0.0, 0.0],
            to: [1.0, 1.0],
            width: 1.0,
            height: 1.0,
        });
        assert!(diagonal.check().unwrap_err().contains("along x or along z"));
        let nan = Feature::Step(Step {
            at: f64::NAN,
            width: 1.0,
            height: 1.0,
        });
        assert!(
            nan.check()
                .unwrap_err()
                .starts_with("`at` must be a finite number")
        );
        assert_eq!(rib_along_z().check(), Ok(()));
    }

    #[test]
    fn crests_only_waves_crease_at_their_zeros() {
        let w = Wave {
            amplitude: 2.0,
            wavelength: 100.0,
            phase: 180.0,
            growth: 0.01,
            growth_from: 300.0,
            crests_only: true,
            tilt: 0.0,
            z_wavelength: None,
        };
        let xs = w.creases_x((-120.0, 120.0));
        for x in [-100.0, -50.0, 0.0, 50.0, 100.0] {
            assert!(xs.contains(&x), "{x} in {xs:?}");
            assert_eq!(w.height(x, 0.0), 0.0);
        }
        // The amplitude would reach 0 at x = 300 + 2 / 0.01 = 500.
        assert!(xs.contains(&500.0));
    }
}
