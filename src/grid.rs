//! Step 1 of SPEC: the height grid, an orthographic depth buffer of the part
//! seen from -y.
//!
//! Nodes sit on multiples of the pitch, `x_i = p (I0 + i)`, `z_j = p (J0 + j)`,
//! so grids at `p`, `p/2`, `p/4` nest. `h[i][j]` is the smallest y at which the
//! line through the node parallel to y meets the part, `+inf` where it meets
//! nothing. Stored row-major by z: `h[j * nx + i]`, so the slide (along -x)
//! reads contiguous memory.

use rayon::prelude::*;

use crate::kneeform::{Footprint, NODE_TOL};
use crate::mesh::{Bbox, Triangle};

/// Where the grid's nodes are (mm, analysis frame).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GridSpec {
    /// Node spacing `p` in x and z (mm).
    pub pitch: f64,
    /// Index of the first node column: `x_0 = p * i_origin`.
    pub i_origin: i64,
    /// Index of the first node row: `z_0 = p * j_origin`.
    pub j_origin: i64,
    /// Number of nodes along x.
    pub nx: usize,
    /// Number of nodes along z.
    pub nz: usize,
}

/// Why a grid cannot be laid out.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// The grid would not fit in memory.
    #[error(
        "a {nx} x {nz} grid needs about {need_gib:.1} GiB, more than the {limit_gib:.1} GiB allowed; use a coarser --pitch or a smaller --grid-size"
    )]
    TooLarge {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
        /// Estimated memory need.
        need_gib: f64,
        /// The limit.
        limit_gib: f64,
    },
    /// The grid has no node.
    #[error("the grid is empty ({nx} x {nz} nodes)")]
    Empty {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
    },
}

/// Bytes of working memory per grid node in a full analysis: the heights,
/// the push window-minimum table (about ten levels of f64), the face levels
/// and one byte of mask per angle in flight, with padding. Measured peak RSS
/// on the paper-sized benchmark divided by its node count, rounded up.
pub const BYTES_PER_NODE: f64 = 160.0;

impl GridSpec {
    /// The default extent of SPEC: every node whose footprint, at any of
    /// `footprints`, can reach the part's xz bounding box. That is the box
    /// grown by the footprints' extent on every side, snapped outwards to
    /// multiples of the pitch.
    pub fn around(bbox: &Bbox, footprints: &[Footprint], pitch: f64) -> GridSpec {
        let (mut fx_lo, mut fx_hi, mut fz_lo, mut fz_hi) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for fp in footprints {
            let (xl, xh) = fp.x_range();
            let (zl, zh) = fp.z_range();
            fx_lo = fx_lo.min(xl);
            fx_hi = fx_hi.max(xh);
            fz_lo = fz_lo.min(zl);
            fz_hi = fz_hi.max(zh);
        }
        let i_lo = ((bbox.min[0] - fx_hi) / pitch).floor() as i64;
        let i_hi = ((bbox.max[0] - fx_lo) / pitch).ceil() as i64;
        let j_lo = ((bbox.min[2] - fz_hi) / pitch).floor() as i64;
        let j_hi = ((bbox.max[2] - fz_lo) / pitch).ceil() as i64;
        GridSpec {
            pitch,
            i_origin: i_lo,
            j_origin: j_lo,
            nx: (i_hi - i_lo + 1) as usize,
            nz: (j_hi - j_lo + 1) as usize,
        }
    }

    /// A grid from an explicit origin (mm) and size; the origin is snapped
    /// to the nearest multiple of the pitch, as SPEC puts nodes there.
    pub fn explicit(origin_x: f64, origin_z: f64, nx: usize, nz: usize, pitch: f64) -> GridSpec {
        GridSpec {
            pitch,
            i_origin: (origin_x / pitch).round() as i64,
            j_origin: (origin_z / pitch).round() as i64,
            nx,
            nz,
        }
    }

    /// The x (mm) of node column `i`.
    pub fn x(&self, i: usize) -> f64 {
        self.pitch * (self.i_origin + i as i64) as f64
    }

    /// The z (mm) of node row `j`.
    pub fn z(&self, j: usize) -> f64 {
        self.pitch * (self.j_origin + j as i64) as f64
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nx * self.nz
    }

