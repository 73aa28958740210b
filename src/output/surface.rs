//! The colliding area as one surface, which the STL and the PLY writers
//! both write: indexed vertices at the colliding nodes' heights, faces
//! joining adjacent colliding nodes.
//!
//! The surface is polyhedral over the grid: a cell with four colliding
//! corners gives two triangles, one with exactly three gives the triangle
//! of those three, and a colliding node that ends up in no face (isolated,
//! or only on a line of nodes) gets a small flat square so that it is still
//! visible. Faces are wound counter-clockwise in (x, z), so their normals
//! face the knee: -y in the analysis frame.

use std::io;

use crate::frame::Placement;
use crate::frame::Side;
use crate::grid::HeightGrid;

/// Side of the square patch drawn on an otherwise unconnected colliding
/// node, as a fraction of the pitch: small enough not to be mistaken for a
/// cell, large enough to see.
const PATCH_FRACTION: f64 = 0.25;

/// The colliding area, in the analysis frame (mm).
pub(crate) struct AreaSurface {
    /// Vertices `(x, h, z)` with the composite count of their node.
    pub vertices: Vec<([f64; 3], u16)>,
    /// Faces indexing `vertices`, counter-clockwise in (x, z).
    pub faces: Vec<[u32; 3]>,
}

impl AreaSurface {
    /// The surface of the nodes with `composite > 0`. Fails with
    /// [`io::ErrorKind::InvalidInput`] when `composite` does not have one
    /// entry per grid node.
    pub fn new(grid: &HeightGrid, composite: &[u16]) -> io::Result<AreaSurface> {
        if composite.len() != grid.spec.len() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "composite has {} entries but the grid has {} nodes",
                    composite.len(),
                    grid.spec.len()
                ),
            ));
        }
        let (nx, nz) = (grid.spec.nx, grid.spec.nz);
        let hit = |i: usize, j: usize| composite[j * nx + i] > 0;
        let mut index = vec![u32::MAX; composite.len()];
        let mut surface = AreaSurface {
            vertices: Vec::new(),
            faces: Vec::new(),
        };
        let mut vertex = |surface: &mut AreaSurface, i: usize, j: usize| -> u32 {
            let k = j * nx + i;
            if index[k] == u32::MAX {
                index[k] = surface.vertices.len() as u32;
                let p = [grid.spec.x(i), grid.h[k], grid.spec.z(j)];
                surface.vertices.push((p, composite[k]));
            }
            index[k]
        };
        for j in 0..nz.saturating_sub(1) {
            for i in 0..nx.saturating_sub(1) {
                // Corners counter-clockwise in (x, z): x to the right, z up.
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let on: Vec<(usize, usize)> =
                    corners.into_iter().filter(|&(a, b)| hit(a, b)).collect();
                let tris: &[[usize; 3]] = match on.len() {
                    4 => &[[0, 1, 2], [0, 2, 3]],
                    // Dropping one corner keeps the others' cyclic order.
                    3 => &[[0, 1, 2]],
                    _ => &[],
                };
                for t in tris {
                    let f = t.map(|c| vertex(&mut surface, on[c].0, on[c].1));
                    surface.faces.push(f);
                }
            }
        }
        let half = 0.5 * PATCH_FRACTION * grid.spec.pitch;
        for k in 0..composite.len() {
            if composite[k] == 0 || index[k] != u32::MAX {
                continue;
            }
            let (x, z) = (grid.spec.x(k % nx), grid.spec.z(k / nx));
            let y = grid.h[k];
            let first = surface.vertices.len() as u32;
            for (dx, dz) in [(-half, -half), (half, -half), (half, half), (-half, half)] {
                surface.vertices.push(([x + dx, y, z + dz], composite[k]));
            }
            surface.faces.push([first, first + 1, first + 2]);
            surface.faces.push([first, first + 2, first + 3]);
        }
        Ok(surface)
    }
}

/// A vertex in the part's frame: y mirrored back for the right side, then
/// the frame undone ([`Placement::to_part`]).
pub(crate) fn to_part(v: [f64; 3], placement: &Placement) -> [f64; 3] {
    placement.to_part(v)
}

/// A face wound towards the knee in the part's frame: a mirror (the right
/// side) reverses the sense of rotation, so two vertices are swapped and
/// normal and winding still agree (right-hand rule). A frame is a proper
/// rotation, which keeps the sense: only the side matters.
pub(crate) fn wound([a, b, c]: [u32; 3], side: Side) -> [u32; 3] {
    match side {
        Side::Left => [a, b, c],
        Side::Right => [a, c, b],
    }
}

/// An `n` x `n` grid at pitch 2 from the origin with heights `h = i + 10 j`
/// (all finite), for the writers' tests.
#[cfg(test)]
pub(crate) fn test_grid(n: usize) -> HeightGrid {
    let spec = crate::grid::GridSpec {
        pitch: 2.0,
        i_origin: 0,
        j_origin: 0,
        nx: n,
        nz: n,
    };
    let h = (0..n * n)
        .map(|k| (k % n) as f64 + 10.0 * (k / n) as f64)
        .collect();
    HeightGrid { spec, h }
}
