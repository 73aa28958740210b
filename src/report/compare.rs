//! Side by side (`kneeform report RUN --compare OTHER_RUN`): a
//! push-and-slide run and a direct-approach run of the same part, both
//! areas painted on the same rendered part, and what each finds that the
//! other does not (the paper's Figure 2: the direct approach cannot reach a
//! depression behind a protrusion).
//!
//! The two runs' grids lie in different frames (SPEC's x, z for the slide;
//! the direct frame's y, z for the direct approach), so nodes are matched
//! as points of the part: a node of one run is **found by the other** when
//! one of the other's colliding nodes lies within [`MATCH_PITCHES`] of the
//! coarser pitch (3-d distance, vehicle coordinates). The counts are
//! computed from both runs' `composite.csv`.

use std::collections::HashMap;

use crate::frame::Approach;

use super::error::ReportError;
use super::render::{Rgb, RgbImage, View, paint, rasterize};
use super::run::{GridAxes, NodeCounts, Run};
use super::views::{Figure, LARGE_WIDTH, OBLIQUE_Y_TOL_PITCHES, run_camera, run_oblique_camera};

/// How near (in pitches of the coarser run) a node of the other run must be
/// for a node to count as found by both: the two grids sample the surface
/// at different nodes, up to a pitch apart along a face and half a
/// diagonal across one; two pitches takes in both, and is far less than
/// the knee-form (120 mm wide).
pub(crate) const MATCH_PITCHES: f64 = 2.0;

/// Colour of what only push-and-slide strikes.
pub(crate) const SLIDE_ONLY: Rgb = [230, 97, 1];
/// Colour of what only the direct approach touches.
pub(crate) const DIRECT_ONLY: Rgb = [33, 102, 172];
/// Colour of what both find.
pub(crate) const BOTH: Rgb = [118, 42, 131];

/// The comparison of the report's run with another run of the same part.
#[derive(Debug)]
pub struct Comparison {
    /// The other run.
    pub other: Run,
    /// The part face on, as the slide sees it, and obliquely from behind
    /// the direct approach's knee, painted with both areas.
    pub figures: Vec<Figure>,
    /// Composite nodes of the slide run found by no direct contact.
    pub slide_only: usize,
    /// Composite nodes of the direct run struck by no slide.
    pub direct_only: usize,
    /// The slide run's pitch (mm): `slide_only` nodes are that pitch
    /// squared each.
    pub slide_pitch: f64,
    /// The direct run's pitch (mm).
    pub direct_pitch: f64,
    /// The match distance (mm).
    pub match_mm: f64,
}

impl Comparison {
    /// Compares `run` with `other`: the same part (SHA-256, scale, side,
    /// frame), the other approach.
    pub fn new(run: &Run, other: Run) -> Result<Comparison, ReportError> {
        let (a, b) = (&run.summary, &other.summary);
        let identity = |s: &crate::summary::Summary| {
            let files: Vec<(String, bool)> = s
                .files
                .iter()
                .map(|f| (f.sha256.clone(), f.ignored))
                .collect();
            (s.sha256.clone(), files)
        };
        let differs = if identity(a) != identity(b) {
            Some("its part is not the run's (SHA-256)")
        } else if a.scale != b.scale {
            Some("its scale is not the run's")
        } else if a.side != b.side {
            Some("its side is not the run's")
        } else if a.frame != b.frame {
            Some("its --frame is not the run's")
        } else if a.approach == b.approach {
            Some("it has the run's approach: compare a slide run with a direct one")
        } else {
            None
        };
        if let Some(reason) = differs {
            return Err(ReportError::Inconsistent {
                path: other.dir.join(crate::output::SUMMARY_JSON),
                reason: format!("cannot be compared with {}: {reason}", run.dir.display()),
            });
        }
        let (slide, direct) = match a.approach {
            Approach::Slide => (run, &other),
            Approach::Direct => (&other, run),
        };
        let match_mm = MATCH_PITCHES * slide.spec.pitch.max(direct.spec.pitch);
        let slide_points = points(slide);
        let direct_points = points(direct);
        let slide_only = unmatched(&slide_points, &direct_points, match_mm);
        let direct_only = unmatched(&direct_points, &slide_points, match_mm);
        let tris = &run.part.triangles;
        let paint_both = |p: [f64; 3]| {
            both_colour(
                hit(&slide.composite, slide.axes, p),
                hit(&direct.composite, direct.axes, p),
            )
        };
        let figures = [run_camera(slide.axes), run_oblique_camera(direct.axes)]
            .into_iter()
            .map(|camera| {
                let view = View::fit(camera, tris, LARGE_WIDTH, 8);
                let image: RgbImage = paint(&rasterize(tris, &view), paint_both);
                Figure { image, view }
            })
            .collect();
        Ok(Comparison {
            slide_pitch: slide.spec.pitch,
            direct_pitch: direct.spec.pitch,
            other,
            figures,
            slide_only,
            direct_only,
            match_mm,
        })
    }
}

