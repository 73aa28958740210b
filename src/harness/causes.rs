//! Why the grid and the exact knee-form disagree, as SPEC names the causes
//! ("Blind spots", "What the window does not fix: the level error"), and
//! the failing figures of a comparison with their mechanism.
//!
//! * **Blind.** The exact knee-form touched a flagged blind spot (a cell
//!   whose mesh sticks out past its sampled corners by more than the
//!   blind-spot depth, [`crate::blind`]) at or before the disagreement, in
//!   the same slide: the grid cannot see what deflected it.
//! * **Level error.** The grid's level is too deep (it follows the surface
//!   only at the nodes it met), so a node poking through it by a little is
//!   a grid strike the exact knee-form never touches: a false alarm, on the
//!   safe side. A grid strike is explained by it when its node lies within
//!   the stated bound of the grid's level error of the exact knee-form at
//!   that travel ([`super::metrics::compare`]).
//! * **Undecided.** The disagreement is on a contact in the tie band:
//!   either answer is right at this pitch.
//! * **Oracle failure.** No exact answer for the pair: never counted
//!   clear.
//! * **Rim.** A missed exact strike lies outside the grid's footprint at
//!   its travel (the polygon through its rows' ends): the knee-form's
//!   outline bulges past it, up to a pitch across the outline and several
//!   millimetres along it where the outline runs almost along the slide,
//!   and the exact knee-form's edge touched the part in that rim (a
//!   surface sloping up towards the knee-form's side, a crease crossing a
//!   rounded corner). It shrinks with the pitch, at half order along the
//!   slide, but is a miss: it fails the verdict.
//! * **Unexplained.** None of the above: a real disagreement.

use serde::{Deserialize, Serialize};

use crate::blind::{CellDepths, cell_depths};
use crate::grid::{GridSpec, HeightGrid};
use crate::mesh::Triangle;

/// How far outside a cell's closed square a point may lie and still be in
/// it (mm): witnesses on a cell's edge belong to both cells.
const CELL_TOL: f64 = 1e-6;

/// How far from a touched mesh point (in pitches, xz) the grid's nearest
/// node under the knee-form may lie ([`Cells::rise_near`]).
pub const RISE_REACH: f64 = std::f64::consts::SQRT_2;

/// What the harness knows of a grid's cells: the depth each hides between
/// its sampled corners, and which are flagged blind spots.
#[derive(Debug, Clone, PartialEq)]
pub struct Cells {
    spec: GridSpec,
    depths: CellDepths,
    threshold: f64,
    /// The grid's heights (mm), row-major.
    heights: Vec<f64>,
}

impl Cells {
    /// The cells of `grid` (sampled from `triangles`), blind spots being
    /// those deeper than `threshold` mm (the analysis's `--blind-depth`).
    pub fn of(triangles: &[Triangle], grid: &HeightGrid, threshold: f64) -> Cells {
        Cells {
            spec: grid.spec,
            depths: cell_depths(triangles, grid),
            threshold,
            heights: grid.h.clone(),
        }
    }

    /// The grid's pitch (mm).
    pub fn pitch(&self) -> f64 {
        self.spec.pitch
    }

