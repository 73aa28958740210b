//! Parts in other coordinates: `--frame` maps a part file's axes into the
//! vehicle frame, and [`Placement`] composes it with `--side` into SPEC's
//! analysis frame.
//!
//! The composition, in this order, for a point `p` of the file (after
//! `--scale`, so in mm):
//!
//! 1. the **frame**: `v = R p + t`, a proper rotation `R` (orthonormal,
//!    determinant +1) and a translation `t` (mm), taking the part into
//!    vehicle coordinates (front -x, z up; the frame SPEC's left side is
//!    written in);
//! 2. the **side**: `a = (v_x, ±v_y, v_z)`, y mirrored for `--side right`.
//!
//! So `--frame` says where the part sits in the vehicle and `--side` which
//! way its analysed face looks there, as without `--frame`. Results go
//! back by the inverse, `p = R^T (S a - t)`. A mirror is never a frame:
//! that is what `--side right` does, and a mirrored frame would reverse
//! every triangle's winding behind the side's back.
//!
//! Without `--frame` nothing is transformed at all (not even by the
//! identity), so such runs give the same bytes as before the flag existed.
//!
//! **Invariant:** the engine never sees a frame: parts enter the analysis
//! frame in [`crate::input`], results leave it in [`crate::output`].

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Point3, Rotation3, Translation3};

/// Which side of the vehicle the analysed surface is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The analysed surface faces -y (SPEC's canonical frame).
    Left,
    /// The analysed surface faces +y: mirrored y -> -y on input and back on
    /// output.
    Right,
}

impl Side {
    /// Both sides, as `--side` offers them.
    pub const ALL: [Side; 2] = [Side::Left, Side::Right];

    /// The name, as `--side` takes it and `summary.json` records it.
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }

    /// Maps a y coordinate between the part's frame and the analysis frame
    /// (the mapping is its own inverse).
    pub fn to_part(self, y: f64) -> f64 {
        match self {
            Side::Left => y,
            Side::Right => -y,
        }
    }
}

/// Which knee motion an analysis follows. See README's "Two approaches".
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Approach {
    /// SPEC's push-and-slide (the paper's method): the knee-form pushed in
    /// +y against a surface facing -y, then slid in -x; strikes by the
    /// deflection threshold.
    #[default]
    Slide,
    /// The direct approach (its predecessor, [`crate::direct`]): the
    /// knee-form moved in -x until it first touches the part; the
    /// first-contact points are the area. The deflection threshold and
    /// rate rule are recorded but not used.
    Direct,
}

impl Approach {
    /// Both approaches, as `--approach` offers them.
    pub const ALL: [Approach; 2] = [Approach::Slide, Approach::Direct];

    /// The name as the flag and `summary.json` write it.
    pub fn name(self) -> &'static str {
        match self {
            Approach::Slide => "slide",
            Approach::Direct => "direct",
        }
    }
}

/// A point of SPEC's analysis frame (mm) in the direct frame: `D(x, y, z)
/// = (y, -x, z)`, a proper rotation.
pub(crate) fn to_direct([x, y, z]: [f64; 3]) -> [f64; 3] {
    [y, -x, z]
}

/// A point of the direct frame (mm) in SPEC's analysis frame: `D^-1(x',
/// y', z') = (-y', x', z')`, the exact inverse of [`to_direct`].
pub(crate) fn from_direct([x, y, z]: [f64; 3]) -> [f64; 3] {
    [-y, x, z]
}

/// How far from orthonormal with determinant +1 a frame's 3 x 3 part may
/// be (entrywise, and the determinant from 1): a matrix written with 16
/// significant digits is within 1e-15; 1e-9 also forgives one written with
/// 10, and still moves a point 1 m from the origin by at most 1 um.
pub(crate) const ROTATION_TOL: f64 = 1e-9;

/// How far from a rotation a matrix file's 3 x 3 part may be and still be
/// taken, made a rotation (its nearest, by polar decomposition): CAD tools
/// write matrices to 6 or 8 decimals (0.70710678 is within 4e-9 of
/// cos 45 degrees). The correction is recorded ([`FrameRecord`]'s
/// `orthonormalised_by`); at this bound a point 1 m from the origin moves
/// by a few um.
pub(crate) const ORTHONORMALISE_TOL: f64 = 1e-6;

/// A rigid map from a part file's coordinates (mm) into vehicle
/// coordinates, or none (the file is in vehicle coordinates already).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    map: Option<Map>,
}

