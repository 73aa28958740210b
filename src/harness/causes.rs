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
//! * **Rim.** A missed exact strike the grid samples late: no node of
//!   the part within `sqrt 2` pitches of the touched point is met by the
//!   slide within `sqrt 2` pitches more of travel (a sliver of the part
//!   between the knee-form's outline and the footprint's outermost row;
//!   under the window rule such a strike is undecided, the grid's drop
//!   error there being unbounded), or the nearest one is met only later
//!   (the outline crossing the grid's rows at a shallow angle, a rounded
//!   corner's side over a crease: on the console at 0.5 mm, the node 0.02
//!   mm from the touched point met 1.3 mm of travel later, the one 0.11 mm
//!   away 3 mm later). It fails the verdict.
//! * **Sampling.** An unexplained residual within `sqrt 2` pitches: the
//!   grid's first-order error at this pitch; or a start's miss inside the
//!   footprint beyond that which, slid again with the grid sampled at half
//!   the pitch against the same exact trace, falls to at most half, or,
//!   where it falls but not to half, at a quarter of the pitch to at most
//!   a quarter (shown by refinement: on trimesh's teapot and the console, exact
//!   strikes along a crease of the mesh between two node rows, which the
//!   grid's strikes meet later); or a brief strike, lasting less than
//!   `sqrt 2` pitches of travel before the knee-form touches elsewhere,
//!   whose nodes the grid meets after it (its miss falls once the pitch
//!   is finer than the touch). It fails the verdict (the pitch is too
//!   coarse for the tolerance).
//! * **Unexplained.** None of the above: a real disagreement.

use serde::{Deserialize, Serialize};

use crate::blind::{BlindSpot, blind_spots, reference_height};
use crate::grid::{GridSpec, HeightGrid};
use crate::mesh::Triangle;

use super::trace::FootprintSpan;

/// How far outside a cell's closed square a point may lie and still be in
/// it (mm): witnesses on a cell's edge belong to both cells.
const CELL_TOL: f64 = 1e-6;

/// How far from a touched mesh point (in pitches, xz) the grid's nearest
/// node under the knee-form may lie ([`Cells::rise_near`]).
pub(crate) const RISE_REACH: f64 = std::f64::consts::SQRT_2;

/// What the harness knows of a grid's cells: which are flagged blind spots
/// (the mesh sticks out past their sampled corners by more than the
/// analysis's `--blind-depth`), and the grid's heights.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cells {
    spec: GridSpec,
    /// The blind spots' cells `(i, j)`, sorted, each with its reference
    /// height (the lowest sampled corner, mm).
    blind: Vec<((usize, usize), f64)>,
    /// The grid's heights (mm), row-major.
    heights: Vec<f64>,
}

impl Cells {
    /// The cells of `grid` (sampled from `triangles`), blind spots being
    /// those deeper than `threshold` mm (the analysis's `--blind-depth`).
    pub fn of(triangles: &[Triangle], grid: &HeightGrid, threshold: f64) -> Cells {
        Cells::of_blind_spots(grid, &blind_spots(triangles, grid, threshold))
    }

