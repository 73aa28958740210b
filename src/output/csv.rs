//! CSV tables of the result: the composite, one row per colliding node
//! with its count and its set of angles (the default, compact table), and
//! on request the colliding points of every angle, one row per node and
//! angle (`analyze --points-csv`).
//!
//! Coordinates are the part's own (mm): the node's x and z and its height,
//! mapped back with [`Placement::to_part`] (y mirrored for the right side,
//! then the `--frame` undone). An assembly's tables end with a `file`
//! column: the index, in `summary.json`'s `files`, of the file whose
//! surface set the node's height; a single part's tables have no such
//! column. Rows come in a fixed order
//! (angle, then row j, then column i) and numbers in a fixed form (coordinates
//! rounded to 1 um: a node at `i * p` is written `-282.72`, not its
//! double's `-282.71999999999997`), so the same result always gives the
//! same bytes.

use std::fmt::Write as _;
use std::io::{self, Write};

use crate::engine::AngleMask;
use crate::frame::Placement;
use crate::grid::HeightGrid;

/// Writes `angle_deg,i,j,x,y,z`: one row per colliding node per angle, in
/// increasing angle (degrees), then j, then i; x, y, z the node at its
/// height in the part's frame (mm, to 1 um). With `node_file` (an assembly's
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
                nodes.node_rounded(grid, k, placement);
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

/// Writes `i,j,x,y,z,angles,angle_mask`: one row per node that at least
/// one angle marks colliding, in increasing j, then i; `angles` is the
/// composite count and `angle_mask` the set of those angles, a hex bit
/// mask over the run's angles in their order ([`angle_mask`]). The
/// coordinates are the node's in the part's frame, rounded to 1 um
/// ([`micrometres`]); with `node_file` (an assembly's attribution per
/// node), a last column `file`.
///
/// This is the run's compact per-angle result: `colliding_points.csv`
/// ([`write_colliding_points`]) holds the same sets, one row per node and
/// angle, some fifty times larger.
///
/// Fails with [`io::ErrorKind::InvalidInput`] when `composite` or a mask
/// does not have one entry per grid node.
pub fn write_composite<W: Write>(
    w: W,
    grid: &HeightGrid,
    masks: &[AngleMask],
    composite: &[u16],
    placement: &Placement,
    node_file: Option<&[u32]>,
) -> csv::Result<()> {
    check_len("composite", composite.len(), grid)?;
    for m in masks {
        check_len("colliding mask", m.mask.len(), grid)?;
    }
    if let Some(files) = node_file {
        check_len("file attribution", files.len(), grid)?;
    }
    let mut out = csv::Writer::from_writer(w);
    let header = ["i", "j", "x", "y", "z", "angles", "angle_mask", "file"];
    out.write_record(&header[..7 + usize::from(node_file.is_some())])?;
    let mut row = Row::default();
    for (k, &count) in composite.iter().enumerate().filter(|&(_, &c)| c > 0) {
        row.start();
        row.node_rounded(grid, k, placement);
        row.int(usize::from(count));
        row.mask(masks, k);
        if let Some(files) = node_file {
            row.int(files[k] as usize);
        }
        out.write_record(row.fields())?;
    }
    out.flush()?;
    Ok(())
}

/// The digits after the point of a coordinate in `composite.csv`: 1 um.
pub const MICROMETRE_DIGITS: usize = 3;

/// `v` (mm) rounded to 1 um and written without trailing zeros: the
/// binary value's exact decimal expansion rounded half to even at the
/// third digit (Rust's `{:.3}`, the same on every machine), then `12.340`
/// as `12.34`, `12.000` as `12` and `-0` as `0`. Every value round-trips
/// to within half a micrometre.
pub fn micrometres(v: f64) -> String {
    let mut s = String::new();
    push_micrometres(&mut s, v);
    s
}

/// `v` rounded to 1 um as [`micrometres`] writes it, as a number (`-0`
/// as `0`): what a reader of the tables parses back.
pub(super) fn micrometres_value(v: f64) -> f64 {
    let mut s = String::new();
    push_micrometres(&mut s, v);
    s.parse().unwrap_or(v)
}

