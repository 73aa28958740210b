//! The one z-buffer rasterizer: per node of a lattice, the depth of the
//! nearest triangle whose projection covers the node, and a tag of that
//! triangle. The height grid ([`crate::grid`]) and the report's renderer
//! (`report::render`) both sample with it; a [`Lattice`] says where the
//! nodes are and how tolerant a triangle's edges are.
//!
//! Triangles are given in lattice coordinates: `[x, y, depth]` per vertex,
//! `x` along the columns and `y` along the rows. A node is covered when its
//! three barycentric weights are each at least the lattice's slack (closed
//! triangles: edges and vertices count); its depth is the weights' blend of
//! the vertices' depths, and the smaller depth wins.
//!
//! The lattice is cut into bands of [`BAND_ROWS`] rows, filled in
//! parallel: each triangle is binned into the bands its rows touch, and
//! each band owns its slice of the buffers. Within a band the triangles
//! are drawn in their input order, and a tie keeps the first, so the
//! result does not depend on the number of threads.
//!
//! **Invariant:** the per-node arithmetic is each caller's as it was
//! before the two were merged (the grid divides each edge function by
//! twice the area, the renderer multiplies by its inverse): the grid's
//! heights are the engine's input, and the report's pictures are compared
//! byte for byte, so neither may move by a rounding.

use rayon::prelude::*;

/// Rows per band of the parallel rasterizer: enough work per task to hide
/// scheduling, small enough to balance two threads on a ragged part.
pub(crate) const BAND_ROWS: usize = 16;

/// How an edge function becomes a barycentric weight.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Weighting {
    /// `edge / area2`: correctly rounded.
    DivideByArea,
    /// `edge * (1 / area2)`: one division per triangle instead of three per
    /// node.
    MultiplyByInverse,
}

/// Where a z-buffer's nodes are, and which triangles cover them.
pub(crate) trait Lattice: Sync {
    /// How weights are computed; a constant, so that each lattice gets its
    /// own inner loop.
    const WEIGHTING: Weighting;

    /// Number of columns (along `x`) and rows (along `y`).
    fn size(&self) -> (usize, usize);

    /// The `x` of column `i`.
    fn x(&self, i: usize) -> f64;

    /// The `y` of row `j`.
    fn y(&self, j: usize) -> f64;

    /// The columns, clamped to the lattice, whose nodes a triangle spanning
    /// `[lo, hi]` in `x` may cover; `None` when there is none.
    fn columns(&self, lo: f64, hi: f64) -> Option<(usize, usize)>;

    /// The rows, clamped to the lattice, whose nodes a triangle spanning
    /// `[lo, hi]` in `y` may cover; `None` when there is none.
    fn rows(&self, lo: f64, hi: f64) -> Option<(usize, usize)>;

    /// Whether a triangle with twice this signed area is skipped: seen
    /// edge-on, it covers no node robustly.
    fn degenerate(&self, area2: f64) -> bool;

    /// Per vertex, the least barycentric weight that still counts as
    /// inside; `edges[k]` is the edge opposite vertex `k`.
    fn slack(&self, edges: &[[[f64; 2]; 2]; 3], area2: f64) -> [f64; 3];
}

/// A filled z-buffer: row-major from row 0, `depth` `+inf` where no
/// triangle covers the node, `tag` the nearest triangle's tag there.
#[derive(Debug, Clone)]
pub(crate) struct ZBuffer<T> {
    /// Depth of the nearest triangle per node.
    pub depth: Vec<f64>,
    /// Its tag (the default where none).
    pub tag: Vec<T>,
}

/// Z-buffers `triangles` on `lattice`: `project` gives a triangle's
/// vertices in lattice coordinates (`[x, y, depth]`) and its tag.
pub(crate) fn zbuffer<L, S, T>(
    lattice: &L,
    triangles: &[S],
    project: impl Fn(&S) -> ([[f64; 3]; 3], T) + Sync,
) -> ZBuffer<T>
where
    L: Lattice,
    S: Sync,
    T: Copy + Default + Send + Sync,
{
    let (nx, ny) = lattice.size();
    let bands = ny.div_ceil(BAND_ROWS);
    // Bin each triangle into the bands its rows touch.
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (k, t) in triangles.iter().enumerate() {
        let (s, _) = project(t);
        let (lo, hi) = min_max([s[0][1], s[1][1], s[2][1]]);
        let Some((r_lo, r_hi)) = lattice.rows(lo, hi) else {
            continue;
        };
        for bin in &mut binned[r_lo / BAND_ROWS..=r_hi / BAND_ROWS] {
            bin.push(k as u32);
        }
    }
    let mut depth = vec![f64::INFINITY; nx * ny];
    let mut tag = vec![T::default(); nx * ny];
    if nx > 0 {
        depth
            .par_chunks_mut(BAND_ROWS * nx)
            .zip(tag.par_chunks_mut(BAND_ROWS * nx))
            .zip(binned.par_iter())
            .enumerate()
            .for_each(|(band, ((depth, tag), bin))| {
                let rows = band * BAND_ROWS..band * BAND_ROWS + depth.len() / nx;
                for &k in bin {
                    let (s, t) = project(&triangles[k as usize]);
                    fill(lattice, &s, t, rows.clone(), depth, tag);
                }
            });
    }
    ZBuffer { depth, tag }
}

