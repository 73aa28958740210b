//! The part's geometry: triangles in mm in SPEC's analysis frame, and
//! their bounding box. Reading files into a part is [`crate::input`]'s.

/// One triangle, three vertices (x, y, z) in mm.
pub type Triangle = [[f64; 3]; 3];
/// A part in the analysis frame.
#[derive(Debug, Clone)]
pub struct Part {
    /// Non-degenerate triangles, in mm, analysis frame.
    pub triangles: Vec<Triangle>,
    /// Triangles in the file.
    pub file_triangles: usize,
    /// Triangles skipped because their area is zero.
    pub degenerate: usize,
    /// Bodies read: an ASCII STL's `solid ... endsolid` blocks (CAD
    /// exporters write one per body), 1 for a binary STL or a scenario;
    /// the sum over an assembly's analysed files.
    pub bodies: usize,
}
/// An axis-aligned box (mm).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Bbox {
    /// Smallest x, y, z.
    pub min: [f64; 3],
    /// Largest x, y, z.
    pub max: [f64; 3],
}

impl Part {
    /// The bounding box of the part (analysis frame, mm).
    pub fn bbox(&self) -> Bbox {
        let mut b = Bbox {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for v in self.triangles.iter().flatten() {
            for ((lo, hi), &c) in b.min.iter_mut().zip(b.max.iter_mut()).zip(v) {
                *lo = lo.min(c);
                *hi = hi.max(c);
            }
        }
        b
    }
}

/// A triangle is degenerate when its area is zero: its edge vectors'
/// cross product vanishes exactly (repeated or collinear vertices).
pub(crate) fn is_degenerate(t: &Triangle) -> bool {
    let e1 = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
    let e2 = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
    let c = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    c == [0.0; 3]
}
