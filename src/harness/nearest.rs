//! Nearest-point distances in the xz plane, for the harness's miss,
//! false-alarm and area distances: a static 2-d tree over a point set.
//!
//! The area distance compares unions of hundreds of thousands of exact
//! contact points with tens of thousands of grid nodes, and each start's
//! thousand exact contacts with its hundreds of grid strikes; a
//! brute-force nearest search would cost their product.
//!
//! Distances are `hypot(dx, dz)`, the same number a brute-force scan
//! gives (the tree only skips points that cannot be nearer).

/// A point set in the plane that answers nearest-distance queries.
#[derive(Debug, Clone)]
pub(crate) struct PointSet {
    /// The points, reordered into a balanced 2-d tree: the median of each
    /// range longer than [`LEAF`] (split on x at even depths, z at odd)
    /// sits at its middle; shorter ranges are leaves, scanned in full.
    points: Vec<[f64; 2]>,
}

/// The longest range the tree leaves unsplit: scanning a few points costs
/// less than descending to each.
const LEAF: usize = 8;

impl PointSet {
    /// Builds the tree over `points`, each point once.
    pub fn new(mut points: Vec<[f64; 2]>) -> PointSet {
        // A point given twice answers nothing more, but its copies are
        // near-ties of each other, which a search cannot skip: the union
        // of a chained strip's exact strikes holds each contact once per
        // start that joined it (up to 64), and searching it took 99.9% of
        // a 20-row comparison.
        unique(&mut points);
        build(&mut points, 0);
        PointSet { points }
    }

    /// The distance from each point of `from` to its nearest point here
    /// (`+inf` when the set is empty).
    pub fn distances(&self, from: &[[f64; 2]]) -> Vec<f64> {
        // Consecutive queries (a trace's contacts) lie close together: the
        // previous answer's point starts each search with a near bound.
        let mut hint = None;
        from.iter()
            .map(|&q| {
                let best = self.nearest(q, hint, 0.0);
                hint = best.point;
                best.distance()
            })
            .collect()
    }

    /// The directed Hausdorff distance from `from` to this set: the largest
    /// distance from a point of `from` to its nearest point here (0 when
    /// `from` is empty, `+inf` when only this set is).
    pub fn hausdorff_from(&self, from: &[[f64; 2]]) -> f64 {
        if self.points.is_empty() {
            return if from.is_empty() { 0.0 } else { f64::INFINITY };
        }
        // Each point of `from` once (the same largest distance).
        let mut from = from.to_vec();
        unique(&mut from);
        // A query whose search finds a point clearly nearer than the
        // largest distance so far cannot raise it: its search stops there.
        let (mut largest, mut largest_d2) = (0.0f64, 0.0f64);
        let mut hint = None;
        for &q in &from {
            let best = self.nearest(q, hint, largest_d2 * (1.0 - TIE));
            hint = best.point;
            if best.d2 >= largest_d2 * (1.0 - TIE) {
                let d = best.distance();
                if d > largest {
                    largest = d;
                }
                largest_d2 = largest_d2.max(best.d2);
            }
        }
        largest
    }

    /// The nearest point to `q`, the search seeded with `hint` (a point of
    /// the set) and stopped as soon as a point nearer than `stop_d2`
    /// (squared) is found.
    fn nearest(&self, q: [f64; 2], hint: Option<[f64; 2]>, stop_d2: f64) -> Best {
        let mut best = Best::new();
        if let Some(p) = hint {
            best.offer(p, q);
        }
        search(&self.points, 0, q, stop_d2, &mut best);
        best
    }
}

/// `points` sorted (on x, then z) with each point once: copies equal to
/// the bit are dropped.
fn unique(points: &mut Vec<[f64; 2]>) {
    points.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup_by(|a, b| a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits());
}

fn build(points: &mut [[f64; 2]], depth: usize) {
    if points.len() <= LEAF {
        return;
    }
    let axis = depth % 2;
    let mid = points.len() / 2;
    points.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
    let (left, right) = points.split_at_mut(mid);
    build(left, depth + 1);
    build(&mut right[1..], depth + 1);
}

/// A relative margin far above the rounding of a squared distance: points
/// whose squared distances are within it of each other are near-ties,
/// which only `hypot` orders as a brute-force scan does.
const TIE: f64 = 1e-12;

/// The search's state: the smallest squared distance found, its point,
/// and the smallest `hypot` among the near-ties met beside it.
///
/// The answer, the brute-force minimum of `hypot` to the bit, is the
/// smallest `hypot` among the points whose squared distance is within
/// [`TIE`] of the smallest: any point beyond that margin is farther by far
/// more than `hypot`'s rounding. `hypot` is taken only for near-ties and
/// once at the end, not at every improvement.
struct Best {
    d2: f64,
    dx: f64,
    dz: f64,
    point: Option<[f64; 2]>,
    /// `min hypot` over the near-ties met so far, other than `point`
    /// (possibly including some that later fell beyond the margin: they
    /// are farther, so the minimum is unchanged).
    ties: f64,
}