/// Writes one triangle (lattice coordinates) into the band of `rows`,
/// keeping the nearest depth; `depth` and `tag` hold exactly those rows.
fn fill<L: Lattice, T: Copy>(
    lattice: &L,
    s: &[[f64; 3]; 3],
    t: T,
    rows: std::ops::Range<usize>,
    depth: &mut [f64],
    tag: &mut [T],
) {
    let [a, b, c] = s.map(|v| [v[0], v[1]]);
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if lattice.degenerate(area2) {
        return;
    }
    // Edge k is opposite vertex k; its edge function, normalised by area2,
    // is vertex k's barycentric weight.
    let edges = [[b, c], [c, a], [a, b]];
    let slack = lattice.slack(&edges, area2);
    let (x_lo, x_hi) = min_max([a[0], b[0], c[0]]);
    let (y_lo, y_hi) = min_max([a[1], b[1], c[1]]);
    let (Some((i_lo, i_hi)), Some((j_lo, j_hi))) =
        (lattice.columns(x_lo, x_hi), lattice.rows(y_lo, y_hi))
    else {
        return;
    };
    let (j_lo, j_hi) = (j_lo.max(rows.start), j_hi.min(rows.end - 1));
    let inv = 1.0 / area2;
    let weight = |[u, v]: [[f64; 2]; 2], x: f64, y: f64| {
        let e = (v[0] - u[0]) * (y - u[1]) - (v[1] - u[1]) * (x - u[0]);
        match L::WEIGHTING {
            Weighting::DivideByArea => e / area2,
            Weighting::MultiplyByInverse => e * inv,
        }
    };
    let nx = lattice.size().0;
    let depths = [s[0][2], s[1][2], s[2][2]];
    for j in j_lo..=j_hi {
        let y = lattice.y(j);
        let row = (j - rows.start) * nx;
        let depth = &mut depth[row..][..nx];
        let tag = &mut tag[row..][..nx];
        for i in i_lo..=i_hi {
            let x = lattice.x(i);
            let w = edges.map(|e| weight(e, x, y));
            if w[0] >= slack[0] && w[1] >= slack[1] && w[2] >= slack[2] {
                let d = w[0] * depths[0] + w[1] * depths[1] + w[2] * depths[2];
                if d < depth[i] {
                    depth[i] = d;
                    tag[i] = t;
                }
            }
        }
    }
}