    /// Whether the grid has no node.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Checks the grid is non-empty and its estimated working memory
    /// ([`BYTES_PER_NODE`] per node) fits in `limit_bytes`, before anything
    /// is allocated.
    pub fn check_fits(&self, limit_bytes: f64) -> Result<(), GridError> {
        if self.is_empty() {
            return Err(GridError::Empty {
                nx: self.nx,
                nz: self.nz,
            });
        }
        let need = self.nx as f64 * self.nz as f64 * BYTES_PER_NODE;
        if need > limit_bytes {
            return Err(GridError::TooLarge {
                nx: self.nx,
                nz: self.nz,
                need_gib: need / f64::from(1u32 << 30),
                limit_gib: limit_bytes / f64::from(1u32 << 30),
            });
        }
        Ok(())
    }
}

/// The sampled part: `h[j * nx + i]` in mm, `+inf` where the node's line
/// misses the part.
#[derive(Debug, Clone)]
pub struct HeightGrid {
    /// Where the nodes are.
    pub spec: GridSpec,
    /// Heights, row-major by z.
    pub h: Vec<f64>,
}

/// Rows per band of the parallel rasterizer: enough work per task to hide
/// scheduling, small enough to balance two threads on a ragged part.
const BAND_ROWS: usize = 16;

impl HeightGrid {
    /// Samples `triangles` (analysis frame) on `spec` with a depth-buffer
    /// rasterizer: each triangle visits only the nodes under its xz
    /// projection. Triangles are closed (edges and vertices count, within
    /// [`NODE_TOL`]); those with a zero-area projection are skipped.
    pub fn sample(triangles: &[Triangle], spec: GridSpec) -> HeightGrid {
        let p = spec.pitch;
        let bands = spec.nz.div_ceil(BAND_ROWS);
        // Bin each triangle into the bands its z-range touches.
        let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (k, t) in triangles.iter().enumerate() {
            let (zlo, zhi) = min_max([t[0][2], t[1][2], t[2][2]]);
            let j_lo = ((zlo - NODE_TOL) / p).ceil() as i64 - spec.j_origin;
            let j_hi = ((zhi + NODE_TOL) / p).floor() as i64 - spec.j_origin;
            if j_hi < 0 || j_lo >= spec.nz as i64 || j_lo > j_hi {
                continue;
            }
            let (b_lo, b_hi) = (
                j_lo.max(0) as usize / BAND_ROWS,
                j_hi.min(spec.nz as i64 - 1) as usize / BAND_ROWS,
            );
            for bin in &mut binned[b_lo..=b_hi] {
                bin.push(k as u32);
            }
        }
        let mut h = vec![f64::INFINITY; spec.len()];
        h.par_chunks_mut(BAND_ROWS * spec.nx)
            .zip(binned.par_iter())
            .enumerate()
            .for_each(|(band, (rows, bin))| {
                let j_first = band * BAND_ROWS;
                let j_end = j_first + rows.len() / spec.nx;
                for &k in bin {
                    rasterize(&triangles[k as usize], &spec, j_first..j_end, rows);
                }
            });
        HeightGrid { spec, h }
    }

    /// The height at node `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.h[j * self.spec.nx + i]
    }

    /// Number of nodes with a finite height.
    pub fn finite_count(&self) -> usize {
        self.h.iter().filter(|h| h.is_finite()).count()
    }
}

fn min_max(v: [f64; 3]) -> (f64, f64) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

