//! The height-field tessellation ([`tessellate`], the only one: the
//! scenario files, the tests and the oracle's tests and examples use it),
//! the lattice the scenario files are tessellated on (a square lattice at
//! multiples of a step, with extra vertex lines at the surface's creases),
//! and the exact profile functions the primitives are built from.

use std::f64::consts::{FRAC_PI_2, PI};

use crate::mesh::Triangle;

/// The most triangles a scenario is tessellated into (72 bytes each in
/// memory, 50 in the STL): 20 million, 54 times the paper's console.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// Lines closer than this (mm) are the same line: `10.3 - 0.3` is
/// `10.000000000000002`, and a cell 2e-15 mm wide would only add a sliver.
/// 1 um, because binary STL stores f32: at 1400 mm its spacing is 1.2e-4 mm,
/// and two lines closer than that became one, their cells zero-area
/// triangles (1,896 of them in console.toml before this was raised from
/// 1e-9).
const SAME_LINE: f64 = 1e-3;

/// The lattice coordinates along one axis: every multiple of `step` inside
/// `range`, the range's ends, and the `extra` creases strictly inside it
/// (each unless within 1 um (`SAME_LINE`) of a line already there), sorted.
pub fn axis(range: (f64, f64), step: f64, extra: &[f64]) -> Vec<f64> {
    let (lo, hi) = range;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let mut v: Vec<f64> = (first..=last).map(|k| k as f64 * step).collect();
    v.push(lo);
    v.push(hi);
    v.sort_by(f64::total_cmp);
    v.dedup_by(|later, earlier| *later - *earlier < SAME_LINE);
    // The range's ends stay exact: a multiple of the step just below `hi`
    // merged with it.
    if let Some(last) = v.last_mut() {
        *last = hi;
    }
    let mut creases: Vec<f64> = extra
        .iter()
        .copied()
        .filter(|&c| lo < c && c < hi)
        .collect();
    creases.sort_by(f64::total_cmp);
    for c in creases {
        // The lattice line at or after c, and the one before it.
        let at = v.partition_point(|&u| u < c);
        let near = |k: usize| v.get(k).is_some_and(|&u| (u - c).abs() <= SAME_LINE);
        if !(near(at) || (at > 0 && near(at - 1))) {
            v.insert(at, c);
        }
    }
    v
}

/// The number of triangles [`tessellate`] makes from the axes
/// [`axis`] gives at `step`.
pub(super) fn triangle_count(ranges: [(f64, f64); 2], step: f64, creases: [&[f64]; 2]) -> usize {
    let nx = axis(ranges[0], step, creases[0]).len();
    let nz = axis(ranges[1], step, creases[1]).len();
    2 * (nx - 1) * (nz - 1)
}

