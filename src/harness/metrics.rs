//! SPEC's harness metrics ("What the harness measures"): per start, the grid
//! trace against the exact trace; over many starts, max, p95 and mean.

use kneeform_oracle::{ContactPoint, LevelCurve, StartStatus, StartTrace};
use serde::{Deserialize, Serialize};

use super::trace::GridTrace;

/// The metric names, as the columns of `verify.csv` and the keys of
/// `verify.json`: each over all strikes, then over the decided strikes
/// (see [`TieBand`]), then the area distances: both directions at once,
/// then each on its own (`area_miss_distance`, from the exact strikes to
/// the grid's: what the grid misses; `area_false_alarm_distance`, from the
/// grid's to the exact ones: what it strikes more).
pub const METRICS: [&str; 15] = [
    "push_error",
    "first_contact_error",
    "miss_distance",
    "false_alarm_distance",
    "unmatched_deflection",
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
];

/// The metrics a user's guarantee is made of (and `verify` passes or fails
/// on): the push error, the decided strike metrics and the decided area
/// distance. The others are shown beside them, never hidden.
pub const DECIDED_METRICS: [&str; 6] = [
    "push_error",
    "first_contact_error_decided",
    "miss_distance_decided",
    "false_alarm_distance_decided",
    "unmatched_deflection_decided",
    "area_distance_decided",
];