/// Writes the triangle's y into the nodes of rows `band` it covers, keeping
/// the minimum. `rows` holds exactly those rows.
fn rasterize(t: &Triangle, spec: &GridSpec, band: std::ops::Range<usize>, rows: &mut [f64]) {
    let p = spec.pitch;
    let [a, b, c] = t.map(|v| [v[0], v[2]]);
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area2 == 0.0 {
        return;
    }
    // Edge k is opposite vertex k; its edge function, divided by area2, is
    // vertex k's barycentric weight. A node within NODE_TOL of an edge
    // counts as on it: weight >= -NODE_TOL * |edge| / |area2|.
    let edges = [(b, c), (c, a), (a, b)];
    let slack = edges.map(|(u, v)| -NODE_TOL * (v[0] - u[0]).hypot(v[1] - u[1]) / area2.abs());
    let (xlo, xhi) = min_max([a[0], b[0], c[0]]);
    let (zlo, zhi) = min_max([a[1], b[1], c[1]]);
    let i_lo = (((xlo - NODE_TOL) / p).ceil() as i64 - spec.i_origin).max(0);
    let i_hi = (((xhi + NODE_TOL) / p).floor() as i64 - spec.i_origin).min(spec.nx as i64 - 1);
    let j_lo = (((zlo - NODE_TOL) / p).ceil() as i64 - spec.j_origin).max(band.start as i64);
    let j_hi = (((zhi + NODE_TOL) / p).floor() as i64 - spec.j_origin).min(band.end as i64 - 1);
    let ys = [t[0][1], t[1][1], t[2][1]];
    for j in j_lo..=j_hi {
        let z = spec.z(j as usize);
        let row = &mut rows[(j as usize - band.start) * spec.nx..][..spec.nx];
        for i in i_lo..=i_hi {
            let x = spec.x(i as usize);
            let w = edges
                .map(|(u, v)| ((v[0] - u[0]) * (z - u[1]) - (v[1] - u[1]) * (x - u[0])) / area2);
            if w[0] >= slack[0] && w[1] >= slack[1] && w[2] >= slack[2] {
                let y = w[0] * ys[0] + w[1] * ys[1] + w[2] * ys[2];
                let cell = &mut row[i as usize];
                if y < *cell {
                    *cell = y;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(nx: usize, nz: usize, pitch: f64) -> GridSpec {
        GridSpec {
            pitch,
            i_origin: 0,
            j_origin: 0,
            nx,
            nz,
        }
    }

    #[test]
    fn plane_is_sampled_exactly_including_shared_edges() {
        // Two triangles splitting the square [0,10]^2 along its diagonal,
        // y = 5 + 0.5 x - 0.25 z: every node, the diagonal's included, is hit.
        let y = |x: f64, z: f64| 5.0 + 0.5 * x - 0.25 * z;
        let v = |x: f64, z: f64| [x, y(x, z), z];
        let tris = vec![
            [v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0)],
            [v(0.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)],
        ];
        let g = HeightGrid::sample(&tris, spec(11, 11, 1.0));
        for j in 0..11 {
            for i in 0..11 {
                let want = y(i as f64, j as f64);
                assert!(
                    (g.at(i, j) - want).abs() < 1e-12,
                    "({i},{j}): {} vs {want}",
                    g.at(i, j)
                );
            }
        }
    }

    #[test]
    fn smallest_y_wins_and_misses_are_infinite() {
        let tri = |y: f64| [[0.0, y, 0.0], [4.0, y, 0.0], [0.0, y, 4.0]];
        let g = HeightGrid::sample(&[tri(3.0), tri(1.0), tri(2.0)], spec(6, 6, 1.0));
        assert_eq!(g.at(0, 0), 1.0);
        assert_eq!(g.at(2, 2), 1.0); // on the hypotenuse: closed triangle
        assert_eq!(g.at(3, 2), f64::INFINITY);
        assert_eq!(g.at(5, 5), f64::INFINITY);
    }

    #[test]
    fn edge_on_triangles_are_skipped() {
        let wall = [[0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 5.0]];
        let g = HeightGrid::sample(&[wall], spec(3, 3, 1.0));
        assert_eq!(g.finite_count(), 0);
    }

    #[test]
    fn default_extent_nests_across_pitches() {
        let bbox = Bbox {
            min: [-10.0, 0.0, -5.0],
            max: [30.0, 1.0, 7.0],
        };
        let fp = [Footprint::new(&crate::KneeForm::default(), 0.0)];
        let coarse = GridSpec::around(&bbox, &fp, 4.0);
        let fine = GridSpec::around(&bbox, &fp, 2.0);
        // Every coarse node is a fine node.
        assert_eq!(coarse.x(0), fine.x((coarse.x(0) - fine.x(0)) as usize / 2));
        assert!(coarse.x(0) <= -10.0 - fp[0].x_range().1);
        assert!(coarse.x(coarse.nx - 1) >= 30.0 - fp[0].x_range().0);
        assert!(coarse.check_fits(1e12).is_ok());
        assert!(matches!(
            coarse.check_fits(10.0),
            Err(GridError::TooLarge { .. })
        ));
    }
}
