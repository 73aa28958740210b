//! The exact **direct approach**: the knee-form comes from far in +x and
//! moves in -x until it first touches the part (issue 12; the definition in
//! README.md, "Two approaches").
//!
//! A knee position is `(y0, z0)`: the knee-form's width covers y in
//! `[y0 - W/2, y0 + W/2]` (closed) and its reference point `v0` lies at
//! height `z0`; the angle rotates `K` about y through `v0` as SPEC's
//! Step 2. The knee-form starts with its whole footprint past the part's +x
//! bound and is cast along -x against the triangle mesh with parry's time
//! of impact (the same footprint-pruned cast as the slide's,
//! [`crate::sweep`]). The answer per position is the **contact level**
//! `X*`, the x of the reference point at first contact, and the touched
//! mesh point; no contact means the knee-form passes the part.
//!
//! In the grid engine's "direct frame" `(x', y', z') = (y, -x, z)` the knee
//! moves in +y' and its first-contact level is `Y* = -X*`; the harness
//! compares the two through that identity.
//!
//! **Ties.** Every triangle the knee-form reaches within
//! [`DirectOptions::tie_tolerance`] of travel after the first contact is
//! touched at the same instant, as the grid's ties within `e0`: its first
//! contact point is listed in [`DirectContact::ties`] (the first one is the
//! cast's witness). A line or area contact (a flat face meeting a plane)
//! gives one point per triangle it touches, each a sample of that set.
//!
//! **Invariant:** as the slide's oracle, a position is never reported clear
//! on a failed query: [`crate::sweep::cast`] confirms every miss.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::details::cast_shapes_support_map_support_map;
use parry3d_f64::query::{ShapeCastOptions, ShapeCastStatus};
use parry3d_f64::shape::Shape;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::knee_form::{KneeForm, KneeFormDims};
use crate::sweep::{self, Motion};
use crate::{FailureReason, OracleError, Part};

/// How far past the part's +x bound the knee-form's front starts, and past
/// its -x bound its back must travel before a cast is a pass, mm. Any
/// positive value works; 1 mm keeps the times of impact small.
const CLEARANCE: f64 = 1.0;

/// A swept knee-form overlapping the mesh by less than this after a cast
/// reported no hit is a grazing pass, not a failure (mm): the slide's
/// default (a tenth of its 1e-3 mm release offset).
const GRAZING: f64 = 1e-4;

/// Options of the exact direct approach. Lengths in mm.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectOptions {
    /// The knee-form's `L`, `R`, `W`.
    pub knee_form: KneeFormDims,
    /// Triangles the knee-form reaches within this travel (mm) after its
    /// first contact are touched at the same instant (ties). Default
    /// 1e-6 mm: SPEC's rounding tolerance `e0`, which the grid uses for
    /// its ties, and parry3d-f64's time-of-impact accuracy on part-sized
    /// coordinates.
    pub tie_tolerance: f64,
}

impl Default for DirectOptions {
    fn default() -> Self {
        Self {
            knee_form: KneeFormDims::default(),
            tie_tolerance: 1e-6,
        }
    }
}

impl DirectOptions {
    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), OracleError> {
        if !self.knee_form.is_valid() {
            return Err(OracleError::InvalidOptions(format!(
                "knee-form dimensions must be finite and > 0, got {:?}",
                self.knee_form
            )));
        }
        if !(self.tie_tolerance.is_finite() && self.tie_tolerance >= 0.0) {
            return Err(OracleError::InvalidOptions(format!(
                "tie_tolerance must be finite and >= 0, got {}",
                self.tie_tolerance
            )));
        }
        Ok(())
    }
}

/// The first contact of one knee position.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectContact {
    /// `X*`: the x of the reference point `v0` when the knee-form first
    /// touches the part (mm, the placed part's frame). The grid's level in
    /// its direct frame is `-X*`.
    pub level: f64,
    /// The touched mesh point, `[x, y, z]` (mm).
    pub witness: [f64; 3],
    /// The first contact point of every triangle touched within
    /// [`DirectOptions::tie_tolerance`] of travel, the witness first.
    pub ties: Vec<[f64; 3]>,
}

/// What the cast of one knee position found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum DirectStatus {
    /// The knee-form touches the part.
    Contact(DirectContact),
    /// The knee-form passes the part without touching it (a confirmed
    /// miss): the position is not placed.
    Clear,
    /// A query failed: the position is unknown, never clear.
    Failed(FailureReason),
}

/// One knee position at one angle and what its cast found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectTrace {
    /// `(y0, z0)`: the centre of the knee-form's width and the height of
    /// its reference point (mm).
    pub position: [f64; 2],
    /// The knee-form's angle, degrees.
    pub angle_deg: f64,
    /// The contact, a pass, or a failure.
    pub status: DirectStatus,
}