/// The index of `name` in [`METRICS`].
pub fn metric_index(name: &str) -> usize {
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
pub enum ExactRule {
    /// `rate > sigma`, decided against [`TieBand`].
    Rate,
    /// SPEC's window rule: `f*(s - W) - f*(s) > sigma W`, the curve read
    /// between its samples ([`LevelCurve`]).
    ///
    /// **Ties at the threshold.** The grid's drop `f(s - W) - h` reads a
    /// node's height (a point of the surface: exact) and the grid's level
    /// `W` back, which follows the surface only at the nodes met, so it
    /// lies *above* the exact level (SPEC: "the grid's level is too deep"),
    /// by up to the exact level's fall over the pitch before that travel
    /// (before a pitch of travel, its push error, bounded the same way by
    /// the fall over the first pitch). The grid's drop is therefore at
    /// least the exact one, up to the travel between the contact and its
    /// node: a grid can strike where the exact knee-form does not (a false
    /// alarm, on the safe side), not the other way round. So the band is
    /// one-sided, as SPEC's "level error" paragraph says: a contact is a
    /// decided strike when its drop exceeds `sigma W` by more than the
    /// drop's stated error, a decided non-strike when it falls short by
    /// more than that error plus twice the grid's level error there (SPEC,
    /// "Ties at the threshold"). The band shrinks with the pitch.
    Window {
        /// `W` (mm).
        window: f64,
        /// The grid's pitch (mm).
        pitch: f64,
    },
}

impl ExactRule {
    /// The exact side of `rule` on a grid of pitch `pitch` (mm).
    pub fn of(rule: &crate::strike::StrikeRule, pitch: f64) -> ExactRule {
        match rule.window_mm() {
            Some(window) => ExactRule::Window { window, pitch },
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
pub struct ExactStrike {
    /// The contact.
    pub contact: ContactPoint,
    /// A strike by the rule (`rate > sigma`, or the window drop above
    /// `sigma W`).
    pub strike: bool,
    /// Against the tie band.
    pub decision: Decision,
}

/// The exact contacts of a placed start with their standing by `rule`;
/// empty for a start that is not placed or failed.
pub fn classify(exact: &StartTrace, band: &TieBand, rule: ExactRule) -> Vec<ExactStrike> {
    let Some(curve) = LevelCurve::of(exact) else {
        return Vec::new();
    };
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
            ExactRule::Window { window, pitch } => {
                let drop = curve.drop_at(k, window, JUMP_TOLERANCE);
                let back = (c.travel - window).max(pitch);
                let grid = 2.0 * (curve.at(back - pitch).value - curve.at(back).value);
                let threshold = band.sigma * window;
                ExactStrike {
                    contact: c,
                    strike: drop.drop > threshold,
                    decision: if drop.drop - drop.error > threshold {
                        Decision::Strike
                    } else if drop.drop + drop.error + grid < threshold {
                        Decision::NoStrike
                    } else {
                        Decision::Undecided
                    },
                }
            }
        })
        .collect()
}

/// One start at one angle, grid against exact. Distances are in xz, the
/// grid's domain (SPEC, "What the harness measures").
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StartComparison {
    /// `yr - yr*` (mm), when both are placed.
    pub push_error: Option<f64>,
    /// Grid travel to the first strike minus the exact travel to the first
    /// strike (mm), when both have one.
    pub first_contact_error: Option<f64>,
    /// The same where the exact first possible strike (not gentler than the
    /// band) is a decided one.
    pub first_contact_error_decided: Option<f64>,
    /// For each exact strike, the xz distance to the nearest grid strike of
    /// the same start (mm); `+inf` where the grid has none.
    pub miss: Vec<f64>,
    /// The same for each decided exact strike.
    pub miss_decided: Vec<f64>,
    /// For each grid strike, the xz distance to the nearest exact strike or
    /// to the exact push contact (mm); `+inf` where there is neither.
    pub false_alarm: Vec<f64>,
    /// For each grid strike, the xz distance to the nearest exact contact
    /// that is not a decided non-strike, or to the exact push contact.
    pub false_alarm_decided: Vec<f64>,
    /// For each exact strike met when the grid strikes nothing in this
    /// start: how far the exact knee-form had been deflected below the
    /// grid's level by then, `yr - f` (mm). The grid slid on at `yr`, so
    /// this is the part of the true path it missed.
    pub unmatched_deflection: Vec<f64>,
    /// The same for decided exact strikes.
    pub unmatched_deflection_decided: Vec<f64>,
    /// Exact strikes (`rate > sigma`).
    pub exact_strikes: usize,
    /// Exact contacts in the tie band.
    pub undecided: usize,
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
    /// The exact strikes (`rate > sigma`), in the order of `miss`.
    pub strikes: Vec<[f64; 2]>,
    /// The decided exact strikes, in the order of `miss_decided`.
    pub decided: Vec<[f64; 2]>,
    /// The exact contacts that are not decided non-strikes.
    pub possible: Vec<[f64; 2]>,
    /// The exact push contact, when placed: a point of the exact curve for
    /// false alarms (see [`compare`]).
    pub push: Vec<[f64; 2]>,
}

impl StartPoints {
    /// Appends `other`'s points to these.
    pub fn extend(&mut self, other: &StartPoints) {
        self.grid.extend(&other.grid);
        self.strikes.extend(&other.strikes);
        self.decided.extend(&other.decided);
        self.possible.extend(&other.possible);
        self.push.extend(&other.push);
    }

    /// `exact`'s points with the push contacts: what a grid strike's false
    /// alarm is measured against.
    pub fn with_push(&self, exact: &[[f64; 2]]) -> Vec<[f64; 2]> {
        exact.iter().chain(&self.push).copied().collect()
    }
}

impl StartComparison {
    /// Where the worst decided disagreement of this start lies (xz, mm)
    /// and how large it is: the decided exact strike furthest from the
    /// grid's strikes or the grid strike furthest from every possible exact
    /// one, whichever is further (infinite distances first).
    pub fn worst_decided_point(&self) -> Option<([f64; 2], f64)> {
        self.points
            .decided
            .iter()
            .zip(&self.miss_decided)
            .chain(self.points.grid.iter().zip(&self.false_alarm_decided))
            .map(|(&p, &d)| (p, d))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

fn xz(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[2]]
}

fn nearest(p: [f64; 2], set: &[[f64; 2]]) -> f64 {
    set.iter()
        .map(|q| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Compares a grid trace with the exact trace of the same start and angle.
///
/// **Strikes on both sides.** The grid's strikes are SPEC's (rule 2 of the
/// slide); the exact strikes are the contacts whose traced deflection rate
/// exceeds `sigma` ([`classify`]). Over *all* strikes, a miss is an exact
/// strike far from every grid strike, a false alarm a grid strike far from
/// every exact strike. Over *decided* strikes, misses are counted only from
/// exact contacts steeper than the tie band, and a grid strike is a false
/// alarm only when it is far from every exact contact that is not gentler
/// than the band: near the threshold either answer is right.
///
/// The exact push contact counts as a point of the exact curve for false
/// alarms: where the grid's push level is above the exact one (its nodes
/// miss the true highest point), the grid strikes, just after the push, the
/// point the exact knee-form rests on. It does not count for misses: the
/// grid's push contact is, by SPEC, not a colliding point.
pub fn compare(
    grid: &GridTrace,
    exact: &StartTrace,
    band: &TieBand,
    rule: ExactRule,
) -> StartComparison {
    let placed = exact.status == StartStatus::Placed;
    let classified = classify(exact, band, rule);
    let push: Vec<[f64; 2]> = exact
        .push_witness
        .filter(|_| placed)
        .map(xz)
        .into_iter()
        .collect();
    let points = |keep: &dyn Fn(&ExactStrike) -> bool| -> Vec<[f64; 2]> {
        classified
            .iter()
            .filter(|c| keep(c))
            .map(|c| xz(c.contact.witness))
            .collect()
    };
    let pts = StartPoints {
        grid: grid.colliding.iter().map(|c| xz(c.point)).collect(),
        strikes: points(&|c| c.strike),
        decided: points(&|c| c.decision == Decision::Strike),
        possible: points(&|c| c.decision != Decision::NoStrike),
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
    StartComparison {
        push_error: match (grid.yr.is_finite(), exact.yr_star) {
            (true, Some(star)) if placed => Some(grid.yr - star),
            _ => None,
        },
        first_contact_error: match (grid_first, first_strike) {
            (Some(g), Some(e)) => Some(g.travel - e.contact.travel),
            _ => None,
        },
        first_contact_error_decided: match (rule, grid_first, first_possible, first_decided) {
            (ExactRule::Rate, Some(g), Some(e), _) if e.decision == Decision::Strike => {
                Some(g.travel - e.contact.travel)
            }
            // Under the window the exact drop rises from 0 at every
            // landing, so the first exact strike sits on the threshold:
            // the grid's first strike is measured against the interval
            // from the first possible exact strike to the first decided
            // one (SPEC's metric table).
            (ExactRule::Window { .. }, Some(g), Some(lo), Some(hi)) => {
                let (lo, hi) = (lo.contact.travel, hi.contact.travel);
                Some(if g.travel < lo {
                    g.travel - lo
                } else if g.travel > hi {
                    g.travel - hi
                } else {
                    0.0
                })
            }
            _ => None,
        },
        miss: pts
            .strikes
            .iter()
            .map(|&e| nearest(e, grid_points))
            .collect(),
        miss_decided: pts
            .decided
            .iter()
            .map(|&e| nearest(e, grid_points))
            .collect(),
        false_alarm: grid_points
            .iter()
            .map(|&g| nearest(g, &strikes_or_push))
            .collect(),
        false_alarm_decided: grid_points
            .iter()
            .map(|&g| nearest(g, &possible_or_push))
            .collect(),
        unmatched_deflection: deflection(&|c| c.strike),
        unmatched_deflection_decided: deflection(&|c| c.decision == Decision::Strike),
        exact_strikes: pts.strikes.len(),
        undecided: classified
            .iter()
            .filter(|c| c.decision == Decision::Undecided)
            .count(),
        points: pts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_use_absolute_values_and_nearest_rank() {
        let s = Stats::of(&[-3.0, 1.0, 2.0, 0.0]);
        assert_eq!((s.max, s.p95, s.mean, s.n), (3.0, 3.0, 1.5, 4));
        let many: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(Stats::of(&many).p95, 95.0);
        assert_eq!(Stats::of(&[]), Stats::default());
    }
}
