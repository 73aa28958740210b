//! The knee-form as an exact parry3d support-map shape.
//!
//! SPEC's knee-form is `K = T (+) D_R` in the xz-plane (an equilateral
//! triangle grown by a disc of radius `R`), extruded along y over
//! `[f - W, f]`. Its support function is exact and cheap: the triangle's
//! support vertex, plus `R` along the xz part of the query direction, plus
//! the face (`y = f`) or the back (`y = f - W`) by the sign of its y part.
//! So the oracle hands parry the exact rounded prism, never a tessellation.
//!
//! Local frame of [`KneeForm`]: the origin is the reference point `v0` on
//! the face, so the shape spans local y in `[-W, 0]`; a pose that translates
//! it by `(x, f, z)` puts the reference point at `(x, z)` and the face at
//! level `f`, in the analysis frame.

use parry3d_f64::bounding_volume::{Aabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Pose, Real, Vector};
use parry3d_f64::query::details::{
    local_point_projection_on_support_map, local_ray_intersection_with_support_map_with_params,
};
use parry3d_f64::query::gjk::VoronoiSimplex;
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::{FeatureId, Shape, ShapeType, SupportMap, TypedShape};
use serde::{Deserialize, Serialize};

/// Dimensions of the knee-form, in mm (SPEC, "The knee-form").
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KneeFormDims {
    /// `L`: side of the equilateral triangle `T`, mm. SPEC's default 200 mm
    /// is an assumption (the regulation's figure was not at hand).
    pub length: f64,
    /// `R`: radius of the disc the triangle is grown by, mm.
    pub radius: f64,
    /// `W`: extrusion width along y, mm.
    pub width: f64,
}

impl Default for KneeFormDims {
    /// `L = 200`, `R = 60`, `W = 120` mm, as SPEC.
    fn default() -> Self {
        Self {
            length: 200.0,
            radius: 60.0,
            width: 120.0,
        }
    }
}

impl KneeFormDims {
    /// Whether every dimension is finite and `L, R, W > 0`.
    pub fn is_valid(&self) -> bool {
        [self.length, self.radius, self.width]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    }
}

/// The knee-form at one angle: the exact rounded prism as a parry3d shape.
///
/// Implements [`SupportMap`], [`RayCast`], [`PointQuery`] and [`Shape`]
/// (as [`ShapeType::Custom`]), so parry's default query dispatcher casts it
/// against a `TriMesh` like any built-in convex shape.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct KneeForm {
    dims: KneeFormDims,
    angle_deg: f64,
    /// `v0, v1, v2` rotated by the angle, as (x, z) relative to `v0`, mm.
    triangle: [[f64; 2]; 3],
    /// Per end ([`End::Left`], [`End::Right`]), what [`KneeForm::x_at`]
    /// reads, computed once: the BVH traversal asks for the footprint's
    /// ends at every node it visits.
    outlines: [Outline; 2],
    /// The footprint's z-range (relative), computed once.
    z_span: (f64, f64),
    /// Per end, the height (relative z) of the triangle's vertex furthest
    /// that way in x: where the footprint's end is extreme.
    apex_z: [f64; 2],
}

/// The footprint mirrored in x so that one of its ends is its left end:
/// the triangle's vertices (centres of the end discs) and, per edge, its
/// two segments offset by `R` along the edge's normals.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Outline {
    vertices: [[f64; 2]; 3],
    /// Per edge `k` (from vertex `k` to `k + 1`), the offset segments on
    /// its two sides, each as its two ends.
    segments: [[[[f64; 2]; 2]; 2]; 3],
}

impl Outline {
    /// The outline of `triangle` rounded by `r`, mirrored by `sign` in x.
    fn new(triangle: [[f64; 2]; 3], r: f64, sign: f64) -> Outline {
        let t = triangle.map(|[x, zz]| [sign * x, zz]);
        let segments = [0, 1, 2].map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let len = e[0].hypot(e[1]);
            [1.0, -1.0].map(|side| {
                let n = [side * e[1] / len, -side * e[0] / len];
                [
                    [a[0] + r * n[0], a[1] + r * n[1]],
                    [b[0] + r * n[0], b[1] + r * n[1]],
                ]
            })
        });
        Outline {
            vertices: t,
            segments,
        }
    }
}