/// [`micrometres`] appended to `s`.
pub(super) fn push_micrometres(s: &mut String, v: f64) {
    // Most values are rounded here with integers. `m` is the product
    // rounded to the nearest double; that rounding is monotone and every
    // half below 2^52 is a double, so `m` lies on the same side of each
    // half as the exact product, or on it. Off the halves, rounding `m` to
    // the nearest integer therefore gives the exact product's rounding. On
    // a half (a tie, or a product just beside one), and for huge or
    // non-finite values, `{:.3}` decides: the definition.
    let m = v * 1000.0;
    if m.abs() < 4e15 && m - m.floor() != 0.5 {
        let n = m.round() as i64;
        if n < 0 {
            s.push('-');
        }
        let n = n.unsigned_abs();
        write!(s, "{}", n / 1000).expect("writing to a String cannot fail");
        let (mut fraction, mut digits) = (n % 1000, MICROMETRE_DIGITS);
        if fraction != 0 {
            while fraction % 10 == 0 {
                fraction /= 10;
                digits -= 1;
            }
            write!(s, ".{fraction:0digits$}").expect("writing to a String cannot fail");
        }
        return;
    }
    push_micrometres_exact(s, v);
}

/// [`micrometres`] by its definition: `{:.3}`, trimmed.
fn push_micrometres_exact(s: &mut String, v: f64) {
    let start = s.len();
    write!(s, "{v:.MICROMETRE_DIGITS$}").expect("writing to a String cannot fail");
    if s[start..].contains('.') {
        let kept = s.trim_end_matches('0').trim_end_matches('.').len();
        s.truncate(kept);
    }
    if &s[start..] == "-0" {
        s.truncate(start);
        s.push('0');
    }
}