    /// The cells whose closed square holds `(x, z)` (mm), within
    /// [`CELL_TOL`].
    fn around(&self, x: f64, z: f64) -> impl Iterator<Item = (usize, usize)> + '_ {
        let spec = self.spec;
        let span = |v: f64, origin: f64, cells: usize| {
            let lo = ((v - origin - CELL_TOL) / spec.pitch).floor().max(0.0);
            let hi = ((v - origin + CELL_TOL) / spec.pitch).floor();
            let hi = hi.min(cells as f64 - 1.0);
            if hi < lo || !lo.is_finite() || !hi.is_finite() {
                0..0
            } else {
                lo as usize..hi as usize + 1
            }
        };
        let has_cells = !self.depths.cells.is_empty();
        let (cx, cz) = if has_cells {
            (spec.nx - 1, spec.nz - 1)
        } else {
            (0, 0)
        };
        let columns = span(x, spec.x(0), cx);
        span(z, spec.z(0), cz).flat_map(move |j| columns.clone().map(move |i| (i, j)))
    }

    /// Whether the mesh point `p` (`[x, y, z]`, mm, analysis frame) lies in
    /// a flagged blind spot, proud of every sampled corner of its cell: the
    /// exact knee-form touching it touches what the grid cannot see (the
    /// feature itself or its foot, anywhere the mesh stands out past the
    /// grid's samples).
    pub fn touches_blind_spot(&self, p: [f64; 3]) -> bool {
        self.around(p[0], p[2]).any(|(i, j)| {
            self.depths.depth(i, j) > self.threshold
                && p[1] < self.depths.reference(i, j) - CELL_TOL
        })
    }

    /// Whether a node on the part among `rows` (`(j, i_lo, i_hi)`, the
    /// knee-form's footprint) lies within [`RISE_REACH`] pitches of `p` in
    /// xz: whether the grid samples the part under the knee-form near the
    /// point the exact knee-form touches.
    pub fn samples_near(&self, p: [f64; 3], rows: &[(usize, i64, i64)]) -> bool {
        let spec = self.spec;
        let reach = RISE_REACH * spec.pitch + CELL_TOL;
        rows.iter().any(|&(j, lo, hi)| {
            let (lo, hi) = (lo.max(0), hi.min(spec.nx as i64 - 1));
            let dz = spec.z(j) - p[2];
            if dz.abs() > reach {
                return false;
            }
            let dx = (reach * reach - dz * dz).sqrt();
            let first = ((p[0] - dx - spec.x(0)) / spec.pitch).ceil().max(lo as f64);
            let last = ((p[0] + dx - spec.x(0)) / spec.pitch)
                .floor()
                .min(hi as f64);
            first <= last
                && (first as usize..=last as usize)
                    .any(|i| self.heights[j * spec.nx + i].is_finite())
        })
    }

    /// Whether the mesh point `p` lies outside the grid's footprint after
    /// `travel` mm of slide, the footprint's rows at the push being `rows`
    /// (`(j, i_lo, i_hi)`): beyond its first or last row, or outside the
    /// polygon through the ends of the two rows around it (their spans
    /// interpolated linearly in z). The knee-form's outline bulges past
    /// that polygon, by up to a pitch across the outline and, where the
    /// outline runs almost along the slide (the rounded corners' sides),
    /// by several millimetres along it (the sagitta's run, about
    /// `sqrt(2 r p)` for a corner of plan radius `r`: half order); a point
    /// touched there lies in that rim, where the grid has no node at this
    /// pitch.
    pub fn outside_footprint(&self, p: [f64; 3], rows: &[(usize, i64, i64)], travel: f64) -> bool {
        let spec = self.spec;
        let t = CELL_TOL;
        let x = |i: i64| spec.x(0) + i as f64 * spec.pitch - travel;
        let below = rows.iter().filter(|r| spec.z(r.0) <= p[2] + t);
        let above = rows.iter().filter(|r| spec.z(r.0) >= p[2] - t);
        let nearest_below = below.max_by(|a, b| spec.z(a.0).total_cmp(&spec.z(b.0)));
        let nearest_above = above.min_by(|a, b| spec.z(a.0).total_cmp(&spec.z(b.0)));
        let (Some(&(jb, lo_b, hi_b)), Some(&(ja, lo_a, hi_a))) = (nearest_below, nearest_above)
        else {
            return true;
        };
        let (zb, za) = (spec.z(jb), spec.z(ja));
        // How far from the row below towards the row above `p` lies (0 on
        // the row below; 0 when both are one row).
        let u = if za > zb {
            ((p[2] - zb) / (za - zb)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let lo = x(lo_b) + u * (x(lo_a) - x(lo_b));
        let hi = x(hi_b) + u * (x(hi_a) - x(hi_b));
        !(lo - t..=hi + t).contains(&p[0])
    }

    /// How much higher than the mesh point `p` (`[x, y, z]`, mm) the grid
    /// may be wherever the knee-form touches `p`: the largest `h - y` over
    /// the nodes within [`RISE_REACH`] pitches of `p` in xz (mm, `>= 0`).
    ///
    /// A knee-form touching `p` on the rim of its outline covers no corner
    /// of `p`'s cell, perhaps, but covers a node within `sqrt 2` pitches of it
    /// (the outline is far wider than a pitch), and that node lies at most
    /// this much above `p`: the grid's level there is at most this much
    /// deeper than the exact one. About the local slope times `sqrt 2` times the
    /// pitch: it shrinks with the pitch.
    pub fn rise_near(&self, p: [f64; 3]) -> f64 {
        self.rises_near(p).map_or(0.0, |(_, highest)| highest)
    }

    /// How much higher than the mesh point `p` the *lowest* node within
    /// [`RISE_REACH`] pitches of it lies (mm, `>= 0`; `+inf` where no node
    /// of the part is that near): the least by which the grid's best node
    /// near a touched point can misjudge it.
    pub fn rise_of_lowest_near(&self, p: [f64; 3]) -> f64 {
        self.rises_near(p)
            .map_or(f64::INFINITY, |(lowest, _)| lowest.max(0.0))
    }

    /// The least and the largest `h - y` over the nodes of the part within
    /// [`RISE_REACH`] pitches of `p` in xz; `None` where there is none.
    fn rises_near(&self, p: [f64; 3]) -> Option<(f64, f64)> {
        let spec = self.spec;
        let reach = RISE_REACH * spec.pitch;
        let index = |v: f64, origin: f64, n: usize| {
            let lo = ((v - reach - origin) / spec.pitch).ceil().max(0.0);
            let hi = ((v + reach - origin) / spec.pitch)
                .floor()
                .min(n as f64 - 1.0);
            if hi < lo || !lo.is_finite() || !hi.is_finite() {
                0..0
            } else {
                lo as usize..hi as usize + 1
            }
        };
        let mut found: Option<(f64, f64)> = None;
        for j in index(p[2], spec.z(0), spec.nz) {
            for i in index(p[0], spec.x(0), spec.nx) {
                let (dx, dz) = (spec.x(i) - p[0], spec.z(j) - p[2]);
                let h = self.heights[j * spec.nx + i];
                if dx.hypot(dz) <= reach + CELL_TOL && h.is_finite() {
                    let r = h - p[1];
                    found = Some(found.map_or((r, r), |(lo, hi)| (lo.min(r), hi.max(r))));
                }
            }
        }
        found.map(|(lo, hi)| (lo, hi.max(0.0)))
    }
}

/// Why a figure fails its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mechanism {
    /// Downstream of a flagged blind spot the exact knee-form touched.
    Blind,
    /// The grid's level error: false alarms on the safe side, within the
    /// stated bound.
    LevelError,
    /// Contacts in the tie band.
    Undecided,
    /// Pairs the oracle failed on.
    OracleFailure,
    /// Exact strikes in the knee-form's rim: between its outline and the
    /// grid's footprint, which reaches up to a pitch less far; the grid
    /// has no node there at this pitch (misses, on the unsafe side: they
    /// fail the verdict).
    Rim,
    /// A real disagreement.
    Unexplained,
}

