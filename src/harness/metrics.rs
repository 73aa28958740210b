//! SPEC's harness metrics ("What the harness measures"): per start, the grid
//! trace against the exact trace; over many starts, max, p95 and mean.

use kneeform_oracle::{ContactPoint, FailureReason, LevelCurve, StartStatus, StartTrace};
use serde::{Deserialize, Serialize};

use super::causes::{Cells, RISE_REACH, SurfaceError};
use super::nearest::PointSet;
use super::trace::GridTrace;

/// The metric names, as the rows of `converge.csv` and the keys of
/// `verify.json`: each over all strikes; over the *decided* strikes (see
/// [`TieBand`]) not downstream of a flagged blind spot (`_decided`); over
/// the disagreements downstream of one (`_blind`, SPEC's "Blind spots");
/// the area distances, both directions at once, then each on its own
/// (`area_miss_distance`, from the exact strikes to the grid's: what the
/// grid misses; `area_false_alarm_distance`, from the grid's to the exact
/// ones: what it strikes more); and the grid's level error at its strikes
/// (`level_error_clearance`: how far a struck node lies from touching the
/// exact knee-form; `level_error_bound`: the stated bound of the grid's
/// level error there, see `compare.rs`).
pub const METRICS: [&str; 26] = [
    "push_error",
    "first_contact_error",
    "miss_distance",
    "false_alarm_distance",
    "unmatched_deflection",
    "push_error_decided",
    "first_contact_error_decided",
    "miss_distance_decided",
    "false_alarm_distance_decided",
    "unmatched_deflection_decided",
    "area_distance",
    "area_distance_decided",
    "area_miss_distance",
    "area_miss_distance_decided",
    "area_false_alarm_distance",
    "area_false_alarm_distance_decided",
    "push_error_blind",
    "first_contact_error_blind",
    "miss_distance_blind",
    "false_alarm_distance_blind",
    "unmatched_deflection_blind",
    "area_distance_blind",
    "area_miss_distance_blind",
    "area_false_alarm_distance_blind",
    "level_error_clearance",
    "level_error_bound",
];

pub use crate::summary::DECIDED_METRICS;

/// The index of `name` in [`METRICS`].
pub(crate) fn metric_index(name: &str) -> usize {
    METRICS
        .iter()
        .position(|m| *m == name)
        .expect("a metric name")
}

/// Max, 95th percentile and mean of absolute values, and their count.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Stats {
    /// Largest value (mm).
    pub max: f64,
    /// 95th percentile, nearest rank (mm).
    pub p95: f64,
    /// Mean (mm).
    pub mean: f64,
    /// Number of values.
    pub n: usize,
}

impl Stats {
    /// Statistics of the absolute values of `values` (all zero when empty).
    pub fn of(values: &[f64]) -> Stats {
        let v = sorted_abs(values);
        if v.is_empty() {
            return Stats::default();
        }
        Stats {
            max: v[v.len() - 1],
            p95: nearest_rank(&v, 0.95),
            mean: v.iter().sum::<f64>() / v.len() as f64,
            n: v.len(),
        }
    }
}

/// The absolute values of `values`, ascending.
pub(crate) fn sorted_abs(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().map(|x| x.abs()).collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The `q` quantile of ascending, non-empty `sorted`, by nearest rank.
pub(crate) fn nearest_rank(sorted: &[f64], q: f64) -> f64 {
    let n = sorted.len();
    sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1]
}

/// SPEC's tie band around the deflection threshold: an exact contact whose
/// rate lies in `[sigma / (1 + m), sigma * (1 + m)]` may fall either side
/// on the grid, whose rate is a difference over one pitch (off from the
/// slope by about curvature x pitch / 2).
///
/// **The rule:** `m = per_mm * p`, the band's relative half-width grows
/// linearly with the pitch `p` (default `per_mm = 1` per mm: at 4 mm the
/// band is `[sigma / 5, 5 sigma]`, at 0.5 mm `[sigma / 1.5, 1.5 sigma]`).
/// A grid rate over one pitch differs from the surface's slope by about
/// `kappa * p / 2` for a curvature `kappa`; with `sigma = tan 0.5 deg` that
/// is within `m * sigma` up to `kappa = 2 sigma per_mm`, a radius of
/// curvature of about 57 mm. The oracle's own uncertainty on a rate
/// (`rate_error`) widens the band for that contact: a contact is decided
/// only when its whole uncertainty interval lies outside the band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TieBand {
    /// The deflection threshold as a rate.
    pub sigma: f64,
    /// The band's relative half-width at this pitch.
    pub m: f64,
    /// The pitch (mm).
    #[serde(default)]
    pub pitch: f64,
}

/// How an exact contact stands against the threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// Steeper than the band: every correct grid strikes it (eventually).
    Strike,
    /// Gentler than the band: no correct grid strikes it.
    NoStrike,
    /// In the band: either answer is correct at this pitch.
    Undecided,
}

impl TieBand {
    /// The default growth of `m` with the pitch (per mm).
    pub const DEFAULT_PER_MM: f64 = 1.0;

    /// The band for threshold `sigma` at pitch `pitch` (mm), `m = per_mm *
    /// pitch`.
    pub fn new(sigma: f64, pitch: f64, per_mm: f64) -> TieBand {
        TieBand {
            sigma,
            m: per_mm * pitch,
            pitch,
        }
    }

    /// The band's lower and upper rates.
    pub fn bounds(&self) -> (f64, f64) {
        (self.sigma / (1.0 + self.m), self.sigma * (1.0 + self.m))
    }

    /// Decides a contact of rate `rate` known to within `error`.
    pub fn decide(&self, rate: f64, error: f64) -> Decision {
        let (lo, hi) = self.bounds();
        if rate - error > hi {
            Decision::Strike
        } else if rate + error < lo {
            Decision::NoStrike
        } else {
            Decision::Undecided
        }
    }
}

