//! A small CPU renderer for the report's views of the part: orthographic,
//! z-buffered, Lambert-shaded triangles, then painted per pixel.
//!
//! Rendering is two passes. [`rasterize`] keeps, per pixel, the depth of the
//! nearest triangle and its shade (a deferred "G-buffer"); [`paint`] then
//! colours each covered pixel from the surface point under it, which an
//! orthographic camera gives back exactly from the pixel and its depth
//! ([`View::surface_point`]). So the painting (which nodes collide) never
//! depends on the triangle order or on the shading.
//!
//! The rasterizer is the crate's one z-buffer (`zbuffer.rs`), on a
//! lattice of pixel centres. A pixel is covered when its centre is inside
//! a triangle (closed, within 1e-9 of its barycentric weights).

use nalgebra::Vector3;
use rayon::prelude::*;

use crate::mesh::Triangle;
use crate::zbuffer::{Lattice, Weighting, zbuffer};

/// A pixel centre within this of a barycentric weight of 0 is on the edge:
/// shared edges are then covered by both of their triangles, never by none
/// (rounding of two edge functions can disagree by about 1e-16).
const EDGE_TOL: f64 = 1e-9;

/// Light that reaches every surface, as a fraction of full brightness: faces
/// seen edge-on stay readable, and a painted face never turns black.
const AMBIENT: f64 = 0.35;

/// An 8-bit sRGB colour.
pub(crate) type Rgb = [u8; 3];

/// An orthographic camera: an orthonormal right-handed basis `right`, `up`,
/// `forward` (the direction of view), all in the part's frame (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Camera {
    /// Screen x grows along this.
    pub right: Vector3<f64>,
    /// Screen rows grow against this (row 0 is the top).
    pub up: Vector3<f64>,
    /// The direction the camera looks in; smaller `p . forward` is nearer.
    pub forward: Vector3<f64>,
}

impl Camera {
    /// The camera looking along `forward` with `up_hint` projected to be
    /// the screen's up (the two must not be parallel).
    pub fn looking(forward: Vector3<f64>, up_hint: Vector3<f64>) -> Camera {
        let f = forward.normalize();
        let right = f.cross(&up_hint).normalize();
        let up = right.cross(&f);
        Camera {
            right,
            up,
            forward: f,
        }
    }
}

/// Where the image lies in the camera's plane: pixel `(c, r)` (column from
/// the left, row from the top) has its centre at
/// `u = u_left + (c + 0.5) * mm_per_px` along [`Camera::right`] and
/// `v = v_top - (r + 0.5) * mm_per_px` along [`Camera::up`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct View {
    /// The camera.
    pub camera: Camera,
    /// `u` of the image's left edge (mm).
    pub u_left: f64,
    /// `v` of the image's top edge (mm).
    pub v_top: f64,
    /// Size of a pixel (mm).
    pub mm_per_px: f64,
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
}