    /// The cells of `grid` whose blind spots are `spots` (an analysis's:
    /// found by [`blind_spots`] on the same grid, at its threshold),
    /// without finding them again.
    pub fn of_blind_spots(grid: &HeightGrid, spots: &[BlindSpot]) -> Cells {
        let mut blind: Vec<((usize, usize), f64)> = spots
            .iter()
            .map(|s| {
                (
                    (s.i, s.j),
                    reference_height(grid, s.i, s.j).unwrap_or(f64::NAN),
                )
            })
            .collect();
        blind.sort_unstable_by_key(|&(cell, _)| cell);
        Cells {
            spec: grid.spec,
            blind,
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
        let (cx, cz) = if spec.nx >= 2 && spec.nz >= 2 {
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
        if self.blind.is_empty() {
            return false;
        }
        self.around(p[0], p[2]).any(|(i, j)| {
            self.blind
                .binary_search_by(|(cell, _)| cell.cmp(&(i, j)))
                .is_ok_and(|k| p[1] < self.blind[k].1 - CELL_TOL)
        })
    }

    /// Whether a node on the part that the slide has met by `travel` mm
    /// (the start's footprint rows at the push being `rows`) lies within
    /// [`RISE_REACH`] pitches of `p` in xz: whether the grid samples the
    /// part under the knee-form near the point the exact knee-form touches.
    pub fn samples_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> bool {
        self.rises_near(p, Some((rows, travel, false))).is_some()
    }

    /// As [`Cells::samples_near`], counting only the nodes met during the
    /// slide (not those under the knee-form at the push, which set the
    /// pushed level and are never struck, SPEC): whether the grid may
    /// strike near `p` by `travel` mm.
    pub fn strikes_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> bool {
        self.rises_near(p, Some((rows, travel, true))).is_some()
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
        self.rises_near(p, None).map_or(0.0, |(_, highest)| highest)
    }

    /// How much higher than the mesh point `p` the *lowest* node within
    /// [`RISE_REACH`] pitches of it and met by the slide by `travel` mm
    /// (the start's footprint rows at the push `rows`) lies (mm, `>= 0`;
    /// `+inf` where the slide met no node of the part that near): the least
    /// by which the grid's best node near a touched point can misjudge it.
    /// Only the nodes the grid meets in the slide count: those under the
    /// knee-form at the push are never struck (SPEC).
    #[cfg(test)]
    pub fn rise_of_lowest_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> f64 {
        self.rises_near(p, Some((rows, travel, true)))
            .map_or(f64::INFINITY, |(lowest, _)| lowest.max(0.0))
    }

    /// [`Cells::samples_near`] then [`Cells::rise_near`] (`+inf` where
    /// not sampled), and [`Cells::rise_of_lowest_near`], of one point in
    /// one walk over the nodes near it: what the level-error bound asks of
    /// every exact contact. The same figures to the bit: each is folded
    /// over the same nodes in the same order.
    pub fn rises_at(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> (f64, f64) {
        let (mut sampled, mut highest, mut lowest) = (false, None::<f64>, None::<f64>);
        for (i, j, _, h) in self.nodes_near(p) {
            let r = h - p[1];
            highest = Some(highest.map_or(r, |hi| hi.max(r)));
            let met = met_at(rows, i, j, self.spec.x(i)).filter(|&m| m <= travel + CELL_TOL);
            sampled |= met.is_some();
            if met.is_some_and(|m| m > CELL_TOL) {
                lowest = Some(lowest.map_or(r, |lo| lo.min(r)));
            }
        }
        let rise = match (sampled, highest) {
            (true, Some(hi)) => hi.max(0.0),
            _ => f64::INFINITY,
        };
        (rise, lowest.map_or(f64::INFINITY, |lo| lo.max(0.0)))
    }

    /// When the slide meets the node of the part nearest `p` in xz (within
    /// [`RISE_REACH`] pitches), the start's footprint rows at the push
    /// being `rows` (mm of travel: 0 for one under the knee-form at the
    /// push; `+inf` where it never does, or no node of the part is that
    /// near).
    pub fn nearest_node_met_at(&self, p: [f64; 3], rows: &[FootprintSpan]) -> f64 {
        self.nodes_near(p)
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .and_then(|(i, j, _, _)| met_at(rows, i, j, self.spec.x(i)))
            .unwrap_or(f64::INFINITY)
    }

    /// The nodes of the part within [`RISE_REACH`] pitches of `p` in xz:
    /// `(i, j, distance, height)`.
    fn nodes_near(&self, p: [f64; 3]) -> impl Iterator<Item = (usize, usize, f64, f64)> + '_ {
        let spec = self.spec;
        let reach = RISE_REACH * spec.pitch;
        let index = move |v: f64, origin: f64, n: usize| {
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
        let columns = index(p[0], spec.x(0), spec.nx);
        index(p[2], spec.z(0), spec.nz)
            .flat_map(move |j| columns.clone().map(move |i| (i, j)))
            .filter_map(move |(i, j)| {
                let d = (spec.x(i) - p[0]).hypot(spec.z(j) - p[2]);
                let h = self.heights[j * spec.nx + i];
                (d <= reach + CELL_TOL && h.is_finite()).then_some((i, j, d, h))
            })
    }

    /// The least and the largest `h - y` over the nodes of the part within
    /// [`RISE_REACH`] pitches of `p` in xz (and, given `(rows, travel,
    /// slide_only)`, met by the slide of the footprint whose rows at the
    /// push are `rows` by `travel` mm: under it at the push too unless
    /// `slide_only`); `None` where there is none.
    fn rises_near(
        &self,
        p: [f64; 3],
        footprint: Option<(&[FootprintSpan], f64, bool)>,
    ) -> Option<(f64, f64)> {
        let covered = |i: usize, j: usize| {
            footprint.is_none_or(|(rows, travel, slide_only)| {
                met_at(rows, i, j, self.spec.x(i))
                    .is_some_and(|m| m <= travel + CELL_TOL && !(slide_only && m <= CELL_TOL))
            })
        };
        self.nodes_near(p)
            .filter(|&(i, j, _, _)| covered(i, j))
            .map(|(_, _, _, h)| h - p[1])
            .fold(None, |found: Option<(f64, f64)>, r| {
                Some(found.map_or((r, r), |(lo, hi)| (lo.min(r), hi.max(r))))
            })
            .map(|(lo, hi)| (lo, hi.max(0.0)))
    }
}

/// When the slide meets node `(i, j)` (its x `x_i`), by the start's
/// footprint rows at the push `rows` ([`FootprintSpan::meets`]; sorted by
/// row, as [`super::trace::GridTrace::push_rows`] are); `None` where it
/// never does.
fn met_at(rows: &[FootprintSpan], i: usize, j: usize, x_i: f64) -> Option<f64> {
    debug_assert!(rows.is_sorted_by_key(|r| r.j), "push rows by row");
    rows[rows.partition_point(|r| r.j < j)..]
        .iter()
        .take_while(|r| r.j == j)
        .find_map(|r| r.meets(i as i64, x_i))
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
    /// Exact strikes in the knee-form's rim, which the grid samples late:
    /// no node of the part within `sqrt 2` pitches of the touched point,
    /// or not the nearest one, is met by the slide within `sqrt 2` pitches
    /// more of travel (a sliver between the outline and the footprint's
    /// outermost row, an outline crossing the rows at a shallow angle).
    /// Misses, on the unsafe side: they fail the verdict.
    Rim,
    /// A residual no mechanism above explains, within `sqrt 2` pitches:
    /// the size of error the grid makes at this pitch, which a finer pitch
    /// shrinks where the figure converges (`results/`); beyond it, a
    /// start's miss that falls with the pitch against the same exact
    /// trace (to half at half the pitch, or to a quarter at a quarter:
    /// `StartComparison::falls_with_the_pitch`), or a brief strike. It fails the verdict: the pitch is too coarse for the
    /// tolerance.
    Sampling,
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
            Mechanism::Sampling => "sampling",
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
            Mechanism::OracleFailure
                | Mechanism::Rim
                | Mechanism::Sampling
                | Mechanism::Unexplained
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
    /// its value (a distance, not a count) is; an unexplained one that is
    /// is the pitch's sampling error ([`Mechanism::Sampling`]).
    pub fn at_pitch(mut self, pitch: f64) -> Failure {
        self.within_pitch = self.side != Side::Coverage
            && self
                .value
                .is_some_and(|v| v <= std::f64::consts::SQRT_2 * pitch + 1e-9);
        if self.within_pitch && self.mechanism == Mechanism::Unexplained {
            self.mechanism = Mechanism::Sampling;
        }
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
    fn a_point_is_sampled_where_a_node_the_slide_met_lies_within_sqrt_2_pitches() {
        let (triangles, grid) = ribbed(0.0);
        let cells = Cells::of(&triangles, &grid, 0.5);
        // Rows z = 4, 6, 8, columns x = 6..12 at the push (pitch 2); the
        // outline crosses each row 1 mm in front of its first node.
        let row = |j, front| FootprintSpan {
            j,
            lo: 3,
            hi: 6,
            front,
        };
        let rows = [row(2, 5.0), row(3, 5.0), row(4, 5.0)];
        assert!(
            cells.samples_near([5.0, 0.0, 5.0], &rows, 0.0),
            "node (6, 4) is 1.41 away"
        );
        assert!(
            !cells.samples_near([2.0, 0.0, 5.0], &rows, 0.0),
            "the nearest node is 4.1 away"
        );
        // After 1 mm of slide the outline reaches x = 4 (met); after 3 mm,
        // x = 2: the point at x = 1 is sampled from then on, and x = 13
        // still is (a met node stays met).
        assert!(!cells.samples_near([1.0, 0.0, 5.0], &rows, 1.0));
        assert!(cells.samples_near([1.0, 0.0, 5.0], &rows, 3.0));
        assert!(cells.samples_near([13.0, 0.0, 5.0], &rows, 3.0));
        // Beyond the rows in z, or behind them in x: never met.
        assert!(!cells.samples_near([8.0, 0.0, 11.0], &rows, 0.0));
        assert!(!cells.samples_near([15.0, 0.0, 5.0], &rows, 30.0));
        // The lowest met node's rise: on this flat part, 0 where sampled,
        // +inf where not.
        // Only nodes met in the slide judge: none by travel 0 (those under
        // the knee-form at the push are never struck), x = 4 from 1 mm.
        assert_eq!(
            cells.rise_of_lowest_near([5.0, 0.0, 5.0], &rows, 0.0),
            f64::INFINITY
        );
        assert_eq!(cells.rise_of_lowest_near([5.0, 0.0, 5.0], &rows, 1.0), 0.0);
        assert!(!cells.strikes_near([5.0, 0.0, 5.0], &rows, 0.0));
        assert!(cells.strikes_near([5.0, 0.0, 5.0], &rows, 1.0));
        assert_eq!(
            cells.rise_of_lowest_near([2.0, 0.0, 5.0], &rows, 0.0),
            f64::INFINITY
        );
        // At travel 2 the point at x = 1 has only x = 2 near, met at 3 mm.
        assert_eq!(
            cells.rise_of_lowest_near([1.0, 0.0, 5.0], &rows, 2.0),
            f64::INFINITY
        );
        assert_eq!(cells.rise_of_lowest_near([1.0, 0.0, 5.0], &rows, 3.0), 0.0);
        // The nearest node's meeting: x = 4 is met after 1 mm, x = 12 at
        // the push, x = 30 (behind the footprint) never.
        assert_eq!(cells.nearest_node_met_at([3.9, 0.0, 4.1], &rows), 1.0);
        assert_eq!(cells.nearest_node_met_at([12.2, 0.0, 6.1], &rows), 0.0);
        assert_eq!(
            cells.nearest_node_met_at([30.0, 0.0, 5.0], &rows),
            f64::INFINITY
        );
        assert_eq!(
            cells.nearest_node_met_at([500.0, 0.0, 5.0], &rows),
            f64::INFINITY
        );
    }

    #[test]
    fn one_walk_gives_the_three_rises_of_the_separate_queries_to_the_bit() {
        // A sloped part with a rib (rises of both signs and zero), points
        // on and off the nodes, travels from the push to past every row.
        let (triangles, grid) = ribbed(0.3);
        let cells = Cells::of(&triangles, &grid, 0.5);
        let row = |j, lo, hi, front| FootprintSpan { j, lo, hi, front };
        let rows = [row(2, 3, 6, 5.0), row(3, 4, 7, 7.5), row(4, 3, 5, 4.2)];
        let mut checked = [0; 3];
        for k in 0..40 {
            for m in 0..30 {
                let (x, z) = (0.55 * f64::from(k) - 1.0, 0.37 * f64::from(m));
                for y in [-5.0, 0.0, 4.0] {
                    for travel in [0.0, 0.5, 1.0, 3.0, 7.7, 40.0] {
                        let p = [x, y, z];
                        let sampled = cells.samples_near(p, &rows, travel);
                        let rise = if sampled {
                            cells.rise_near(p)
                        } else {
                            f64::INFINITY
                        };
                        let lowest = cells.rise_of_lowest_near(p, &rows, travel);
                        let (a, b) = cells.rises_at(p, &rows, travel);
                        assert_eq!(a.to_bits(), rise.to_bits(), "{p:?} {travel}");
                        assert_eq!(b.to_bits(), lowest.to_bits(), "{p:?} {travel}");
                        checked[0] += usize::from(sampled);
                        checked[1] += usize::from(lowest.is_finite());
                        checked[2] += usize::from(rise > 0.0 && rise.is_finite());
                    }
                }
            }
        }
        assert!(checked.iter().all(|&n| n > 100), "{checked:?}");
    }

    #[test]
    fn only_unexplained_figures_rim_misses_and_oracle_failures_fail_the_verdict() {
        for (m, fails) in [
            (Mechanism::Blind, false),
            (Mechanism::LevelError, false),
            (Mechanism::Undecided, false),
            (Mechanism::OracleFailure, true),
            (Mechanism::Rim, true),
            (Mechanism::Sampling, true),
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
