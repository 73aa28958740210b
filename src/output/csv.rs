//! CSV tables of the result: the colliding points of every angle, and the
//! composite count per node.
//!
//! Coordinates are the part's own (mm): the node's x and z and its height,
//! mapped back with [`Placement::to_part`] (y mirrored for the right side,
//! then the `--frame` undone). An assembly's tables end with a `file`
//! column: the index, in `summary.json`'s `files`, of the file whose
//! surface set the node's height; a single part's tables have no such
//! column. Rows come in a fixed order
//! (angle, then row j, then column i) and numbers in Rust's shortest
//! round-trip form, so the same result always gives the same bytes.

use std::fmt::Write as _;
use std::io::{self, Write};

use crate::engine::AngleMask;
use crate::frame::Placement;
use crate::grid::HeightGrid;

/// Writes `angle_deg,i,j,x,y,z`: one row per colliding node per angle, in
/// increasing angle (degrees), then j, then i; x, y, z the node at its
/// height in the part's frame (mm). With `node_file` (an assembly's
/// attribution per node), a last column `file`.
///
/// Fails with [`io::ErrorKind::InvalidInput`] when a mask does not have one
/// entry per grid node.
pub fn write_colliding_points<W: Write>(
    w: W,
    grid: &HeightGrid,
    masks: &[AngleMask],
    placement: &Placement,
    node_file: Option<&[u32]>,
) -> csv::Result<()> {
    if let Some(files) = node_file {
        check_len("file attribution", files.len(), grid)?;
    }
    for m in masks {
        check_len("colliding mask", m.mask.len(), grid)?;
    }
    let mut order: Vec<&AngleMask> = masks.iter().collect();
    order.sort_by(|a, b| a.angle_deg.total_cmp(&b.angle_deg));
    // A node colliding at many angles is written many times: format its
    // fields once (a paper-sized run writes some ten million rows).
    let mut first_row = vec![u32::MAX; grid.spec.len()];
    let mut nodes = Row::default();
    for m in &order {
        for (k, _) in m.mask.iter().enumerate().filter(|&(_, &v)| v != 0) {
            if first_row[k] == u32::MAX {
                first_row[k] = nodes.ends.len() as u32;
                nodes.node(grid, k, placement);
                if let Some(files) = node_file {
                    nodes.int(files[k] as usize);
                }
            }
        }
    }
    let width = if node_file.is_some() { 6 } else { 5 };
    let mut out = csv::Writer::from_writer(w);
    let header = ["angle_deg", "i", "j", "x", "y", "z", "file"];
    out.write_record(&header[..1 + width])?;
    let mut angle = Row::default();
    for m in order {
        angle.start();
        angle.num(m.angle_deg);
        let angle_field = angle.fields().next().expect("one field");
        for (k, _) in m.mask.iter().enumerate().filter(|&(_, &v)| v != 0) {
            let first = first_row[k] as usize;
            out.write_record(
                std::iter::once(angle_field).chain(nodes.field_range(first..first + width)),
            )?;
        }
    }
    out.flush()?;
    Ok(())
}

/// Writes `i,j,x,y,z,angles`: one row per node that at least one angle
/// marks colliding, in increasing j, then i; `angles` is the composite
/// count. Coordinates as in [`write_colliding_points`]; with `node_file`
/// (an assembly's attribution per node), a last column `file`.
///
/// Fails with [`io::ErrorKind::InvalidInput`] when `composite` does not have
/// one entry per grid node.
pub fn write_composite<W: Write>(
    w: W,
    grid: &HeightGrid,
    composite: &[u16],
    placement: &Placement,
    node_file: Option<&[u32]>,
) -> csv::Result<()> {
    check_len("composite", composite.len(), grid)?;
    if let Some(files) = node_file {
        check_len("file attribution", files.len(), grid)?;
    }
    let mut out = csv::Writer::from_writer(w);
    let header = ["i", "j", "x", "y", "z", "angles", "file"];
    out.write_record(&header[..6 + usize::from(node_file.is_some())])?;
    let mut row = Row::default();
    for (k, &count) in composite.iter().enumerate().filter(|&(_, &c)| c > 0) {
        row.start();
        row.node(grid, k, placement);
        row.int(usize::from(count));
        if let Some(files) = node_file {
            row.int(files[k] as usize);
        }
        out.write_record(row.fields())?;
    }
    out.flush()?;
    Ok(())
}

fn check_len(what: &str, len: usize, grid: &HeightGrid) -> csv::Result<()> {
    if len == grid.spec.len() {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{what} has {len} entries but the grid has {} x {} = {} nodes",
            grid.spec.nx,
            grid.spec.nz,
            grid.spec.len()
        ),
    )
    .into())
}

/// One record's fields, formatted into one reused buffer.
#[derive(Default)]
struct Row {
    text: String,
    ends: Vec<usize>,
}

impl Row {
    fn start(&mut self) {
        self.text.clear();
        self.ends.clear();
    }

    /// Shortest round-trip decimal; -0 is written as 0 (mirroring a zero
    /// height for the right side must not change the file).
    fn num(&mut self, v: f64) {
        let v = if v == 0.0 { 0.0 } else { v };
        write!(self.text, "{v}").expect("writing to a String cannot fail");
        self.ends.push(self.text.len());
    }

    fn int(&mut self, v: usize) {
        write!(self.text, "{v}").expect("writing to a String cannot fail");
        self.ends.push(self.text.len());
    }

