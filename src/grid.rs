//! Step 1 of SPEC: the height grid, an orthographic depth buffer of the part
//! seen from -y.
//!
//! Nodes sit on multiples of the pitch, `x_i = p (I0 + i)`, `z_j = p (J0 + j)`,
//! so grids at `p`, `p/2`, `p/4` nest. `h[i][j]` is the smallest y at which the
//! line through the node parallel to y meets the part, `+inf` where it meets
//! nothing. Stored row-major by z: `h[j * nx + i]`, so the slide (along -x)
//! reads contiguous memory.

use crate::mesh::{Bbox, Triangle};
use crate::zbuffer::{Lattice, Weighting, zbuffer};

/// Distance (mm) within which a node counts as inside the closed footprint
/// (SPEC, "push"), and within which two slide distances form one tie group
/// (SPEC, "slide"). It only has to absorb floating-point rounding of
/// coordinates of order 1e3 mm (about 1e-13 mm), so it is far below any pitch.
pub(crate) const NODE_TOL: f64 = 1e-9;

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
    /// The run would need more memory than allowed.
    #[error(
        "this run needs about {need_gib:.2} GiB ({nx} x {nz} grid, {angles} angles), more than the {limit_gib:.2} GiB allowed by --max-memory; use a coarser --pitch, fewer --angles or a smaller --grid-size, or raise --max-memory"
    )]
    TooLarge {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
        /// Angles analysed.
        angles: usize,
        /// Estimated memory need ([`crate::memory::MemoryEstimate`]).
        need_gib: f64,
        /// The limit.
        limit_gib: f64,
    },
    /// The run would need more memory than the machine has.
    #[error(
        "this run needs about {need_gib:.2} GiB ({nx} x {nz} grid, {angles} angles), more than the {machine_gib:.2} GiB of {what}; use a coarser --pitch, fewer --angles or a smaller --grid-size"
    )]
    BeyondMachine {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
        /// Angles analysed.
        angles: usize,
        /// Estimated memory need.
        need_gib: f64,
        /// The least of the machine's memory and its limits
        /// (`limit_bytes`).
        machine_gib: f64,
        /// Which limit, in words.
        what: &'static str,
    },
    /// The grid has more nodes than `MAX_GRID_NODES`.
    #[error(
        "a {nx} x {nz} grid has more than the {} nodes a grid may have; use a coarser --pitch or a smaller --grid-size",
        crate::limits::MAX_GRID_NODES
    )]
    TooManyNodes {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
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

impl GridSpec {
    /// Every node from which a shape spanning `x` and `z` (mm, relative to
    /// the node) can reach `bbox`'s xz extent, snapped outwards to
    /// multiples of the pitch.
    pub fn reaching(bbox: &Bbox, x: (f64, f64), z: (f64, f64), pitch: f64) -> GridSpec {
        let i_lo = ((bbox.min[0] - x.1) / pitch).floor() as i64;
        let i_hi = ((bbox.max[0] - x.0) / pitch).ceil() as i64;
        let j_lo = ((bbox.min[2] - z.1) / pitch).floor() as i64;
        let j_hi = ((bbox.max[2] - z.0) / pitch).ceil() as i64;
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
        self.nx == 0 || self.nz == 0
    }

    /// Checks the grid has at least one node and at most
    /// `MAX_GRID_NODES`, before anything is allocated (the
    /// memory a run needs is [`crate::memory::MemoryEstimate`]'s).
    pub fn check_nodes(&self) -> Result<(), GridError> {
        let (nx, nz) = (self.nx, self.nz);
        if self.is_empty() {
            return Err(GridError::Empty { nx, nz });
        }
        if nx
            .checked_mul(nz)
            .is_none_or(|n| n > crate::limits::MAX_GRID_NODES)
        {
            return Err(GridError::TooManyNodes { nx, nz });
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

#[cfg(test)]
impl HeightGrid {
    /// The grid on `spec` whose height at the node at `(x, z)` (mm) is
    /// `height(x, z)`: the tests' synthetic parts.
    pub(crate) fn from_fn(spec: GridSpec, height: impl Fn(f64, f64) -> f64) -> HeightGrid {
        let h = (0..spec.len())
            .map(|n| height(spec.x(n % spec.nx), spec.z(n / spec.nx)))
            .collect();
        HeightGrid { spec, h }
    }
}

impl HeightGrid {
    /// Samples `triangles` (analysis frame) on `spec` with a depth-buffer
    /// rasterizer: each triangle visits only the nodes under its xz
    /// projection. Triangles are closed (edges and vertices count, within
    /// `NODE_TOL`); those with a zero-area projection are skipped.
    pub fn sample(triangles: &[Triangle], spec: GridSpec) -> HeightGrid {
        // Seen from -y: x along the columns, z along the rows, y the depth.
        let h = zbuffer(&spec, triangles, |t| (t.map(|v| [v[0], v[2], v[1]]), ())).depth;
        HeightGrid { spec, h }
    }

    /// [`HeightGrid::sample`], and per node the tag (`tags[k]` of triangle
    /// `k`: an assembly's file index) of the triangle that set its height;
    /// of equal heights, the first triangle's. The heights are
    /// [`HeightGrid::sample`]'s to the bit; the tag is 0 where the height is
    /// `+inf`.
    pub fn sample_attributed(
        triangles: &[Triangle],
        tags: &[u32],
        spec: GridSpec,
    ) -> (HeightGrid, Vec<u32>) {
        assert_eq!(triangles.len(), tags.len(), "one tag per triangle");
        let index: Vec<u32> = (0..triangles.len() as u32).collect();
        let buffer = zbuffer(&spec, &index, |&k| {
            let t = &triangles[k as usize];
            (t.map(|v| [v[0], v[2], v[1]]), tags[k as usize])
        });
        (
            HeightGrid {
                spec,
                h: buffer.depth,
            },
            buffer.tag,
        )
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

/// The grid's nodes as a z-buffer lattice: columns are x, rows are z.
/// Triangles are closed within [`NODE_TOL`]; a zero-area one is skipped.
impl Lattice for GridSpec {
    const WEIGHTING: Weighting = Weighting::DivideByArea;

    fn size(&self) -> (usize, usize) {
        (self.nx, self.nz)
    }

    fn x(&self, i: usize) -> f64 {
        GridSpec::x(self, i)
    }

    fn y(&self, j: usize) -> f64 {
        self.z(j)
    }

    fn columns(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        nodes_within(self.pitch, self.i_origin, self.nx, lo, hi)
    }

    fn rows(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        nodes_within(self.pitch, self.j_origin, self.nz, lo, hi)
    }

    fn degenerate(&self, area2: f64) -> bool {
        area2 == 0.0
    }

    /// A node within [`NODE_TOL`] of an edge counts as on it: its weight
    /// is at least `-NODE_TOL * |edge| / |area2|`.
    fn slack(&self, edges: &[[[f64; 2]; 2]; 3], area2: f64) -> [f64; 3] {
        edges.map(|[u, v]| -NODE_TOL * (v[0] - u[0]).hypot(v[1] - u[1]) / area2.abs())
    }
}

/// The nodes `k` of `0..n` (at `pitch * (origin + k)`) within
/// [`NODE_TOL`] of `[lo, hi]`.
fn nodes_within(pitch: f64, origin: i64, n: usize, lo: f64, hi: f64) -> Option<(usize, usize)> {
    let k_lo = (((lo - NODE_TOL) / pitch).ceil() as i64 - origin).max(0);
    let k_hi = (((hi + NODE_TOL) / pitch).floor() as i64 - origin).min(n as i64 - 1);
    (k_lo <= k_hi).then_some((k_lo as usize, k_hi as usize))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kneeform::Footprint;

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
    fn attribution_names_the_lowest_triangle_and_the_first_of_a_tie() {
        let tri = |y: f64| [[0.0, y, 0.0], [4.0, y, 0.0], [0.0, y, 4.0]];
        let far = [[0.0, 9.0, 0.0], [6.0, 9.0, 0.0], [0.0, 9.0, 6.0]];
        let tris = [tri(3.0), tri(1.0), tri(1.0), far];
        let (g, tag) = HeightGrid::sample_attributed(&tris, &[7, 5, 2, 4], spec(7, 7, 1.0));
        assert_eq!(g.h, HeightGrid::sample(&tris, spec(7, 7, 1.0)).h);
        // Triangles 1 and 2 tie at y = 1: the first (tag 5) keeps the node.
        assert_eq!((g.at(0, 0), tag[0]), (1.0, 5));
        // Only the far triangle covers (5, 0).
        assert_eq!((g.at(5, 0), tag[5]), (9.0, 4));
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
        let coarse = Footprint::grid_around(&bbox, &fp, 4.0);
        let fine = Footprint::grid_around(&bbox, &fp, 2.0);
        // Every coarse node is a fine node.
        assert_eq!(coarse.x(0), fine.x((coarse.x(0) - fine.x(0)) as usize / 2));
        assert!(coarse.x(0) <= -10.0 - fp[0].x_range().1);
        assert!(coarse.x(coarse.nx - 1) >= 30.0 - fp[0].x_range().0);
        assert!(coarse.check_nodes().is_ok());
        let huge = GridSpec {
            nx: 1 << 20,
            nz: 1 << 20,
            ..coarse
        };
        assert!(matches!(
            huge.check_nodes(),
            Err(GridError::TooManyNodes { .. })
        ));
        let wrapping = GridSpec {
            nx: usize::MAX,
            nz: 2,
            ..coarse
        };
        assert!(matches!(
            wrapping.check_nodes(),
            Err(GridError::TooManyNodes { .. })
        ));
    }
}
