//! The colliding area as a binary STL surface, for viewing over the part in
//! a CAD tool.
//!
//! The surface is [`AreaSurface`], the one the PLY writer writes too:
//! vertices at the colliding nodes' heights, so it lies on the part.
//!
//! Triangles face the knee: -y in the analysis frame. For the right side y
//! is mirrored back to the part, and a mirror reverses the sense of
//! rotation, so the vertex order is reversed too; normal and winding then
//! agree (right-hand rule) and the normal faces +y, the knee's side there.

use std::io::{self, Write};
use std::path::Path;

use super::surface::{AreaSurface, to_part, wound};
use crate::frame::Placement;
use crate::grid::HeightGrid;
use crate::mesh::Triangle;

/// Writes the composite area (nodes with `composite > 0`) as a binary STL
/// in the part's coordinates (mm; vertex `(x, h, z)` mapped back by
/// [`Placement::to_part`]), facing the knee. Returns the number of triangles written.
///
/// Fails with [`io::ErrorKind::InvalidInput`] when `composite` does not have
/// one entry per grid node.
pub fn write_colliding_area<W: Write>(
    mut w: W,
    grid: &HeightGrid,
    composite: &[u16],
    placement: &Placement,
) -> io::Result<usize> {
    let surface = AreaSurface::new(grid, composite)?;
    let triangles: Vec<stl_io::Triangle> = surface
        .faces
        .iter()
        .map(|&f| {
            to_stl_triangle(
                &wound(f, placement.side)
                    .map(|v| to_part(surface.vertices[v as usize].0, placement)),
            )
        })
        .collect();
    stl_io::write_stl(&mut w, triangles.iter())?;
    Ok(triangles.len())
}

/// Writes `triangles` (mm) as a binary STL at `path`, through a temporary
/// file in the same directory renamed into place, so `path` is never a
/// partial file.
pub fn write_stl(path: &Path, triangles: &[Triangle]) -> io::Result<()> {
    super::write_file_atomically(path, |file| {
        let stl: Vec<stl_io::Triangle> = triangles.iter().map(to_stl_triangle).collect();
        stl_io::write_stl(file, stl.iter())
    })
}

/// An STL triangle with its unit normal from the winding (right-hand rule);
/// zero for a degenerate triangle.
pub(crate) fn to_stl_triangle(t: &Triangle) -> stl_io::Triangle {
    let [a, b, c] = *t;
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let unit = if len > 0.0 {
        n.map(|v| v / len)
    } else {
        [0.0; 3]
    };
    stl_io::Triangle {
        normal: stl_io::Normal::new(unit.map(|v| v as f32)),
        vertices: t.map(|v| stl_io::Vertex::new(v.map(|c| c as f32))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Side;

    fn grid() -> HeightGrid {
        crate::output::surface::test_grid(4)
    }

    fn composite_of(nodes: &[(usize, usize)]) -> Vec<u16> {
        let mut c = vec![0u16; 16];
        for &(i, j) in nodes {
            c[j * 4 + i] = 1;
        }
        c
    }

    fn read_back(bytes: &[u8]) -> Vec<stl_io::Triangle> {
        let mut cursor = io::Cursor::new(bytes);
        stl_io::create_stl_reader(&mut cursor)
            .unwrap()
            .map(Result::unwrap)
            .collect()
    }

    fn cross_y(t: &stl_io::Triangle) -> f32 {
        let [a, b, c] = t.vertices;
        (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2])
    }

    fn write(composite: &[u16], side: Side) -> (usize, Vec<stl_io::Triangle>) {
        let mut buf = Vec::new();
        let n = write_colliding_area(&mut buf, &grid(), composite, &side.into()).unwrap();
        assert_eq!(buf.len(), 84 + 50 * n);
        (n, read_back(&buf))
    }

    #[test]
    fn a_two_by_two_block_is_two_triangles_on_the_nodes() {
        let (n, tris) = write(&composite_of(&[(1, 1), (2, 1), (1, 2), (2, 2)]), Side::Left);
        assert_eq!(n, 2);
        for t in &tris {
            for v in t.vertices {
                // Each vertex is a node (x = 2 i, z = 2 j) at its height.
                let (i, j) = ((v[0] / 2.0) as usize, (v[2] / 2.0) as usize);
                assert!((1..=2).contains(&i) && (1..=2).contains(&j));
                assert_eq!(v[1], (i + 10 * j) as f32);
            }
        }
    }

    #[test]
    fn three_corners_give_one_triangle_and_a_line_gives_patches() {
        let (n, _) = write(&composite_of(&[(0, 0), (1, 0), (0, 1)]), Side::Left);
        assert_eq!(n, 1);
        // Two nodes side by side form no cell: each gets its own patch.
        let (n, _) = write(&composite_of(&[(0, 3), (1, 3)]), Side::Left);
        assert_eq!(n, 4);
    }

    #[test]
    fn an_isolated_node_is_a_small_flat_patch_centred_on_it() {
        let (n, tris) = write(&composite_of(&[(2, 1)]), Side::Left);
        assert_eq!(n, 2);
        let vs: Vec<_> = tris.iter().flat_map(|t| t.vertices).collect();
        let (xs, zs): (Vec<f32>, Vec<f32>) = vs.iter().map(|v| (v[0], v[2])).unzip();
        let span = |v: &[f32]| {
            let lo = v.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            (lo, hi)
        };
        // Side pitch / 4 = 0.5 around the node (x, z) = (4, 2).
        assert_eq!(span(&xs), (3.75, 4.25));
        assert_eq!(span(&zs), (1.75, 2.25));
        assert!(vs.iter().all(|v| v[1] == 12.0));
    }

    #[test]
    fn normals_face_the_knee_and_agree_with_the_winding_on_both_sides() {
        let nodes = composite_of(&[(0, 0), (1, 0), (0, 1), (1, 1), (2, 1), (3, 3)]);
        let (_, left) = write(&nodes, Side::Left);
        let (_, right) = write(&nodes, Side::Right);
        assert_eq!(left.len(), right.len());
        for (l, r) in left.iter().zip(&right) {
            // Knee side: -y on the left, +y (mirrored) on the right.
            assert!(l.normal[1] < 0.0 && r.normal[1] > 0.0, "{l:?} {r:?}");
            assert!(cross_y(l) * l.normal[1] > 0.0);
            // Mirroring maps y to -y and reverses the winding.
            assert!(cross_y(r) * r.normal[1] > 0.0);
            assert_eq!(r.normal[0], l.normal[0]);
            assert_eq!(r.normal[1], -l.normal[1]);
            let mirrored: Vec<[f32; 3]> = l.vertices.iter().map(|v| [v[0], -v[1], v[2]]).collect();
            let got: Vec<[f32; 3]> = r.vertices.iter().map(|v| [v[0], v[1], v[2]]).collect();
            assert_eq!(got, [mirrored[0], mirrored[2], mirrored[1]]);
        }
    }
}