/// How the exact side judges its contacts: SPEC's window rule on the
/// traced level curve, or (under `--rate x-slope`) the traced deflection
/// rate against `sigma`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ExactRule {
    /// `rate > sigma`, decided against [`TieBand`].
    Rate,
    /// SPEC's window rule: `f*(s - W) - f*(s) > sigma W`, the curve read
    /// between its samples ([`LevelCurve`]).
    ///
    /// **Ties at the threshold.** The grid's drop `f(s - W) - h` reads a
    /// node's height (a point of the surface: exact) and the grid's level
    /// `W` back, which follows the surface only at the nodes met, so it
    /// lies *above* the exact level (SPEC: "the grid's level is too deep"),
    /// by up to the stated bound of the grid's level error there
    /// ([`LevelErrorBound`]: the exact level's fall over the pitch before
    /// that travel plus the rise of the surface within `sqrt 2` pitches of
    /// the exact contacts; before any travel, the push error, bounded by
    /// the rise at the push contact). The grid's drop is therefore at
    /// least the exact one, but for the node itself: the grid judges the
    /// nodes near the touched point that its slide meets, the lowest of
    /// which within `sqrt 2` pitches (met by `sqrt 2` pitches more of
    /// travel) may still lie higher than it, and where it met none it
    /// cannot judge the point at all ([`Cells::rise_of_lowest_near`];
    /// measured on the console at 0.5 mm: a strike on a facet crease
    /// crossing the outline's rounded corner, 0.11 mm from a node the
    /// outline reaches 3 mm of travel later, the nodes met by then 0.36 mm
    /// higher, missed by 5.6 mm). So a contact is a decided
    /// strike when its drop exceeds `sigma W` by more than the drop's
    /// stated error plus that rise, a decided non-strike when it falls
    /// short by more than that error plus the bound of the grid's level
    /// error `W` back (SPEC, "Ties at the threshold"). Both terms come from
    /// the grid's cells ([`LevelErrorBound`]) and shrink with the pitch.
    ///
    /// **Under the surface level** (SPEC v4) the grid's level error goes
    /// both ways (`two_sided`): the surface cuts below a convex crease
    /// between nodes (the level too deep, as the node level's) and may
    /// stand proud of the part elsewhere (too shallow), and the grid judges
    /// the surface near the touched point, not a node. The band is then the
    /// surface's own error, measured against the mesh near each contact
    /// ([`Cells::with_surface_error`], [`LevelErrorBound::surface_at`],
    /// `surface_margins`): second order in the pitch on a smooth part,
    /// first order across a crease and at a riser, unbounded where the
    /// grid has no surface over the mesh (the part's edge between its last
    /// node and the true edge). Where the cells do not measure it, each
    /// side is widened by both of the node level's terms.
    Window {
        /// `W` (mm).
        window: f64,
        /// Whether the grid's error goes both ways (the surface level).
        two_sided: bool,
    },
}

impl ExactRule {
    /// The exact side of `rule`.
    pub fn of(rule: &crate::strike::StrikeRule) -> ExactRule {
        match rule.window_mm() {
            Some(window) => ExactRule::Window {
                window,
                two_sided: rule.level == crate::strike::Level::Surface,
            },
            None => ExactRule::Rate,
        }
    }
}

/// The casts' gap tolerance (mm) the harness's oracle runs with, which a
/// drop's error includes ([`kneeform_oracle::OracleOptions`]).
const JUMP_TOLERANCE: f64 = 1e-6;

/// An exact contact's standing: a strike by SPEC's rule, and its decision
/// against the tie band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ExactStrike {
    /// The contact.
    pub contact: ContactPoint,
    /// A strike by the rule (`rate > sigma`, or the window drop above
    /// `sigma W`).
    pub strike: bool,
    /// Against the tie band.
    pub decision: Decision,
}

/// The window rule's decision of an exact contact whose `drop` is known
/// to within `error`, against `threshold` (`sigma W`), the grid's drop
/// short of the exact one by up to `node` (the lowest near node's rise)
/// and beyond it by up to `grid` (the level error's bound `W` back); under
/// the surface level (`two_sided`) either error may move it either way,
/// so each side takes both ([`ExactRule::Window`]).
fn decide_drop(
    (drop, error): (f64, f64),
    threshold: f64,
    (node, grid): (f64, f64),
    two_sided: bool,
) -> Decision {
    let (short, beyond) = if two_sided {
        (node + grid, node + grid)
    } else {
        (node, grid)
    };
    if drop - error - short > threshold {
        Decision::Strike
    } else if drop + error + beyond < threshold {
        Decision::NoStrike
    } else {
        Decision::Undecided
    }
}

/// Under the surface level, how far short of the exact drop over the
/// window the grid's may fall and how far beyond it it may reach (mm),
/// given the surface's error and the exact level's fall over a step at
/// the contact (`now`) and one window back (`back`)
/// ([`LevelErrorBound::surface_at`]). The grid's drop is its level `W`
/// back less its level now, each judged at the grid's step at or after
/// the exact contact's travel, within a step: short by at most the level
/// back too shallow (`below`, and the exact level's fall over the step
/// there) plus the level now too deep (`above`); beyond by at most the
/// level back too deep plus the level now too shallow (and the fall over
/// the step now).
fn surface_margins(now: (SurfaceError, f64), back: (SurfaceError, f64)) -> (f64, f64) {
    let ((now, fall_now), (back, fall_back)) = (now, back);
    (
        back.below + fall_back + now.above,
        back.above + now.below + fall_now,
    )
}

/// The exact contacts of a placed start with their standing by `rule`,
/// against the grid's level error `bound` along it.
fn classify(
    exact: &StartTrace,
    band: &TieBand,
    rule: ExactRule,
    bound: &LevelErrorBound,
) -> Vec<ExactStrike> {
    let curve = &bound.curve;
    exact
        .contacts
        .iter()
        .enumerate()
        .map(|(k, &c)| match rule {
            ExactRule::Rate => ExactStrike {
                contact: c,
                strike: c.rate > band.sigma,
                decision: band.decide(c.rate, c.rate_error),
            },
            ExactRule::Window { window, two_sided } => {
                let drop = curve.drop_at(k, window, JUMP_TOLERANCE);
                let grid = bound.at(c.travel - window);
                // The grid judges the nodes near the touched point, the
                // lowest of them up to its rise above it: its drop may
                // fall short by that.
                let node = bound.lowest[k];
                let threshold = band.sigma * window;
                // Under the surface level, the surface's own measured
                // error at both ends of the window, each way.
                let surface = match (
                    bound.surface_at(c.travel),
                    bound.surface_at(c.travel - window),
                ) {
                    (Some(now), Some(back)) if two_sided => Some(surface_margins(now, back)),
                    _ => None,
                };
                let decision = match surface {
                    Some((short, beyond)) => {
                        decide_drop((drop.drop, drop.error), threshold, (short, beyond), false)
                    }
                    None => {
                        decide_drop((drop.drop, drop.error), threshold, (node, grid), two_sided)
                    }
                };
                ExactStrike {
                    contact: c,
                    strike: drop.drop > threshold,
                    decision,
                }
            }
        })
        .collect()
}