impl KneeForm {
    /// The knee-form with `dims` at `angle_deg` degrees: SPEC's rotation
    /// `(x, z) -> (x cos t - z sin t, x sin t + z cos t)` about `v0`;
    /// positive angles raise the back.
    pub fn new(dims: KneeFormDims, angle_deg: f64) -> Self {
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        let half_height = dims.length * 3f64.sqrt() / 2.0;
        let unrotated = [
            [0.0, 0.0],
            [half_height, dims.length / 2.0],
            [half_height, -dims.length / 2.0],
        ];
        let triangle = unrotated.map(|[x, z]| [x * cos - z * sin, x * sin + z * cos]);
        let apex = |dir: f64| {
            triangle
                .iter()
                .max_by(|p, q| (dir * p[0]).total_cmp(&(dir * q[0])))
                .map_or(0.0, |v| v[1])
        };
        let mut knee = Self {
            dims,
            angle_deg,
            triangle,
            outlines: [1.0, -1.0].map(|sign| Outline::new(triangle, dims.radius, sign)),
            z_span: (0.0, 0.0),
            apex_z: [apex(-1.0), apex(1.0)],
        };
        let (min, max) = knee.xz_extent();
        knee.z_span = (min[1], max[1]);
        knee
    }

    /// The dimensions this knee-form was built with.
    pub fn dims(&self) -> KneeFormDims {
        self.dims
    }

    /// The angle in degrees.
    pub fn angle_deg(&self) -> f64 {
        self.angle_deg
    }

    /// The rotated triangle `v0, v1, v2` as (x, z) offsets from the
    /// reference point, mm (`v0` is always `(0, 0)`).
    pub fn triangle(&self) -> [[f64; 2]; 3] {
        self.triangle
    }

    /// The pose that puts the reference point at `(x, z)` = `reference` and
    /// the face at level `face_level` (mm, analysis frame).
    pub fn pose(reference: [f64; 2], face_level: f64) -> Pose {
        Pose::from_translation(Vector::new(reference[0], face_level, reference[1]))
    }

    /// The footprint's extent in x relative to the reference point,
    /// `(min, max)` in mm.
    pub fn x_extent(&self) -> (f64, f64) {
        let xs = self.triangle.map(|v| v[0]);
        let min = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let max = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (min - self.dims.radius, max + self.dims.radius)
    }

    fn xz_extent(&self) -> ([f64; 2], [f64; 2]) {
        let mut min = [f64::INFINITY; 2];
        let mut max = [f64::NEG_INFINITY; 2];
        for v in self.triangle {
            for k in 0..2 {
                min[k] = min[k].min(v[k] - self.dims.radius);
                max[k] = max[k].max(v[k] + self.dims.radius);
            }
        }
        (min, max)
    }

    /// The triangle's support in xz plus the disc's, i.e. `T (+) D_R`.
    fn xz_support(&self, dx: f64, dz: f64) -> [f64; 2] {
        let mut best = self.triangle[0];
        let mut best_dot = f64::NEG_INFINITY;
        for v in self.triangle {
            let dot = v[0] * dx + v[1] * dz;
            if dot > best_dot {
                best_dot = dot;
                best = v;
            }
        }
        let norm = dx.hypot(dz);
        if norm > 0.0 {
            let r = self.dims.radius / norm;
            [best[0] + r * dx, best[1] + r * dz]
        } else {
            best
        }
    }
}

/// Which end of a horizontal line through the footprint.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum End {
    /// The -x end (the leading edge of a slide).
    Left,
    /// The +x end.
    Right,
}

impl KneeForm {
    /// The footprint's z-range relative to the reference point, mm.
    pub(crate) fn z_range(&self) -> (f64, f64) {
        self.z_span
    }