/// Whether the surface point `p` (vehicle coordinates) is painted by a
/// run's `composite` (its grid mapped by `axes`): within half a pitch of a
/// colliding node across its grid ([`NodeCounts::at`]), and within
/// [`OBLIQUE_Y_TOL_PITCHES`] of the node's depth.
fn hit(composite: &NodeCounts, axes: GridAxes, p: [f64; 3]) -> bool {
    let g = axes.grid(p);
    let tol = OBLIQUE_Y_TOL_PITCHES * composite.spec.pitch;
    composite
        .at(g[0], g[2])
        .is_some_and(|(_, depth)| (g[1] - depth).abs() <= tol)
}

/// The colour of a point the slide run paints (`slide`) or the direct run
/// paints (`direct`), or both; `None` (the part's grey) for neither.
fn both_colour(slide: bool, direct: bool) -> Option<Rgb> {
    match (slide, direct) {
        (true, true) => Some(BOTH),
        (true, false) => Some(SLIDE_ONLY),
        (false, true) => Some(DIRECT_ONLY),
        (false, false) => None,
    }
}

/// The colliding nodes of `run`'s composite as points (vehicle
/// coordinates, mm).
fn points(run: &Run) -> Vec<[f64; 3]> {
    let c: &NodeCounts = &run.composite;
    let s = c.spec;
    (0..s.len())
        .filter(|&k| c.count[k] > 0)
        .map(|k| vehicle(run.axes, [s.x(k % s.nx), c.y[k], s.z(k / s.nx)]))
        .collect()
}

/// The inverse of [`GridAxes::grid`].
fn vehicle(axes: GridAxes, [g0, g1, g2]: [f64; 3]) -> [f64; 3] {
    match axes.approach {
        Approach::Slide => [g0, g1, g2],
        Approach::Direct => [-g1, axes.side.to_part(g0), g2],
    }
}