/// One start at one angle, grid against exact. Distances are in xz, the
/// grid's domain (SPEC, "What the harness measures").
///
/// A disagreement is *blind* when the exact knee-form touched a flagged
/// blind spot ([`Cells::touches_blind_spot`]) at or before its travel in
/// this slide; the `_decided` figures leave blind ones out and the
/// `_blind` figures hold them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StartComparison {
    /// `yr - yr*` (mm), when both are placed.
    pub push_error: Option<f64>,
    /// Whether the exact push contact lies on a flagged blind spot (the
    /// push error is then blind).
    pub push_blind: bool,
    /// Whether the push error lies within the grid's level error at the
    /// push: at most the push contact's rise ([`LevelErrorBound`]), and not
    /// below the exact push level.
    pub push_explained: bool,
    /// Grid travel to the first strike minus the exact travel to the first
    /// strike (mm), when both have one.
    pub first_contact_error: Option<f64>,
    /// The same against the interval from the first possible exact strike
    /// to the first decided one (under x-slope: where the first possible
    /// one is decided), when the disagreement is not blind.
    pub first_contact_error_decided: Option<f64>,
    /// The same, when the disagreement is blind.
    pub first_contact_error_blind: Option<f64>,
    /// Whether a grid first strike earlier than the exact interval is
    /// explained by the level error.
    pub first_contact_explained: bool,
    /// What is left of a grid first strike later than the exact interval
    /// once the decided exact strikes in the knee-form's rim are set
    /// aside (mm, `>= 0`): the grid's first strike against the first
    /// decided exact strike inside its footprint. `None` unless the grid
    /// strikes late.
    pub first_contact_late_inside: Option<f64>,
    /// For each exact strike, the xz distance to the nearest grid strike of
    /// the same start (mm); `+inf` where the grid has none.
    pub miss: Vec<f64>,
    /// The same for each decided exact strike not downstream of a blind
    /// spot.
    pub miss_decided: Vec<f64>,
    /// Whether each of those lies in the knee-form's rim: the slide meets
    /// no node of the part near it, or not the nearest one, by
    /// [`MEETING_REACH`] pitches more of travel ([`Cells::samples_near`],
    /// [`Cells::nearest_node_met_at`]).
    pub miss_rim: Vec<bool>,
    /// Whether each of those is brief: the exact knee-form touches within
    /// `sqrt 2` pitches of it for less than [`MEETING_REACH`] pitches of
    /// travel, and then touches elsewhere (a drop under another part of
    /// the knee-form): shorter than the travel the grid needs to meet a
    /// node there, a sampling error in travel.
    pub miss_brief: Vec<bool>,
    /// Where the largest decided miss inside the footprint (neither in
    /// the rim nor brief, [`StartComparison::inside_miss`]) exceeds `sqrt
    /// 2` pitches: the same figure with the grid sampled at half the pitch,
    /// against the same exact trace (mm; `+inf` where the finer grid
    /// strikes nothing in the start). See
    /// [`StartComparison::falls_with_the_pitch`].
    pub miss_half_pitch: Option<f64>,
    /// Where that figure falls, but not to half: the same at a quarter of
    /// the pitch (mm; `+inf` where the finer grid strikes nothing).
    pub miss_quarter_pitch: Option<f64>,
    /// The same for each exact strike downstream of one, decided or not
    /// (blind is a category beside decided and undecided).
    pub miss_blind: Vec<f64>,
    /// For each grid strike, the xz distance to the nearest exact strike or
    /// to the exact push contact (mm); `+inf` where there is neither.
    pub false_alarm: Vec<f64>,
    /// For each grid strike not downstream of a blind spot, the xz
    /// distance to the nearest exact contact that is not a decided
    /// non-strike, or to the exact push contact.
    pub false_alarm_decided: Vec<f64>,
    /// Whether each of those is explained by the grid's level error.
    pub false_alarm_explained: Vec<bool>,
    /// The same distance for each grid strike downstream of a blind spot.
    pub false_alarm_blind: Vec<f64>,
    /// For each exact strike met when the grid strikes nothing in this
    /// start: how far the exact knee-form had been deflected below the
    /// grid's level by then, `yr - f` (mm). The grid slid on at `yr`, so
    /// this is the part of the true path it missed.
    pub unmatched_deflection: Vec<f64>,
    /// The same for decided exact strikes not downstream of a blind spot.
    pub unmatched_deflection_decided: Vec<f64>,
    /// The same for those inside the grid's footprint (not in the rim).
    pub unmatched_deflection_inside: Vec<f64>,
    /// The same for exact strikes downstream of one, decided or not.
    pub unmatched_deflection_blind: Vec<f64>,
    /// For each grid strike not downstream of a blind spot: how far its
    /// node lies from touching the exact knee-form at its travel,
    /// `h - f*(s)` (mm).
    pub level_clearance: Vec<f64>,
    /// For each of those, the stated bound of the grid's level error at
    /// that travel (mm; see [`compare`]).
    pub level_bound: Vec<f64>,
    /// Why the oracle failed on this pair, when it did.
    pub oracle_failure: Option<FailureReason>,
    /// Exact strikes (`rate > sigma`).
    pub exact_strikes: usize,
    /// Exact contacts in the tie band.
    pub undecided: usize,
    /// Whether the exact knee-form touched a flagged blind spot in this
    /// slide.
    pub blind: bool,
    /// Exact strikes at or after that touch.
    pub blind_strikes: usize,
    /// The points compared, xz (mm).
    pub points: StartPoints,
}

/// The points of one start that its metrics compare, in xz (mm): the
/// grid's strikes and the exact side's by standing. The area distance
/// compares their unions over many starts.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StartPoints {
    /// The grid strikes, in the order of `false_alarm`.
    pub grid: Vec<[f64; 2]>,
    /// The grid strikes not downstream of a blind spot, in the order of
    /// `false_alarm_decided`.
    pub grid_decided: Vec<[f64; 2]>,
    /// Those of them the level error does not explain.
    pub grid_unexplained: Vec<[f64; 2]>,
    /// The grid strikes downstream of a blind spot.
    pub grid_blind: Vec<[f64; 2]>,
    /// The exact strikes (by SPEC's rule), in the order of `miss`.
    pub strikes: Vec<[f64; 2]>,
    /// The decided exact strikes not downstream of a blind spot, in the
    /// order of `miss_decided`.
    pub decided: Vec<[f64; 2]>,
    /// The exact strikes downstream of one, decided or not.
    pub blind: Vec<[f64; 2]>,
    /// The decided exact strikes away from blind spots that lie inside the
    /// grid's footprint at their travel (not in the knee-form's rim), and
    /// not brief.
    pub decided_inside: Vec<[f64; 2]>,
    /// Those of them in a start whose inside miss falls with the pitch
    /// ([`StartComparison::falls_with_the_pitch`]): moved here from
    /// `decided_inside`.
    pub decided_refined: Vec<[f64; 2]>,
    /// The exact contacts that are not decided non-strikes.
    pub possible: Vec<[f64; 2]>,
    /// The undecided exact contacts (in the tie band: either answer is
    /// right at this pitch): where the grid's boundary is undecided. A
    /// comparison takes them as their nearest nodes and keeps no point.
    pub undecided: Vec<[f64; 2]>,
    /// The exact push contact, when placed: a point of the exact curve for
    /// false alarms (see [`compare`]).
    pub push: Vec<[f64; 2]>,
}

