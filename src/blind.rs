//! Blind spots: where the part sticks out towards the knee between the
//! grid's nodes by more than a threshold, so that the grid cannot see it at
//! this pitch (a thin rib, a sharp edge, a switch boss).
//!
//! For every grid cell (the square between four neighbouring nodes) the
//! smallest y of the mesh over the cell's whole xz square is computed
//! exactly: a conservative rasterization of the same triangles the height
//! grid samples. A linear function's minimum over a convex polygon lies at
//! one of its vertices, so each triangle is clipped to the square
//! (Sutherland-Hodgman) and its y read at the clipped polygon's vertices.
//! The cell's **depth missed** is how far that minimum lies below (towards
//! the knee of) the lowest of the cell's sampled corner heights; a cell
//! whose depth missed exceeds the threshold is a blind spot.
//!
//! For each blind spot: where its lowest point is, the width of the part
//! of it proud by more than the threshold (the smaller side of the box
//! holding that part within the cell), and the **resolving pitch**: the
//! largest pitch `p / 2^k` no larger than that width, at which a node
//! lands on it wherever it lies.
//!
//! Whether one matters is the engine's to say: its fast path keeps, for
//! every node, the highest face level that met it, and a blind spot whose
//! lowest point sticks out past the level that met one of its cell's
//! corners would have been a contact (`Probe`).
//!
//! **Invariant:** blind spots are a diagnostic beside the grid; they never
//! change a height, a mask or the composite.

use rayon::prelude::*;

use crate::grid::HeightGrid;
use crate::mesh::Triangle;

/// The columns of `blind_spots.csv`, as the writer writes them: the cell
/// (`i`, `j`), its lowest point in the part's coordinates (`x`, `y`, `z`,
/// mm), and the rest of [`BlindSpot`].
pub(crate) const CSV_COLUMNS: [&str; 9] = [
    "i",
    "j",
    "x",
    "y",
    "z",
    "depth_missed_mm",
    "width_mm",
    "resolving_pitch_mm",
    "met_angles_deg",
];

/// The columns of `blind_spots.csv` the report reads, by name: every
/// version's file has them (`y` came later).
pub(crate) const CSV_READ_COLUMNS: [&str; 8] = [
    "i",
    "j",
    "x",
    "z",
    "depth_missed_mm",
    "width_mm",
    "resolving_pitch_mm",
    "met_angles_deg",
];

/// One grid cell in which the mesh sticks out past the cell's sampled
/// corners by more than the threshold.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BlindSpot {
    /// Column of the cell's first corner node (the cell spans columns `i`
    /// and `i + 1`).
    pub i: usize,
    /// Row of the cell's first corner node.
    pub j: usize,
    /// x of the mesh's lowest point in the cell (mm, the analysis grid's
    /// frame: [`BlindSpot::in_part`] maps it to the part's).
    pub x: f64,
    /// z of that point (mm).
    pub z: f64,
    /// How far the mesh sticks out past the lowest sampled corner (mm).
    pub depth_missed_mm: f64,
    /// Width of the part proud by more than the threshold (mm).
    pub width_mm: f64,
    /// The largest pitch `p / 2^k` (k >= 1) no larger than `width_mm`.
    pub resolving_pitch_mm: f64,
    /// The height of that point (mm, analysis frame).
    pub y: f64,
    /// The angles (degrees) at which the knee-form's face meets the cell at
    /// a level this point sticks out past: a contact the grid cannot see
    /// (filled in by the analysis, from the engine's probes).
    pub met_angles_deg: Vec<f64>,
}

impl BlindSpot {
    /// The lowest point `(x, y, z)` in the part's coordinates (mm), mapped
    /// back from the analysis grid's frame by `placement` (the side's
    /// mirror, a `--frame`, the direct approach's turn).
    pub fn in_part(&self, placement: &crate::frame::Placement) -> [f64; 3] {
        placement.to_part([self.x, self.y, self.z])
    }
}

/// The blind spots of `grid` (sampled from `triangles`) deeper than
/// `threshold` mm, in row-major cell order.
pub fn blind_spots(triangles: &[Triangle], grid: &HeightGrid, threshold: f64) -> Vec<BlindSpot> {
    let spec = grid.spec;
    if spec.nx < 2 || spec.nz < 2 {
        return Vec::new();
    }
    let rows = bin_by_cell_row(triangles, grid);
    let lowest = lowest_points(triangles, grid, &rows);
    let mut spots = Vec::new();
    for (j, row) in lowest.iter().enumerate() {
        for (i, &(y_min, [x, z])) in row.iter().enumerate() {
            let Some(reference) = reference_height(grid, i, j) else {
                continue;
            };
            let depth = reference - y_min;
            if depth.is_nan() || depth <= threshold {
                continue;
            }
            let width = proud_width(triangles, &rows[j], grid, i, j, reference - threshold);
            spots.push(BlindSpot {
                i,
                j,
                x,
                z,
                depth_missed_mm: depth,
                width_mm: width,
                resolving_pitch_mm: resolving_pitch(spec.pitch, width),
                y: y_min,
                met_angles_deg: Vec::new(),
            });
        }
    }
    debug_assert!(spots.iter().all(|s| s.i < spec.nx - 1 && s.j < spec.nz - 1));
    spots
}

