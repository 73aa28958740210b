//! Which triangles a cast cannot meet, decided exactly in the xz-plane
//! before any GJK: the knee-form is a prism along y, so the volume it
//! sweeps is a prism too, and a triangle meets that volume only if its part
//! inside the prism's y-slab, seen along y, comes within `R` of the swept
//! polygon.
//!
//! The knee-form is `(T (+) D_R) x [f - W, f]` ([`crate::knee_form`]). Cast
//! along -x for at most `s` mm it sweeps `((T (+) [-s, 0] x {0}) (+) D_R)
//! x [f - W, f]`; cast along +y, `(T (+) D_R) x [f - W, f + s]`. Write `P`
//! for the polygon (`T` placed, swept in x for the slide) and `[y0, y1]`
//! for the slab: a triangle meets the swept volume exactly when its part
//! with `y0 <= y <= y1`, projected on xz, lies within `R` of `P`.
//!
//! [`far_from_sweep`] says so only with a margin ([`MARGIN`], far above
//! the clipping's rounding): a triangle it rejects is further than that from
//! the swept volume, so GJK's cast would report no impact within the travel
//! and the confirming contact query no overlap; the cast returns what it
//! returned before, without them. Most triangles the BVH hands to GJK are
//! such misses, each of which a contact query on the swept shape had to
//! confirm (measured: `results/design.md`, "The oracle's prune").

use parry3d_f64::math::Vector;

/// How far beyond `R` a triangle must lie from the swept polygon to be
/// skipped (mm): a thousand times the accuracy of parry's casts on
/// part-sized coordinates, and a millionth of a typical pitch.
pub(crate) const MARGIN: f64 = 1e-3;

/// The volume a cast sweeps: the polygon `P` (its points, in xz) and the
/// y-slab, with the rounding radius.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sweep {
    /// `T` placed (x, z, mm).
    pub(crate) triangle: [[f64; 2]; 3],
    /// How far `T` is swept along -x (mm; 0 for the push).
    pub(crate) sweep_x: f64,
    /// The slab `[y0, y1]` (mm).
    pub(crate) y0: f64,
    /// See `y0`.
    pub(crate) y1: f64,
    /// `R` (mm).
    pub(crate) radius: f64,
}

/// Whether the triangle `[a, b, c]` (mm) lies further than `R + MARGIN`
/// from `sweep`'s volume, so that no cast within it can meet the triangle.
pub(crate) fn far_from_sweep(sweep: &Sweep, tri: [Vector; 3]) -> bool {
    let finite = |v: f64| v.is_finite() && v.abs() < 1e12;
    if !(finite(sweep.sweep_x) && finite(sweep.y0) && finite(sweep.y1)) {
        // Beyond part-sized numbers the squared distances overflow: cast.
        return false;
    }
    // The slab widened by the margin too: a triangle just beyond the face
    // (or the back) is not skipped on a rounding's strength.
    let Some((q, n)) = clip_to_slab(tri, sweep.y0 - MARGIN, sweep.y1 + MARGIN) else {
        return true;
    };
    let q = &q[..n];
    let reach = sweep.radius + MARGIN;
    // Cheap first: the boxes.
    let (p_lo, p_hi) = sweep_box(sweep);
    let (q_lo, q_hi) = points_box(q);
    if q_lo[0] > p_hi[0] + reach
        || q_hi[0] < p_lo[0] - reach
        || q_lo[1] > p_hi[1] + reach
        || q_hi[1] < p_lo[1] - reach
    {
        return true;
    }
    // Still cheap: a line between them, further than `reach` from both.
    if separated(sweep, q, reach) {
        return true;
    }
    // Overlap: a point of Q in P, or a point of P in Q.
    if q.iter().any(|&p| in_sweep(sweep, p)) {
        return false;
    }
    let t = sweep.triangle;
    let shifted = t.map(|[x, z]| [x - sweep.sweep_x, z]);
    if n >= 3 && t.iter().chain(&shifted).any(|&p| in_convex(q, p)) {
        return false;
    }
    // Otherwise the distance is between boundaries: P's boundary lies on
    // the union of T's edges, the shifted T's edges and the connectors.
    let mut segments = [[[0.0; 2]; 2]; 9];
    let mut m = 0;
    for k in 0..3 {
        segments[m] = [t[k], t[(k + 1) % 3]];
        m += 1;
        if sweep.sweep_x > 0.0 {
            segments[m] = [shifted[k], shifted[(k + 1) % 3]];
            segments[m + 1] = [t[k], shifted[k]];
            m += 2;
        }
    }
    let reach2 = reach * reach;
    for k in 0..n {
        let e = [q[k], q[(k + 1) % n]];
        for s in &segments[..m] {
            if segment_distance2(e, *s) <= reach2 {
                return false;
            }
        }
    }
    true
}