impl View {
    /// The sign of the face-on view's horizontal axis: the picture's
    /// column coordinate grows with `sign` times the horizontal coordinate
    /// (x for push-and-slide, y for the direct approach), mirrored when the
    /// camera looks from the other side.
    pub fn horizontal_sign(&self) -> f64 {
        if self.camera.right[0] + self.camera.right[1] < 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    /// The view that fits `triangles` into `width` pixels (less `margin` on
    /// each side), as tall as the part needs plus the same margin.
    pub fn fit(camera: Camera, triangles: &[Triangle], width: usize, margin: usize) -> View {
        let (mut u_lo, mut u_hi, mut v_lo, mut v_hi) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in triangles.iter().flatten().map(|&p| Vector3::from(p)) {
            let (u, v) = (p.dot(&camera.right), p.dot(&camera.up));
            u_lo = u_lo.min(u);
            u_hi = u_hi.max(u);
            v_lo = v_lo.min(v);
            v_hi = v_hi.max(v);
        }
        if u_lo > u_hi {
            (u_lo, u_hi, v_lo, v_hi) = (0.0, 1.0, 0.0, 1.0);
        }
        let inner = width.saturating_sub(2 * margin).max(1) as f64;
        let mm_per_px = ((u_hi - u_lo) / inner).max(1e-9);
        let height = ((v_hi - v_lo) / mm_per_px).ceil() as usize + 2 * margin;
        View {
            camera,
            u_left: u_lo - margin as f64 * mm_per_px,
            v_top: v_hi + margin as f64 * mm_per_px,
            mm_per_px,
            width: width.max(1),
            height: height.max(1),
        }
    }

    /// The camera-plane coordinates `(u, v)` (mm) of the centre of pixel
    /// `(c, r)`.
    pub fn pixel_centre(&self, c: usize, r: usize) -> (f64, f64) {
        (
            self.u_left + (c as f64 + 0.5) * self.mm_per_px,
            self.v_top - (r as f64 + 0.5) * self.mm_per_px,
        )
    }

    /// The point (part frame, mm) seen at the centre of pixel `(c, r)` at
    /// `depth` along [`Camera::forward`]. For a camera whose `right` is
    /// `(±1, 0, 0)` and `up` `(0, 0, 1)` (the side views) this is exactly
    /// `x = ±u`, `z = v` of [`View::pixel_centre`].
    pub fn surface_point(&self, c: usize, r: usize, depth: f64) -> [f64; 3] {
        let (u, v) = self.pixel_centre(c, r);
        let cam = &self.camera;
        (cam.right * u + cam.up * v + cam.forward * depth).into()
    }
}

/// The rasterized part: per pixel (row-major from the top) the depth of the
/// nearest surface (`+inf` where none) and its Lambert shade in
/// `[AMBIENT, 1]`.
#[derive(Debug, Clone)]
pub(crate) struct DepthImage {
    /// The view it was rendered for.
    pub view: View,
    /// Depth along the camera's forward axis (mm).
    pub depth: Vec<f64>,
    /// Brightness of the surface, 1 when it faces the light.
    pub shade: Vec<f32>,
}

impl DepthImage {
    /// Whether pixel `(c, r)` shows the part.
    #[cfg(test)]
    pub fn covered(&self, c: usize, r: usize) -> bool {
        self.depth[r * self.view.width + c].is_finite()
    }
}

/// Z-buffers `triangles` (part frame, mm) into `view`, shading each by the
/// angle between its normal and a light above the camera (two-sided: an STL
/// may wind its triangles either way).
pub(crate) fn rasterize(triangles: &[Triangle], view: &View) -> DepthImage {
    let cam = view.camera;
    let light = (-cam.forward + cam.up * 0.4 - cam.right * 0.2).normalize();
    // Screen coordinates: (column, row, depth), pixel centres at k + 0.5.
    let screen: Vec<([[f64; 3]; 3], f32)> = triangles
        .par_iter()
        .map(|t| {
            let t = t.map(Vector3::from);
            let s = t.map(|p| {
                [
                    (p.dot(&cam.right) - view.u_left) / view.mm_per_px,
                    (view.v_top - p.dot(&cam.up)) / view.mm_per_px,
                    p.dot(&cam.forward),
                ]
            });
            let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
            let len = n.norm();
            let lambert = if len > 0.0 {
                (n.dot(&light) / len).abs()
            } else {
                0.0
            };
            (s, (AMBIENT + (1.0 - AMBIENT) * lambert) as f32)
        })
        .collect();
    let buffer = zbuffer(view, &screen, |&(s, lit)| (s, lit));
    DepthImage {
        view: *view,
        depth: buffer.depth,
        shade: buffer.tag,
    }
}

/// The pixels of a view as a z-buffer lattice: pixel centres at `k + 0.5`,
/// edges within [`EDGE_TOL`], and triangles seen edge-on skipped.
impl Lattice for View {
    const WEIGHTING: Weighting = Weighting::MultiplyByInverse;

    fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    fn x(&self, c: usize) -> f64 {
        c as f64 + 0.5
    }

    fn y(&self, r: usize) -> f64 {
        r as f64 + 0.5
    }

    fn columns(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        centres_within(self.width, lo, hi)
    }

    fn rows(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        centres_within(self.height, lo, hi)
    }

    fn degenerate(&self, area2: f64) -> bool {
        area2.abs() < 1e-12
    }

    fn slack(&self, _: &[[[f64; 2]; 2]; 3], _: f64) -> [f64; 3] {
        [-EDGE_TOL; 3]
    }
}

/// The pixels `k` of `0..n` whose centre `k + 0.5` lies in `[lo, hi]`.
fn centres_within(n: usize, lo: f64, hi: f64) -> Option<(usize, usize)> {
    let k_lo = (lo - 0.5).ceil().max(0.0);
    let k_hi = (hi - 0.5).floor().min(n as f64 - 1.0);
    (k_lo <= k_hi).then_some((k_lo as usize, k_hi as usize))
}

/// An RGB image, row-major from the top, 3 bytes per pixel.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RgbImage {
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
    /// `3 * width * height` bytes.
    pub pixels: Vec<u8>,
}

impl RgbImage {
    /// The colour of pixel `(c, r)`.
    #[cfg(test)]
    pub fn at(&self, c: usize, r: usize) -> Rgb {
        let k = 3 * (r * self.width + c);
        [self.pixels[k], self.pixels[k + 1], self.pixels[k + 2]]
    }
}

/// Colour of the background (no part under the pixel).
pub(crate) const BACKGROUND: Rgb = [255, 255, 255];
/// Colour of the part where nothing is painted, before shading: a neutral
/// grey (equal channels) so any painted colour stands out.
pub(crate) const PART_GREY: Rgb = [205, 205, 205];

