//! A second view of the slide: rapier3d's kinematic character controller.
//!
//! The knee-form is driven as a [`KinematicCharacterController`] from its
//! pushed pose with a desired translation of `-step` along x per call:
//! `up` is -y (away from the part), climb and slide angles are 90 degrees,
//! no snap-to-ground, no autostep. The controller casts along the motion,
//! stops at its `offset` from the part and spends the rest of the step
//! along the tangent plane of the contact, so it may slide away from the
//! part but never moves back towards it: SPEC's motion, discretised. No
//! physics pipeline runs; a broad phase over the part's one collider
//! serves the controller's queries.
//!
//! **Verdict: it follows SPEC's motion, and is kept as a second view.**
//! On synthetic parts (tests below) the controller never moves towards
//! the part and is never ahead of the exact `f(s)` (to 1e-6 mm); each of
//! its contacts lies on the exact curve to 1e-3 mm (its offset is 1e-4
//! mm), at a mesh point within 0.05 mm of an exact witness. Between
//! contacts it trails the curve on the side away from the part: each
//! tangent move leaves a smooth contact curve of radius `rho` by
//! `step^2 / (2 rho)` (0.0076 mm at 1 mm steps on a 80 mm bump), and
//! overshoots a ridge by up to `step * slope` (0.28 mm at 1 mm steps on a
//! slope of 0.5), after which it runs on at that lower level: an error of
//! first order in `step` that only the exact trace avoids.

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::DefaultQueryDispatcher;
use rapier3d_f64::control::CharacterLength;
use rapier3d_f64::control::KinematicCharacterController;
use rapier3d_f64::dynamics::{IntegrationParameters, RigidBodySet};
use rapier3d_f64::geometry::{BroadPhaseBvh, ColliderBuilder, ColliderSet, SharedShape};
use rapier3d_f64::pipeline::QueryFilter;
use serde::{Deserialize, Serialize};

use crate::{KneeForm, KneeFormDims, OracleError, Part, StartTrace};

/// Options of the rapier3d slide. Lengths in mm.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RapierOptions {
    /// The knee-form's `L`, `R`, `W`.
    pub knee_form: KneeFormDims,
    /// Desired travel per controller call (mm, > 0). Default 0.5 mm.
    pub step: f64,
    /// The controller's `offset`: the gap it keeps from the part (mm,
    /// > 0). Default 1e-4 mm, below the oracle's `eps`.
    pub offset: f64,
    /// The slide stops after this much travel (mm).
    pub max_travel: f64,
}

impl Default for RapierOptions {
    fn default() -> Self {
        Self {
            knee_form: KneeFormDims::default(),
            step: 0.5,
            offset: 1e-4,
            max_travel: 2000.0,
        }
    }
}

/// A contact reported by the controller. Unlike an exact
/// [`crate::ContactPoint`] it has no deflection rate: the controller's
/// contacts are not a traced curve.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RapierContact {
    /// Travel of the reference point along -x from the start (mm).
    pub travel: f64,
    /// Face level of the knee-form when it touched (mm, analysis y).
    pub face_level: f64,
    /// The touched point of the mesh, `[x, y, z]` (mm, analysis frame).
    pub witness: [f64; 3],
}

/// The controller's slide of one start.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RapierSlide {
    /// Contacts reported by the controller, in call order.
    pub contacts: Vec<RapierContact>,
    /// The pose after each controller call: `(travel, face level)` in mm.
    pub path: Vec<[f64; 2]>,
    /// Travel reached (mm).
    pub travel: f64,
    /// Whether any call moved the knee-form towards the part (+y); SPEC's
    /// motion never does.
    pub moved_towards_part: bool,
}

/// How the controller's slide compares with the exact trace (mm).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RapierComparison {
    /// Largest `|level - f(s)|` at the controller's contacts.
    pub contact_gap: f64,
    /// Largest `f(s) - level` over the controller's poses after each call:
    /// how far it trails the exact curve on the side away from the part.
    pub lag: f64,
    /// Largest `level - f(s)` over those poses: how far it is on the part's
    /// side of the exact curve, which SPEC's motion never is.
    pub lead: f64,
    /// Largest distance from a controller witness to the nearest exact one.
    pub witness_distance: f64,
}

/// The exact face level `f(s)` at travel `s`, from a trace's contacts:
/// the release level before the first contact, the last contact's level
/// after the last one (the knee-form runs on at it), and linear between
/// consecutive contacts (exact across a straight run, whose two contacts
/// share a level; within `witness_tolerance`-spaced contacts elsewhere).
fn exact_level(exact: &StartTrace, s: f64) -> Option<f64> {
    let contacts = &exact.contacts;
    let next = contacts.iter().position(|c| c.travel >= s);
    match next {
        Some(0) => Some(contacts[0].face_level),
        Some(j) => {
            let (a, b) = (contacts[j - 1], contacts[j]);
            let span = b.travel - a.travel;
            let u = if span > 0.0 {
                (s - a.travel) / span
            } else {
                1.0
            };
            Some(a.face_level + u * (b.face_level - a.face_level))
        }
        None => contacts.last().map(|c| c.face_level),
    }
}

