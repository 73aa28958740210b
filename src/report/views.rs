//! The report's pictures of the part: the analysed side seen face on and an
//! oblique view, painted with the composite (colour by number of angles, the
//! paper's Figure 13), and small multiples of single angles (its Figure 12).
//!
//! The side view looks at the analysed surface along the knee's push: from
//! -y towards +y for the left side, from +y towards -y for the right side
//! (both in the part's own frame, so the right side is not mirrored: its
//! vehicle front, -x, is on the right of the picture). Its pixel ↔ (x, z)
//! mapping is [`View::pixel_centre`] with `x = ±u`, `z = v`.
//!
//! A pixel is painted when the surface point under it lies within half a
//! pitch, in x and in z, of a colliding node ([`NodeCounts::at`]); in the
//! oblique view the point must also lie within [`OBLIQUE_Y_TOL_PITCHES`]
//! pitches of the node's y, so faces that only share the node's x and z
//! (the top of a console seen from above) stay grey.

use nalgebra::Vector3;

use crate::frame::Approach;
use crate::frame::Side;
use crate::mesh::Triangle;
use crate::output::count_colour;

use super::render::{Camera, Rgb, RgbImage, View, paint, rasterize};
use super::run::{GridAxes, NodeCounts, Run};

/// Width of the large views (pixels): sharp on a printed A4 page.
pub(crate) const LARGE_WIDTH: usize = 1100;
/// Width of each small multiple (pixels).
pub(crate) const SMALL_WIDTH: usize = 560;
/// Empty border around the part (pixels).
const MARGIN: usize = 8;
/// Colour of a single angle's colliding area in the small multiples: a red
/// that no grey shade of the part can take.
pub(crate) const ANGLE_COLOUR: Rgb = [215, 48, 39];
/// In the oblique view, a surface point is painted only within this many
/// pitches of its node's y: enough for the slope across a cell of any face
/// the knee can strike, far less than a console's depth.
pub(crate) const OBLIQUE_Y_TOL_PITCHES: f64 = 2.0;

/// One rendered picture.
#[derive(Debug, Clone)]
pub(crate) struct Figure {
    /// The pixels.
    pub image: RgbImage,
    /// How pixels map to the part.
    pub view: View,
}

/// Every picture of the report.
#[derive(Debug, Clone)]
pub(crate) struct Views {
    /// The analysed side, face on, painted with the composite.
    pub side: Figure,
    /// The oblique view, painted with the composite.
    pub oblique: Figure,
    /// Per chosen angle (degrees), the side view painted with its mask.
    pub per_angle: Vec<(f64, Figure)>,
    /// Wall-clock time of all the rendering (seconds).
    pub render_s: f64,
}

/// The camera of the side view: along the knee's push, z up.
pub(crate) fn side_camera(side: Side) -> Camera {
    Camera::looking(Vector3::new(0.0, side.to_part(1.0), 0.0), Vector3::z())
}

/// The camera of the oblique view: from the analysed side, in front of the
/// part (towards -x) and above it, looking back at it.
pub(crate) fn oblique_camera(side: Side) -> Camera {
    Camera::looking(Vector3::new(0.55, side.to_part(1.0), -0.45), Vector3::z())
}

/// The face-on camera of a run: [`side_camera`] for push-and-slide; along
/// the knee's motion (-x, z up) for the direct approach.
pub(crate) fn run_camera(axes: GridAxes) -> Camera {
    match axes.approach {
        Approach::Slide => side_camera(axes.side),
        Approach::Direct => Camera::looking(-Vector3::x(), Vector3::z()),
    }
}

/// The oblique camera of a run: [`oblique_camera`] for push-and-slide;
/// for the direct approach from behind the knee (+x), beside the analysed
/// side and above, looking along its motion.
pub(crate) fn run_oblique_camera(axes: GridAxes) -> Camera {
    match axes.approach {
        Approach::Slide => oblique_camera(axes.side),
        Approach::Direct => Camera::looking(
            Vector3::new(-1.0, 0.55 * axes.side.to_part(1.0), -0.45),
            Vector3::z(),
        ),
    }
}

/// [`View::fit`] at `width` pixels; narrower when that would make the
/// picture more than [`MAX_ASPECT`] times as tall as wide (seen along -x,
/// a console side is a thin strip, and a picture 1100 pixels wide would be
/// ten thousand tall; so is a part turned by `--frame` to face +x, seen
/// along the push: tilted-wave's was 1100 x 40,667).
fn fit(camera: Camera, tris: &[Triangle], width: usize) -> View {
    let view = View::fit(camera, tris, width, MARGIN);
    let tall = MAX_ASPECT * width as f64;
    if view.height as f64 > tall {
        let narrower = (width as f64 * tall / view.height as f64).floor() as usize;
        return View::fit(camera, tris, narrower.max(4 * MARGIN), MARGIN);
    }
    view
}

/// The tallest a picture is, in widths.
const MAX_ASPECT: f64 = 1.5;

/// The number of colours of the composite's ramp: the angles analysed (or
/// the largest count, if a file had more).
pub(crate) fn ramp_len(run: &Run) -> usize {
    let max = run.composite.count.iter().copied().max().unwrap_or(0);
    run.summary.angles_deg.len().max(usize::from(max)).max(1)
}

/// The blind spots' colour on the rendered part: the composite image's
/// magenta.
pub const BLIND_COLOUR: Rgb = [
    crate::output::BLIND_COLOUR.0,
    crate::output::BLIND_COLOUR.1,
    crate::output::BLIND_COLOUR.2,
];