/// Colours every covered pixel: `paint(surface point)` when it returns a
/// colour, else [`PART_GREY`], either times the pixel's shade; uncovered
/// pixels are [`BACKGROUND`].
pub(crate) fn paint(
    image: &DepthImage,
    paint: impl Fn([f64; 3]) -> Option<Rgb> + Sync,
) -> RgbImage {
    let view = &image.view;
    let w = view.width;
    let mut pixels = vec![0u8; 3 * w * view.height];
    pixels
        .par_chunks_mut(3 * w)
        .enumerate()
        .for_each(|(r, row)| {
            for c in 0..w {
                let k = r * w + c;
                let d = image.depth[k];
                let rgb = if d.is_finite() {
                    let base = paint(view.surface_point(c, r, d)).unwrap_or(PART_GREY);
                    let s = image.shade[k];
                    base.map(|v| (f32::from(v) * s).round() as u8)
                } else {
                    BACKGROUND
                };
                row[3 * c..3 * c + 3].copy_from_slice(&rgb);
            }
        });
    RgbImage {
        width: w,
        height: view.height,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 100 x 50 mm rectangle in the plane y = `y`, two triangles.
    fn rectangle(y: f64) -> Vec<Triangle> {
        let (a, b, c, d) = (
            [0.0, y, 0.0],
            [100.0, y, 0.0],
            [100.0, y, 50.0],
            [0.0, y, 50.0],
        );
        vec![[a, b, c], [a, c, d]]
    }

    #[test]
    fn a_rectangle_seen_face_on_covers_exactly_its_pixels() {
        let tris = rectangle(0.0);
        let cam = Camera::looking(Vector3::y(), Vector3::z());
        assert_eq!(cam.right, Vector3::x());
        let view = View::fit(cam, &tris, 120, 10);
        // 100 mm over 100 pixels: 1 mm per pixel, 50 rows plus margins.
        assert_eq!(view.mm_per_px, 1.0);
        assert_eq!((view.width, view.height), (120, 70));
        let img = rasterize(&tris, &view);
        let covered = (0..view.height)
            .flat_map(|r| (0..view.width).map(move |c| (c, r)))
            .filter(|&(c, r)| img.covered(c, r))
            .count();
        assert_eq!(covered, 100 * 50);
        // Facing the camera, lit from just above it: nearly full brightness.
        assert!(img.shade[30 * 120 + 60] > 0.9);
        // The pixel (10, 10) is the corner (0, 50) of the rectangle.
        assert_eq!(view.surface_point(10, 10, 0.0), [0.5, 0.0, 49.5]);
    }

    #[test]
    fn the_nearer_surface_wins_whatever_the_order() {
        let mut tris = rectangle(5.0);
        tris.extend(rectangle(-5.0));
        let cam = Camera::looking(Vector3::y(), Vector3::z());
        let view = View::fit(cam, &tris, 100, 0);
        let img = rasterize(&tris, &view);
        tris.reverse();
        let again = rasterize(&tris, &view);
        assert!(
            img.depth
                .iter()
                .all(|&d| (d + 5.0).abs() < 1e-9 || d.is_infinite())
        );
        assert_eq!(img.depth, again.depth);
        // Seen from +y, the other one is in front.
        let back = Camera::looking(-Vector3::y(), Vector3::z());
        assert_eq!(back.right, -Vector3::x());
        let view = View::fit(back, &tris, 100, 0);
        let img = rasterize(&tris, &view);
        // Depth along -y: y = 5 is at depth -5 (interpolated: to rounding).
        assert!(
            img.depth
                .iter()
                .all(|&d| (d + 5.0).abs() < 1e-9 || d.is_infinite())
        );
        let p = view.surface_point(0, 0, img.depth[0]);
        assert_eq!(p[0], 99.5);
        assert!((p[1] - 5.0).abs() < 1e-9);
    }

    #[test]
    fn paint_colours_the_surface_point_under_each_pixel() {
        let tris = rectangle(0.0);
        let cam = Camera::looking(Vector3::y(), Vector3::z());
        let view = View::fit(cam, &tris, 100, 0);
        let img = rasterize(&tris, &view);
        let red = paint(&img, |p| (p[0] < 30.0).then_some([250, 0, 0]));
        for (c, r) in [(0, 0), (29, 49), (30, 0), (99, 20)] {
            let [cr, cg, cb] = red.at(c, r);
            assert_eq!(cr > 0 && cg == 0 && cb == 0, c < 30, "{c},{r}");
            if c >= 30 {
                assert!(cr == cg && cg == cb && cr > 100);
            }
        }
        assert_eq!(red.pixels.len(), 3 * 100 * 50);
    }

    #[test]
    fn shared_edges_leave_no_crack() {
        // A fan of thin triangles around a centre: every interior pixel is
        // covered by at least one of them.
        let n = 97;
        let tris: Vec<Triangle> = (0..n)
            .map(|k| {
                let a = |k: usize| {
                    let t = k as f64 * std::f64::consts::TAU / n as f64;
                    [50.0 * t.cos(), 0.0, 50.0 * t.sin()]
                };
                [[0.0, 0.0, 0.0], a(k), a(k + 1)]
            })
            .collect();
        let cam = Camera::looking(Vector3::y(), Vector3::z());
        let view = View::fit(cam, &tris, 211, 0);
        let img = rasterize(&tris, &view);
        for r in 0..view.height {
            for c in 0..view.width {
                let p = view.surface_point(c, r, 0.0);
                if p[0].hypot(p[2]) < 49.0 {
                    assert!(img.covered(c, r), "crack at {c},{r}");
                }
            }
        }
    }
}