/// The smallest and the largest of three values.
fn min_max(v: [f64; 3]) -> (f64, f64) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lattice of unit spacing, its nodes at `k + 0.5`, with a fixed
    /// slack and either weighting.
    struct Unit<const DIVIDE: bool> {
        nx: usize,
        ny: usize,
    }

    impl<const DIVIDE: bool> Lattice for Unit<DIVIDE> {
        const WEIGHTING: Weighting = if DIVIDE {
            Weighting::DivideByArea
        } else {
            Weighting::MultiplyByInverse
        };

        fn size(&self) -> (usize, usize) {
            (self.nx, self.ny)
        }

        fn x(&self, i: usize) -> f64 {
            i as f64 + 0.5
        }

        fn y(&self, j: usize) -> f64 {
            j as f64 + 0.5
        }

        fn columns(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
            let lo = (lo - 0.5).ceil().max(0.0);
            let hi = (hi - 0.5).floor().min(self.nx as f64 - 1.0);
            (lo <= hi).then_some((lo as usize, hi as usize))
        }

        fn rows(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
            let lo = (lo - 0.5).ceil().max(0.0);
            let hi = (hi - 0.5).floor().min(self.ny as f64 - 1.0);
            (lo <= hi).then_some((lo as usize, hi as usize))
        }

        fn degenerate(&self, area2: f64) -> bool {
            area2 == 0.0
        }

        fn slack(&self, _: &[[[f64; 2]; 2]; 3], _: f64) -> [f64; 3] {
            [-1e-9; 3]
        }
    }

    /// Every node against every triangle, in input order, with the same
    /// arithmetic: what banding and binning must reproduce exactly.
    fn brute_force<L: Lattice>(lattice: &L, tris: &[[[f64; 3]; 3]]) -> ZBuffer<u32> {
        let (nx, ny) = lattice.size();
        let mut out = ZBuffer {
            depth: vec![f64::INFINITY; nx * ny],
            tag: vec![0; nx * ny],
        };
        for (k, s) in tris.iter().enumerate() {
            let [a, b, c] = s.map(|v| [v[0], v[1]]);
            let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if lattice.degenerate(area2) {
                continue;
            }
            let edges = [[b, c], [c, a], [a, b]];
            let slack = lattice.slack(&edges, area2);
            for j in 0..ny {
                for i in 0..nx {
                    let (x, y) = (lattice.x(i), lattice.y(j));
                    let w = edges.map(|[u, v]| {
                        let e = (v[0] - u[0]) * (y - u[1]) - (v[1] - u[1]) * (x - u[0]);
                        match L::WEIGHTING {
                            Weighting::DivideByArea => e / area2,
                            Weighting::MultiplyByInverse => e * (1.0 / area2),
                        }
                    });
                    if (0..3).all(|m| w[m] >= slack[m]) {
                        let d = w[0] * s[0][2] + w[1] * s[1][2] + w[2] * s[2][2];
                        if d < out.depth[j * nx + i] {
                            out.depth[j * nx + i] = d;
                            out.tag[j * nx + i] = k as u32;
                        }
                    }
                }
            }
        }
        out
    }

    /// Triangles of every size, some beyond the lattice, some sharing
    /// edges, some edge-on, from a fixed seed (splitmix64).
    fn triangles(n: usize) -> Vec<[[f64; 3]; 3]> {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)) as f64 / u64::MAX as f64
        };
        let mut tris: Vec<[[f64; 3]; 3]> = (0..n)
            .map(|_| {
                let centre = [next() * 70.0 - 5.0, next() * 90.0 - 5.0];
                let size = 0.3 + 20.0 * next() * next();
                std::array::from_fn(|_| {
                    [
                        centre[0] + size * (next() - 0.5),
                        centre[1] + size * (next() - 0.5),
                        next() * 10.0,
                    ]
                })
            })
            .collect();
        // A square split along its diagonal, nodes on its edges, and a
        // triangle seen edge-on.
        let (a, b, c, d) = (
            [2.5, 2.5, 1.0],
            [9.5, 2.5, 1.0],
            [9.5, 9.5, 1.0],
            [2.5, 9.5, 1.0],
        );
        tris.extend([[a, b, c], [a, c, d], [a, a, c]]);
        tris
    }

    fn banded_equals_brute_force<L: Lattice>(lattice: &L) {
        let tris = triangles(400);
        let banded = zbuffer(lattice, &tris, |s| (*s, 0u32));
        let want = brute_force(lattice, &tris);
        assert_eq!(banded.depth.len(), want.depth.len());
        for (k, (got, want)) in banded.depth.iter().zip(&want.depth).enumerate() {
            assert_eq!(got.to_bits(), want.to_bits(), "node {k}");
        }
        assert!(want.depth.iter().any(|d| d.is_finite()));
        // Tags follow the nearest triangle.
        let tagged = zbuffer(lattice, &tris, |s| (*s, 1u8));
        for (d, t) in tagged.depth.iter().zip(&tagged.tag) {
            assert_eq!(*t, u8::from(d.is_finite()));
        }
    }

    #[test]
    fn banding_and_binning_match_every_node_against_every_triangle() {
        // Row counts on, off and below a band boundary.
        for ny in [1, BAND_ROWS, 3 * BAND_ROWS + 5, 83] {
            banded_equals_brute_force(&Unit::<true> { nx: 61, ny });
            banded_equals_brute_force(&Unit::<false> { nx: 61, ny });
        }
    }

    #[test]
    fn an_empty_lattice_is_an_empty_buffer() {
        let tris = triangles(10);
        let buffer = zbuffer(&Unit::<true> { nx: 0, ny: 5 }, &tris, |s| (*s, ()));
        assert!(buffer.depth.is_empty());
        let buffer = zbuffer(&Unit::<true> { nx: 5, ny: 0 }, &tris, |s| (*s, ()));
        assert!(buffer.depth.is_empty());
    }
}
