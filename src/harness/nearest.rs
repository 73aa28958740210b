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
pub struct PointSet {
    /// The points, reordered into a balanced 2-d tree: the median of each
    /// range (split on x at even depths, z at odd) sits at its middle.
    points: Vec<[f64; 2]>,
}

impl PointSet {
    /// Builds the tree over `points`.
    pub fn new(mut points: Vec<[f64; 2]>) -> PointSet {
        build(&mut points, 0);
        PointSet { points }
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The distance from `q` to the nearest point of the set, `+inf` when
    /// the set is empty.
    pub fn distance(&self, q: [f64; 2]) -> f64 {
        let mut best = Best {
            d2: f64::INFINITY,
            d: f64::INFINITY,
        };
        search(&self.points, 0, q, &mut best);
        best.d
    }

    /// The distance from each point of `from` to its nearest point here.
    pub fn distances(&self, from: &[[f64; 2]]) -> Vec<f64> {
        from.iter().map(|&q| self.distance(q)).collect()
    }

    /// The directed Hausdorff distance from `from` to this set: the largest
    /// distance from a point of `from` to its nearest point here (0 when
    /// `from` is empty, `+inf` when only this set is).
    pub fn hausdorff_from(&self, from: &[[f64; 2]]) -> f64 {
        from.iter().map(|&q| self.distance(q)).fold(0.0, f64::max)
    }
}

fn build(points: &mut [[f64; 2]], depth: usize) {
    if points.len() <= 1 {
        return;
    }
    let axis = depth % 2;
    let mid = points.len() / 2;
    points.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
    let (left, right) = points.split_at_mut(mid);
    build(left, depth + 1);
    build(&mut right[1..], depth + 1);
}

/// The nearest distance found so far: squared (to prune with) and as
/// `hypot` measures it (the answer).
struct Best {
    d2: f64,
    d: f64,
}

/// A relative margin far above the rounding of a squared distance: a point
/// whose squared distance is within it of the best is measured by `hypot`.
const TIE: f64 = 1e-12;

/// Folds the nearest point of the subtree `points` into `best`. Points are
/// compared by squared distance, and `hypot` is taken for those within
/// [`TIE`] of the best, so the answer is the brute-force minimum of
/// `hypot` to the bit (the two orders differ only among such near-ties);
/// a far side is skipped only beyond that margin.
fn search(points: &[[f64; 2]], depth: usize, q: [f64; 2], best: &mut Best) {
    if points.is_empty() {
        return;
    }
    let mid = points.len() / 2;
    let p = points[mid];
    let (dx, dz) = (p[0] - q[0], p[1] - q[1]);
    let d2 = dx * dx + dz * dz;
    if d2 <= best.d2 * (1.0 + TIE) {
        best.d = best.d.min(dx.hypot(dz));
        best.d2 = best.d2.min(d2);
    }
    let axis = depth % 2;
    let delta = q[axis] - p[axis];
    let (near, far) = if delta < 0.0 {
        (&points[..mid], &points[mid + 1..])
    } else {
        (&points[mid + 1..], &points[..mid])
    };
    search(near, depth + 1, q, best);
    if delta * delta <= best.d2 * (1.0 + TIE) {
        search(far, depth + 1, q, best);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_distance_equals_brute_force() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 100.0
        };
        // Duplicates and a line of equal x, to exercise ties in the split.
        let mut points: Vec<[f64; 2]> = (0..500).map(|_| [next(), next()]).collect();
        points.extend((0..50).map(|k| [50.0, k as f64]));
        points.extend((0..20).map(|_| [10.0, 10.0]));
        let set = PointSet::new(points.clone());
        for _ in 0..300 {
            let q = [next() * 1.5 - 25.0, next() * 1.5 - 25.0];
            let brute = points
                .iter()
                .map(|p| (p[0] - q[0]).hypot(p[1] - q[1]))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(set.distance(q), brute, "{q:?}");
        }
    }

    #[test]
    fn hausdorff_of_empty_sets() {
        let empty = PointSet::new(Vec::new());
        assert!(empty.is_empty());
        assert_eq!(empty.distance([0.0, 0.0]), f64::INFINITY);
        assert_eq!(empty.hausdorff_from(&[[1.0, 2.0]]), f64::INFINITY);
        let one = PointSet::new(vec![[0.0, 0.0]]);
        assert_eq!(one.hausdorff_from(&[]), 0.0);
        assert_eq!(one.hausdorff_from(&[[3.0, 4.0], [0.0, 1.0]]), 5.0);
    }
}