impl StartPoints {
    /// Appends `other`'s points to these.
    pub fn extend(&mut self, other: &StartPoints) {
        for (to, from) in self.sets_mut().into_iter().zip(other.sets()) {
            to.extend(from);
        }
    }

    /// Every set, in a fixed order (what a shard's file holds).
    pub fn sets(&self) -> [&Vec<[f64; 2]>; 12] {
        [
            &self.grid,
            &self.grid_decided,
            &self.grid_unexplained,
            &self.grid_blind,
            &self.strikes,
            &self.decided,
            &self.blind,
            &self.decided_inside,
            &self.decided_refined,
            &self.possible,
            &self.undecided,
            &self.push,
        ]
    }

    /// Every set, mutable, in the order of [`StartPoints::sets`].
    pub fn sets_mut(&mut self) -> [&mut Vec<[f64; 2]>; 12] {
        [
            &mut self.grid,
            &mut self.grid_decided,
            &mut self.grid_unexplained,
            &mut self.grid_blind,
            &mut self.strikes,
            &mut self.decided,
            &mut self.blind,
            &mut self.decided_inside,
            &mut self.decided_refined,
            &mut self.possible,
            &mut self.undecided,
            &mut self.push,
        ]
    }

    /// `exact`'s points with the push contacts: what a grid strike's false
    /// alarm is measured against.
    pub fn with_push(&self, exact: &[[f64; 2]]) -> Vec<[f64; 2]> {
        exact.iter().chain(&self.push).copied().collect()
    }
}

impl StartComparison {
    /// The largest decided miss inside the grid's footprint: over the
    /// decided exact strikes away from blind spots that are neither in the
    /// rim nor brief (mm; `+inf` where the grid strikes nothing in the
    /// start); `None` where there is none.
    pub fn inside_miss(&self) -> Option<f64> {
        self.miss_decided
            .iter()
            .zip(self.miss_rim.iter().zip(&self.miss_brief))
            .filter(|(_, (rim, brief))| !**rim && !**brief)
            .map(|(d, _)| *d)
            .reduce(f64::max)
    }

    /// Whether this start's inside miss is the grid's sampling error,
    /// shown by refinement against the same exact trace: with the grid
    /// sampled at half the pitch it falls to at most half its value, or,
    /// where it falls but not to half, at a quarter of the pitch to at
    /// most a quarter (first order or better over two halvings: a term of
    /// higher order keeps the first step above half, as on the console at
    /// 1.24 mm, 2.29 -> 1.18 -> 0.43 mm). A crease of the mesh between two
    /// node rows, struck along by the exact knee-form, is such a miss: the
    /// grid's strike along it starts later, by less at a finer pitch. (A
    /// brief strike is left to [`StartComparison::miss_brief`]: its miss
    /// falls once the pitch is finer than the touch, not in proportion to
    /// it.)
    pub fn falls_with_the_pitch(&self) -> bool {
        let Some(d) = self.inside_miss().filter(|d| d.is_finite()) else {
            return false;
        };
        let within = |refined: Option<f64>, factor: f64| {
            refined.is_some_and(|r| r <= d / factor + LEVEL_TOL)
        };
        within(self.miss_half_pitch, 2.0) || within(self.miss_quarter_pitch, 4.0)
    }

    /// Where the worst decided disagreement of this start lies (xz, mm)
    /// and how large it is: the decided exact strike furthest from the
    /// grid's strikes or the grid strike furthest from every possible exact
    /// one, whichever is further (infinite distances first), away from
    /// blind spots.
    pub fn worst_decided_point(&self) -> Option<([f64; 2], f64)> {
        self.points
            .decided
            .iter()
            .zip(&self.miss_decided)
            .chain(
                self.points
                    .grid_decided
                    .iter()
                    .zip(&self.false_alarm_decided),
            )
            .map(|(&p, &d)| (p, d))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

fn xz(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[2]]
}

/// The stated bound of the grid's level error along one exact trace: how
/// much deeper than the exact knee-form's level `f*(s)` the grid's level
/// may lie at travel `s` (mm).
///
/// **The bound.** The grid's level follows the exact one at the nodes it
/// meets. Where the exact knee-form touches the mesh at `w`, the grid has
/// a node under the knee-form within `sqrt 2` pitches of `w`, at most
/// [`Cells::rise_near`] above it, met within about a pitch more of
/// travel; so at travel `s` the grid's level lies at most
/// `f*(s - p) - f*(s) + rise` deeper than the exact one: the exact level's
/// fall over the pitch before `s` (`yr*` for travel below 0) plus the
/// largest rise of the exact contacts in force over that pitch (the push
/// contact's before the first contact: the push error is bounded the same
/// way). Both terms shrink with the pitch.
///
/// It serves twice: a node poking through the grid's level by no more than
/// the bound is a contact the exact knee-form need not make (a false alarm
/// on the safe side, SPEC's "What the window does not fix"), and the grid's
/// window drop may exceed the exact one by up to the bound at `s - W` (the
/// tie band's grid term, [`ExactRule::Window`]).
pub(crate) struct LevelErrorBound<'a> {
    curve: LevelCurve<'a>,
    travels: Vec<f64>,
    rises: Vec<f64>,
    /// Per contact, the rise of the lowest node near it that the slide met
    /// by [`MEETING_REACH`] pitches more of travel
    /// ([`Cells::rise_of_lowest_near`]).
    lowest: Vec<f64>,
    push_rise: f64,
    pitch: f64,
    /// Under the surface level, the surface's measured error near each
    /// contact and near the push contact ([`Cells::surface_error_near`]).
    surface: Option<(Vec<SurfaceError>, SurfaceError)>,
}

