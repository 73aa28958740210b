//! One shape cast of the knee-form against the part's mesh, along +y (the
//! push) or -x (the slide).
//!
//! parry's composite cast bounds each BVH node by the knee-form's bounding
//! box; on a part-sized mesh that box overlaps thousands of triangles the
//! rounded triangle never reaches (beside its slanted back edges), and each
//! costs a GJK cast: measured at ~4 ms per cast on 400k triangles. Here
//! the traversal of the mesh's own BVH ([`parry3d_f64::partitioning::Bvh::find_best`])
//! uses the exact footprint instead: a node is skipped unless its
//! xz-rectangle meets the footprint's path, and its cost is the travel
//! before the footprint's leading end can reach it. Each triangle that
//! survives is cast with parry's GJK
//! ([`parry3d_f64::query::details::cast_shapes_support_map_support_map`]).
//!
//! **No silent misses.** GJK returns "no hit" when it runs out of
//! iterations. Every triangle the traversal hands over and GJK reports as
//! missed is checked with a contact query against the knee-form swept over
//! the travel still open; an overlap deeper than the grazing depth makes
//! the cast fail.

use std::cell::Cell;

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::details::{
    cast_shapes_support_map_support_map, contact_support_map_support_map,
};
use parry3d_f64::query::{ShapeCastHit, ShapeCastOptions, ShapeCastStatus};
use parry3d_f64::shape::TriMesh;

use crate::FailureReason;
use crate::knee_form::{End, KneeForm, SweptKneeForm};

/// The two motions of SPEC's push and slide.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Motion {
    /// Along +y (the push).
    Push,
    /// Along -x (the slide).
    Slide,
}

impl Motion {
    fn dir(self) -> Vector {
        match self {
            Motion::Push => Vector::Y,
            Motion::Slide => -Vector::X,
        }
    }
}

/// A cast's first contact: travel (mm) and the touched mesh point
/// (analysis frame).
#[derive(Copy, Clone, Debug)]
pub(crate) struct Contact {
    pub(crate) travel: f64,
    pub(crate) witness: Vector,
}