impl Mechanism {
    /// The name `verify.json` writes.
    pub fn name(self) -> &'static str {
        match self {
            Mechanism::Blind => "blind",
            Mechanism::LevelError => "level-error",
            Mechanism::Undecided => "undecided",
            Mechanism::OracleFailure => "oracle-failure",
            Mechanism::Rim => "rim",
            Mechanism::Unexplained => "unexplained",
        }
    }

    /// Whether a figure failing by this mechanism fails the verdict: blind
    /// disagreements are reported apart, the level error's false alarms
    /// against their bound and undecided contacts beside the decided ones
    /// (SPEC); an oracle failure or an unexplained figure fails.
    pub fn fails_verdict(self) -> bool {
        matches!(
            self,
            Mechanism::OracleFailure | Mechanism::Rim | Mechanism::Unexplained
        )
    }
}

/// Which side of the guarantee a figure speaks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Side {
    /// Exact strikes the grid misses: safety.
    Miss,
    /// Grid strikes with no exact one near: cost (design freedom).
    FalseAlarm,
    /// The push level or the travel to the first strike.
    Level,
    /// Pairs without an answer to compare.
    Coverage,
}

/// One failing figure of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The metric (a row of `verify.csv`'s statistics) or count.
    pub metric: String,
    /// Its value: mm for a metric (`null` when infinite), a count for a
    /// count.
    pub value: Option<f64>,
    /// Why it fails.
    pub mechanism: Mechanism,
    /// Which side of the guarantee it speaks for.
    pub side: Side,
    /// Whether it fails the verdict ([`Mechanism::fails_verdict`]).
    pub fails_verdict: bool,
    /// Whether the value (a distance) is within `sqrt 2` pitches: a
    /// sampling error of the size the grid makes at this pitch, which a
    /// finer pitch shrinks where the figure converges (`results/`).
    #[serde(default)]
    pub within_pitch: bool,
}