impl DirectTrace {
    /// The contact, if the knee-form touched the part; a failed query is
    /// an error, so no caller can take it for a pass.
    pub fn contact(&self) -> Result<Option<&DirectContact>, FailureReason> {
        match &self.status {
            DirectStatus::Contact(c) => Ok(Some(c)),
            DirectStatus::Clear => Ok(None),
            DirectStatus::Failed(reason) => Err(*reason),
        }
    }
}

/// Casts the knee-form at `angle_deg` degrees, positioned at
/// `position = (y0, z0)` (mm), from past the part's +x bound along -x:
/// its exact first contact with the part.
pub fn direct_contact(
    part: &Part,
    position: [f64; 2],
    angle_deg: f64,
    options: &DirectOptions,
) -> Result<DirectTrace, OracleError> {
    options.validate()?;
    check_finite(&[position], &[angle_deg])?;
    let knee = KneeForm::new(options.knee_form, angle_deg);
    Ok(trace(part, &knee, position, options))
}

/// [`direct_contact`] for every position at every angle, in parallel on
/// rayon's current thread pool; angle-major: the trace of `positions[p]`
/// at `angles_deg[a]` is at index `a * positions.len() + p`.
pub fn evaluate_direct(
    part: &Part,
    positions: &[[f64; 2]],
    angles_deg: &[f64],
    options: &DirectOptions,
) -> Result<Vec<DirectTrace>, OracleError> {
    options.validate()?;
    check_finite(positions, angles_deg)?;
    let knees: Vec<KneeForm> = angles_deg
        .iter()
        .map(|&angle| KneeForm::new(options.knee_form, angle))
        .collect();
    let n = positions.len();
    Ok((0..knees.len() * n)
        .into_par_iter()
        .map(|k| trace(part, &knees[k / n], positions[k % n], options))
        .collect())
}

fn check_finite(positions: &[[f64; 2]], angles_deg: &[f64]) -> Result<(), OracleError> {
    if let Some(bad) = angles_deg.iter().find(|a| !a.is_finite()) {
        return Err(OracleError::InvalidOptions(format!(
            "angle {bad} is not finite"
        )));
    }
    if let Some(bad) = positions
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(OracleError::InvalidOptions(format!(
            "knee position {bad:?} is not finite"
        )));
    }
    Ok(())
}

fn trace(part: &Part, knee: &KneeForm, position: [f64; 2], options: &DirectOptions) -> DirectTrace {
    let status = match first_contact(part, knee, position, options) {
        Ok(Some(contact)) => DirectStatus::Contact(contact),
        Ok(None) => DirectStatus::Clear,
        Err(reason) => DirectStatus::Failed(reason),
    };
    DirectTrace {
        position,
        angle_deg: knee.angle_deg(),
        status,
    }
}

fn first_contact(
    part: &Part,
    knee: &KneeForm,
    [y0, z0]: [f64; 2],
    options: &DirectOptions,
) -> Result<Option<DirectContact>, FailureReason> {
    let (mins, maxs) = part.bounds();
    let (front, back) = knee.x_extent();
    // The knee-form's local y spans [-W, 0] below its "face": put the face
    // at y0 + W/2 so that it covers [y0 - W/2, y0 + W/2].
    let origin = Vector::new(
        maxs[0] - front + CLEARANCE,
        y0 + options.knee_form.width / 2.0,
        z0,
    );
    // Past this travel the knee-form's back has left the part's -x bound.
    let max_travel = origin.x + back - mins[0] + CLEARANCE;
    let Some(hit) = sweep::cast(
        part.mesh(),
        knee,
        origin,
        Motion::Slide,
        max_travel,
        GRAZING,
        true,
    )?
    else {
        return Ok(None);
    };
    let ties = ties(part, knee, origin, hit.travel, hit.witness, options)?;
    Ok(Some(DirectContact {
        level: origin.x - hit.travel,
        witness: hit.witness.to_array(),
        ties,
    }))
}