/// Whether a line perpendicular to an edge of `P` or of `Q` separates them
/// by more than `reach` (the separating-axis test: a lower bound of their
/// distance, exact unless their nearest points are two corners). `P` is
/// `T` and `T` moved by `-sweep_x` along x: its edges are `T`'s and, swept,
/// two along x.
fn separated(sweep: &Sweep, q: &[[f64; 2]], reach: f64) -> bool {
    let t = sweep.triangle;
    let apart = |n: [f64; 2]| {
        let dot = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1];
        let (mut p_lo, mut p_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let shift = -sweep.sweep_x * n[0];
        for &v in &t {
            let d = dot(v);
            p_lo = p_lo.min(d).min(d + shift);
            p_hi = p_hi.max(d).max(d + shift);
        }
        let (mut q_lo, mut q_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in q {
            let d = dot(v);
            q_lo = q_lo.min(d);
            q_hi = q_hi.max(d);
        }
        let gap = (q_lo - p_hi).max(p_lo - q_hi);
        gap > 0.0 && gap * gap > reach * reach * (n[0] * n[0] + n[1] * n[1])
    };
    let normal = |a: [f64; 2], b: [f64; 2]| [b[1] - a[1], a[0] - b[0]];
    let n = q.len();
    (0..3).any(|k| apart(normal(t[k], t[(k + 1) % 3])))
        || (sweep.sweep_x > 0.0 && apart([0.0, 1.0]))
        || (n >= 2 && (0..n).any(|k| apart(normal(q[k], q[(k + 1) % n]))))
}

/// The triangle's part with `y0 <= y <= y1`, as its xz-projection: up to
/// five points in order around it, or `None` when it lies outside the slab.
fn clip_to_slab(tri: [Vector; 3], y0: f64, y1: f64) -> Option<([[f64; 2]; 5], usize)> {
    if tri.iter().all(|p| p.y < y0) || tri.iter().all(|p| p.y > y1) {
        return None;
    }
    // Sutherland-Hodgman against y >= y0, then y <= y1, in 3D; a triangle
    // clipped by two planes keeps at most five points. Fixed arrays: this
    // runs for every triangle a cast's traversal reaches.
    let mut a = [Vector::ZERO; 5];
    a[..3].copy_from_slice(&tri);
    let mut n = 3;
    for (bound, keep_above) in [(y0, true), (y1, false)] {
        let inside = |p: &Vector| {
            if keep_above {
                p.y >= bound
            } else {
                p.y <= bound
            }
        };
        let mut out = [Vector::ZERO; 5];
        let mut m = 0;
        for k in 0..n {
            let (p, q) = (a[k], a[(k + 1) % n]);
            let (pin, qin) = (inside(&p), inside(&q));
            if pin {
                out[m] = p;
                m += 1;
            }
            if pin != qin {
                let t = (bound - p.y) / (q.y - p.y);
                out[m] = p + (q - p) * t;
                m += 1;
            }
        }
        (a, n) = (out, m);
        if n == 0 {
            return None;
        }
    }
    let mut points = [[0.0; 2]; 5];
    for (slot, p) in points.iter_mut().zip(&a[..n]) {
        *slot = [p.x, p.z];
    }
    Some((points, n))
}

/// The box of `P`.
fn sweep_box(sweep: &Sweep) -> ([f64; 2], [f64; 2]) {
    let (mut lo, hi) = points_box(&sweep.triangle);
    lo[0] -= sweep.sweep_x;
    (lo, hi)
}

/// The box of `points`.
fn points_box(points: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Whether `p` lies in `P`: the segment from `p` to `p + (sweep_x, 0)`
/// meets `T` (a point of `P` is a point of `T` moved by at most `sweep_x`
/// along -x).
fn in_sweep(sweep: &Sweep, p: [f64; 2]) -> bool {
    let t = sweep.triangle;
    if in_convex(&t, p) {
        return true;
    }
    if sweep.sweep_x <= 0.0 {
        return false;
    }
    let end = [p[0] + sweep.sweep_x, p[1]];
    if in_convex(&t, end) {
        return true;
    }
    (0..3).any(|k| segment_distance2([p, end], [t[k], t[(k + 1) % 3]]) == 0.0)
}

/// Whether `p` lies in the convex polygon `poly` (in order, either way
/// round; closed: its boundary counts).
fn in_convex(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = poly.len();
    let (mut pos, mut neg) = (false, false);
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        pos |= cross > 0.0;
        neg |= cross < 0.0;
        if pos && neg {
            return false;
        }
    }
    true
}

/// The squared distance between the segments `u` and `v` (0 when they
/// cross).
fn segment_distance2(u: [[f64; 2]; 2], v: [[f64; 2]; 2]) -> f64 {
    let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let (d1, d2) = (orient(u[0], u[1], v[0]), orient(u[0], u[1], v[1]));
    let (d3, d4) = (orient(v[0], v[1], u[0]), orient(v[0], v[1], u[1]));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return 0.0;
    }
    point_segment_distance2(u[0], v)
        .min(point_segment_distance2(u[1], v))
        .min(point_segment_distance2(v[0], u))
        .min(point_segment_distance2(v[1], u))
}