/// Per cell row, the lowest mesh point `(y, [x, z])` of each cell (`+inf`
/// where no triangle meets the cell), in parallel over the rows.
fn lowest_points(
    triangles: &[Triangle],
    grid: &HeightGrid,
    rows: &[Vec<u32>],
) -> Vec<Vec<(f64, [f64; 2])>> {
    let cx = grid.spec.nx - 1;
    rows.par_iter()
        .enumerate()
        .map(|(j, bin)| {
            let mut row = vec![(f64::INFINITY, [0.0; 2]); cx];
            for &k in bin {
                let t = &triangles[k as usize];
                // No point of the triangle lies lower than its lowest vertex.
                let lowest = t[0][1].min(t[1][1]).min(t[2][1]);
                for i in cell_columns(t, grid) {
                    if lowest >= row[i].0 {
                        continue;
                    }
                    let clipped = clip_to_cell(t, grid, i, j);
                    for &[x, y, z] in clipped.points() {
                        if y < row[i].0 {
                            row[i] = (y, [x, z]);
                        }
                    }
                }
            }
            row
        })
        .collect()
}

/// The largest `pitch / 2^k` (k >= 1) no larger than `width` mm.
pub(crate) fn resolving_pitch(pitch: f64, width: f64) -> f64 {
    let mut p = pitch / 2.0;
    // 2^-30 of a pitch is below any width a mesh in f32 holds.
    for _ in 0..30 {
        if p <= width {
            break;
        }
        p /= 2.0;
    }
    p
}

/// The height the grid sampled for the cell `(i, j)`: the lowest of its
/// finite corners, or, where none is on the part, of the finite nodes of
/// the cells around it; `None` where the grid has sampled nothing near.
pub(crate) fn reference_height(grid: &HeightGrid, i: usize, j: usize) -> Option<f64> {
    let lowest = |i0: usize, i1: usize, j0: usize, j1: usize| {
        (j0..=j1)
            .flat_map(|jj| (i0..=i1).map(move |ii| (ii, jj)))
            .map(|(ii, jj)| grid.at(ii, jj))
            .filter(|h| h.is_finite())
            .reduce(f64::min)
    };
    let spec = grid.spec;
    lowest(i, i + 1, j, j + 1).or_else(|| {
        lowest(
            i.saturating_sub(1),
            (i + 2).min(spec.nx - 1),
            j.saturating_sub(1),
            (j + 2).min(spec.nz - 1),
        )
    })
}

/// Triangle indices per cell row, each triangle in every row its z-range
/// touches (closed).
fn bin_by_cell_row(triangles: &[Triangle], grid: &HeightGrid) -> Vec<Vec<u32>> {
    let spec = grid.spec;
    let cz = spec.nz - 1;
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); cz];
    for (k, t) in triangles.iter().enumerate() {
        let (lo, hi) = range(t.map(|v| v[2]));
        let j_lo = ((lo - spec.z(0)) / spec.pitch).floor();
        let j_hi = ((hi - spec.z(0)) / spec.pitch).floor();
        if j_hi < 0.0 || j_lo >= cz as f64 {
            continue;
        }
        for row in &mut rows[j_lo.max(0.0) as usize..=(j_hi as usize).min(cz - 1)] {
            row.push(k as u32);
        }
    }
    rows
}

/// The cell columns the triangle's x-range touches.
fn cell_columns(t: &Triangle, grid: &HeightGrid) -> std::ops::Range<usize> {
    let spec = grid.spec;
    let cx = spec.nx - 1;
    let (lo, hi) = range(t.map(|v| v[0]));
    let i_lo = ((lo - spec.x(0)) / spec.pitch).floor();
    let i_hi = ((hi - spec.x(0)) / spec.pitch).floor();
    if i_hi < 0.0 || i_lo >= cx as f64 {
        return 0..0;
    }
    i_lo.max(0.0) as usize..(i_hi as usize).min(cx - 1) + 1
}

fn range(v: [f64; 3]) -> (f64, f64) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

/// A convex polygon of at most [`Polygon::MAX`] vertices: a triangle cut
/// by up to five lines (each adds at most one vertex to a convex polygon;
/// the room beyond is for rounding at near-degenerate cuts), without
/// allocating.
#[derive(Clone, Copy)]
struct Polygon {
    v: [[f64; 3]; Polygon::MAX],
    n: usize,
}

impl Polygon {
    /// Three vertices, plus one per cut, with room to spare.
    const MAX: usize = 16;

    fn points(&self) -> &[[f64; 3]] {
        &self.v[..self.n]
    }

    fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Appends `p`; beyond [`Polygon::MAX`] (only rounding at a cut along
    /// an edge could get there) the vertex is dropped.
    fn push(&mut self, p: [f64; 3]) {
        if self.n < Polygon::MAX {
            self.v[self.n] = p;
            self.n += 1;
        }
    }
}

/// The triangle clipped to the cell's closed xz square: the vertices of the
/// intersection polygon with y interpolated along the triangle (empty when
/// they do not meet).
fn clip_to_cell(t: &Triangle, grid: &HeightGrid, i: usize, j: usize) -> Polygon {
    let spec = grid.spec;
    let (x0, x1) = (spec.x(i), spec.x(i + 1));
    let (z0, z1) = (spec.z(j), spec.z(j + 1));
    let mut poly = Polygon {
        v: [[0.0; 3]; Polygon::MAX],
        n: 0,
    };
    for &p in t {
        poly.push(p);
    }
    // The square's four edges, each keeping the side towards the cell.
    for (axis, bound, sign) in [(0, x0, 1.0), (0, x1, -1.0), (2, z0, 1.0), (2, z1, -1.0)] {
        poly = clip(&poly, axis, bound, sign);
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// One Sutherland-Hodgman step: the polygon's part where
/// `sign * (v[axis] - bound) >= 0`, with points on the cut interpolated
/// linearly (so y stays on the triangle).
fn clip(poly: &Polygon, axis: usize, bound: f64, sign: f64) -> Polygon {
    let s = |v: &[f64; 3]| sign * (v[axis] - bound);
    let mut out = Polygon {
        v: [[0.0; 3]; Polygon::MAX],
        n: 0,
    };
    let points = poly.points();
    for (k, a) in points.iter().enumerate() {
        let b = &points[(k + 1) % points.len()];
        let (sa, sb) = (s(a), s(b));
        if sa >= 0.0 {
            out.push(*a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            let u = sa / (sa - sb);
            out.push([0, 1, 2].map(|c| a[c] + u * (b[c] - a[c])));
        }
    }
    out
}

/// The smaller side of the xz box holding the mesh of cell `(i, j)` lower
/// than `level` (mm), from the triangles of its cell row.
fn proud_width(
    triangles: &[Triangle],
    row: &[u32],
    grid: &HeightGrid,
    i: usize,
    j: usize,
    level: f64,
) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &k in row {
        let t = &triangles[k as usize];
        if !cell_columns(t, grid).contains(&i) {
            continue;
        }
        let clipped = clip_to_cell(t, grid, i, j);
        if clipped.is_empty() {
            continue;
        }
        for &[x, _, z] in clip(&clipped, 1, level, -1.0).points() {
            lo = [lo[0].min(x), lo[1].min(z)];
            hi = [hi[0].max(x), hi[1].max(z)];
        }
    }
    (hi[0] - lo[0]).min(hi[1] - lo[1]).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::scenario::{axis, tessellate};

    fn sample(tris: &[Triangle], pitch: f64) -> HeightGrid {
        let spec = GridSpec::explicit(
            -40.0,
            -40.0,
            (80.0 / pitch) as usize + 1,
            (80.0 / pitch) as usize + 1,
            pitch,
        );
        HeightGrid::sample(tris, spec)
    }

    #[test]
    fn a_plane_and_a_gentle_wave_have_none() {
        let xs = axis((-50.0, 50.0), 1.0, &[]);
        let plane = tessellate(&xs, &xs, |i, k| 0.3 * xs[i] - 0.1 * xs[k]);
        assert!(blind_spots(&plane, &sample(&plane, 4.0), 0.01).is_empty());
        let wave = tessellate(&xs, &xs, |i, _| {
            5.0 * (xs[i] / 100.0 * std::f64::consts::TAU).sin()
        });
        assert!(blind_spots(&wave, &sample(&wave, 4.0), 0.5).is_empty());
    }

    #[test]
    fn a_rib_between_nodes_is_found_with_its_depth_width_and_pitch() {
        // A tent 0.6 mm wide at the foot, 5 mm proud, crest at x = 1.3,
        // between the 2 mm grid's nodes at 0 and 2.
        let xs = axis((-50.0, 50.0), 2.0, &[1.0, 1.3, 1.6]);
        let zs = axis((-50.0, 50.0), 2.0, &[]);
        let rib = tessellate(&xs, &zs, |i, _| {
            -5.0 * (1.0 - (xs[i] - 1.3).abs() / 0.3).max(0.0)
        });
        let grid = sample(&rib, 2.0);
        let spots = blind_spots(&rib, &grid, 0.5);
        // One cell per row of cells, all in the column from x = 0 to 2.
        assert_eq!(spots.len(), grid.spec.nz - 1);
        for s in &spots {
            assert_eq!(grid.spec.x(s.i), 0.0);
            assert!((s.x - 1.3).abs() < 1e-12);
            assert!((s.depth_missed_mm - 5.0).abs() < 1e-12);
            // Proud by more than 0.5 mm: |x - 1.3| < 0.3 (1 - 0.5 / 5).
            assert!((s.width_mm - 0.54).abs() < 1e-9, "{}", s.width_mm);
            assert_eq!(s.resolving_pitch_mm, 0.5);
        }
    }
}