    /// Where the line at height `z` (relative to the reference point)
    /// leaves the footprint at `end`, or `None` outside its z-range.
    ///
    /// `T (+) D_R` is the union of the three capsules `edge (+) D_R`; a
    /// capsule's end on the line lies on one of its two offset segments
    /// or on one of its end discs, so the extreme of those candidates is
    /// exact.
    pub(crate) fn x_at(&self, z: f64, end: End) -> Option<f64> {
        let (sign, outline) = match end {
            End::Left => (1.0, &self.outlines[0]),
            End::Right => (-1.0, &self.outlines[1]),
        };
        let r = self.dims.radius;
        // On the shape mirrored in x for the right end: its left end.
        let t = &outline.vertices;
        let mut best = f64::INFINITY;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            for v in [a, b] {
                let dz = z - v[1];
                if dz.abs() <= r {
                    best = best.min(v[0] - (r * r - dz * dz).sqrt());
                }
            }
            for [a_off, b_off] in outline.segments[k] {
                let dz = b_off[1] - a_off[1];
                if dz != 0.0 {
                    let u = (z - a_off[1]) / dz;
                    if (0.0..=1.0).contains(&u) {
                        best = best.min(a_off[0] + u * (b_off[0] - a_off[0]));
                    }
                }
            }
        }
        best.is_finite().then_some(sign * best)
    }

    /// The extreme of [`KneeForm::x_at`] over the heights `[za, zb]`
    /// (relative, clipped to the footprint): the smallest left end or the
    /// largest right end; `None` when the interval misses the footprint.
    /// The left end is convex in z and the right end concave, so the
    /// extreme is at the footprint's extreme point clamped to the interval.
    pub(crate) fn extreme_x(&self, za: f64, zb: f64, end: End) -> Option<f64> {
        let (lo, hi) = self.z_range();
        let (za, zb) = (za.max(lo), zb.min(hi));
        if za > zb {
            return None;
        }
        // The extreme point in x is a vertex's (the disc adds R along x).
        let apex = match end {
            End::Left => self.apex_z[0],
            End::Right => self.apex_z[1],
        };
        self.x_at(apex.clamp(za, zb), end)
    }
}

impl SupportMap for KneeForm {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let [x, z] = self.xz_support(dir.x, dir.z);
        // A direction with no y part is supported by the whole side wall;
        // its middle keeps GJK's simplex away from the face and back edges.
        let y = if dir.y > 0.0 {
            0.0
        } else if dir.y < 0.0 {
            -self.dims.width
        } else {
            -self.dims.width / 2.0
        };
        Vector::new(x, y, z)
    }
}

/// The knee-form swept along a straight segment: `K (+) [0, sweep]`.
///
/// Used to confirm that a cast which reported no hit really missed: parry's
/// GJK ray cast returns `None` both for a miss and when it runs out of
/// iterations, and a start must never be counted as clear on a failure.
#[derive(Copy, Clone, Debug)]
pub(crate) struct SweptKneeForm {
    pub(crate) knee: KneeForm,
    pub(crate) sweep: Vector,
}

impl SupportMap for SweptKneeForm {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let base = self.knee.local_support_point(dir);
        if self.sweep.dot(dir) > 0.0 {
            base + self.sweep
        } else {
            base
        }
    }
}

impl KneeForm {
    fn local_aabb_impl(&self) -> Aabb {
        let (min, max) = self.xz_extent();
        Aabb::new(
            Vector::new(min[0], -self.dims.width, min[1]),
            Vector::new(max[0], 0.0, max[1]),
        )
    }
}

impl SweptKneeForm {
    fn local_aabb_impl(&self) -> Aabb {
        let aabb = self.knee.local_aabb_impl();
        Aabb::new(
            aabb.mins.min(aabb.mins + self.sweep),
            aabb.maxs.max(aabb.maxs + self.sweep),
        )
    }
}