#[derive(Debug, Clone, PartialEq)]
struct Map {
    /// The flag's value as given: `x,-z,y` or `@FILE`.
    given: String,
    rotation: Rotation3<f64>,
    /// `R^-1`, computed rather than taken as `R^T`: for a matrix
    /// orthonormal only within [`ROTATION_TOL`] the two differ by up to
    /// that much, and results must go back exactly where they came from
    /// (to rounding). For signed axes it is exact.
    inverse: Matrix3<f64>,
    translation: Translation3<f64>,
    /// The largest change made to an entry of the given matrix to make it
    /// a rotation, where one was ([`ORTHONORMALISE_TOL`]).
    orthonormalised_by: Option<f64>,
}

/// A frame as `summary.json`, `verify.json` and `converge.json` record it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FrameRecord {
    /// The `--frame` value as given (`x,-z,y`, or `@FILE`).
    pub given: String,
    /// The map from the part's coordinates into vehicle coordinates (mm),
    /// as the rows of a 3 x 4 matrix `[R | t]`.
    pub part_to_vehicle: [[f64; 4]; 3],
    /// Where the given matrix was a rotation within 1e-6
    /// (`ORTHONORMALISE_TOL`) but not within 1e-9: the largest change made
    /// to one of its entries to make it the nearest rotation,
    /// `part_to_vehicle`'s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orthonormalised_by: Option<f64>,
}

/// Why a `--frame` value was refused.
#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    /// Not three signed axes and not `@FILE`.
    #[error(
        "expected three signed part axes, one per vehicle axis x, y, z (e.g. x,-z,y), or @FILE with a 4x4 or 3x4 matrix; got {0:?}"
    )]
    Syntax(String),
    /// A part axis is named twice.
    #[error("{given:?} names the part's {axis} axis twice: each must map to one vehicle axis")]
    RepeatedAxis {
        /// The value given.
        given: String,
        /// The repeated axis.
        axis: char,
    },
    /// The matrix file could not be read.
    #[error("cannot read the matrix file {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The matrix file does not hold a 3x4 or 4x4 matrix.
    #[error("{}: {reason}", path.display())]
    Matrix {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The 3 x 3 part is not a proper rotation.
    #[error("{given:?} is not a rotation: {reason} (a mirror is --side right's job)")]
    NotRotation {
        /// The value given.
        given: String,
        /// Why.
        reason: String,
    },
}

impl Frame {
    /// No frame: the part is in vehicle coordinates.
    pub fn none() -> Frame {
        Frame::default()
    }

    /// Parses a `--frame` value: three signed part axes, one per vehicle
    /// axis x, y, z (`x,-z,y`: vehicle x is the part's x, vehicle y its
    /// -z, vehicle z its y), or `@FILE`, a 4x4 or 3x4 matrix (row by row,
    /// numbers separated by spaces, commas or line breaks; `#` starts a
    /// comment) mapping the part's homogeneous coordinates (mm, after
    /// `--scale`) to vehicle coordinates. Refused unless a proper rotation
    /// within `ORTHONORMALISE_TOL` (made its nearest rotation beyond
    /// `ROTATION_TOL`) with a finite translation, its rows one a line.
    pub fn parse(value: &str) -> Result<Frame, FrameError> {
        match value.strip_prefix('@') {
            Some(path) => Frame::from_file(Path::new(path), value),
            None => Frame::from_axes(value),
        }
    }

    fn from_axes(given: &str) -> Result<Frame, FrameError> {
        let syntax = || FrameError::Syntax(given.to_string());
        let tokens: Vec<&str> = given.split(',').map(str::trim).collect();
        if tokens.len() != 3 {
            return Err(syntax());
        }
        let mut m = Matrix3::zeros();
        let mut seen = [false; 3];
        for (row, token) in tokens.iter().enumerate() {
            let (sign, axis) = match token.strip_prefix('-') {
                Some(rest) => (-1.0, rest),
                None => (1.0, token.strip_prefix('+').unwrap_or(token)),
            };
            let (col, name) = match axis {
                "x" | "X" => (0, 'x'),
                "y" | "Y" => (1, 'y'),
                "z" | "Z" => (2, 'z'),
                _ => return Err(syntax()),
            };
            if seen[col] {
                return Err(FrameError::RepeatedAxis {
                    given: given.to_string(),
                    axis: name,
                });
            }
            seen[col] = true;
            m[(row, col)] = sign;
        }
        Frame::from_parts(given, m, [0.0; 3])
    }

