//! The knee-form of SPEC: its cross-section `K = T (+) D_R` in the xz-plane,
//! rotated about the reference point, and the row intervals `[a(dz), b(dz)]`
//! that push and slide work with.
//!
//! All lengths are mm and all angles degrees, in the canonical analysis frame
//! (front is -x, z up). The reference point is the triangle vertex `v0`, the
//! centre of the rounded front corner, at the origin of the footprint.

use crate::grid::{GridSpec, NODE_TOL};
use crate::mesh::Bbox;

/// The knee-form's dimensions (mm).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KneeForm {
    /// Side `L` of the equilateral triangle `T`. The default of 200 mm is an
    /// assumption: the regulation's figure was not at hand.
    pub triangle_side: f64,
    /// Radius `R` of the disc rounding the triangle.
    pub radius: f64,
    /// Extrusion `W` along y. The grid method does not use it (SPEC's slide
    /// compares heights with the face level only); the oracle does.
    pub thickness: f64,
}

impl Default for KneeForm {
    fn default() -> Self {
        KneeForm {
            triangle_side: 200.0,
            radius: 60.0,
            thickness: 120.0,
        }
    }
}

/// The knee-form's cross-section at one angle, relative to its reference
/// point: a rounded triangle with vertices `vertices` and rounding `radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// The rotated triangle `T`, as (x, z) in mm, counter-clockwise.
    pub vertices: [[f64; 2]; 3],
    /// The rounding radius `R` in mm.
    pub radius: f64,
}

impl Footprint {
    /// The default extent of SPEC: every node whose footprint, at any of
    /// `footprints`, can reach the part's xz bounding box. That is the box
    /// grown by the footprints' extent on every side, snapped outwards to
    /// multiples of the pitch.
    pub fn grid_around(bbox: &Bbox, footprints: &[Footprint], pitch: f64) -> GridSpec {
        let (mut fx_lo, mut fx_hi, mut fz_lo, mut fz_hi) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for fp in footprints {
            let (xl, xh) = fp.x_range();
            let (zl, zh) = fp.z_range();
            fx_lo = fx_lo.min(xl);
            fx_hi = fx_hi.max(xh);
            fz_lo = fz_lo.min(zl);
            fz_hi = fz_hi.max(zh);
        }
        GridSpec::reaching(bbox, (fx_lo, fx_hi), (fz_lo, fz_hi), pitch)
    }

    /// The footprint of `knee` at `angle_deg` (positive raises the back).
    pub fn new(knee: &KneeForm, angle_deg: f64) -> Footprint {
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        let half = knee.triangle_side / 2.0;
        let depth = knee.triangle_side * 3f64.sqrt() / 2.0;
        // v0, v2, v1: counter-clockwise in (x, z), so edge normals rotated
        // clockwise point outwards.
        let unrotated = [[0.0, 0.0], [depth, -half], [depth, half]];
        let vertices = unrotated.map(|[x, z]| [x * cos - z * sin, x * sin + z * cos]);
        Footprint {
            vertices,
            radius: knee.radius,
        }
    }

