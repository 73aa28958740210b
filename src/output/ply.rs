//! The colliding area as a coloured PLY mesh: the surface of
//! [`write_colliding_area`](super::write_colliding_area), indexed, with a
//! per-vertex colour by composite count, to open over the part in MeshLab
//! or Blender.
//!
//! Each colliding node is one vertex at its height, so a vertex's colour is
//! exactly its node's count (the viridis ramp of the composite image, 1
//! dark to `n_angles` bright); the count itself is also stored as the
//! vertex `quality`, MeshLab's scalar per vertex. Faces join colliding nodes
//! as in the STL (a cell with four colliding corners gives two triangles,
//! one with three gives one), and a node in no face gets a small square of
//! its own colour. Binary little-endian PLY (what MeshLab, Blender and
//! CloudCompare read): coordinates rounded to 1 um, as in `composite.csv`,
//! then stored as 32-bit floats (within 0.1 um up to 1 m from the origin,
//! 0.25 um up to 4 m), some 45 bytes a colliding node where ASCII took 77.

use std::io::{self, Write};

use crate::frame::Placement;
use crate::grid::HeightGrid;

use super::count_colour;
use super::csv::micrometres_value;
use super::surface::{AreaSurface, to_part, wound};

/// Writes the composite area (nodes with `composite > 0`) as a binary
/// little-endian PLY mesh in the part's coordinates (mm; vertex `(x, h, z)`
/// mapped back by [`Placement::to_part`], rounded to 1 um, as 32-bit
/// floats), faces wound towards the knee, every vertex coloured by its
/// node's count of `n_angles` and carrying the count as its `quality`.
/// Returns the number of faces written.
///
/// Fails with [`io::ErrorKind::InvalidInput`] when `composite` does not have
/// one entry per grid node.
pub fn write_colliding_area_ply<W: Write>(
    mut w: W,
    grid: &HeightGrid,
    composite: &[u16],
    n_angles: usize,
    placement: &Placement,
) -> io::Result<usize> {
    let mesh = AreaSurface::new(grid, composite)?;
    let max_count = composite.iter().copied().max().unwrap_or(0);
    let n = n_angles.max(usize::from(max_count)).max(1);
    writeln!(w, "ply")?;
    writeln!(w, "format binary_little_endian 1.0")?;
    writeln!(
        w,
        "comment kneeform {} colliding area (mm, part frame); colour and quality = number of knee-form angles (of {n}) striking the node",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(w, "element vertex {}", mesh.vertices.len())?;
    for axis in ["x", "y", "z"] {
        writeln!(w, "property float {axis}")?;
    }
    for channel in ["red", "green", "blue"] {
        writeln!(w, "property uchar {channel}")?;
    }
    writeln!(w, "property float quality")?;
    writeln!(w, "element face {}", mesh.faces.len())?;
    writeln!(w, "property list uchar int vertex_indices")?;
    writeln!(w, "end_header")?;
    let mut record = Vec::with_capacity(19);
    for &(v, count) in &mesh.vertices {
        record.clear();
        for coordinate in to_part(v, placement) {
            // To 1 um, as composite.csv (-0 as 0: mirroring a zero height
            // must not change the file).
            let c = micrometres_value(coordinate) as f32;
            record.extend_from_slice(&c.to_le_bytes());
        }
        let c = count_colour(usize::from(count), n);
        record.extend_from_slice(&[c.0, c.1, c.2]);
        record.extend_from_slice(&f32::from(count).to_le_bytes());
        w.write_all(&record)?;
    }
    for &f in &mesh.faces {
        let [a, b, c] = wound(f, placement.side);
        w.write_all(&[3])?;
        for index in [a, b, c] {
            let index = i32::try_from(index).map_err(|_| {
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    "more than 2^31 vertices: too many for a PLY index",
                )
            })?;
            w.write_all(&index.to_le_bytes())?;
        }
    }
    w.flush()?;
    Ok(mesh.faces.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Side;

    fn grid() -> HeightGrid {
        crate::output::surface::test_grid(3)
    }

    /// A vertex as read back: x, y, z, red, green, blue, quality.
    type Vertex = ([f32; 3], [u8; 3], f32);

    /// The header's text, and the vertices and faces of the binary body,
    /// parsed as a PLY reader would from the header's counts.
    fn parse(bytes: &[u8]) -> (String, Vec<Vertex>, Vec<[i32; 3]>) {
        let end = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .expect("a header")
            + 11;
        let header = String::from_utf8(bytes[..end].to_vec()).unwrap();
        let count = |element: &str| -> usize {
            let prefix = format!("element {element} ");
            header
                .lines()
                .find_map(|l| l.strip_prefix(&prefix))
                .expect("an element count")
                .parse()
                .unwrap()
        };
        let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let mut at = end;
        let mut vertices = Vec::new();
        for _ in 0..count("vertex") {
            let xyz = [f32_at(at), f32_at(at + 4), f32_at(at + 8)];
            let rgb = [bytes[at + 12], bytes[at + 13], bytes[at + 14]];
            vertices.push((xyz, rgb, f32_at(at + 15)));
            at += 19;
        }
        let mut faces = Vec::new();
        for _ in 0..count("face") {
            assert_eq!(bytes[at], 3, "a triangle");
            let i = |n: usize| {
                i32::from_le_bytes(bytes[at + 1 + 4 * n..at + 5 + 4 * n].try_into().unwrap())
            };
            faces.push([i(0), i(1), i(2)]);
            at += 13;
        }
        assert_eq!(at, bytes.len(), "nothing after the faces");
        (header, vertices, faces)
    }

    #[test]
    fn a_full_cell_and_an_isolated_node_with_colours_by_count() {
        let g = grid();
        // Cell (0,0)-(1,1) fully colliding; node (2,2) alone.
        let mut composite = vec![0u16; 9];
        for k in [0, 1, 3, 4] {
            composite[k] = 1;
        }
        composite[4] = 3;
        composite[8] = 3;
        let mut out = Vec::new();
        let faces =
            write_colliding_area_ply(&mut out, &g, &composite, 3, &Side::Left.into()).unwrap();
        let (header, vertices, face_list) = parse(&out);
        assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"));
        assert!(header.contains("element vertex 8\n"), "{header}");
        assert!(header.contains("element face 4\n"), "{header}");
        assert_eq!(faces, 4);
        assert_eq!(face_list.len(), 4);
        // Node (0,0): count 1, the darkest colour (viridis's first,
        // 68 1 84); node (1,1): count 3 of 3, the brightest (253 231 37);
        // vertices at the nodes' heights.
        assert_eq!(vertices[0], ([0.0, 0.0, 0.0], [68, 1, 84], 1.0));
        assert!(
            vertices.contains(&([2.0, 11.0, 2.0], [253, 231, 37], 3.0)),
            "{vertices:?}"
        );
        // The faces of the cell are counter-clockwise in (x, z).
        assert_eq!(face_list[0], [0, 1, 2]);
        assert_eq!(face_list[1], [0, 2, 3]);
        // The isolated node gets a patch of its own colour at its height.
        assert_eq!(vertices[4], ([3.75, 22.0, 3.75], [253, 231, 37], 3.0));
    }

    #[test]
    fn right_side_mirrors_y_and_reverses_the_winding() {
        let g = grid();
        let composite = vec![1u16; 9];
        let mut left = Vec::new();
        let mut right = Vec::new();
        write_colliding_area_ply(&mut left, &g, &composite, 1, &Side::Left.into()).unwrap();
        write_colliding_area_ply(&mut right, &g, &composite, 1, &Side::Right.into()).unwrap();
        let ((_, lv, lf), (_, rv, rf)) = (parse(&left), parse(&right));
        assert_eq!(lv.len(), rv.len());
        assert_eq!(lv[1], ([2.0, 1.0, 0.0], [253, 231, 37], 1.0));
        assert_eq!(rv[1], ([2.0, -1.0, 0.0], [253, 231, 37], 1.0));
        let (fl, fr) = (lf[1], rf[1]);
        assert_eq!((fl[0], fl[1], fl[2]), (fr[0], fr[2], fr[1]));
        assert!(matches!(
            write_colliding_area_ply(Vec::new(), &g, &[1], 1, &Side::Left.into()),
            Err(e) if e.kind() == io::ErrorKind::InvalidInput
        ));
    }

    #[test]
    fn coordinates_are_rounded_to_a_micrometre_before_the_float() {
        // 0.1 + 0.2 is 0.30000000000000004 as a double: written as 0.3's
        // nearest float, as composite.csv writes it 0.3.
        assert_eq!(micrometres_value(0.1 + 0.2) as f32, 0.3f32);
        assert_eq!(micrometres_value(-0.0000001).to_bits(), 0f64.to_bits());
        assert_eq!(micrometres_value(1234.5678), 1234.568);
    }
}