impl Best {
    fn new() -> Best {
        Best {
            d2: f64::INFINITY,
            dx: f64::INFINITY,
            dz: 0.0,
            point: None,
            ties: f64::INFINITY,
        }
    }

    fn offer(&mut self, p: [f64; 2], q: [f64; 2]) {
        let (dx, dz) = (p[0] - q[0], p[1] - q[1]);
        let d2 = dx * dx + dz * dz;
        if d2 < self.d2 {
            if self.d2 <= d2 * (1.0 + TIE) {
                self.ties = self.ties.min(self.dx.hypot(self.dz));
            } else {
                self.ties = f64::INFINITY;
            }
            (self.d2, self.dx, self.dz, self.point) = (d2, dx, dz, Some(p));
        } else if d2 <= self.d2 * (1.0 + TIE) {
            self.ties = self.ties.min(dx.hypot(dz));
        }
    }

    fn distance(&self) -> f64 {
        match self.point {
            Some(_) => self.dx.hypot(self.dz).min(self.ties),
            None => f64::INFINITY,
        }
    }
}

/// Folds the nearest point of the subtree `points` into `best`, skipping a
/// far side only beyond the [`TIE`] margin, and returning early once
/// `best.d2 < stop_d2`.
fn search(points: &[[f64; 2]], depth: usize, q: [f64; 2], stop_d2: f64, best: &mut Best) {
    if points.len() <= LEAF {
        for &p in points {
            best.offer(p, q);
        }
        return;
    }
    let mid = points.len() / 2;
    let p = points[mid];
    best.offer(p, q);
    let axis = depth % 2;
    let delta = q[axis] - p[axis];
    let (near, far) = if delta < 0.0 {
        (&points[..mid], &points[mid + 1..])
    } else {
        (&points[mid + 1..], &points[..mid])
    };
    search(near, depth + 1, q, stop_d2, best);
    if best.d2 >= stop_d2 && delta * delta <= best.d2 * (1.0 + TIE) {
        search(far, depth + 1, q, stop_d2, best);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::harness::compare::SplitMix;

    /// Uniform numbers in `[0, 1)` from `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut bits = SplitMix(seed);
        move || (bits.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The distance from `q` to the nearest of `points` by a scan.
    fn brute(points: &[[f64; 2]], q: [f64; 2]) -> f64 {
        points
            .iter()
            .map(|p| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn nearest_distance_equals_brute_force() {
        let mut next = uniform(12345);
        // Duplicates and a line of equal x, to exercise ties in the split.
        let mut points: Vec<[f64; 2]> =
            (0..500).map(|_| [next() * 100.0, next() * 100.0]).collect();
        points.extend((0..50).map(|k| [50.0, k as f64]));
        points.extend((0..20).map(|_| [10.0, 10.0]));
        let set = PointSet::new(points.clone());
        for _ in 0..300 {
            let q = [next() * 150.0 - 25.0, next() * 150.0 - 25.0];
            assert_eq!(set.distances(&[q]), [brute(&points, q)], "{q:?}");
        }
    }

    #[test]
    fn seeded_and_early_stopped_searches_equal_brute_force() {
        let mut next = uniform(777);
        // Grid nodes (many equidistant near-ties) and a walk of queries
        // along a curve, as a trace's contacts come.
        let points: Vec<[f64; 2]> = (0..40)
            .flat_map(|i| (0..30).map(move |j| [i as f64 * 1.24 + 0.1, j as f64 * 1.24]))
            .collect();
        let set = PointSet::new(points.clone());
        let brute = |q: [f64; 2]| brute(&points, q);
        let mut queries: Vec<[f64; 2]> = (0..400)
            .map(|k| {
                let t = k as f64 * 0.13;
                [60.0 - t, 20.0 + 8.0 * (t / 7.0).sin()]
            })
            .collect();
        // Midpoints between nodes: exact ties, reached by rounding.
        queries
            .extend((0..50).map(|k| [0.72 + 1.24 * (k % 7) as f64, 0.62 + 1.24 * (k / 7) as f64]));
        queries.extend((0..100).map(|_| [next() * 70.0 - 10.0, next() * 60.0 - 10.0]));
        let expected: Vec<f64> = queries.iter().map(|&q| brute(q)).collect();
        assert_eq!(set.distances(&queries), expected);
        let largest = expected.iter().copied().fold(0.0, f64::max);
        assert_eq!(set.hausdorff_from(&queries), largest);
        for window in queries.chunks(37) {
            let largest = window.iter().map(|&q| brute(q)).fold(0.0, f64::max);
            assert_eq!(set.hausdorff_from(window), largest);
        }
    }

    #[test]
    fn hausdorff_of_empty_sets() {
        let empty = PointSet::new(Vec::new());
        assert_eq!(empty.distances(&[[0.0, 0.0]]), [f64::INFINITY]);
        assert_eq!(empty.hausdorff_from(&[[1.0, 2.0]]), f64::INFINITY);
        let one = PointSet::new(vec![[0.0, 0.0]]);
        assert_eq!(one.hausdorff_from(&[]), 0.0);
        assert_eq!(one.hausdorff_from(&[[3.0, 4.0], [0.0, 1.0]]), 5.0);
    }
}