    /// `i, j, x, y, z` of node `k` (row-major index) in the part's frame.
    fn node(&mut self, grid: &HeightGrid, k: usize, placement: &Placement) {
        let (i, j) = (k % grid.spec.nx, k / grid.spec.nx);
        self.int(i);
        self.int(j);
        let [x, y, z] = placement.to_part([grid.spec.x(i), grid.h[k], grid.spec.z(j)]);
        self.num(x);
        self.num(y);
        self.num(z);
    }

    fn fields(&self) -> impl Iterator<Item = &str> {
        self.field_range(0..self.ends.len())
    }

    /// Fields `range` of the buffer.
    fn field_range(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = &str> {
        range.map(|f| {
            let start = if f == 0 { 0 } else { self.ends[f - 1] };
            &self.text[start..self.ends[f]]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::mesh::Side;

    /// A 3 x 2 grid at pitch 0.5 starting at x = -1, z = 2.
    fn grid() -> HeightGrid {
        HeightGrid {
            spec: GridSpec {
                pitch: 0.5,
                i_origin: -2,
                j_origin: 4,
                nx: 3,
                nz: 2,
            },
            h: vec![0.0, 1.25, -3.0, 0.1, f64::INFINITY, 7.0],
        }
    }

    fn mask(angle_deg: f64, mask: Vec<u8>) -> AngleMask {
        AngleMask {
            angle_deg,
            colliding: mask.iter().filter(|&&m| m != 0).count(),
            mask,
            placed: 1,
            probes_met: Vec::new(),
        }
    }

    fn text(write: impl FnOnce(&mut Vec<u8>)) -> String {
        let mut buf = Vec::new();
        write(&mut buf);
        String::from_utf8(buf).unwrap()
    }

    #[test]
    fn colliding_points_sorted_by_angle_then_row_then_column() {
        let g = grid();
        let masks = [
            mask(5.0, vec![0, 0, 1, 1, 0, 0]),
            mask(-30.0, vec![1, 1, 0, 0, 0, 1]),
        ];
        let out =
            text(|buf| write_colliding_points(buf, &g, &masks, &Side::Left.into(), None).unwrap());
        assert_eq!(
            out,
            "angle_deg,i,j,x,y,z\n\
             -30,0,0,-1,0,2\n\
             -30,1,0,-0.5,1.25,2\n\
             -30,2,1,0,7,2.5\n\
             5,2,0,0,-3,2\n\
             5,0,1,-1,0.1,2.5\n"
        );
    }

    #[test]
    fn right_side_mirrors_y_back_to_the_part() {
        let g = grid();
        let masks = [mask(0.0, vec![1, 0, 1, 0, 0, 0])];
        let out =
            text(|buf| write_colliding_points(buf, &g, &masks, &Side::Right.into(), None).unwrap());
        // h = 0 stays "0", not "-0"; h = -3 becomes +3.
        assert_eq!(out, "angle_deg,i,j,x,y,z\n0,0,0,-1,0,2\n0,2,0,0,3,2\n");
    }

    #[test]
    fn composite_lists_counted_nodes_only() {
        let g = grid();
        let out = text(|buf| {
            write_composite(buf, &g, &[0, 3, 0, 61, 0, 1], &Side::Left.into(), None).unwrap()
        });
        assert_eq!(
            out,
            "i,j,x,y,z,angles\n\
             1,0,-0.5,1.25,2,3\n\
             0,1,-1,0.1,2.5,61\n\
             2,1,0,7,2.5,1\n"
        );
    }

    #[test]
    fn an_assembly_names_each_node_s_file_in_a_last_column() {
        let g = grid();
        let files = [0, 1, 0, 2, 0, 1];
        let masks = [
            mask(0.0, vec![0, 1, 0, 1, 0, 0]),
            mask(5.0, vec![0, 0, 0, 0, 0, 1]),
        ];
        let left = Side::Left.into();
        let out = text(|buf| write_colliding_points(buf, &g, &masks, &left, Some(&files)).unwrap());
        assert_eq!(
            out,
            "angle_deg,i,j,x,y,z,file\n\
             0,1,0,-0.5,1.25,2,1\n\
             0,0,1,-1,0.1,2.5,2\n\
             5,2,1,0,7,2.5,1\n"
        );
        let out =
            text(|buf| write_composite(buf, &g, &[0, 3, 0, 0, 0, 1], &left, Some(&files)).unwrap());
        assert_eq!(
            out,
            "i,j,x,y,z,angles,file\n1,0,-0.5,1.25,2,3,1\n2,1,0,7,2.5,1,1\n"
        );
    }

    #[test]
    fn a_frame_maps_every_coordinate_back_to_the_part() {
        let g = grid();
        let placement = crate::frame::Placement {
            side: Side::Right,
            frame: crate::frame::Frame::parse("z,x,y").unwrap(),
            approach: crate::analysis::Approach::Slide,
        };
        // Node (2, 0): analysis (0, -3, 2), vehicle (0, 3, 2); vehicle
        // (x, y, z) = part (z, x, y), so part (3, 2, 0).
        let out =
            text(|buf| write_composite(buf, &g, &[0, 0, 4, 0, 0, 0], &placement, None).unwrap());
        assert_eq!(out, "i,j,x,y,z,angles\n2,0,3,2,0,4\n");
    }

    #[test]
    fn wrong_length_is_refused() {
        let g = grid();
        let err = write_composite(Vec::new(), &g, &[1, 2], &Side::Left.into(), None).unwrap_err();
        assert!(err.to_string().contains("2 entries"), "{err}");
        let err = write_colliding_points(
            Vec::new(),
            &g,
            &[mask(0.0, vec![1])],
            &Side::Left.into(),
            None,
        );
        assert!(err.is_err());
    }
}