/// How many of `these` have none of `those` within `d` (mm).
fn unmatched(these: &[[f64; 3]], those: &[[f64; 3]], d: f64) -> usize {
    let cell = |p: &[f64; 3]| p.map(|c| (c / d).floor() as i64);
    let mut buckets: HashMap<[i64; 3], Vec<[f64; 3]>> = HashMap::new();
    for p in those {
        buckets.entry(cell(p)).or_default().push(*p);
    }
    these
        .iter()
        .filter(|p| {
            let [ci, cj, ck] = cell(p);
            let near = (-1..=1).any(|di| {
                (-1..=1).any(|dj| {
                    (-1..=1).any(|dk| {
                        buckets.get(&[ci + di, cj + dj, ck + dk]).is_some_and(|b| {
                            b.iter().any(|q| {
                                let dd: f64 = (0..3).map(|n| (p[n] - q[n]).powi(2)).sum();
                                dd <= d * d
                            })
                        })
                    })
                })
            });
            !near
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::report::render::BACKGROUND;

    #[test]
    fn points_are_matched_within_the_distance_only() {
        let those = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]];
        let these = [
            [0.0, 1.9, 0.0],
            [5.0, 0.0, 0.0],
            [10.0, 0.0, -2.0],
            [-2.1, 0.0, 0.0],
        ];
        assert_eq!(unmatched(&these, &those, 2.0), 2);
    }

    /// A grey pixel (the part's, painted by neither run) whose eight
    /// neighbours are all painted: a speckle.
    fn speckles(image: &RgbImage) -> Vec<(usize, usize)> {
        let grey = |[r, g, b]: Rgb| r == g && g == b && [r, g, b] != BACKGROUND;
        let painted = |[r, g, b]: Rgb| !(r == g && g == b);
        let (w, h) = (image.width, image.height);
        (1..h.saturating_sub(1))
            .flat_map(|r| (1..w.saturating_sub(1)).map(move |c| (c, r)))
            .filter(|&(c, r)| {
                grey(image.at(c, r))
                    && (r - 1..=r + 1).all(|rr| {
                        (c - 1..=c + 1).all(|cc| (cc, rr) == (c, r) || painted(image.at(cc, rr)))
                    })
            })
            .collect()
    }

    #[test]
    fn a_surface_on_a_cell_border_is_painted_whole_without_grey_speckles() {
        // scenarios/pocket-behind-ridge.toml at 4 mm: the pocket's floor
        // lies at y = 30, half a pitch between the direct grid's node
        // columns y = 28 (the near wall's first contact, x = 60) and
        // y = 32 (behind the floor: no part). The floor within two pitches
        // of x = 60 is the direct run's, on the border of its cell.
        let pitch = 4.0;
        let direct_spec = GridSpec {
            pitch,
            i_origin: 0,
            j_origin: -6,
            nx: 12,
            nz: 13,
        };
        let mut direct = NodeCounts {
            spec: direct_spec,
            count: vec![0; direct_spec.len()],
            y: vec![f64::NAN; direct_spec.len()],
        };
        for j in 0..direct_spec.nz {
            direct.count[j * direct_spec.nx + 7] = 3;
            direct.y[j * direct_spec.nx + 7] = -60.0;
        }
        let slide = NodeCounts {
            spec: direct_spec,
            count: vec![0; direct_spec.len()],
            y: vec![f64::NAN; direct_spec.len()],
        };
        let left = |approach| GridAxes {
            approach,
            side: crate::Side::Left,
        };
        // The floor, x in [50, 70], z in [-20, 20], as a mesh of 1 mm
        // squares (as a scenario is written: many triangles, each
        // interpolating the same depth with its own rounding).
        let mut tris = Vec::new();
        for a in 0..20 {
            for b in 0..40 {
                let (x, z) = (50.0 + f64::from(a), -20.0 + f64::from(b));
                let q = |dx: f64, dz: f64| [x + dx, 30.0, z + dz];
                tris.push([q(0.0, 0.0), q(1.0, 0.0), q(1.0, 1.0)]);
                tris.push([q(0.0, 0.0), q(1.0, 1.0), q(0.0, 1.0)]);
            }
        }
        let view = View::fit(run_camera(left(Approach::Slide)), &tris, 400, 8);
        let image = paint(&rasterize(&tris, &view), |p| {
            both_colour(
                hit(&slide, left(Approach::Slide), p),
                hit(&direct, left(Approach::Direct), p),
            )
        });
        // Every pixel of the floor within two pitches of x = 60 is the
        // direct run's, away from that band's ends.
        let mut inside = 0;
        let mut grey = Vec::new();
        for r in 0..view.height {
            for c in 0..view.width {
                let (u, _) = view.pixel_centre(c, r);
                let [red, green, blue] = image.at(c, r);
                if image.at(c, r) == BACKGROUND {
                    continue;
                }
                if (53.0..67.0).contains(&u) {
                    inside += 1;
                    if red == green && green == blue {
                        grey.push((c, r));
                    }
                }
                // Beyond two pitches of the contact's depth: the part's.
                if !(51.0..69.0).contains(&u) {
                    assert!(red == green && green == blue, "painted at x = {u}");
                }
            }
        }
        assert!(inside > 1000, "{inside}");
        assert!(grey.is_empty(), "{} grey of {inside}: {grey:?}", grey.len());
        assert_eq!(speckles(&image), []);
    }

    #[test]
    fn grid_axes_and_vehicle_are_inverse() {
        for side in [crate::Side::Left, crate::Side::Right] {
            for approach in [Approach::Slide, Approach::Direct] {
                let axes = GridAxes { approach, side };
                let v = [1.5, -2.25, 3.0];
                assert_eq!(vehicle(axes, axes.grid(v)), v);
            }
        }
    }
}