/// Implements parry's ray cast, point query and `Shape` for a support-map
/// shape through the generic GJK helpers, as parry does for its own convex
/// shapes. Mass properties are those of the bounding box: the oracle never
/// simulates dynamics, and rapier's kinematic controller does not read them.
macro_rules! support_map_shape {
    ($shape:ty) => {
        impl RayCast for $shape {
            fn cast_local_ray_and_get_normal(
                &self,
                ray: &Ray,
                max_time_of_impact: Real,
                solid: bool,
            ) -> Option<RayIntersection> {
                local_ray_intersection_with_support_map_with_params(
                    self,
                    &mut VoronoiSimplex::new(),
                    ray,
                    max_time_of_impact,
                    solid,
                )
            }
        }

        impl PointQuery for $shape {
            fn project_local_point(&self, point: Vector, solid: bool) -> PointProjection {
                local_point_projection_on_support_map(
                    self,
                    &mut VoronoiSimplex::new(),
                    point,
                    solid,
                )
            }

            fn project_local_point_and_get_feature(
                &self,
                point: Vector,
            ) -> (PointProjection, FeatureId) {
                (self.project_local_point(point, false), FeatureId::Unknown)
            }
        }

        impl Shape for $shape {
            fn compute_local_aabb(&self) -> Aabb {
                self.local_aabb_impl()
            }

            fn compute_local_bounding_sphere(&self) -> BoundingSphere {
                let aabb = self.local_aabb_impl();
                BoundingSphere::new(aabb.center(), aabb.half_extents().length())
            }

            fn clone_dyn(&self) -> Box<dyn Shape> {
                Box::new(*self)
            }

            fn scale_dyn(&self, _scale: Vector, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
                None
            }

            fn mass_properties(&self, density: Real) -> MassProperties {
                let aabb = self.local_aabb_impl();
                MassProperties::from_cuboid(density, aabb.half_extents())
                    .transform_by(&Pose::from_translation(aabb.center()))
            }

            fn shape_type(&self) -> ShapeType {
                ShapeType::Custom
            }

            fn as_typed_shape(&self) -> TypedShape<'_> {
                TypedShape::Custom(self)
            }

            fn ccd_thickness(&self) -> Real {
                self.local_aabb_impl().half_extents().min_element()
            }

            fn ccd_angular_thickness(&self) -> Real {
                core::f64::consts::FRAC_PI_2
            }

            fn is_convex(&self) -> bool {
                true
            }

            fn as_support_map(&self) -> Option<&dyn SupportMap> {
                Some(self as &dyn SupportMap)
            }
        }
    };
}