/// The colour of composite count `c` (of [`ramp_len`]).
pub(crate) fn composite_colour(c: u16, n: usize) -> Rgb {
    let rgb = count_colour(usize::from(c), n);
    [rgb.0, rgb.1, rgb.2]
}

/// Renders every view of `run`, the small multiples from `masks` (angle in
/// degrees and its mask).
pub(crate) fn render_views(run: &Run, masks: &[(f64, NodeCounts)]) -> Views {
    let started = std::time::Instant::now();
    let tris = &run.part.triangles;
    let n = ramp_len(run);
    let composite = &run.composite;
    // Blind spots over the composite: the cells the grid cannot see into.
    let blind: std::collections::HashSet<(i64, i64)> = run
        .blind_spots
        .iter()
        .map(|b| (b.i as i64, b.j as i64))
        .collect();
    let spec = run.spec;
    let axes = run.axes;
    let in_blind_cell = |p: [f64; 3]| {
        let p = axes.grid(p);
        let i = ((p[0] - spec.x(0)) / spec.pitch).floor() as i64;
        let j = ((p[2] - spec.z(0)) / spec.pitch).floor() as i64;
        blind.contains(&(i, j))
    };
    let by_count = |p: [f64; 3]| {
        if in_blind_cell(p) {
            return Some(BLIND_COLOUR);
        }
        let p = axes.grid(p);
        composite
            .at(p[0], p[2])
            .map(|(c, _)| composite_colour(c, n))
    };

    let view = fit(run_camera(axes), tris, LARGE_WIDTH);
    let side = Figure {
        image: paint(&rasterize(tris, &view), by_count),
        view,
    };

    let y_tol = OBLIQUE_Y_TOL_PITCHES * run.spec.pitch;
    let view = fit(run_oblique_camera(axes), tris, LARGE_WIDTH);
    let oblique = Figure {
        image: paint(&rasterize(tris, &view), |p| {
            let p = axes.grid(p);
            composite
                .at(p[0], p[2])
                .filter(|&(_, y)| (p[1] - y).abs() <= y_tol)
                .map(|(c, _)| composite_colour(c, n))
        }),
        view,
    };

    let view = fit(run_camera(axes), tris, SMALL_WIDTH);
    let small = rasterize(tris, &view);
    let per_angle = masks
        .iter()
        .map(|(angle, mask)| {
            let image = paint(&small, |p| {
                let p = axes.grid(p);
                mask.at(p[0], p[2]).map(|_| ANGLE_COLOUR)
            });
            (*angle, Figure { image, view })
        })
        .collect();
    Views {
        side,
        oblique,
        per_angle,
        render_s: started.elapsed().as_secs_f64(),
    }
}

/// The angles of the small multiples: the analysed angles nearest to -30,
/// 0 and +30 degrees (the paper's Figure 12), each once, in increasing
/// order.
pub(crate) fn small_multiple_angles(angles: &[f64]) -> Vec<f64> {
    let mut chosen: Vec<f64> = [-30.0, 0.0, 30.0]
        .iter()
        .filter_map(|&want: &f64| {
            angles
                .iter()
                .copied()
                .min_by(|a, b| (a - want).abs().total_cmp(&(b - want).abs()))
        })
        .collect();
    chosen.sort_by(f64::total_cmp);
    chosen.dedup();
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_multiples_pick_the_nearest_analysed_angles() {
        let all: Vec<f64> = (-30..=30).map(f64::from).collect();
        assert_eq!(small_multiple_angles(&all), [-30.0, 0.0, 30.0]);
        assert_eq!(
            small_multiple_angles(&[-10.0, 5.0, 25.0]),
            [-10.0, 5.0, 25.0]
        );
        assert_eq!(small_multiple_angles(&[3.0]), [3.0]);
        assert!(small_multiple_angles(&[]).is_empty());
    }

    #[test]
    fn the_side_cameras_look_along_the_push_with_z_up() {
        let left = side_camera(Side::Left);
        assert_eq!(left.forward, Vector3::y());
        assert_eq!(left.right, Vector3::x());
        assert_eq!(left.up, Vector3::z());
        let right = side_camera(Side::Right);
        assert_eq!(right.forward, -Vector3::y());
        assert_eq!(right.right, -Vector3::x());
        assert_eq!(right.up, Vector3::z());
        // The oblique camera sits on the analysed side, in front and above.
        let o = oblique_camera(Side::Left);
        assert!(o.forward[0] > 0.0 && o.forward[1] > 0.0 && o.forward[2] < 0.0);
        assert!(o.up[2] > 0.0);
    }

    /// A part far taller than wide, seen along the push (tilted-wave turned
    /// by `--frame=-y,x,z`: a slide run's face-on view was 1100 x 40,667
    /// pixels), is drawn narrower: at most [`MAX_ASPECT`] widths tall.
    #[test]
    fn a_tall_thin_part_is_drawn_narrower_not_taller() {
        let tris: Vec<Triangle> = vec![
            [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, 400.0]],
            [[10.0, 0.0, 0.0], [10.0, 0.0, 400.0], [0.0, 0.0, 400.0]],
        ];
        let view = fit(side_camera(Side::Left), &tris, LARGE_WIDTH);
        assert!(view.width < LARGE_WIDTH, "{} wide", view.width);
        assert!(
            view.height as f64 <= MAX_ASPECT * LARGE_WIDTH as f64,
            "{} x {}",
            view.width,
            view.height
        );
        // A wide part keeps the full width.
        let wide: Vec<Triangle> = tris.iter().map(|t| t.map(|[x, y, z]| [z, y, x])).collect();
        assert_eq!(
            fit(side_camera(Side::Left), &wide, LARGE_WIDTH).width,
            LARGE_WIDTH
        );
    }
}
