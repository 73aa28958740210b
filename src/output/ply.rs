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
//! its own colour. ASCII PLY, so the file can be read and diffed as text;
//! coordinates to 1 um, as in `composite.csv`.

use std::fmt::Write as _;
use std::io::{self, Write};

use crate::frame::Placement;
use crate::grid::HeightGrid;

use super::count_colour;
use super::csv::push_micrometres;
use super::surface::{AreaSurface, to_part, wound};

/// Writes the composite area (nodes with `composite > 0`) as an ASCII PLY
/// mesh in the part's coordinates (mm; vertex `(x, h, z)` mapped back by
/// [`Placement::to_part`]),
/// faces wound towards the knee, every vertex coloured by its node's count
/// of `n_angles`. Returns the number of faces written.
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
    writeln!(w, "format ascii 1.0")?;
    writeln!(
        w,
        "comment kneeform {} colliding area (mm, part frame); colour and quality = number of knee-form angles (of {n}) striking the node",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(w, "element vertex {}", mesh.vertices.len())?;
    for axis in ["x", "y", "z"] {
        writeln!(w, "property double {axis}")?;
    }
    for channel in ["red", "green", "blue"] {
        writeln!(w, "property uchar {channel}")?;
    }
    writeln!(w, "property float quality")?;
    writeln!(w, "element face {}", mesh.faces.len())?;
    writeln!(w, "property list uchar int vertex_indices")?;
    writeln!(w, "end_header")?;
    // To 1 um, as composite.csv (-0 as 0: mirroring a zero height must not
    // change the file).
    let mut line = String::new();
    for &(v, count) in &mesh.vertices {
        line.clear();
        for coordinate in to_part(v, placement) {
            push_micrometres(&mut line, coordinate);
            line.push(' ');
        }
        let c = count_colour(usize::from(count), n);
        writeln!(line, "{} {} {} {count}", c.0, c.1, c.2).expect("writing to a String cannot fail");
        w.write_all(line.as_bytes())?;
    }
    for &f in &mesh.faces {
        let [a, b, c] = wound(f, placement.side);
        writeln!(w, "3 {a} {b} {c}")?;
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

    fn body(text: &str) -> Vec<&str> {
        let end = text.find("end_header\n").expect("a header") + "end_header\n".len();
        text[end..].lines().collect()
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
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("ply\nformat ascii 1.0\n"));
        assert!(text.contains("element vertex 8\n"), "{text}");
        assert!(text.contains("element face 4\n"), "{text}");
        assert_eq!(faces, 4);
        let lines = body(&text);
        assert_eq!(lines.len(), 12);
        // Node (0,0): count 1, the darkest colour; node (1,1): count 3 of 3,
        // the brightest; vertices at the nodes' heights.
        assert_eq!(lines[0], "0 0 0 68 1 84 1");
        assert!(lines.contains(&"2 11 2 253 231 37 3"), "{lines:?}");
        // The faces of the cell are counter-clockwise in (x, z).
        assert_eq!(lines[8], "3 0 1 2");
        assert_eq!(lines[9], "3 0 2 3");
        // The isolated node gets a patch of its own colour at its height.
        assert_eq!(lines[4], "3.75 22 3.75 253 231 37 3");
    }

    #[test]
    fn right_side_mirrors_y_and_reverses_the_winding() {
        let g = grid();
        let composite = vec![1u16; 9];
        let mut left = Vec::new();
        let mut right = Vec::new();
        write_colliding_area_ply(&mut left, &g, &composite, 1, &Side::Left.into()).unwrap();
        write_colliding_area_ply(&mut right, &g, &composite, 1, &Side::Right.into()).unwrap();
        let (left, right) = (
            String::from_utf8(left).unwrap(),
            String::from_utf8(right).unwrap(),
        );
        let (l, r) = (body(&left), body(&right));
        assert_eq!(l.len(), r.len());
        assert_eq!(l[1], "2 1 0 253 231 37 1");
        assert_eq!(r[1], "2 -1 0 253 231 37 1");
        let face = |s: &str| -> Vec<u32> { s.split(' ').map(|v| v.parse().unwrap()).collect() };
        let (fl, fr) = (face(l[9]), face(r[9]));
        assert_eq!((fl[1], fl[2], fl[3]), (fr[1], fr[3], fr[2]));
        assert!(matches!(
            write_colliding_area_ply(Vec::new(), &g, &[1], 1, &Side::Left.into()),
            Err(e) if e.kind() == io::ErrorKind::InvalidInput
        ));
    }
}