/// The squared distance from `p` to the segment `s`.
fn point_segment_distance2(p: [f64; 2], s: [[f64; 2]; 2]) -> f64 {
    let d = [s[1][0] - s[0][0], s[1][1] - s[0][1]];
    let w = [p[0] - s[0][0], p[1] - s[0][1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = if len2 > 0.0 {
        ((w[0] * d[0] + w[1] * d[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [w[0] - t * d[0], w[1] - t * d[1]];
    e[0] * e[0] + e[1] * e[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knee_form::{KneeForm, KneeFormDims, SweptKneeForm};
    use parry3d_f64::math::Pose;
    use parry3d_f64::query::details::distance_support_map_support_map;
    use parry3d_f64::shape::Triangle;

    /// A small deterministic generator (SplitMix64).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// Against parry's GJK distance between the swept knee-form and the
    /// triangle, on random triangles around it, at random angles, travels
    /// and both motions: every triangle skipped lies further than half the
    /// margin from the swept volume, and every triangle 10 mm from it is
    /// skipped (the test is exact, not a box).
    #[test]
    fn a_skipped_triangle_is_never_within_reach_of_the_swept_knee_form() {
        let mut rng = Rng(5);
        let (mut skipped, mut far_kept) = (0, 0);
        for _ in 0..4000 {
            let dims = KneeFormDims::default();
            let knee = KneeForm::new(dims, rng.range(-30.0, 30.0));
            let origin = Vector::new(
                rng.range(-50.0, 50.0),
                rng.range(-20.0, 20.0),
                rng.range(-50.0, 50.0),
            );
            let slide = rng.next() < 0.7;
            let travel = if rng.next() < 0.2 {
                0.0
            } else {
                rng.range(0.0, 300.0)
            };
            let dir = if slide { -Vector::X } else { Vector::Y };
            let centre = Vector::new(
                rng.range(-300.0, 300.0),
                rng.range(-150.0, 100.0),
                rng.range(-250.0, 250.0),
            );
            let size = rng.range(0.5, 80.0);
            let tri = [0, 1, 2].map(|_| {
                centre
                    + Vector::new(
                        rng.range(-size, size),
                        rng.range(-size, size),
                        rng.range(-size, size),
                    )
            });
            let placed = knee.triangle().map(|[x, z]| [x + origin.x, z + origin.z]);
            let w = dims.width;
            let sweep = if slide {
                Sweep {
                    triangle: placed,
                    sweep_x: travel,
                    y0: origin.y - w,
                    y1: origin.y,
                    radius: dims.radius,
                }
            } else {
                Sweep {
                    triangle: placed,
                    sweep_x: 0.0,
                    y0: origin.y - w,
                    y1: origin.y + travel,
                    radius: dims.radius,
                }
            };
            let swept = SweptKneeForm {
                knee,
                sweep: dir * travel,
            };
            // The triangle as the cast sees it: in the knee-form's frame.
            let pose = Pose::from_translation(-origin);
            let shape = Triangle::new(tri[0], tri[1], tri[2]);
            let d = distance_support_map_support_map(&pose, &swept, &shape);
            let skip = far_from_sweep(&sweep, tri);
            if skip {
                skipped += 1;
                assert!(
                    d > 0.5 * MARGIN,
                    "skipped at distance {d}: {tri:?}, {sweep:?}"
                );
            }
            if d > 10.0 && !skip {
                far_kept += 1;
            }
        }
        assert!(skipped > 1000, "{skipped} skipped");
        assert_eq!(far_kept, 0, "triangles 10 mm from the sweep were kept");
    }
}