    fn from_file(path: &Path, given: &str) -> Result<Frame, FrameError> {
        let text = crate::limits::read_text_bounded(path).map_err(|source| FrameError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Frame::from_matrix_text(&text, path, given)
    }

    /// The frame of a matrix file's `text` (`path` and `given` for
    /// messages): a 4x4 or 3x4 matrix, row by row, `#` comments.
    pub fn from_matrix_text(text: &str, path: &Path, given: &str) -> Result<Frame, FrameError> {
        let bad = |reason: String| FrameError::Matrix {
            path: path.to_path_buf(),
            reason,
        };
        let mut numbers = Vec::new();
        // Numbers per line holding any, with the line's number: rows must
        // be rows.
        let mut rows: Vec<(usize, usize)> = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or_default();
            let before = numbers.len();
            for token in line
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
            {
                let v: f64 = token
                    .parse()
                    .map_err(|_| bad(format!("{token:?} is not a number")))?;
                if !v.is_finite() {
                    return Err(bad(format!("{token} is not a finite number")));
                }
                numbers.push(v);
            }
            if numbers.len() > before {
                rows.push((k + 1, numbers.len() - before));
            }
        }
        if numbers.len() != 12 && numbers.len() != 16 {
            return Err(bad(format!(
                "expected a 4x4 or 3x4 matrix (16 or 12 numbers, row by row), found {} numbers",
                numbers.len()
            )));
        }
        // One row a line (or the whole matrix on one line): 12 numbers in
        // lines of 4, 3 and 5 are no matrix.
        if rows.len() > 1
            && let Some((line, count)) = rows.iter().find(|(_, count)| *count != 4)
        {
            return Err(bad(format!(
                "line {line} holds {count} numbers: write the matrix row by row, 4 numbers a line"
            )));
        }
        if numbers.len() == 16 {
            let last = &numbers[12..];
            if last
                .iter()
                .zip([0.0, 0.0, 0.0, 1.0])
                .any(|(a, b)| (a - b).abs() > ROTATION_TOL)
            {
                return Err(bad(format!(
                    "the last row of a 4x4 rigid transform must be 0 0 0 1, found {last:?}"
                )));
            }
        }
        let m = Matrix3::from_fn(|r, c| numbers[4 * r + c]);
        let t = [numbers[3], numbers[7], numbers[11]];
        Frame::from_parts(given, m, t)
    }

    /// A frame from its rotation (checked) and translation (mm).
    fn from_parts(given: &str, m: Matrix3<f64>, t: [f64; 3]) -> Result<Frame, FrameError> {
        let refuse = |reason: String| FrameError::NotRotation {
            given: given.to_string(),
            reason,
        };
        let det = m.determinant();
        if det < 0.0 {
            return Err(refuse(format!("its determinant is {det}, a mirror")));
        }
        let off = (m.transpose() * m - Matrix3::identity()).amax();
        if off > ORTHONORMALISE_TOL {
            return Err(refuse(format!(
                "its rows are not orthonormal (R^T R differs from the identity by {off:.3e}, more than {ORTHONORMALISE_TOL:e}): a scaling or a shear"
            )));
        }
        if (det - 1.0).abs() > ORTHONORMALISE_TOL {
            return Err(refuse(format!(
                "its determinant is {det:.9}, not 1: a scaling"
            )));
        }
        // Within ROTATION_TOL the matrix is taken as given (its inverse
        // computed); beyond it, up to ORTHONORMALISE_TOL, it is made its
        // nearest rotation and the change recorded.
        let (m, orthonormalised_by) = if off > ROTATION_TOL || (det - 1.0).abs() > ROTATION_TOL {
            let r = nearest_rotation(&m).ok_or_else(|| refuse("it has no inverse".into()))?;
            let change = (r - m).amax();
            (r, Some(change))
        } else {
            (m, None)
        };
        let inverse = m
            .try_inverse()
            .ok_or_else(|| refuse("it has no inverse".into()))?;
        Ok(Frame {
            map: Some(Map {
                given: given.to_string(),
                rotation: Rotation3::from_matrix_unchecked(m),
                inverse,
                translation: Translation3::new(t[0], t[1], t[2]),
                orthonormalised_by,
            }),
        })
    }

    /// Whether there is no frame (the part is in vehicle coordinates).
    pub fn is_none(&self) -> bool {
        self.map.is_none()
    }

    /// The frame as the run's files record it; `None` without a frame.
    pub fn record(&self) -> Option<FrameRecord> {
        self.map.as_ref().map(|m| {
            let r = m.rotation.matrix();
            let t = m.translation.vector;
            FrameRecord {
                given: m.given.clone(),
                part_to_vehicle: std::array::from_fn(|row| {
                    [r[(row, 0)], r[(row, 1)], r[(row, 2)], t[row]]
                }),
                orthonormalised_by: m.orthonormalised_by,
            }
        })
    }