    /// The footprint's extent in z, `(min, max)`, in mm.
    pub fn z_range(&self) -> (f64, f64) {
        let zs = self.vertices.map(|v| v[1]);
        let lo = zs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = zs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo - self.radius, hi + self.radius)
    }

    /// The footprint's extent in x, `(min, max)`, in mm.
    pub fn x_range(&self) -> (f64, f64) {
        let xs = self.vertices.map(|v| v[0]);
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo - self.radius, hi + self.radius)
    }

    /// The interval `[a, b]` (mm, relative to the reference point) in which
    /// the line `z = dz` meets the footprint, or `None` when it misses it by
    /// more than `NODE_TOL`. Rows grazing the top or bottom within the
    /// tolerance get the tangent point.
    ///
    /// The boundary of a rounded triangle is made of its three vertex arcs
    /// and its three edges pushed out by `R`; every one of those features
    /// lies inside the footprint, so the extreme x over them is exact.
    pub fn row_interval(&self, dz: f64) -> Option<(f64, f64)> {
        let (zlo, zhi) = self.z_range();
        if dz < zlo - NODE_TOL || dz > zhi + NODE_TOL {
            return None;
        }
        let dz = dz.clamp(zlo, zhi);
        let r = self.radius;
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut take = |x: f64| {
            lo = lo.min(x);
            hi = hi.max(x);
        };
        for (k, &[vx, vz]) in self.vertices.iter().enumerate() {
            let u = dz - vz;
            if u.abs() <= r {
                let half_chord = (r * r - u * u).max(0.0).sqrt();
                take(vx - half_chord);
                take(vx + half_chord);
            }
            let [wx, wz] = self.vertices[(k + 1) % 3];
            let (ex, ez) = (wx - vx, wz - vz);
            let len = ex.hypot(ez);
            // Outward normal of a counter-clockwise polygon's edge.
            let (nx, nz) = (ez / len, -ex / len);
            let (ax, az) = (vx + r * nx, vz + r * nz);
            let (bx, bz) = (wx + r * nx, wz + r * nz);
            if (az - bz).abs() > 0.0 && dz >= az.min(bz) && dz <= az.max(bz) {
                let t = (dz - az) / (bz - az);
                take(ax + t * (bx - ax));
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}

/// One grid row of a footprint at a given pitch: the row `dj` (so
/// `dz = dj * p`), the node offsets `klo..=khi` inside the footprint
/// (possibly empty), the offset `kf = klo - 1` of the first node in front, and
/// that node's slide distance `d0 = a - kf * p`, in `(NODE_TOL, p + NODE_TOL]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootprintRow {
    /// Row offset from the start row (grid rows, +z).
    pub dj: i32,
    /// First node offset (grid columns, +x) inside the footprint.
    pub klo: i32,
    /// Last node offset inside the footprint; `khi < klo` when the row's
    /// interval holds no node.
    pub khi: i32,
    /// Offset of the first node in front, `klo - 1`.
    pub kf: i32,
    /// Distance (mm) the knee-form travels before its front in this row
    /// reaches the first node in front.
    pub d0: f64,
}

/// A footprint laid on a grid of pitch `p`: its rows, plus the order in
/// which the slide meets their first nodes in front (by `d0`, ties grouped).
/// Built from the grid it is laid on ([`GridFootprint::new`] takes the
/// grid's [`GridSpec`]), so its pitch is the grid's.
#[derive(Debug, Clone)]
pub struct GridFootprint {
    /// Angle (degrees) of this footprint.
    pub angle_deg: f64,
    /// The pitch (mm) of the grid it was laid on; the engine and the
    /// harness refuse a footprint of another grid.
    pub pitch: f64,
    /// The cross-section itself, whose outline the surface level samples
    /// (the crate's `surface` module).
    pub shape: Footprint,
    /// Rows sorted by `dj`.
    pub rows: Vec<FootprintRow>,
    /// Indices into `rows`, sorted by `d0` (ties by `dj`).
    pub slide_order: Vec<u32>,
    /// Tie groups as ranges of `slide_order`: consecutive entries whose `d0`
    /// differ by at most `NODE_TOL`.
    pub groups: Vec<std::ops::Range<usize>>,
}

impl GridFootprint {
    /// Lays the footprint of `knee` at `angle_deg` on the grid `spec`.
    pub fn new(knee: &KneeForm, angle_deg: f64, spec: &GridSpec) -> GridFootprint {
        let footprint = Footprint::new(knee, angle_deg);
        let pitch = spec.pitch;
        let (zlo, zhi) = footprint.z_range();
        let dj_lo = ((zlo - NODE_TOL) / pitch).ceil() as i32;
        let dj_hi = ((zhi + NODE_TOL) / pitch).floor() as i32;
        let rows: Vec<FootprintRow> = (dj_lo..=dj_hi)
            .filter_map(|dj| {
                let (a, b) = footprint.row_interval(f64::from(dj) * pitch)?;
                let klo = ((a - NODE_TOL) / pitch).ceil() as i32;
                let khi = ((b + NODE_TOL) / pitch).floor() as i32;
                let kf = klo - 1;
                Some(FootprintRow {
                    dj,
                    klo,
                    khi,
                    kf,
                    d0: a - f64::from(kf) * pitch,
                })
            })
            .collect();
        let mut slide_order: Vec<u32> = (0..rows.len() as u32).collect();
        slide_order.sort_by(|&x, &y| {
            let (rx, ry) = (&rows[x as usize], &rows[y as usize]);
            rx.d0.total_cmp(&ry.d0).then(rx.dj.cmp(&ry.dj))
        });
        let groups = tie_groups(slide_order.iter().map(|&r| rows[r as usize].d0));
        GridFootprint {
            angle_deg,
            pitch,
            shape: footprint,
            rows,
            slide_order,
            groups,
        }
    }

    /// The smallest and largest `dj` of the rows.
    pub fn dj_range(&self) -> (i32, i32) {
        (
            self.rows.first().map_or(0, |r| r.dj),
            self.rows.last().map_or(0, |r| r.dj),
        )
    }

    /// The smallest `klo - 1` and the largest `khi` over rows: how far the
    /// footprint and its first layer reach, in columns.
    pub fn k_range(&self) -> (i32, i32) {
        let lo = self.rows.iter().map(|r| r.kf).min().unwrap_or(0);
        let hi = self.rows.iter().map(|r| r.khi.max(r.kf)).max().unwrap_or(0);
        (lo, hi)
    }
}

/// Splits sorted distances into tie groups: a new group starts where a value
/// exceeds its predecessor by more than [`NODE_TOL`].
pub(crate) fn tie_groups(sorted: impl Iterator<Item = f64>) -> Vec<std::ops::Range<usize>> {
    let mut groups = Vec::new();
    let mut start = 0;
    let mut prev = f64::NAN;
    let mut n = 0;
    for (k, d) in sorted.enumerate() {
        if k > 0 && d - prev > NODE_TOL {
            groups.push(start..k);
            start = k;
        }
        prev = d;
        n = k + 1;
    }
    if n > start {
        groups.push(start..n);
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_corner_at_zero_angle() {
        let fp = Footprint::new(&KneeForm::default(), 0.0);
        let (a, b) = fp.row_interval(0.0).unwrap();
        assert_eq!(a, -60.0);
        assert!((b - (200.0 * 3f64.sqrt() / 2.0 + 60.0)).abs() < 1e-12);
        assert_eq!(fp.z_range(), (-160.0, 160.0));
    }

    #[test]
    fn rows_on_exact_pitch_include_boundary_nodes() {
        // a(0) = -60 is a multiple of 1, 2 and 4 mm: that node is inside.
        for p in [1.0, 2.0, 4.0] {
            let spec = GridSpec::explicit(0.0, 0.0, 1, 1, p);
            let fp = GridFootprint::new(&KneeForm::default(), 0.0, &spec);
            let row = fp.rows.iter().find(|r| r.dj == 0).unwrap();
            assert_eq!(f64::from(row.klo) * p, -60.0);
            assert_eq!(row.d0, p);
            assert_eq!(fp.dj_range(), ((-160.0 / p) as i32, (160.0 / p) as i32));
        }
    }

    #[test]
    fn tie_groups_split_on_gaps() {
        let g = tie_groups([0.5, 0.5 + 1e-10, 0.7, 0.9, 0.9].into_iter());
        assert_eq!(g, vec![0..2, 2..3, 3..5]);
        assert!(tie_groups(std::iter::empty()).is_empty());
    }
}