impl<'a> LevelErrorBound<'a> {
    /// The bound along `exact` on the grid of `cells`, whose push covered
    /// the footprint rows `push_rows` ([`GridTrace::push_rows`]); `None`
    /// for a start that is not placed or failed.
    ///
    /// Where no node of the part under the knee-form lies within `sqrt 2`
    /// pitches of an exact contact (at the push, or at the contact's
    /// travel: the knee-form's rim cuts a sliver of the part, or an edge,
    /// narrower than the pitch, or runs along the slide there), the grid
    /// cannot sample what the exact knee-form rests on: that contact's
    /// rise is unbounded at this pitch (a finer grid samples it).
    pub fn of(
        exact: &'a StartTrace,
        cells: &Cells,
        push_rows: &[super::trace::FootprintSpan],
    ) -> Option<LevelErrorBound<'a>> {
        let curve = LevelCurve::of(exact)?;
        let pitch = cells.pitch();
        // The nodes the slide has met near a touched point, or meets within
        // about a pitch more of travel (a node ahead of the leading edge):
        // not one the outline reaches only later, where it runs almost
        // along the slide.
        let ahead = |c: &ContactPoint| c.travel + MEETING_REACH * pitch;
        let (rises, lowest) = exact
            .contacts
            .iter()
            .map(|c| cells.rises_at(c.witness, push_rows, ahead(c)))
            .unzip();
        let surface = exact
            .contacts
            .iter()
            .map(|c| cells.surface_error_near(c.witness))
            .collect::<Option<Vec<SurfaceError>>>()
            .map(|errors| {
                let push = exact
                    .push_witness
                    .and_then(|w| cells.surface_error_near(w))
                    .unwrap_or(SurfaceError::UNBOUNDED);
                (errors, push)
            });
        Some(LevelErrorBound {
            curve,
            travels: exact.contacts.iter().map(|c| c.travel).collect(),
            rises,
            lowest,
            push_rise: exact.push_witness.map_or(0.0, |w| {
                if cells.samples_near(w, push_rows, 0.0) {
                    cells.rise_near(w)
                } else {
                    f64::INFINITY
                }
            }),
            pitch,
            surface,
        })
    }

    /// Under the surface level, how far the grid's level may lie from the
    /// exact one at travel `s` (mm; `None` where the surface's error was
    /// not measured): the surface's measured error near the exact contacts
    /// in force from `s` to one step (`p / 8`) of travel on (the push
    /// contact's before the first), each way ([`SurfaceError`]: the grid's
    /// level is the surface's minimum over the swept footprint, at most
    /// `above` deeper than the mesh's minimum there and at most `below`
    /// shallower), and the exact level's fall over that step (the grid
    /// evaluates its level at steps of `p / 8`, SPEC v4).
    pub fn surface_at(&self, s: f64) -> Option<(SurfaceError, f64)> {
        let (errors, push) = self.surface.as_ref()?;
        let step = self.pitch / crate::surface::STEPS_PER_PITCH;
        let in_force = |t: f64| self.travels.partition_point(|&c| c <= t + LEVEL_TOL);
        let (from, to) = (in_force(s), in_force(s + step));
        let before = if from == 0 { *push } else { errors[from - 1] };
        let error = errors[from..to].iter().fold(before, |m, &e| m.max(e));
        let fall = self.curve.at(s).value - self.curve.at(s + step).value;
        Some((error, fall.max(0.0)))
    }

    /// The rise of the exact push contact (mm).
    pub fn push_rise(&self) -> f64 {
        self.push_rise
    }

    /// The largest rise of the exact contacts in force over the pitch of
    /// travel before `s` (mm).
    fn rise_in_force(&self, s: f64) -> f64 {
        // The contact in force at travel t: the last one at or before t.
        let in_force = |t: f64| self.travels.partition_point(|&c| c <= t + LEVEL_TOL);
        let (from, to) = (in_force(s - self.pitch), in_force(s));
        let before = if from == 0 {
            self.push_rise
        } else {
            self.rises[from - 1]
        };
        self.rises[from..to].iter().fold(before, |m, &r| m.max(r))
    }

    /// The bound at travel `s` (mm).
    pub fn at(&self, s: f64) -> f64 {
        let fall = self.curve.at(s - self.pitch).value - self.curve.at(s).value;
        fall.max(0.0) + self.rise_in_force(s)
    }

    /// Under the surface level where its error is measured, the
    /// surface's error and the exact level's fall over one step from `s`
    /// ([`LevelErrorBound::surface_at`]); `None` under the node level.
    fn surface_in(&self, s: f64, rule: ExactRule) -> Option<(SurfaceError, f64)> {
        match rule {
            ExactRule::Window {
                two_sided: true, ..
            } => self.surface_at(s),
            _ => None,
        }
    }

    /// How much deeper than the exact level `f*(s)` the grid's level may
    /// lie at a grid step at travel `s` (mm), by `rule`'s level: under the
    /// surface level where its error is measured, the surface's `above`
    /// near the exact contacts in force (the grid's level is the
    /// surface's minimum over the swept footprint, which holds those
    /// contacts: at most `above` deeper than the mesh's minimum there) plus
    /// the exact level's fall over a step; otherwise the node level's
    /// bound ([`LevelErrorBound::at`]).
    pub fn deeper_at(&self, s: f64, rule: ExactRule) -> f64 {
        match self.surface_in(s, rule) {
            Some((error, fall)) => error.above + fall,
            None => self.at(s),
        }
    }

    /// Whether a grid strike whose new level is `h`, at a grid step at
    /// travel `s`, may owe its deflection test to the level error: under
    /// the window rule, whether the drop from the exact level `W` back,
    /// raised by how much deeper the grid's level may lie there, exceeds
    /// `sigma W`. Under the node level that is the bound at `s - W`
    /// ([`LevelErrorBound::at`]). Under the surface level the grid reads
    /// its level after its last step at or before `s - W`, at most a step
    /// earlier (SPEC v4): at most the exact level a step before `s - W`
    /// (the fall over that step) plus the surface's `above` near the
    /// contacts in force over it. Under x-slope the grid's rate is no
    /// level's difference: the level error explains no strike there.
    fn explains_drop(&self, h: f64, s: f64, sigma: f64, rule: ExactRule) -> bool {
        match rule {
            ExactRule::Rate => false,
            ExactRule::Window { window, .. } => {
                let back = s - window;
                let step = self.pitch / crate::surface::STEPS_PER_PITCH;
                let deeper = match self.surface_in(back - step, rule) {
                    Some((error, fall)) => error.above + fall,
                    None => self.at(back),
                };
                self.curve.at(back).value - h + deeper > sigma * window - LEVEL_TOL
            }
        }
    }

    /// Whether a grid strike that judged the value `h` (the node's height;
    /// under the surface level the surface's value at its witness: the
    /// new level, or a tie's own value at most `slack` above it), at
    /// travel `s`, is the level error's: `h` lies within
    /// [`LevelErrorBound::deeper_at`] plus `slack` of the exact
    /// knee-form's level there (a node poking through the exact level by
    /// no more than that; under the surface level, the grid's level cut
    /// that much deeper at a crease near the exact contact, a tie that
    /// much above it: SPEC v4's tie set marks every outline point within
    /// `tau` of the new level), and its deflection test passes only by the
    /// level error `W` back ([`LevelErrorBound::explains_drop`]).
    pub fn explains(
        &self,
        (h, slack): (f64, f64),
        s: f64,
        sigma: f64,
        rule: ExactRule,
    ) -> Explanation {
        let (clearance, bound) = (self.clearance(h, s), self.deeper_at(s, rule) + slack);
        Explanation {
            clearance,
            bound,
            explained: clearance <= bound + LEVEL_TOL && self.explains_drop(h, s, sigma, rule),
        }
    }

    /// How far a mesh point of height `h` met at travel `s` lies from
    /// touching the exact knee-form, `h - f*(s)` (mm).
    pub fn clearance(&self, h: f64, s: f64) -> f64 {
        h - self.curve.at(s).value
    }
}