/// The lattice step for at least `min_triangles` triangles: `step` itself
/// when it gives enough, else the largest step below it that does, to the
/// resolution of a bisection (the count falls as the step grows, by one
/// lattice line at a time, so the result is within a line's worth of
/// triangles, a fraction of a percent, of the request: a benchmark asking
/// for the paper's 369,408 gets close to it).
pub(super) fn refined_step(
    ranges: [(f64, f64); 2],
    step: f64,
    creases: [&[f64]; 2],
    min_triangles: usize,
) -> f64 {
    let enough = |s: f64| triangle_count(ranges, s, creases) >= min_triangles;
    if enough(step) {
        return step;
    }
    // Bracket: `hi` too coarse, `lo` fine enough. The bare lattice's step
    // for the count is a good first guess for `lo`.
    let area = (ranges[0].1 - ranges[0].0) * (ranges[1].1 - ranges[1].0);
    let mut hi = step;
    let mut lo = step.min((2.0 * area / min_triangles as f64).sqrt());
    while !enough(lo) {
        hi = lo;
        lo *= 0.9;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if enough(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Tessellates the height field `y = height(i, k)` over the lattice
/// vertices `(xs[i], zs[k])` (mm, analysis frame): each cell splits into
/// two triangles along its `(i, k)`-`(i + 1, k + 1)` diagonal,
/// counter-clockwise in (x, z) so that their normals face -y, towards the
/// knee. Vertex y is exactly `height(i, k)`, evaluated once per vertex.
///
/// This is the one height-field tessellation: the scenario files, the
/// console, the tests and the oracle's tests and examples all build their
/// parts with it. `xs` and `zs` ascend; a value given twice makes a
/// vertical riser, its two copies taking the heights `height` gives their
/// two indices (the cells between them have no extent in xz).
pub fn tessellate(xs: &[f64], zs: &[f64], height: impl Fn(usize, usize) -> f64) -> Vec<Triangle> {
    let row = |k: usize| -> Vec<[f64; 3]> {
        xs.iter()
            .enumerate()
            .map(|(i, &x)| [x, height(i, k), zs[k]])
            .collect()
    };
    let cells = xs.len().saturating_sub(1) * zs.len().saturating_sub(1);
    let mut out = Vec::with_capacity(2 * cells);
    if zs.is_empty() {
        return out;
    }
    let mut below = row(0);
    for k in 1..zs.len() {
        let above = row(k);
        for i in 0..xs.len().saturating_sub(1) {
            // Counter-clockwise in (x, z), x right and z up: normal -y.
            let (a, b, c, d) = (below[i], below[i + 1], above[i + 1], above[i]);
            out.push([a, b, c]);
            out.push([a, c, d]);
        }
        below = above;
    }
    out
}

/// `sin(2 pi t)`, exact at quarter turns: the waves' zeros and crests on
/// the lattice are then exactly 0 and the amplitude, not 1e-16 off (a crest
/// region that starts 1e-15 mm out would show up in the results).
pub(super) fn sin_turns(t: f64) -> f64 {
    let phase = t.rem_euclid(1.0);
    match phase {
        0.0 | 0.5 => 0.0,
        0.25 => 1.0,
        0.75 => -1.0,
        _ => (2.0 * PI * phase).sin(),
    }
}

/// 1 at `u = 0` falling smoothly to 0 at `|u| = 1`, 0 beyond:
/// `cos^2(pi u / 2)`. Exactly 1 at 0 and exactly 0 from 1 on.
pub(super) fn cos2_bell(u: f64) -> f64 {
    if u.abs() < 1.0 {
        let c = (u * FRAC_PI_2).cos();
        c * c
    } else {
        0.0
    }
}

/// A flat plateau with a `cos^2` shoulder: 1 for `d <= half`, falling to 0
/// at `d = half + shoulder` (`d >= 0`, `shoulder > 0`). Exactly 1 on the
/// plateau and exactly 0 beyond the shoulder; C1 everywhere.
pub(super) fn plateau(d: f64, half: f64, shoulder: f64) -> f64 {
    if d <= half {
        1.0
    } else {
        cos2_bell((d - half) / shoulder)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_ranges_keep_multiples_and_add_the_ends() {
        assert_eq!(
            axis((-3.0, 4.5), 2.0, &[-0.5, 9.0]),
            [-3.0, -2.0, -0.5, 0.0, 2.0, 4.0, 4.5]
        );
        // A crease a rounding error off a lattice line is that line.
        assert_eq!(axis((0.0, 20.0), 2.0, &[10.3 - 0.3, 10.3, 10.3 + 1e-12]), {
            let mut want: Vec<f64> = (0..=10).map(|k| 2.0 * k as f64).collect();
            want.insert(6, 10.3);
            want
        });
    }

    #[test]
    fn refined_step_reaches_the_count_and_stays_close() {
        let ranges = [(0.0, 1500.0), (0.0, 600.0)];
        assert_eq!(refined_step(ranges, 8.0, [&[], &[]], 1000), 8.0);
        // With creases as well. The count steps by whole lattice lines, a
        // line along x adding a row of cells, 2 (nx - 1) triangles: the
        // result overshoots by less than that.
        let creases: [&[f64]; 2] = [&[1000.3, 1000.6, 1394.0], &[59.7, 330.3]];
        for c in [[&[][..], &[][..]], creases] {
            let s = refined_step(ranges, 8.0, c, 369_408);
            let n = triangle_count(ranges, s, c);
            let row = 2 * (axis(ranges[0], s, c[0]).len() - 1);
            assert!((369_408..369_408 + row).contains(&n), "{n} at {s}");
        }
    }

    #[test]
    fn cells_are_two_triangles_facing_the_knee() {
        let xs = [0.0, 1.0, 3.0];
        let zs = [0.0, 2.0];
        let tris = tessellate(&xs, &zs, |i, k| xs[i] * zs[k]);
        assert_eq!(tris.len(), 4);
        for [a, b, c] in tris {
            for v in [a, b, c] {
                assert_eq!(v[1], v[0] * v[2]);
            }
            let (e1, e2) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
            // The y component of the normal e1 x e2 (x, y, z order).
            assert!(e1[1] * e2[0] - e1[0] * e2[1] < 0.0);
        }
    }

    #[test]
    fn a_repeated_line_is_a_vertical_riser() {
        // A step 10 mm towards the knee for x < 1: x = 1 twice, the first
        // copy at the step's top, the second at the wall.
        let xs = [0.0, 1.0, 1.0, 2.0];
        let zs = [0.0, 1.0];
        let tris = tessellate(&xs, &zs, |i, _| if i <= 1 { -10.0 } else { 0.0 });
        assert_eq!(tris.len(), 6);
        // The riser's two triangles lie in the plane x = 1 and span y in
        // [-10, 0] and z in [0, 1].
        let riser: Vec<_> = tris
            .iter()
            .filter(|t| t.iter().all(|v| v[0] == 1.0))
            .collect();
        assert_eq!(riser.len(), 2);
        let ys: Vec<f64> = riser.iter().flat_map(|t| t.map(|v| v[1])).collect();
        assert!(ys.contains(&-10.0) && ys.contains(&0.0));
    }

    #[test]
    fn profiles_are_exact_where_it_matters() {
        assert_eq!(cos2_bell(0.0), 1.0);
        assert_eq!(cos2_bell(-1.0), 0.0);
        assert_eq!(cos2_bell(1.0), 0.0);
        // cos^2(pi u / 2) = (1 + cos(pi u)) / 2, within rounding.
        assert!((cos2_bell(0.3) - 0.5 * (1.0 + (0.3 * PI).cos())).abs() < 1e-15);
        assert_eq!(plateau(2.0, 2.0, 1.0), 1.0);
        assert_eq!(plateau(3.0, 2.0, 1.0), 0.0);
        assert!((plateau(2.5, 2.0, 1.0) - 0.5).abs() < 1e-15);
        assert_eq!(sin_turns(-0.75), 1.0);
        assert_eq!(sin_turns(2.5), 0.0);
    }
}