/// The set of angles (bit `a` for `masks[a]`, in the run's order) at
/// which node `k` collides, as `0x` and `ceil(n / 4)` hex digits, the most
/// significant first: angle 0 is the last digit's lowest bit. A reader
/// takes angle `a` as `(int(mask, 16) >> a) & 1` (Python's `int` takes the
/// `0x`); the prefix keeps pandas and polars from reading a mask of decimal
/// digits as a number.
#[cfg(test)]
fn angle_mask(masks: &[AngleMask], k: usize) -> String {
    let mut row = Row::default();
    row.mask(masks, k);
    row.text
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

    /// `i, j, x, y, z` of node `k` (row-major index) in the part's frame,
    /// the coordinates rounded to 1 um ([`micrometres`]).
    fn node_rounded(&mut self, grid: &HeightGrid, k: usize, placement: &Placement) {
        let (i, j) = (k % grid.spec.nx, k / grid.spec.nx);
        self.int(i);
        self.int(j);
        let [x, y, z] = placement.to_part([grid.spec.x(i), grid.h[k], grid.spec.z(j)]);
        for v in [x, y, z] {
            push_micrometres(&mut self.text, v);
            self.ends.push(self.text.len());
        }
    }

    /// Node `k`'s [`angle_mask`].
    fn mask(&mut self, masks: &[AngleMask], k: usize) {
        self.text.push_str("0x");
        let digits = masks.len().div_ceil(4).max(1);
        for d in (0..digits).rev() {
            let nibble = (0..4).fold(0u32, |n, b| {
                let set = masks.get(4 * d + b).is_some_and(|m| m.mask[k] != 0);
                n | (u32::from(set) << b)
            });
            self.text
                .push(char::from_digit(nibble, 16).expect("a nibble is a hex digit"));
        }
        self.ends.push(self.text.len());
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
    use crate::frame::Side;
    use crate::grid::GridSpec;

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
        AngleMask::new(angle_deg, mask, 1, Vec::new())
    }

    fn composite_of(masks: &[AngleMask]) -> Vec<u16> {
        crate::engine::composite(masks)
    }

    #[test]
    fn coordinates_are_micrometres_without_noise() {
        for (v, s) in [
            (313.71999999999997, "313.72"),
            (-234.35999999999999, "-234.36"),
            (12.0, "12"),
            (0.0004, "0"),
            (-0.0004, "0"),
            (-0.0, "0"),
            (1.0005, "1"),
            (1.0015, "1.002"),
            (-7.12345, "-7.123"),
            (1e-3, "0.001"),
        ] {
            assert_eq!(micrometres(v), s, "{v}");
            // Symmetric: a mirrored side negates y and nothing else.
            let negated = match micrometres(v.abs()) {
                zero if zero == "0" => zero,
                m => format!("-{m}"),
            };
            assert_eq!(micrometres(-v.abs()), negated, "{v}");
        }
    }

    #[test]
    fn micrometres_agree_with_their_definition() {
        let exact = |v: f64| {
            let mut s = String::new();
            push_micrometres_exact(&mut s, v);
            s
        };
        // Halves and their neighbours (where the shortcut must step
        // aside), grid-like coordinates, and values from tiny to huge.
        let mut values = vec![0.0, -0.0, 0.0005, -0.0005, 2.5e-4, 1e9, -1e12, 1.0 / 3.0];
        for k in -3000..3000 {
            let half = (f64::from(k) + 0.5) / 1000.0;
            values.extend([half, half.next_up(), half.next_down(), f64::from(k) * 0.124]);
        }
        let mut rng = crate::harness::compare::SplitMix(7);
        for _ in 0..100_000 {
            // Spread over magnitudes 1e-4 .. 1e7, both signs.
            let x = rng.next();
            let unit = (x >> 11) as f64 / (1u64 << 53) as f64;
            let v = 10f64.powf(unit * 11.0 - 4.0);
            values.push(if x & 1 == 0 { v } else { -v });
        }
        values.extend([f64::INFINITY, f64::NEG_INFINITY, f64::NAN]);
        for v in values {
            assert_eq!(micrometres(v), exact(v), "{v:e}");
        }
    }

    #[test]
    fn a_mask_has_a_digit_per_four_angles_angle_zero_lowest() {
        let masks: Vec<AngleMask> = (0..9)
            .map(|a| mask(f64::from(a), vec![u8::from(a == 0 || a == 8)]))
            .collect();
        assert_eq!(angle_mask(&masks, 0), "0x101");
        assert_eq!(angle_mask(&masks[..1], 0), "0x1");
        assert_eq!(angle_mask(&[], 0), "0x0");
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
        let masks = [
            mask(-5.0, vec![0, 1, 0, 1, 0, 1]),
            mask(0.0, vec![0, 1, 0, 1, 0, 0]),
            mask(5.0, vec![0, 0, 0, 1, 0, 0]),
            mask(10.0, vec![0, 1, 0, 0, 0, 0]),
            mask(15.0, vec![0, 0, 0, 1, 0, 0]),
        ];
        let counts = composite_of(&masks);
        let out = text(|buf| {
            write_composite(buf, &g, &masks, &counts, &Side::Left.into(), None).unwrap()
        });
        // Angle a is bit a: node 1 at -5, 0 and 10 is 0b01011.
        assert_eq!(
            out,
            "i,j,x,y,z,angles,angle_mask\n\
             1,0,-0.5,1.25,2,3,0x0b\n\
             0,1,-1,0.1,2.5,4,0x17\n\
             2,1,0,7,2.5,1,0x01\n"
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
        let counts = composite_of(&masks);
        let out =
            text(|buf| write_composite(buf, &g, &masks, &counts, &left, Some(&files)).unwrap());
        assert_eq!(
            out,
            "i,j,x,y,z,angles,angle_mask,file\n\
             1,0,-0.5,1.25,2,1,0x1,1\n\
             0,1,-1,0.1,2.5,1,0x1,2\n\
             2,1,0,7,2.5,1,0x2,1\n"
        );
    }

    #[test]
    fn a_frame_maps_every_coordinate_back_to_the_part() {
        let g = grid();
        let placement = crate::frame::Placement {
            side: Side::Right,
            frame: crate::frame::Frame::parse("z,x,y").unwrap(),
            approach: crate::frame::Approach::Slide,
        };
        // Node (2, 0): analysis (0, -3, 2), vehicle (0, 3, 2); vehicle
        // (x, y, z) = part (z, x, y), so part (3, 2, 0).
        let masks = [mask(0.0, vec![0, 0, 1, 0, 0, 0])];
        let out = text(|buf| {
            write_composite(buf, &g, &masks, &composite_of(&masks), &placement, None).unwrap()
        });
        assert_eq!(out, "i,j,x,y,z,angles,angle_mask\n2,0,3,2,0,1,0x1\n");
    }

    #[test]
    fn wrong_length_is_refused() {
        let g = grid();
        let err =
            write_composite(Vec::new(), &g, &[], &[1, 2], &Side::Left.into(), None).unwrap_err();
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