    /// The frame a record describes (checked as [`Frame::parse`] checks).
    pub fn from_record(record: &FrameRecord) -> Result<Frame, FrameError> {
        let rows = &record.part_to_vehicle;
        let m = Matrix3::from_fn(|r, c| rows[r][c]);
        let mut frame = Frame::from_parts(&record.given, m, [rows[0][3], rows[1][3], rows[2][3]])?;
        // The recorded matrix is the corrected one: the correction is the
        // record's.
        if let Some(map) = frame.map.as_mut() {
            map.orthonormalised_by = map.orthonormalised_by.or(record.orthonormalised_by);
        }
        Ok(frame)
    }

    /// A point of the part (mm) in vehicle coordinates.
    pub fn to_vehicle(&self, p: [f64; 3]) -> [f64; 3] {
        match &self.map {
            None => p,
            Some(m) => {
                let v = m.translation * (m.rotation * Point3::from(p));
                [v.x, v.y, v.z]
            }
        }
    }

    /// A point in vehicle coordinates (mm) in the part's: the inverse of
    /// [`Frame::to_vehicle`].
    pub fn to_part(&self, v: [f64; 3]) -> [f64; 3] {
        match &self.map {
            None => v,
            Some(m) => {
                let p = m.inverse
                    * m.translation
                        .inverse_transform_point(&Point3::from(v))
                        .coords;
                [p.x, p.y, p.z]
            }
        }
    }
}

/// The rotation nearest `m` (its polar decomposition's: `U V^T` of its
/// SVD), for a matrix of determinant near +1; `None` where the SVD fails.
fn nearest_rotation(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let svd = m.svd(true, true);
    let r = svd.u? * svd.v_t?;
    (r.determinant() > 0.0).then_some(r)
}

/// How a part file's coordinates (mm, after `--scale`) map into SPEC's
/// analysis frame: the [`Frame`] into vehicle coordinates, then the
/// [`Side`] (y mirrored for the right side). See the module's docs.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Which way the analysed face looks in vehicle coordinates.
    pub side: Side,
    /// Where the part sits in the vehicle.
    pub frame: Frame,
    /// For [`Approach::Direct`], the analysis frame is turned into the
    /// direct frame last (`to_direct`); the slide's is
    /// SPEC's.
    pub approach: Approach,
}

impl From<Side> for Placement {
    /// The side alone: the part is in vehicle coordinates.
    fn from(side: Side) -> Placement {
        Placement {
            side,
            frame: Frame::none(),
            approach: Approach::Slide,
        }
    }
}

impl Placement {
    /// A point of the part (mm) in the analysis frame (the direct frame
    /// for the direct approach).
    pub fn to_analysis(&self, p: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = self.frame.to_vehicle(p);
        let a = [x, self.side.to_part(y), z];
        match self.approach {
            Approach::Slide => a,
            Approach::Direct => to_direct(a),
        }
    }