support_map_shape!(KneeForm);
support_map_shape!(SweptKneeForm);

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from `p` to the closed triangle `t` in the plane.
    fn distance_to_triangle(p: [f64; 2], t: [[f64; 2]; 3]) -> f64 {
        let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let signs = [
            cross(t[0], t[1], p),
            cross(t[1], t[2], p),
            cross(t[2], t[0], p),
        ];
        if signs.iter().all(|s| *s >= 0.0) || signs.iter().all(|s| *s <= 0.0) {
            return 0.0;
        }
        (0..3)
            .map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let ab = [b[0] - a[0], b[1] - a[1]];
                let ap = [p[0] - a[0], p[1] - a[1]];
                let u = ((ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1]))
                    .clamp(0.0, 1.0);
                (ap[0] - u * ab[0]).hypot(ap[1] - u * ab[1])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Dense samples of the boundary of `T (+) D_R`, built from SPEC's
    /// vertex formulas directly (not from `KneeForm`'s rotated triangle).
    fn analytic_boundary(dims: KneeFormDims, angle_deg: f64) -> Vec<[f64; 2]> {
        let (s, c) = angle_deg.to_radians().sin_cos();
        let h = dims.length * 3f64.sqrt() / 2.0;
        let t = [[0.0, 0.0], [h, dims.length / 2.0], [h, -dims.length / 2.0]]
            .map(|[x, z]| [x * c - z * s, x * s + z * c]);
        let mut out = Vec::new();
        // Every point at distance R from T in a fine polar sweep around each
        // vertex, kept when its nearest point on T is that vertex's region:
        // simply keep all circle points whose distance to T is R.
        for v in t {
            for k in 0..20_000 {
                let phi = k as f64 / 20_000.0 * std::f64::consts::TAU;
                let p = [
                    v[0] + dims.radius * phi.cos(),
                    v[1] + dims.radius * phi.sin(),
                ];
                if (distance_to_triangle(p, t) - dims.radius).abs() < 1e-9 {
                    out.push(p);
                }
            }
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let len = e[0].hypot(e[1]);
            // Outward normal: the triangle is counter-clockwise in (x, z)
            // only for some orderings, so pick the side away from the centroid.
            let centroid = [
                (t[0][0] + t[1][0] + t[2][0]) / 3.0,
                (t[0][1] + t[1][1] + t[2][1]) / 3.0,
            ];
            let mut n = [e[1] / len, -e[0] / len];
            if (a[0] - centroid[0]) * n[0] + (a[1] - centroid[1]) * n[1] < 0.0 {
                n = [-n[0], -n[1]];
            }
            for i in 0..=2000 {
                let u = i as f64 / 2000.0;
                out.push([
                    a[0] + u * e[0] + dims.radius * n[0],
                    a[1] + u * e[1] + dims.radius * n[1],
                ]);
            }
        }
        out
    }

    #[test]
    fn support_points_lie_on_the_analytic_rounded_triangle_and_are_extreme() {
        let dims = KneeFormDims::default();
        for angle in [-30.0, -17.0, 0.0, 12.5, 30.0] {
            let knee = KneeForm::new(dims, angle);
            let boundary = analytic_boundary(dims, angle);
            for k in 0..360 {
                let phi = (k as f64 + 0.37).to_radians();
                for dy in [-0.7, 0.0, 0.4] {
                    let dir = Vector::new(phi.cos(), dy, phi.sin());
                    let p = knee.local_support_point(dir);
                    // On the boundary of T (+) D_R ...
                    let d = distance_to_triangle([p.x, p.z], knee.triangle());
                    assert!(
                        (d - dims.radius).abs() < 1e-9,
                        "angle {angle} dir {dir:?}: {d}"
                    );
                    // ... at the face or the back as the y part says ...
                    let want_y = if dy > 0.0 {
                        0.0
                    } else if dy < 0.0 {
                        -dims.width
                    } else {
                        p.y
                    };
                    assert_eq!(p.y, want_y);
                    assert!((-dims.width..=0.0).contains(&p.y));
                    // ... and no sample of the analytic boundary is further
                    // along the direction (sampling step 2*pi*R/20000 < 0.02 mm).
                    let support = p.x * dir.x + p.z * dir.z;
                    let best = boundary
                        .iter()
                        .map(|q| q[0] * dir.x + q[1] * dir.z)
                        .fold(f64::NEG_INFINITY, f64::max);
                    assert!(best <= support + 1e-9, "angle {angle}: {best} > {support}");
                    assert!(best >= support - 1e-3, "angle {angle}: {best} << {support}");
                }
            }
        }
    }

    #[test]
    fn left_and_right_ends_agree_with_the_distance_to_the_triangle() {
        let dims = KneeFormDims::default();
        for angle in [-30.0, -7.0, 0.0, 25.0, 30.0] {
            let knee = KneeForm::new(dims, angle);
            let (lo, hi) = knee.z_range();
            assert_eq!(knee.x_at(lo - 0.1, End::Left), None);
            for k in 1..400 {
                let z = lo + (hi - lo) * k as f64 / 400.0;
                let left = knee.x_at(z, End::Left).unwrap();
                let right = knee.x_at(z, End::Right).unwrap();
                assert!(left <= right);
                // Both ends are on the boundary of T (+) D_R ...
                for x in [left, right] {
                    let d = distance_to_triangle([x, z], knee.triangle());
                    assert!((d - dims.radius).abs() < 1e-9, "angle {angle} z {z}: {d}");
                }
                // ... and just outside them is outside the shape.
                assert!(distance_to_triangle([left - 1e-6, z], knee.triangle()) > dims.radius);
                assert!(distance_to_triangle([right + 1e-6, z], knee.triangle()) > dims.radius);
                // The interval extremes bound every height inside.
                let (za, zb) = (z - 7.0, z + 3.0);
                let min_left = knee.extreme_x(za, zb, End::Left).unwrap();
                let max_right = knee.extreme_x(za, zb, End::Right).unwrap();
                for i in 0..=20 {
                    let zi = za + (zb - za) * i as f64 / 20.0;
                    if let Some(x) = knee.x_at(zi, End::Left) {
                        assert!(min_left <= x + 1e-9);
                    }
                    if let Some(x) = knee.x_at(zi, End::Right) {
                        assert!(max_right >= x - 1e-9);
                    }
                }
            }
        }
    }

    #[test]
    fn rotation_follows_spec_and_keeps_v0_at_the_reference_point() {
        let dims = KneeFormDims::default();
        let knee = KneeForm::new(dims, 30.0);
        let [v0, v1, v2] = knee.triangle();
        assert_eq!(v0, [0.0, 0.0]);
        let h = 200.0 * 3f64.sqrt() / 2.0;
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!((v1[0] - (h * c - 100.0 * s)).abs() < 1e-12);
        assert!((v1[1] - (h * s + 100.0 * c)).abs() < 1e-12);
        assert!((v2[0] - (h * c + 100.0 * s)).abs() < 1e-12);
        assert!((v2[1] - (h * s - 100.0 * c)).abs() < 1e-12);
        // Positive angles raise the back: the back vertices' mean z is up.
        assert!(v1[1] + v2[1] > 0.0);
        // The front point of the footprint is v0 - (R, 0) for |angle| <= 30.
        assert_eq!(knee.x_extent().0, -dims.radius);
    }
}