/// The first contact points of every triangle the knee-form reaches within
/// `tie_tolerance` of travel past `travel`, the cast's witness first.
fn ties(
    part: &Part,
    knee: &KneeForm,
    origin: Vector,
    travel: f64,
    witness: Vector,
    options: &DirectOptions,
) -> Result<Vec<[f64; 3]>, FailureReason> {
    let reach = travel + options.tie_tolerance;
    // Only triangles the knee-form's box meets at the end of that travel
    // can be touched by then (it came from beyond the part).
    let at_reach = Pose::from_translation(origin - Vector::X * reach);
    let aabb: Aabb = knee
        .compute_aabb(&at_reach)
        .loosened(options.tie_tolerance + GRAZING);
    let pos12 = Pose::from_translation(-origin);
    let mut ties = vec![witness.to_array()];
    for id in part.mesh().bvh().intersect_aabb(&aabb) {
        let triangle = part.mesh().triangle(id);
        let cast_options = ShapeCastOptions {
            max_time_of_impact: reach,
            target_distance: 0.0,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        };
        let hit =
            cast_shapes_support_map_support_map(&pos12, Vector::X, knee, &triangle, cast_options);
        match hit.map(|h| h.status) {
            None | Some(ShapeCastStatus::Converged) => {}
            Some(ShapeCastStatus::PenetratingOrWithinTargetDist) => {
                return Err(FailureReason::PenetratingStart);
            }
            Some(ShapeCastStatus::OutOfIterations | ShapeCastStatus::Failed) => {
                return Err(FailureReason::CastNotConverged);
            }
        }
        if let Some(hit) = hit {
            let point = hit.witness2;
            if (point - witness).length() > 0.0 {
                ties.push(point.to_array());
            }
        }
    }
    Ok(ties)
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::query::PointQuery;

    const R: f64 = 60.0;
    const W: f64 = 120.0;
    /// parry's GJK time of impact and witnesses: measured within 1.4e-7 mm
    /// of the closed forms below (the tilted planes); held to SPEC's
    /// rounding tolerance e0.
    const TOL: f64 = 1e-6;

    /// The surface `x = g(y, z)` facing +x over the grid `ys x zs`, two
    /// triangles per cell; repeated `zs` make a riser (a face at constant
    /// z between two rows).
    fn surface(ys: &[f64], zs: &[f64], g: impl Fn(usize, usize) -> f64) -> Part {
        let p = |i: usize, j: usize| [g(i, j), ys[i], zs[j]];
        let mut triangles = Vec::new();
        for i in 0..ys.len() - 1 {
            for j in 0..zs.len() - 1 {
                let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i, j + 1), p(i + 1, j + 1));
                triangles.push([a, b, d]);
                triangles.push([a, d, c]);
            }
        }
        Part::from_triangles(&triangles).unwrap()
    }

    fn span(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        (0..=n)
            .map(|k| lo + (hi - lo) * k as f64 / n as f64)
            .collect()
    }

    fn contact(part: &Part, position: [f64; 2], angle: f64) -> DirectContact {
        direct_contact(part, position, angle, &DirectOptions::default())
            .unwrap()
            .contact()
            .unwrap()
            .unwrap_or_else(|| panic!("{position:?} at {angle}: no contact"))
            .clone()
    }

    /// Every tie lies on the mesh and on the knee-form's boundary at `X*`,
    /// within the cast's accuracy.
    fn assert_on_both(part: &Part, c: &DirectContact, position: [f64; 2], angle: f64) {
        let knee = KneeForm::new(KneeFormDims::default(), angle);
        let pose = Pose::from_translation(Vector::new(c.level, position[0] + W / 2.0, position[1]));
        assert_eq!(c.ties[0], c.witness);
        for p in &c.ties {
            let p = Vector::from_array(*p);
            let on_mesh = part.mesh().distance_to_point(&Pose::IDENTITY, p, true);
            assert!(on_mesh < TOL, "{p:?} is {on_mesh} mm off the mesh");
            let to_knee = knee.distance_to_point(&pose, p, false);
            assert!(to_knee < TOL, "{p:?} is {to_knee} mm off the knee-form");
            assert!((p.y - position[0]).abs() <= W / 2.0 + TOL, "{p:?}");
        }
    }

    #[test]
    fn a_plane_facing_plus_x_is_met_by_the_rounded_front_corner() {
        let c0 = 25.0;
        let part = surface(&span(-300.0, 300.0, 6), &span(-300.0, 300.0, 6), |_, _| c0);
        for position in [[0.0, 0.0], [-70.0, 40.0], [110.0, -90.0]] {
            for angle in [-30.0, 0.0, 17.0, 30.0] {
                let c = contact(&part, position, angle);
                // For |angle| <= 30 the frontmost point of K is v0 - (R, 0).
                assert!((c.level - (c0 + R)).abs() < TOL, "{angle}: {}", c.level);
                assert!((c.witness[0] - c0).abs() < TOL);
                assert!((c.witness[2] - position[1]).abs() < 1e-3, "{c:?}");
                assert_on_both(&part, &c, position, angle);
            }
        }
    }

    #[test]
    fn a_plane_tilted_about_z_is_met_at_the_knee_forms_side_edge() {
        // x = c + a y: the side of the width with the larger y touches first.
        let (c0, a) = (10.0, 0.2);
        let ys = span(-400.0, 400.0, 8);
        let part = surface(&ys, &span(-300.0, 300.0, 6), |i, _| c0 + a * ys[i]);
        for position in [[0.0, 0.0], [-130.0, 55.0]] {
            let c = contact(&part, position, 0.0);
            let edge = position[0] + W / 2.0;
            assert!((c.level - (c0 + a * edge + R)).abs() < TOL, "{c:?}");
            assert!((c.witness[1] - edge).abs() < TOL, "{c:?}");
            assert_on_both(&part, &c, position, 0.0);
        }
    }

    #[test]
    fn a_plane_tilted_about_y_is_met_where_its_normal_leaves_the_front_arc() {
        // x = c + b z, normal n = (1, 0, -b) / s: the point v0 - R n touches
        // it, at X* = c + b z0 + R s, for directions within v0's arc.
        let c0 = -5.0;
        for b in [-0.4, 0.25, 0.5] {
            let zs = span(-400.0, 400.0, 8);
            let part = surface(&span(-300.0, 300.0, 6), &zs, |_, j| c0 + b * zs[j]);
            let s = f64::hypot(1.0, b);
            for (position, angle) in [([0.0, 0.0], 0.0), ([40.0, -60.0], 20.0)] {
                let c = contact(&part, position, angle);
                let want = c0 + b * position[1] + R * s;
                assert!((c.level - want).abs() < TOL, "b {b}: {c:?} vs {want}");
                assert!((c.witness[2] - (position[1] + R * b / s)).abs() < 1e-4);
                assert_on_both(&part, &c, position, angle);
            }
        }
    }

    #[test]
    fn a_step_is_met_on_its_edge() {
        // x = c below z = 0, x = c + 20 above: a riser at z = 0 whose edge
        // (c + 20, y, 0) the arc of v0 meets from below at
        // X* = c + 20 + sqrt(R^2 - dz^2), ahead of the plane below (c + R).
        let c0 = 0.0;
        let zs = vec![-300.0, -150.0, 0.0, 0.0, 150.0, 300.0];
        let part = surface(&span(-300.0, 300.0, 6), &zs, |_, j| {
            if j <= 2 { c0 } else { c0 + 20.0 }
        });
        // Below the step: the knee-form's arc meets the edge.
        let c = contact(&part, [15.0, -30.0], 0.0);
        let want = c0 + 20.0 + (R * R - 30.0f64.powi(2)).sqrt();
        assert!((c.level - want).abs() < TOL, "{c:?} vs {want}");
        assert!((c.witness[0] - 20.0).abs() < TOL && c.witness[2].abs() < TOL);
        assert_on_both(&part, &c, [15.0, -30.0], 0.0);
        // Well above the step: the upper plane, at c + 20 + R.
        let c = contact(&part, [15.0, 100.0], 0.0);
        assert!((c.level - (c0 + 20.0 + R)).abs() < TOL, "{c:?}");
    }

    #[test]
    fn a_part_outside_the_width_or_height_is_passed_and_ties_are_listed() {
        let part = surface(&span(-50.0, 50.0, 2), &span(-50.0, 50.0, 2), |_, _| 0.0);
        let options = DirectOptions::default();
        // The width covers y in [y0 - 60, y0 + 60]: closed at 110 - 60 = 50.
        let touching = direct_contact(&part, [110.0, 0.0], 0.0, &options).unwrap();
        assert!(touching.contact().unwrap().is_some(), "{touching:?}");
        let passing = direct_contact(&part, [110.5, 0.0], 0.0, &options).unwrap();
        assert_eq!(passing.status, DirectStatus::Clear);
        let high = direct_contact(&part, [0.0, 400.0], 0.0, &options).unwrap();
        assert_eq!(high.status, DirectStatus::Clear);
        // A flat face meets the plane along a line across all four cells'
        // triangles: several ties, all on mesh and knee-form.
        let c = contact(&part, [0.0, 0.0], 0.0);
        assert!(c.ties.len() >= 2, "{c:?}");
        assert_on_both(&part, &c, [0.0, 0.0], 0.0);
        // Bad input is one error.
        let err = direct_contact(&part, [f64::NAN, 0.0], 0.0, &options).unwrap_err();
        assert!(err.to_string().contains("not finite"), "{err}");
    }

    #[test]
    fn evaluate_direct_is_angle_major_and_matches_single_casts() {
        let zs = span(-300.0, 300.0, 12);
        let part = surface(&span(-300.0, 300.0, 12), &zs, |i, j| {
            8.0 * (zs[j] / 40.0).sin() + 0.01 * i as f64
        });
        let positions = [[0.0, 0.0], [50.0, 33.0], [-120.0, -80.0]];
        let angles = [-30.0, 0.0, 30.0];
        let options = DirectOptions::default();
        let all = evaluate_direct(&part, &positions, &angles, &options).unwrap();
        assert_eq!(all.len(), 9);
        for (a, &angle) in angles.iter().enumerate() {
            for (p, &position) in positions.iter().enumerate() {
                let one = direct_contact(&part, position, angle, &options).unwrap();
                assert_eq!(all[a * positions.len() + p], one);
            }
        }
    }
}
