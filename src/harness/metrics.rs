//! SPEC's harness metrics ("What the harness measures"): per start, the grid
//! trace against the exact trace; over many starts, max, p95 and mean.

use kneeform_oracle::{ContactPoint, StartStatus, StartTrace};
use serde::{Deserialize, Serialize};

use super::trace::GridTrace;

/// The metric names, as the columns of `verify.csv` and the keys of
/// `verify.json`.
pub const METRICS: [&str; 5] = [
    "push_error",
    "first_contact_error",
    "miss_distance",
    "false_alarm_distance",
    "unmatched_deflection",
];

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
        if values.is_empty() {
            return Stats::default();
        }
        let mut v: Vec<f64> = values.iter().map(|x| x.abs()).collect();
        v.sort_by(f64::total_cmp);
        let rank = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len());
        Stats {
            max: v[v.len() - 1],
            p95: v[rank - 1],
            mean: v.iter().sum::<f64>() / v.len() as f64,
            n: v.len(),
        }
    }
}

/// One start at one angle, grid against exact.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StartComparison {
    /// `yr - yr*` (mm), when both are placed.
    pub push_error: Option<f64>,
    /// Grid travel to the first colliding group minus the exact travel to
    /// the first contact (mm), when both have one.
    pub first_contact_error: Option<f64>,
    /// For each exact contact, the distance to the nearest grid colliding
    /// point of the same start (mm); `+inf` where the grid has none.
    pub miss: Vec<f64>,
    /// For each grid colliding point, the distance to the nearest exact
    /// contact or to the exact push contact (mm).
    pub false_alarm: Vec<f64>,
    /// For each exact contact met when the grid strikes nothing in this
    /// start: how far the exact knee-form had been deflected below the
    /// grid's level by then, `yr - f` (mm). The grid slid on at `yr`, so
    /// this is the part of the true path it missed.
    pub unmatched_deflection: Vec<f64>,
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn nearest(p: [f64; 3], set: impl Iterator<Item = [f64; 3]>) -> f64 {
    set.map(|q| distance(p, q)).fold(f64::INFINITY, f64::min)
}

/// Compares a grid trace with the exact trace of the same start and angle.
///
/// The exact push contact counts as a point of the exact contact curve
/// (its start, at travel 0) when measuring false alarms: where the grid's
/// push level is above the exact one (its nodes miss the true highest
/// point), the grid strikes, just after the push, the point the exact
/// knee-form rests on. It does not count for misses: the grid's push
/// contact is, by SPEC, not a colliding point.
///
/// **Strikes.** The grid counts a point only when it stands more than
/// `eps` above the level the knee-form had when it was met; where the
/// knee-form rides a nearly level surface, the exact trace records a
/// contact at every step while the grid, rightly by SPEC's rule, strikes
/// nothing until the surface has risen by `eps`. So misses (and the area
/// IoU and unmatched deflection) are measured from the exact **strikes**:
/// the contacts whose level is at least `eps` below the level of the
/// previous strike (`yr*` for the first), the same tolerance carried over
/// to the exact curve. False alarms are measured against every exact
/// contact: a grid strike anywhere on the exact contact curve is no false
/// alarm. Found on the tilted wave, where the exact knee-form rests on
/// successive crests 0.2 um apart in height for 550 mm.
pub fn compare(grid: &GridTrace, exact: &StartTrace, eps: f64) -> StartComparison {
    let placed = exact.status == StartStatus::Placed;
    let all_points: Vec<[f64; 3]> = if placed {
        exact.contacts.iter().map(|c| c.witness).collect()
    } else {
        Vec::new()
    };
    let exact_or_push: Vec<[f64; 3]> = all_points
        .iter()
        .copied()
        .chain(exact.push_witness.filter(|_| placed))
        .collect();
    let strikes = strikes(exact, eps);
    let exact_points: Vec<[f64; 3]> = strikes.iter().map(|c| c.witness).collect();
    let grid_points: Vec<[f64; 3]> = grid.colliding.iter().map(|c| c.point).collect();
    let unmatched_deflection = if grid_points.is_empty() && grid.yr.is_finite() && placed {
        strikes
            .iter()
            .map(|c| (grid.yr - c.face_level).max(0.0))
            .collect()
    } else {
        Vec::new()
    };
    StartComparison {
        push_error: match (grid.yr.is_finite(), exact.yr_star) {
            (true, Some(star)) if placed => Some(grid.yr - star),
            _ => None,
        },
        first_contact_error: match (grid.colliding.first(), strikes.first()) {
            (Some(g), Some(e)) if placed => Some(g.travel - e.travel),
            _ => None,
        },
        miss: exact_points
            .iter()
            .map(|&e| nearest(e, grid_points.iter().copied()))
            .collect(),
        false_alarm: grid_points
            .iter()
            .map(|&g| nearest(g, exact_or_push.iter().copied()))
            .collect(),
        unmatched_deflection,
    }
}

/// The exact contacts that are strikes by SPEC's tolerance (see
/// [`compare`]).
pub fn strikes(exact: &StartTrace, eps: f64) -> Vec<ContactPoint> {
    let (Some(mut level), StartStatus::Placed) = (exact.yr_star, exact.status) else {
        return Vec::new();
    };
    exact
        .contacts
        .iter()
        .filter(|c| {
            let strike = c.face_level <= level - eps;
            if strike {
                level = c.face_level;
            }
            strike
        })
        .copied()
        .collect()
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