impl RapierSlide {
    /// Compares this slide with the exact trace of the same start.
    pub fn compare(&self, exact: &StartTrace) -> RapierComparison {
        let mut out = RapierComparison {
            contact_gap: 0.0,
            lag: 0.0,
            lead: 0.0,
            witness_distance: 0.0,
        };
        for c in &self.contacts {
            if let Some(f) = exact_level(exact, c.travel) {
                out.contact_gap = out.contact_gap.max((c.face_level - f).abs());
            }
            let nearest = exact
                .contacts
                .iter()
                .map(|e| {
                    let d: f64 = (0..3).map(|k| (e.witness[k] - c.witness[k]).powi(2)).sum();
                    d.sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            out.witness_distance = out.witness_distance.max(nearest);
        }
        for &[s, level] in &self.path {
            if let Some(f) = exact_level(exact, s) {
                out.lag = out.lag.max(f - level);
                out.lead = out.lead.max(level - f);
            }
        }
        out
    }
}

/// Slides the knee-form at `angle_deg` from the reference point `start =
/// (x, z)` and face level `face_level` (mm, analysis frame; the oracle's
/// `yr* - eps` makes the two views start alike) with rapier3d's kinematic
/// character controller.
pub fn rapier_slide(
    part: &Part,
    start: [f64; 2],
    angle_deg: f64,
    face_level: f64,
    options: &RapierOptions,
) -> Result<RapierSlide, OracleError> {
    let valid = |v: f64| v.is_finite() && v > 0.0;
    if !(options.knee_form.is_valid()
        && valid(options.step)
        && valid(options.offset)
        && valid(options.max_travel))
    {
        return Err(OracleError::InvalidOptions(format!("{options:?}")));
    }
    let knee = KneeForm::new(options.knee_form, angle_deg);
    let bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let handle =
        colliders.insert(ColliderBuilder::new(SharedShape::new(part.mesh().clone())).build());
    let mut broad_phase = BroadPhaseBvh::new();
    let aabb = colliders[handle].compute_aabb();
    broad_phase.set_aabb(&IntegrationParameters::default(), handle, aabb);
    let queries = broad_phase.as_query_pipeline(
        &DefaultQueryDispatcher,
        &bodies,
        &colliders,
        QueryFilter::default(),
    );
    let controller = KinematicCharacterController {
        up: -Vector::Y,
        offset: CharacterLength::Absolute(options.offset),
        slide: true,
        autostep: None,
        max_slope_climb_angle: std::f64::consts::FRAC_PI_2,
        min_slope_slide_angle: std::f64::consts::FRAC_PI_2,
        snap_to_ground: None,
        ..KinematicCharacterController::default()
    };
    let mut pose = KneeForm::pose(start, face_level);
    let mut slide = RapierSlide {
        contacts: Vec::new(),
        path: Vec::new(),
        travel: 0.0,
        moved_towards_part: false,
    };
    let (mins, _) = part.bounds();
    let (_, back) = knee.x_extent();
    while slide.travel < options.max_travel && pose.translation.x + back > mins[0] {
        let mut hits = Vec::new();
        let movement = controller.move_shape(
            1.0,
            &queries,
            &knee,
            &pose,
            Vector::new(-options.step, 0.0, 0.0),
            |collision| hits.push(collision),
        );
        for hit in hits {
            let at: Pose = hit.character_pos;
            slide.contacts.push(RapierContact {
                travel: start[0] - at.translation.x,
                face_level: at.translation.y,
                // rapier's query pipeline casts with the hit collider as the
                // first shape: witness1 is the mesh point in world space
                // (the analysis frame), witness2 the knee-form's own point.
                witness: hit.hit.witness1.to_array(),
            });
        }
        if movement.translation.y > 0.0 {
            slide.moved_towards_part = true;
        }
        if movement.translation.x > -1e-9 {
            // Stuck: the controller cannot move in -x any more.
            break;
        }
        pose = Pose::from_translation(movement.translation) * pose;
        slide.travel = start[0] - pose.translation.x;
        slide.path.push([slide.travel, pose.translation.y]);
    }
    Ok(slide)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{OracleOptions, StartStatus, trace_start};

    /// Flat `y = 0` with a cylindrical bump along z of radius `r`, cut at
    /// half-width `a`, centred at x = 0; 0.25 mm chords over the bump.
    fn bump_part(r: f64, a: f64) -> Part {
        let yc = (r * r - a * a).sqrt();
        let g = |x: f64| {
            if x.abs() < a {
                yc - (r * r - x * x).sqrt()
            } else {
                0.0
            }
        };
        let mut xs: Vec<f64> = (0..=(8.0 * a) as usize)
            .map(|i| -a + i as f64 * 0.25)
            .collect();
        xs.extend([-600.0, -300.0, 300.0, 600.0]);
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        let zs: Vec<f64> = (0..=8).map(|j| -400.0 + 100.0 * j as f64).collect();
        let triangles = kneeform::scenario::tessellate(&xs, &zs, |i, _| g(xs[i]));
        Part::from_triangles(&triangles).unwrap()
    }

    /// Flat `y = 0` with a roof-shaped ridge along z, `h` high (towards
    /// -y) and `2 w` wide, centred at x = 0.
    fn ridge_part(h: f64, w: f64) -> Part {
        let g = |x: f64| {
            if x.abs() < w {
                -h * (1.0 - x.abs() / w)
            } else {
                0.0
            }
        };
        let xs = [-600.0, -300.0, -w, 0.0, w, 300.0, 600.0];
        let zs: Vec<f64> = (0..=8).map(|j| -400.0 + 100.0 * j as f64).collect();
        let triangles = kneeform::scenario::tessellate(&xs, &zs, |i, _| g(xs[i]));
        Part::from_triangles(&triangles).unwrap()
    }

    /// The exact trace and the controller's slide of one start at angle 0.
    fn both(part: &Part, x0: f64, step: f64) -> (StartTrace, RapierSlide) {
        let exact_options = OracleOptions {
            witness_tolerance: 0.05,
            ..OracleOptions::default()
        };
        let exact = trace_start(part, [x0, 0.0], 0.0, &exact_options).unwrap();
        assert_eq!(exact.status, StartStatus::Placed);
        let release = exact.yr_star.unwrap() - exact_options.eps;
        let options = RapierOptions {
            step,
            max_travel: 400.0,
            ..RapierOptions::default()
        };
        let slide = rapier_slide(part, [x0, 0.0], 0.0, release, &options).unwrap();
        (exact, slide)
    }

    /// What both views must share on any part: the controller never moves
    /// towards the part nor gets ahead of `f(s)`, and its contacts are on
    /// the exact curve to 1e-3 mm (its offset is 1e-4 mm; the rest is the
    /// linear interpolation of `f` between exact contacts), at witnesses
    /// within 0.05 mm of exact ones (the exact contacts are 0.05 mm apart;
    /// tangential witness error ~0.02 mm seen).
    fn assert_agree(exact: &StartTrace, slide: &RapierSlide) -> RapierComparison {
        let cmp = slide.compare(exact);
        assert!(!slide.moved_towards_part);
        assert!(!slide.contacts.is_empty());
        assert!(cmp.lead < 1e-6, "{cmp:?}");
        assert!(cmp.contact_gap < 1e-3, "{cmp:?}");
        assert!(cmp.witness_distance < 0.05 + 1e-3, "{cmp:?}");
        cmp
    }

    #[test]
    fn controller_trails_a_smooth_bump_by_step_squared_over_twice_its_radius() {
        // The face's front corner rides a circle of radius 80 mm: a tangent
        // move of `step` leaves it by step^2 / 160 (measured: 0.0076 mm at
        // 1 mm, 0.0025 at 0.5 mm, 0.0011 at 0.25 mm, 0.00064 at 0.125 mm,
        // where the offset and the interpolation of f take over).
        let rho = 80.0;
        let part = bump_part(rho, 40.0);
        for step in [1.0, 0.5, 0.25] {
            let (exact, slide) = both(&part, 200.0, step);
            let cmp = assert_agree(&exact, &slide);
            assert!(
                cmp.lag < 1.5 * step * step / (2.0 * rho) + 1e-3,
                "step {step}: {cmp:?}"
            );
        }
    }

    #[test]
    fn controller_overshoots_a_ridge_by_at_most_step_times_its_slope() {
        // A roof of slope 0.5: after the apex the controller spends the
        // rest of its step along the back slope's tangent, so it ends below
        // the ridge level by up to step * 0.5, depending on where the apex
        // falls in the step (measured: 0.40 mm at 2 mm steps, 0.28 at 1,
        // 0.12 at 0.5, 0.08 at 0.25, 0.03 at 0.125): first order in step.
        let part = ridge_part(10.0, 20.0);
        for x0 in [200.0, 200.3, 200.7] {
            for step in [1.0, 0.5, 0.25] {
                let (exact, slide) = both(&part, x0, step);
                let cmp = assert_agree(&exact, &slide);
                assert!(cmp.lag <= 0.5 * step + 1e-3, "x0 {x0} step {step}: {cmp:?}");
            }
        }
    }
}