impl Failure {
    /// A failing figure `metric` of `value` by `mechanism`.
    pub fn new(metric: &str, value: f64, mechanism: Mechanism, side: Side) -> Failure {
        Failure {
            metric: metric.into(),
            value: Some(value).filter(|v| v.is_finite()),
            mechanism,
            side,
            fails_verdict: mechanism.fails_verdict(),
            within_pitch: false,
        }
    }

    /// This failure, marked within `sqrt 2` pitches of `pitch` (mm) where
    /// its value (a distance, not a count) is.
    pub fn at_pitch(mut self, pitch: f64) -> Failure {
        self.within_pitch = self.side != Side::Coverage
            && self
                .value
                .is_some_and(|v| v <= std::f64::consts::SQRT_2 * pitch + 1e-9);
        self
    }

    /// The figure in words, for a console line.
    pub fn phrase(&self) -> String {
        let value = match self.value {
            Some(v) if self.side == Side::Coverage => format!("{v}"),
            Some(v) => format!("{v:.3} mm"),
            None => "infinite".into(),
        };
        let pitch = if self.within_pitch {
            ", within sqrt 2 pitches"
        } else {
            ""
        };
        format!("{} {value} ({}{pitch})", self.metric, self.mechanism.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::tessellate;

    /// A plane `y = slope * x` at pitch 2 mm over [0, 40] x [0, 20], with a
    /// rib 0.4 mm wide and 3 mm proud (towards the knee, -y) along z at
    /// x = 21 (between node columns 20 and 22).
    fn ribbed(slope: f64) -> (Vec<Triangle>, HeightGrid) {
        let xs = [0.0, 10.0, 20.0, 20.8, 21.0, 21.2, 22.0, 30.0, 40.0];
        let zs = [0.0, 10.0, 20.0];
        let y = |x: f64| {
            let rib = if (20.8..=21.2).contains(&x) { 3.0 } else { 0.0 };
            slope * x - rib
        };
        let triangles = tessellate(&xs, &zs, |i, _| y(xs[i]));
        let spec = GridSpec {
            pitch: 2.0,
            i_origin: 0,
            j_origin: 0,
            nx: 21,
            nz: 11,
        };
        let grid = HeightGrid::sample(&triangles, spec);
        (triangles, grid)
    }

    #[test]
    fn a_point_on_a_flagged_rib_or_its_foot_touches_a_blind_spot_and_the_plane_does_not() {
        let (triangles, grid) = ribbed(0.0);
        let cells = Cells::of(&triangles, &grid, 0.5);
        assert!(cells.touches_blind_spot([21.0, -3.0, 7.0]), "the rib's top");
        assert!(cells.touches_blind_spot([20.9, -1.0, 7.0]), "its flank");
        assert!(
            !cells.touches_blind_spot([21.0, -3.0, 30.0]),
            "off the grid"
        );
        assert!(!cells.touches_blind_spot([15.0, 0.0, 7.0]), "the plane");
        // In the rib's cell but on the plane at the sampled corners' height.
        assert!(!cells.touches_blind_spot([20.2, 0.0, 7.0]));
        // A deeper threshold flags nothing.
        let deep = Cells::of(&triangles, &grid, 3.5);
        assert!(!deep.touches_blind_spot([21.0, -3.0, 7.0]));
    }

    #[test]
    fn the_rise_near_a_point_is_the_slope_times_sqrt_2_pitches_up_to_the_nodes() {
        let (triangles, grid) = ribbed(0.25);
        let cells = Cells::of(&triangles, &grid, 10.0);
        // On the plane at x = 9: the highest node within 2.83 mm lies at
        // x = 10 (x = 12 is 3 mm away), 1 mm uphill.
        let p = [9.0, 0.25 * 9.0, 7.0];
        let rise = cells.rise_near(p);
        let reach = RISE_REACH * 2.0;
        let highest_x = (0..=20)
            .map(|i| 2.0 * f64::from(i))
            .filter(|&x| {
                (0..=10).any(|j| (x - 9.0).hypot(2.0 * f64::from(j) - 7.0) <= reach + 1e-9)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(highest_x, 10.0);
        assert!((rise - 0.25 * (highest_x - 9.0)).abs() < 1e-12, "{rise}");
        // A point above every node near it rises by nothing.
        assert_eq!(cells.rise_near([9.0, 100.0, 7.0]), 0.0);
    }

    #[test]
    fn a_point_between_the_footprint_s_outer_row_and_the_outline_is_in_the_rim() {
        let (triangles, grid) = ribbed(0.0);
        let cells = Cells::of(&triangles, &grid, 0.5);
        // Rows j = 2..=4 (z = 4, 6, 8), columns 3..=6 (x = 6..12) at the
        // push.
        let rows = [(2, 3, 6), (3, 3, 6), (4, 3, 6)];
        let inside =
            |x: f64, z: f64, travel: f64| !cells.outside_footprint([x, 0.0, z], &rows, travel);
        assert!(inside(9.0, 5.0, 0.0));
        assert!(inside(6.0, 8.0, 0.0), "on the outer nodes");
        assert!(!inside(9.0, 8.5, 0.0), "beyond the last row");
        assert!(!inside(9.0, 3.5, 0.0), "before the first row");
        assert!(!inside(12.5, 5.0, 0.0), "beyond the rows' span in x");
        // After 3 mm of slide the footprint spans x = 3..9.
        assert!(inside(3.5, 5.0, 3.0));
        assert!(!inside(11.0, 5.0, 3.0));
        // A footprint whose outline runs at a slant between two rows: row
        // j = 2 spans x = 6..12, row j = 3 x = 12..18. Half way between
        // them the footprint's polygon spans x = 9..15: x = 7 lies in the
        // span of the row below but outside the polygon, in the rim (the
        // console's 5.6 mm miss at 0.5 mm, where the outline's rounded
        // corner runs almost along the slide between two rows).
        let slanted = [(2, 3, 6), (3, 6, 9)];
        let inside = |x: f64, z: f64| !cells.outside_footprint([x, 0.0, z], &slanted, 0.0);
        assert!(!inside(7.0, 5.0));
        assert!(inside(9.5, 5.0));
        assert!(inside(14.5, 5.0));
        assert!(!inside(15.5, 5.0));
        assert!(inside(7.0, 4.0), "on the row below");
    }

    #[test]
    fn only_unexplained_figures_rim_misses_and_oracle_failures_fail_the_verdict() {
        for (m, fails) in [
            (Mechanism::Blind, false),
            (Mechanism::LevelError, false),
            (Mechanism::Undecided, false),
            (Mechanism::OracleFailure, true),
            (Mechanism::Rim, true),
            (Mechanism::Unexplained, true),
        ] {
            assert_eq!(m.fails_verdict(), fails, "{m:?}");
            let f = Failure::new("miss_distance_decided", 2.5, m, Side::Miss);
            assert_eq!(f.fails_verdict, fails);
            assert!(f.phrase().contains(m.name()));
        }
        let json = serde_json::to_string(&Failure::new(
            "area_miss_distance_decided",
            f64::INFINITY,
            Mechanism::LevelError,
            Side::FalseAlarm,
        ))
        .unwrap();
        assert!(json.contains(r#""mechanism":"level-error""#), "{json}");
        assert!(json.contains(r#""value":null"#), "{json}");
        assert!(json.contains(r#""side":"false-alarm""#), "{json}");
    }
}