    /// A point of the analysis frame in the part's coordinates (mm): the
    /// inverse of [`Placement::to_analysis`]. Without a frame only y is
    /// touched (mirrored for the right side), exactly as before frames.
    pub fn to_part(&self, a: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = match self.approach {
            Approach::Slide => a,
            Approach::Direct => from_direct(a),
        };
        self.frame.to_part([x, self.side.to_part(y), z])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flags_names_are_the_names_summary_json_records() {
        // A flag's value (`name`, parsed by the CLI) and the JSON that
        // records it (serde) must spell every value alike.
        fn same<T: serde::Serialize + Copy>(all: &[T], name: fn(T) -> &'static str) {
            for &v in all {
                let json = serde_json::to_string(&v).expect("a name");
                assert_eq!(json, format!("\"{}\"", name(v)));
            }
        }
        same(&Side::ALL, Side::name);
        same(&Approach::ALL, Approach::name);
        same(&crate::Algorithm::ALL, crate::Algorithm::name);
        same(
            &crate::strike::RateEstimate::ALL,
            crate::strike::RateEstimate::name,
        );
    }

    #[test]
    fn axes_map_part_axes_to_vehicle_axes_and_back_exactly() {
        let f = Frame::parse("x,-z,y").unwrap();
        // Vehicle x = part x, vehicle y = -part z, vehicle z = part y.
        assert_eq!(f.to_vehicle([1.5, 2.25, -3.0]), [1.5, 3.0, 2.25]);
        assert_eq!(f.to_part([1.5, 3.0, 2.25]), [1.5, 2.25, -3.0]);
        let r = f.record().unwrap();
        assert_eq!(r.given, "x,-z,y");
        assert_eq!(r.part_to_vehicle[1], [0.0, 0.0, -1.0, 0.0]);
        assert_eq!(Frame::from_record(&r).unwrap(), f);
        assert!(Frame::none().record().is_none());
    }

    #[test]
    fn side_applies_after_the_frame() {
        let p = Placement {
            side: Side::Right,
            frame: Frame::parse("y,z,x").unwrap(),
            approach: Approach::Slide,
        };
        // Vehicle (y, z, x) = (2, 3, 1), mirrored in y: (2, -3, 1).
        assert_eq!(p.to_analysis([1.0, 2.0, 3.0]), [2.0, -3.0, 1.0]);
        assert_eq!(p.to_part([2.0, -3.0, 1.0]), [1.0, 2.0, 3.0]);
        // The direct approach turns the analysis frame last: (x, y, z) ->
        // (y, -x, z), and back exactly.
        let d = Placement {
            approach: Approach::Direct,
            ..p
        };
        assert_eq!(d.to_analysis([1.0, 2.0, 3.0]), [-3.0, -2.0, 1.0]);
        assert_eq!(d.to_part([-3.0, -2.0, 1.0]), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn mirrors_repeats_and_nonsense_are_refused() {
        assert!(matches!(
            Frame::parse("x,y,-z"),
            Err(FrameError::NotRotation { .. })
        ));
        assert!(matches!(
            Frame::parse("x,x,z"),
            Err(FrameError::RepeatedAxis { axis: 'x', .. })
        ));
        for bad in ["x,y", "x,y,w", "", "x,y,z,x", "2x,y,z"] {
            assert!(
                matches!(Frame::parse(bad), Err(FrameError::Syntax(_))),
                "{bad}"
            );
        }
    }

    #[test]
    fn matrix_files_are_checked() {
        let dir = std::env::temp_dir().join(format!("kneeform-frame-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            format!("@{}", path.display())
        };
        // A quarter turn about z and a shift, 4x4 with a comment.
        let (c, s) = (0.0, 1.0);
        let quarter = file(
            "quarter.txt",
            &format!(
                "# part to vehicle\n{c} {} 0 10\n{s} {c} 0 -5\n0 0 1 2\n0 0 0 1\n",
                -s
            ),
        );
        let f = Frame::parse(&quarter).unwrap();
        assert_eq!(f.to_vehicle([1.0, 0.0, 0.0]), [10.0, -4.0, 2.0]);
        let back = f.to_part([10.0, -4.0, 2.0]);
        assert!(
            back.iter()
                .zip([1.0, 0.0, 0.0])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
        // 3x4, commas: a 30-degree turn about x.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let turn = file(
            "turn.csv",
            &format!("1,0,0,0\n0,{c},{},0\n0,{s},{c},0\n", -s),
        );
        assert!(Frame::parse(&turn).is_ok());
        // Ten digits: orthonormal within 1e-9 only, yet a point goes back
        // where it came from, to rounding.
        let ten = file(
            "ten.txt",
            &format!("1 0 0 0\n0 {c:.10} {:.10} 100\n0 {s:.10} {c:.10} -40\n", -s),
        );
        let f = Frame::parse(&ten).unwrap();
        let p = [350.0, -120.5, 980.25];
        let back = f.to_part(f.to_vehicle(p));
        assert!(
            back.iter().zip(p).all(|(a, b)| (a - b).abs() < 1e-12),
            "{back:?}"
        );
        let refused = |text: &str| Frame::parse(&file("bad.txt", text)).unwrap_err();
        assert!(matches!(
            refused("1 0 0 0\n0 1 0 0\n"),
            FrameError::Matrix { .. }
        ));
        assert!(matches!(
            refused("1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1"),
            FrameError::Matrix { .. }
        ));
        assert!(matches!(
            refused("2 0 0 0 0 1 0 0 0 0 1 0"),
            FrameError::NotRotation { .. }
        ));
        assert!(matches!(
            refused("1 0 0 0 0 1 0 0 0 0 -1 0"),
            FrameError::NotRotation { .. }
        ));
        assert!(matches!(
            refused("1 0 0 0 0 1 0 0 0 0 1 nan"),
            FrameError::Matrix { .. }
        ));
        assert!(matches!(
            Frame::parse(&format!("@{}", dir.join("missing.txt").display())),
            Err(FrameError::Io { .. })
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
