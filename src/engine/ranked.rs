//! The fast path's heights as **ranks**: each finite height replaced by its
//! place among the grid's distinct heights, in 32-bit integers.
//!
//! Push and slide only ever compare heights and take minima and maxima of
//! them: a face level is always one of the grid's heights (a push minimum,
//! then minima along the slide). A strictly increasing map from heights to
//! integers keeps every comparison, minimum and maximum, so on ranks they
//! give the same answers as on heights, **exactly**. Ranks are half the
//! bytes of an `f64` and twice the lanes per vector register, and integer
//! `min`/`max` need no care for NaN.
//!
//! The one place heights are more than compared is SPEC's strike rule, and
//! it is monotone in the level ([`StrikeRule::strikes`]). So each node has
//! a **threshold**: the lowest rank whose height, as a face level, strikes
//! the node. It is found once per analysis, for every angle, by evaluating
//! the rule itself on the grid's own heights (a binary search over them),
//! and a node is struck exactly when the highest level that met it (its
//! reach) is at least its threshold. No arithmetic of the rule is redone in
//! another form, so nothing about rounding changes.

use rayon::prelude::*;

use crate::engine::padded::PaddedGrid;
use crate::strike::{Meeting, RateEstimate, StrikeRule};

/// A height's rank: `NEVER` below every height, `1..=n` for the grid's `n`
/// distinct finite heights in increasing order, [`OFF`] for `+inf`.
pub(crate) type Rank = u32;

/// The rank of `-inf`: a node no face level met, a start not placed.
pub(crate) const NEVER: Rank = 0;

/// The rank of `+inf`: off the part. Also the threshold of a node no level
/// strikes (no level is finite and that high).
pub(crate) const OFF: Rank = Rank::MAX;

/// The ranks of a padded grid's heights, and the heights they stand for.
#[derive(Debug)]
pub(crate) struct RankedGrid {
    /// `ranks[n]` is the rank of `padded.h[n]`, same layout.
    pub ranks: Vec<Rank>,
    /// The distinct finite heights in increasing order: rank `k` stands
    /// for `heights[k - 1]`. Heights that compare equal (`0.0` and
    /// `-0.0`) share one rank, as they share every comparison.
    heights: Vec<f64>,
}

impl RankedGrid {
    /// Ranks the heights of `padded`.
    ///
    /// # Panics
    ///
    /// When a height is NaN (the height grid never holds one), or the grid
    /// has `2^32 - 2` distinct heights or more (grids are bounded to
    /// `2^30` nodes).
    pub fn new(padded: &PaddedGrid) -> RankedGrid {
        let mut heights: Vec<f64> = padded.h.iter().copied().filter(|h| h.is_finite()).collect();
        // The total order puts -0.0 before 0.0, so the one of the two that
        // stands for their shared rank is -0.0 whatever the thread count.
        assert!(!heights.iter().any(|h| h.is_nan()), "no NaN height");
        heights.par_sort_unstable_by(f64::total_cmp);
        heights.dedup_by(|a, b| a == b);
        heights.shrink_to_fit();
        assert!(heights.len() < (OFF - 1) as usize, "too many heights");
        let mut ranks = vec![OFF; padded.h.len()];
        ranks
            .par_chunks_mut(padded.stride)
            .zip(padded.h.par_chunks(padded.stride))
            .for_each(|(ranks, h)| {
                for (r, &h) in ranks.iter_mut().zip(h) {
                    if h.is_finite() {
                        *r = heights.partition_point(|&v| v < h) as Rank + 1;
                    }
                }
            });
        RankedGrid { ranks, heights }
    }

    /// The height rank `r` stands for: `-inf` for [`NEVER`], `+inf` for
    /// [`OFF`].
    pub fn height(&self, r: Rank) -> f64 {
        match r {
            NEVER => f64::NEG_INFINITY,
            OFF => f64::INFINITY,
            r => self.heights[r as usize - 1],
        }
    }

    /// Per node of `padded` (ranked as `self`), the lowest rank whose
    /// height, as the face level that meets the node, makes it a strike by
    /// `rule` on a grid of pitch `pitch` (under the window rule: a
    /// contact, the deflection test being [`RankedGrid::window_thresholds`]);
    /// [`OFF`] where no height does. The node behind `n` is `n + 1`: the
    /// next column, or past a row's last real column the padding's `+inf`;
    /// the last node is padding.
    ///
    /// A level strikes only above the node's own height, so the search
    /// runs over the heights above it, and it is a binary search because
    /// the rule is monotone in the level; galloping, because the threshold
    /// is most often a few heights above the node's own (`h + e0`).
    pub fn thresholds(&self, padded: &PaddedGrid, rule: &StrikeRule) -> Vec<Rank> {
        let pitch = padded.spec.pitch;
        self.per_node(padded, |own, behind, f| match rule.rate {
            RateEstimate::Window => rule.is_contact(own, f),
            RateEstimate::XSlope => rule.strikes(Meeting {
                h: own,
                behind,
                level: f,
                earlier: f,
                pitch,
            }),
        })
    }

    /// Per node of `padded`, the lowest rank whose height, as the level
    /// `W` mm of travel before the node, passes the window rule's
    /// deflection test ([`StrikeRule::window_strikes`]); [`OFF`] where no
    /// height does. Monotone in that level, so a binary search again.
    pub fn window_thresholds(&self, padded: &PaddedGrid, rule: &StrikeRule) -> Vec<Rank> {
        self.per_node(padded, |own, _, earlier| rule.window_strikes(own, earlier))
    }