/// A grid strike against the level error ([`LevelErrorBound::explains`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Explanation {
    /// How far its level lies from touching the exact knee-form (mm).
    pub clearance: f64,
    /// How much deeper than the exact level the grid's may lie there (mm).
    pub bound: f64,
    /// Whether the level error explains it.
    pub explained: bool,
}

/// A clearance within its bound, up to rounding (mm).
const LEVEL_TOL: f64 = 1e-6;

/// How much more travel than an exact contact's (in pitches) the grid may
/// take to meet a node near the touched point and still be judging that
/// point: a node ahead of the footprint within [`RISE_REACH`] pitches is
/// met within about as much more travel. A node the footprint meets only
/// later (where the knee-form's outline runs almost along the slide, a
/// crease crossing its rounded corner: 3 mm later for a node 0.11 mm from
/// the touched point on the console at 0.5 mm) judges another contact.
pub(crate) const MEETING_REACH: f64 = RISE_REACH;

/// Whether the exact contact `k` of `contacts` (a start's, in travel
/// order) is brief at pitch `pitch`: the run of contacts around it whose
/// witnesses lie within `sqrt 2` pitches of its own spans less than
/// [`MEETING_REACH`] pitches of travel, and a contact elsewhere follows
/// it. On the teapot at 1.24 mm the knee-form rode a crest at the push
/// contact for 0.43 mm of travel, then its far end met a riser that
/// dropped the level 2 mm: the grid met the nodes by the crest only
/// after that, clear of them.
fn brief(contacts: &[ContactPoint], k: usize, pitch: f64) -> bool {
    let c = &contacts[k];
    let reach = RISE_REACH * pitch + LEVEL_TOL;
    let near = |d: &ContactPoint| {
        (d.witness[0] - c.witness[0]).hypot(d.witness[2] - c.witness[2]) <= reach
    };
    let first = contacts[..k]
        .iter()
        .rev()
        .take_while(|d| near(d))
        .last()
        .unwrap_or(c);
    let run = contacts[k..].iter().take_while(|d| near(d)).count();
    let last = &contacts[k + run - 1];
    k + run < contacts.len() && last.travel - first.travel < MEETING_REACH * pitch
}