/// Casts `knee`, reference point at `(origin.x, origin.z)` and face at
/// `origin.y`, along `motion` for at most `max_travel` mm. `grazing` is the
/// overlap (mm) below which a reported miss is believed.
pub(crate) fn cast(
    mesh: &TriMesh,
    knee: &KneeForm,
    origin: Vector,
    motion: Motion,
    max_travel: f64,
    grazing: f64,
) -> Result<Option<Contact>, FailureReason> {
    let width = knee.dims().width;
    let (z_lo, z_hi) = knee.z_range();
    let (_, x_back) = knee.x_extent();
    // Lower bound of the travel before the knee-form can touch anything in
    // the box [mins, maxs]; f64::MAX when it never can.
    let bound = |mins: Vector, maxs: Vector| -> f64 {
        let (za, zb) = (mins.z - origin.z, maxs.z - origin.z);
        if zb < z_lo || za > z_hi {
            return f64::MAX;
        }
        let (Some(left), Some(right)) = (
            knee.extreme_x(za, zb, End::Left),
            knee.extreme_x(za, zb, End::Right),
        ) else {
            return f64::MAX;
        };
        match motion {
            Motion::Push => {
                // The footprint does not move in xz: the box must overlap
                // its x-span at these heights, and lie above the face.
                if maxs.x < origin.x + left || mins.x > origin.x + right {
                    return f64::MAX;
                }
                (mins.y - origin.y).max(0.0)
            }
            Motion::Slide => {
                // The prism spans y in [f - W, f]; it moves towards -x.
                if mins.y > origin.y || maxs.y < origin.y - width {
                    return f64::MAX;
                }
                if mins.x > origin.x + x_back.min(right) {
                    return f64::MAX;
                }
                (origin.x + left - maxs.x).max(0.0)
            }
        }
    };
    let pos12 = Pose::from_translation(-origin);
    let vel12 = -motion.dir();
    let failure: Cell<Option<FailureReason>> = Cell::new(None);
    let leaf = |id: u32, best: f64| -> Option<ShapeCastHit> {
        let triangle = mesh.triangle(id);
        let options = ShapeCastOptions {
            max_time_of_impact: best,
            target_distance: 0.0,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        };
        match cast_shapes_support_map_support_map(&pos12, vel12, knee, &triangle, options) {
            Some(hit) => match hit.status {
                ShapeCastStatus::Converged => Some(hit),
                ShapeCastStatus::PenetratingOrWithinTargetDist => {
                    failure.set(Some(FailureReason::PenetratingStart));
                    None
                }
                ShapeCastStatus::OutOfIterations | ShapeCastStatus::Failed => {
                    failure.set(Some(FailureReason::CastNotConverged));
                    None
                }
            },
            None => {
                let swept = SweptKneeForm {
                    knee: *knee,
                    sweep: motion.dir() * best,
                };
                let overlap = contact_support_map_support_map(&pos12, &swept, &triangle, 0.0);
                if overlap.is_some_and(|c| -c.dist > grazing) {
                    failure.set(Some(FailureReason::UnconfirmedMiss));
                }
                None
            }
        }
    };
    let node_cost = |node: &BvhNode, _best: f64| bound(node.mins(), node.maxs());
    let best = mesh.bvh().find_best(max_travel, node_cost, leaf);
    if let Some(reason) = failure.get() {
        return Err(reason);
    }
    Ok(best.map(|(_, hit)| Contact {
        travel: hit.time_of_impact,
        witness: hit.witness2,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{KneeFormDims, Part};
    use parry3d_f64::query::cast_shapes;

    /// A wavy height field facing -y, 600 x 400 mm, 10 mm cells.
    fn wavy() -> Part {
        let g = |x: f64, z: f64| 6.0 * (x / 37.0).sin() * (z / 23.0).cos() + 0.01 * x;
        let xs: Vec<f64> = (0..=60).map(|i| -300.0 + 10.0 * i as f64).collect();
        let zs: Vec<f64> = (0..=40).map(|j| -200.0 + 10.0 * j as f64).collect();
        let triangles = kneeform::scenario::tessellate(&xs, &zs, |i, j| g(xs[i], zs[j]));
        Part::from_triangles(&triangles).unwrap()
    }

    #[test]
    fn footprint_pruned_cast_equals_parrys_composite_cast() {
        let part = wavy();
        let mut compared = 0;
        for angle in [-30.0, 0.0, 18.0] {
            let knee = KneeForm::new(KneeFormDims::default(), angle);
            for (x, z) in [(150.0, 0.0), (40.0, -70.0), (-100.0, 90.0), (260.0, 150.0)] {
                let push = cast(
                    part.mesh(),
                    &knee,
                    Vector::new(x, -20.0, z),
                    Motion::Push,
                    60.0,
                    1e-4,
                )
                .unwrap()
                .expect("placed");
                let yr = -20.0 + push.travel;
                for (motion, level) in [
                    (Motion::Push, -20.0),
                    (Motion::Slide, yr - 1e-3),
                    (Motion::Slide, yr - 4.0),
                ] {
                    let origin = Vector::new(x, level, z);
                    let ours = cast(part.mesh(), &knee, origin, motion, 800.0, 1e-4).unwrap();
                    let options = ShapeCastOptions {
                        max_time_of_impact: 800.0,
                        stop_at_penetration: false,
                        ..ShapeCastOptions::default()
                    };
                    let pose = KneeForm::pose([x, z], level);
                    let theirs = cast_shapes(
                        &pose,
                        motion.dir(),
                        &knee,
                        &Pose::IDENTITY,
                        Vector::ZERO,
                        part.mesh(),
                        options,
                    )
                    .unwrap();
                    match (ours, theirs) {
                        (Some(a), Some(b)) => {
                            assert_eq!(b.status, ShapeCastStatus::Converged);
                            // Near grazing the travel is ill-conditioned:
                            // compare the gap between the two poses along
                            // the contact normal instead.
                            let gap = (a.travel - b.time_of_impact).abs()
                                * b.normal1.dot(motion.dir()).abs();
                            assert!(gap < 1e-6, "{a:?} vs {b:?}");
                            // Witnesses of a face meeting a nearly parallel
                            // triangle slide along it (gap ~ offset^2 / 2R).
                            assert!((a.witness - b.witness2).length() < 0.05, "{a:?} vs {b:?}");
                            compared += 1;
                        }
                        (None, None) => {}
                        (a, b) => panic!("angle {angle} at {origin:?}: {a:?} vs {b:?}"),
                    }
                }
            }
        }
        assert!(compared >= 20, "only {compared} hits compared");
    }
}