    /// Per node, the lowest rank above the node's own height for which
    /// `passes(h, behind, level)` holds, `passes` being monotone in the
    /// level.
    fn per_node(
        &self,
        padded: &PaddedGrid,
        passes: impl Fn(f64, f64, f64) -> bool + Sync,
    ) -> Vec<Rank> {
        let h = &padded.h;
        let mut out = vec![OFF; h.len()];
        out.par_chunks_mut(padded.stride)
            .enumerate()
            .for_each(|(row, out)| {
                let first = row * padded.stride;
                for (k, t) in out.iter_mut().enumerate() {
                    let n = first + k;
                    let (own, Some(&behind)) = (h[n], h.get(n + 1)) else {
                        continue;
                    };
                    if !own.is_finite() {
                        continue;
                    }
                    let above = self.ranks[n] as usize;
                    let higher = &self.heights[above..];
                    let lowest = first_true(higher, |f| passes(own, behind, f));
                    if lowest < higher.len() {
                        *t = (above + lowest) as Rank + 1;
                    }
                }
            });
        out
    }
}

/// The index of the first element of `values` for which `pred` holds
/// (`values.len()` if none), for a `pred` false and then true along
/// `values`: a galloping search from the front, then a binary search in
/// the last gallop's step.
fn first_true(values: &[f64], pred: impl Fn(f64) -> bool) -> usize {
    let mut lo = 0;
    let mut step = 1;
    loop {
        let probe = lo + step - 1;
        if probe >= values.len() {
            return lo + values[lo..].partition_point(|&v| !pred(v));
        }
        if pred(values[probe]) {
            return lo + values[lo..probe].partition_point(|&v| !pred(v));
        }
        lo = probe + 1;
        step *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{GridSpec, HeightGrid};
    use crate::kneeform::{GridFootprint, KneeForm};

    fn padded(h: Vec<f64>, nx: usize, nz: usize) -> PaddedGrid {
        let spec = GridSpec {
            pitch: 0.5,
            i_origin: 0,
            j_origin: 0,
            nx,
            nz,
        };
        let knee = KneeForm {
            triangle_side: 1.0,
            radius: 0.5,
            thickness: 1.0,
        };
        let fp = GridFootprint::new(&knee, 0.0, &spec);
        PaddedGrid::new(&HeightGrid { spec, h }, std::slice::from_ref(&fp))
    }

    #[test]
    fn ranks_keep_order_and_equality_and_stand_for_their_heights() {
        let h = vec![3.0, -0.0, f64::INFINITY, 0.0, -7.5, 3.0, 1e-300, 2.0];
        let grid = padded(h, 4, 2);
        let ranked = RankedGrid::new(&grid);
        for (a, &ha) in grid.h.iter().enumerate() {
            let ra = ranked.ranks[a];
            assert!(ranked.height(ra) == ha, "{ha}");
            for (b, &hb) in grid.h.iter().enumerate() {
                let rb = ranked.ranks[b];
                assert_eq!(ha < hb, ra < rb, "{ha} {hb}");
                assert_eq!(ha == hb, ra == rb, "{ha} {hb}");
            }
        }
        assert_eq!(ranked.height(NEVER), f64::NEG_INFINITY);
        // -0.0 and 0.0 share a rank (-0.0 stands for it); 3.0 appears
        // twice: 5 distinct.
        assert_eq!(ranked.heights.len(), 5);
        assert!(
            ranked
                .heights
                .iter()
                .any(|h| *h == 0.0 && h.is_sign_negative())
        );
    }

    #[test]
    fn galloping_finds_the_first_true_at_every_place() {
        let values: Vec<f64> = (0..100).map(f64::from).collect();
        for len in [0, 1, 2, 3, 7, 64, 100] {
            for first in 0..=len {
                let got = first_true(&values[..len], |v| v >= first as f64);
                assert_eq!(got, first, "len {len}");
            }
        }
    }

    /// The threshold decides as the rule does, at every level the grid
    /// holds and at none.
    #[test]
    fn a_reach_strikes_exactly_from_the_threshold_on() {
        let h: Vec<f64> = (0..48)
            .map(|n| match n % 7 {
                3 => f64::INFINITY,
                k => (k as f64 * 0.37 + (n / 7) as f64 * 0.011).sin() * 2.0,
            })
            .collect();
        let grid = padded(h, 8, 6);
        let ranked = RankedGrid::new(&grid);
        for rule in [
            StrikeRule::new(0.0, 1e-6),
            StrikeRule::new(0.5, 1e-6),
            StrikeRule::new(30.0, 0.0),
            StrikeRule::new(3.0, 0.05).with_rate(RateEstimate::XSlope),
            StrikeRule::new(0.0, 1e-6).with_rate(RateEstimate::XSlope),
        ] {
            let thr = ranked.thresholds(&grid, &rule);
            let thr_w = ranked.window_thresholds(&grid, &rule);
            let mut struck = 0;
            for (n, (&t, &tw)) in thr.iter().zip(&thr_w).enumerate().take(grid.h.len() - 1) {
                for r in (0..=ranked.heights.len() as Rank).chain([OFF]) {
                    let level = ranked.height(r);
                    if !level.is_finite() && r != NEVER {
                        continue;
                    }
                    let h = grid.h[n];
                    let want = match rule.rate {
                        RateEstimate::Window => rule.is_contact(h, level),
                        RateEstimate::XSlope => rule.strikes(Meeting {
                            h,
                            behind: grid.h[n + 1],
                            level,
                            earlier: level,
                            pitch: 0.5,
                        }),
                    };
                    assert_eq!(r >= t, want, "node {n}, rank {r}");
                    assert_eq!(r >= tw, rule.window_strikes(h, level), "node {n}, rank {r}");
                    struck += usize::from(want);
                }
            }
            assert!(struck > 0);
        }
    }
}