/// Compares a grid trace with the exact trace of the same start and angle.
///
/// **Strikes on both sides.** The grid's strikes are SPEC's (rule 2 of the
/// slide); the exact strikes are the contacts SPEC's rule finds striking (`classify`).
/// Over *all* strikes, a miss is an exact strike far from every grid
/// strike, a false alarm a grid strike far from every exact strike. Over
/// *decided* strikes, misses are counted only from exact contacts beyond
/// the tie band, and a grid strike is a false alarm only when it is far
/// from every exact contact that is not a decided non-strike: near the
/// threshold either answer is right.
///
/// **Blind.** From the first exact contact (the push contact included) on
/// a flagged blind spot of `cells` on, the exact strikes and the grid
/// strikes of this slide are blind: reported apart from the decided ones.
///
/// **Level error.** Each grid strike not blind is checked against the
/// exact level curve: its node's clearance `h - f*(s)` against
/// the bound of [`LevelErrorBound`]. A false alarm within it is the level error's.
///
/// The exact push contact counts as a point of the exact curve for false
/// alarms: where the grid's push level is above the exact one (its nodes
/// miss the true highest point), the grid strikes, just after the push, the
/// point the exact knee-form rests on. It does not count for misses: the
/// grid's push contact is, by SPEC, not a colliding point.
pub(crate) fn compare(
    grid: &GridTrace,
    exact: &StartTrace,
    band: &TieBand,
    rule: ExactRule,
    cells: &Cells,
) -> StartComparison {
    let placed = exact.status == StartStatus::Placed;
    // A start the grid did not place never slides: it meets no node, and
    // judges none of the exact contacts.
    let rows: &[super::trace::FootprintSpan] = if grid.yr.is_finite() {
        &grid.push_rows
    } else {
        &[]
    };
    let bound = LevelErrorBound::of(exact, cells, rows);
    let classified = match &bound {
        Some(bound) => classify(exact, band, rule, bound),
        None => Vec::new(),
    };
    let push_witness = exact.push_witness.filter(|_| placed);
    let push: Vec<[f64; 2]> = push_witness.map(xz).into_iter().collect();
    // Where the exact knee-form first touches a flagged blind spot.
    let push_blind = push_witness.is_some_and(|w| cells.touches_blind_spot(w));
    let blind_from: Option<f64> = if !placed {
        None
    } else if push_blind {
        Some(0.0)
    } else {
        exact
            .contacts
            .iter()
            .find(|c| cells.touches_blind_spot(c.witness))
            .map(|c| c.travel)
    };
    let is_blind = |s: f64| blind_from.is_some_and(|b| s >= b - LEVEL_TOL);
    // Each grid strike: blind, or its clearance against the bound.
    let mut grid_blind = Vec::new();
    let mut grid_decided = Vec::new();
    let mut grid_unexplained = Vec::new();
    let mut explained_flags = Vec::new();
    let mut level_clearance = Vec::new();
    let mut level_bound = Vec::new();
    let mut first_grid_explained = false;
    for (k, g) in grid.colliding.iter().enumerate() {
        let p = g.point;
        if is_blind(g.travel) {
            grid_blind.push(p);
            continue;
        }
        let explained = bound.as_ref().is_some_and(|b| {
            let e = b.explains((g.value, g.slack), g.travel, band.sigma, rule);
            level_clearance.push(e.clearance);
            level_bound.push(e.bound);
            e.explained
        });
        if k == 0 {
            first_grid_explained = explained;
        }
        grid_decided.push(p);
        explained_flags.push(explained);
        if !explained {
            grid_unexplained.push(p);
        }
    }
    let points = |keep: &dyn Fn(&ExactStrike) -> bool| -> Vec<[f64; 2]> {
        classified
            .iter()
            .filter(|c| keep(c))
            .map(|c| xz(c.contact.witness))
            .collect()
    };
    let decided_strike = |c: &ExactStrike| c.decision == Decision::Strike;
    // In the rim: the slide meets no node near the touched point by
    // then, or not its nearest one (the outline crossing the grid's rows
    // at a shallow angle, a rounded corner's side; or the nearest node
    // under the knee-form since the push, never struck).
    let in_rim = |c: &ExactStrike| {
        let by = c.contact.travel + MEETING_REACH * cells.pitch();
        let nearest = cells.nearest_node_met_at(c.contact.witness, rows);
        !cells.strikes_near(c.contact.witness, rows, by)
            || !(LEVEL_TOL..=by + LEVEL_TOL).contains(&nearest)
    };
    // The decided strikes away from blind spots, with their indices.
    let decided_away: Vec<(usize, &ExactStrike)> = classified
        .iter()
        .enumerate()
        .filter(|(_, c)| decided_strike(c) && !is_blind(c.contact.travel))
        .collect();
    let miss_rim: Vec<bool> = decided_away.iter().map(|(_, c)| in_rim(c)).collect();
    let miss_brief: Vec<bool> = decided_away
        .iter()
        .map(|&(k, _)| brief(&exact.contacts, k, cells.pitch()))
        .collect();
    let pts = StartPoints {
        grid: grid.colliding.iter().map(|c| c.point).collect(),
        grid_decided,
        grid_unexplained,
        grid_blind,
        strikes: points(&|c| c.strike),
        decided: points(&|c| decided_strike(c) && !is_blind(c.contact.travel)),
        blind: points(&|c| c.strike && is_blind(c.contact.travel)),
        decided_inside: decided_away
            .iter()
            .zip(miss_rim.iter().zip(&miss_brief))
            .filter(|(_, (rim, brief))| !**rim && !**brief)
            .map(|((_, c), _)| xz(c.contact.witness))
            .collect(),
        decided_refined: Vec::new(),
        possible: points(&|c| c.decision != Decision::NoStrike),
        undecided: points(&|c| c.decision == Decision::Undecided),
        push,
    };
    let strikes_or_push = pts.with_push(&pts.strikes);
    let possible_or_push = pts.with_push(&pts.possible);
    let grid_points = &pts.grid;
    let deflection = |keep: &dyn Fn(&ExactStrike) -> bool| -> Vec<f64> {
        if grid_points.is_empty() && grid.yr.is_finite() && placed {
            classified
                .iter()
                .filter(|c| keep(c))
                .map(|c| (grid.yr - c.contact.face_level).max(0.0))
                .collect()
        } else {
            Vec::new()
        }
    };
    let first_strike = classified.iter().find(|c| c.strike);
    let first_possible = classified.iter().find(|c| c.decision != Decision::NoStrike);
    let first_decided = classified.iter().find(|c| c.decision == Decision::Strike);
    let grid_first = grid.colliding.first().filter(|_| placed);
    // The decided first-contact error, and the travel where that
    // disagreement begins (blind when the exact knee-form touched a blind
    // spot by then).
    let first_decided_error: Option<(f64, f64)> =
        match (rule, grid_first, first_possible, first_decided) {
            (ExactRule::Rate, Some(g), Some(e), _) if e.decision == Decision::Strike => {
                Some((g.travel - e.contact.travel, g.travel.min(e.contact.travel)))
            }
            // Under the window the exact drop rises from 0 at every
            // landing, so the first exact strike sits on the threshold:
            // the grid's first strike is measured against the interval
            // from the first possible exact strike to the first decided
            // one (SPEC's metric table).
            (ExactRule::Window { .. }, Some(g), Some(lo), Some(hi)) => {
                let (lo, hi) = (lo.contact.travel, hi.contact.travel);
                Some(if g.travel < lo {
                    (g.travel - lo, g.travel)
                } else if g.travel > hi {
                    (g.travel - hi, hi)
                } else {
                    (0.0, f64::NEG_INFINITY)
                })
            }
            _ => None,
        };
    let first_blind = first_decided_error.is_some_and(|(_, at)| is_blind(at));
    // A late grid first strike where the exact strikes before it lie in
    // the rim, outside the footprint (an exact strike on a sliver of the
    // part the grid's rows never reach): the late part is the rim's.
    let first_contact_late_inside = match (first_decided_error, grid_first) {
        (Some((e, _)), Some(g)) if e > 0.0 && !first_blind => Some(
            classified
                .iter()
                .find(|c| {
                    c.decision == Decision::Strike && !is_blind(c.contact.travel) && !in_rim(c)
                })
                .map_or(0.0, |c| (g.travel - c.contact.travel).clamp(0.0, e)),
        ),
        _ => None,
    };
    let first_of = |blind: bool| {
        first_decided_error
            .filter(|_| first_blind == blind)
            .map(|(e, _)| e)
    };
    let grid_set = PointSet::new(grid_points.clone());
    let miss_of = |set: &[[f64; 2]]| grid_set.distances(set);
    let strikes_or_push = PointSet::new(strikes_or_push);
    let possible_or_push = PointSet::new(possible_or_push);
    StartComparison {
        push_error: match (grid.yr.is_finite(), exact.yr_star) {
            (true, Some(star)) if placed => Some(grid.yr - star),
            _ => None,
        },
        push_blind,
        push_explained: match (grid.yr.is_finite(), exact.yr_star) {
            (true, Some(star)) if placed => bound.as_ref().is_some_and(|b| {
                (-LEVEL_TOL..=b.push_rise() + LEVEL_TOL).contains(&(grid.yr - star))
            }),
            _ => false,
        },
        first_contact_error: match (grid_first, first_strike) {
            (Some(g), Some(e)) => Some(g.travel - e.contact.travel),
            _ => None,
        },
        first_contact_error_decided: first_of(false),
        first_contact_error_blind: first_of(true),
        first_contact_explained: first_grid_explained,
        first_contact_late_inside,
        miss: miss_of(&pts.strikes),
        miss_decided: miss_of(&pts.decided),
        miss_rim,
        miss_brief,
        miss_half_pitch: None,
        miss_quarter_pitch: None,
        miss_blind: miss_of(&pts.blind),
        false_alarm: strikes_or_push.distances(grid_points),
        false_alarm_decided: possible_or_push.distances(&pts.grid_decided),
        false_alarm_explained: explained_flags,
        false_alarm_blind: possible_or_push.distances(&pts.grid_blind),
        unmatched_deflection: deflection(&|c| c.strike),
        unmatched_deflection_decided: deflection(&|c| {
            decided_strike(c) && !is_blind(c.contact.travel)
        }),
        unmatched_deflection_inside: deflection(&|c| {
            decided_strike(c) && !is_blind(c.contact.travel) && !in_rim(c)
        }),
        unmatched_deflection_blind: deflection(&|c| c.strike && is_blind(c.contact.travel)),
        level_clearance,
        level_bound,
        oracle_failure: match exact.status {
            StartStatus::Failed { reason } => Some(reason),
            _ => None,
        },
        exact_strikes: pts.strikes.len(),
        undecided: pts.undecided.len(),
        blind: blind_from.is_some(),
        blind_strikes: classified
            .iter()
            .filter(|c| c.strike && is_blind(c.contact.travel))
            .count(),
        points: pts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_surface_levels_band_is_two_sided() {
        // Threshold 0.044, error 0.001, near node's rise 0.002, level
        // error W back 0.02.
        let decide = |drop, two_sided| decide_drop((drop, 0.001), 0.044, (0.002, 0.02), two_sided);
        // Beyond the threshold by more than error + rise, within the
        // level error: decided under the node level (its level is only
        // ever too deep), not under the surface level.
        assert_eq!(decide(0.05, false), Decision::Strike);
        assert_eq!(decide(0.05, true), Decision::Undecided);
        assert_eq!(decide(0.07, true), Decision::Strike);
        // Short of it by more than error + level error but less than that
        // plus the rise: the same, mirrored.
        assert_eq!(decide(0.0215, false), Decision::NoStrike);
        assert_eq!(decide(0.0215, true), Decision::Undecided);
        assert_eq!(decide(0.01, true), Decision::NoStrike);
    }

    /// A start whose exact level holds at 10 mm to travel 10, where it
    /// falls 0.03 mm (short of `sigma W`, 0.044 mm): a grid strike there
    /// at a level 0.02 mm deeper than the exact one.
    fn crease_cut_trace() -> StartTrace {
        let contact = |travel: f64, face_level: f64| ContactPoint {
            travel,
            face_level,
            witness: [-travel, face_level, 0.0],
            rate: 0.0,
            rate_error: 0.0,
        };
        StartTrace {
            angle_deg: 0.0,
            start: [0.0, 0.0],
            status: StartStatus::Placed,
            yr_star: Some(10.0),
            push_witness: Some([0.0, 10.0, 0.0]),
            contacts: vec![contact(2.0, 10.0), contact(10.0, 9.97)],
            slide_end: kneeform_oracle::SlideEnd::Cleared,
            casts: 0,
        }
    }

    #[test]
    fn a_surface_strike_is_explained_by_the_surface_s_own_error() {
        let trace = crease_cut_trace();
        // The nodes near both contacts rise 1 um: the node level's bound.
        // The surface cuts a crease at the first contact 0.05 mm deep and
        // stands 0.03 mm off the mesh at the second (`above`).
        let errors = vec![
            SurfaceError {
                above: 0.05,
                below: 0.0,
            },
            SurfaceError {
                above: 0.03,
                below: 0.0,
            },
        ];
        let bound = LevelErrorBound {
            curve: LevelCurve::of(&trace).unwrap(),
            travels: vec![2.0, 10.0],
            rises: vec![0.001, 0.001],
            lowest: vec![0.001, 0.001],
            push_rise: 0.001,
            pitch: 1.0,
            surface: Some((errors, SurfaceError::default())),
        };
        let sigma = 0.044 / 5.0;
        let node = ExactRule::Window {
            window: 5.0,
            two_sided: false,
        };
        let surface = ExactRule::Window {
            window: 5.0,
            two_sided: true,
        };
        // The grid's level 0.02 mm deeper than the exact one at travel 10:
        // it strikes when its level 5 mm back lay more than 0.034 mm deeper
        // than the exact 10 mm, which the crease cut there allows (0.05)
        // and the node level's bound there does not (0.001).
        assert!(!bound.explains((9.99, 0.0), 10.0, sigma, node).explained);
        assert!(bound.explains((9.99, 0.0), 10.0, sigma, surface).explained);
        assert_eq!(bound.deeper_at(10.0, surface), 0.03);
        // 0.04 mm deeper at travel 10: more than the surface's error there.
        assert!(!bound.explains((10.01, 0.0), 10.0, sigma, surface).explained);
        // Without the crease cut 5 mm back, the drop is not explained.
        let mut flat = bound;
        flat.surface.as_mut().unwrap().0[0].above = 0.01;
        assert!(!flat.explains((9.99, 0.0), 10.0, sigma, surface).explained);
        // A tie 0.04 mm above the exact level at travel 10, its drop
        // explained by a deeper cut 5 mm back (0.1 mm): beyond the
        // surface's error there (0.03) as a witness, within it and the
        // tie's slack (0.02) as a tie.
        let mut deep = flat;
        deep.surface.as_mut().unwrap().0[0].above = 0.1;
        assert!(!deep.explains((10.01, 0.0), 10.0, sigma, surface).explained);
        let tie = deep.explains((10.01, 0.02), 10.0, sigma, surface);
        assert!(tie.explained, "{tie:?}");
        assert!((tie.bound - 0.05).abs() < 1e-12, "{tie:?}");
        // The node level has no ties: its slack is 0, and its bound holds.
        assert!(!deep.explains((10.01, 0.0), 10.0, sigma, node).explained);
    }

    #[test]
    fn stats_use_absolute_values_and_nearest_rank() {
        let s = Stats::of(&[-3.0, 1.0, 2.0, 0.0]);
        assert_eq!((s.max, s.p95, s.mean, s.n), (3.0, 3.0, 1.5, 4));
        let many: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(Stats::of(&many).p95, 95.0);
        assert_eq!(Stats::of(&[]), Stats::default());
    }
}
