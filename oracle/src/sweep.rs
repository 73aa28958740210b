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
//! the travel still open; where it overlaps deeper than the grazing depth,
//! the impact is found again by bisection on GJK distances
//! (`impact_by_bisection`), and only if that fails too does the cast
//! fail.

use std::cell::Cell;

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::details::{
    cast_shapes_support_map_support_map, closest_points_support_map_support_map,
    contact_support_map_support_map, distance_support_map_support_map,
};
use parry3d_f64::query::{ClosestPoints, ShapeCastHit, ShapeCastOptions, ShapeCastStatus};
use parry3d_f64::shape::TriMesh;

use crate::FailureReason;
use crate::knee_form::{End, KneeForm, SweptKneeForm};
use crate::prune::{Sweep, far_from_sweep};

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
/// overlap (mm) below which a reported miss is believed. With `prune`,
/// triangles the cast cannot meet are skipped before GJK
/// ([`crate::prune`]; the same answer, faster).
pub(crate) fn cast(
    mesh: &TriMesh,
    knee: &KneeForm,
    origin: Vector,
    motion: Motion,
    max_travel: f64,
    grazing: f64,
    prune: bool,
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
        // The slide's cheap rejections first: the footprint's ends (below)
        // cost a few square roots, and most nodes fail on y or x alone.
        if motion == Motion::Slide
            && (mins.y > origin.y || maxs.y < origin.y - width || mins.x > origin.x + x_back)
        {
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
    let placed = knee.triangle().map(|[x, z]| [x + origin.x, z + origin.z]);
    let leaf = |id: u32, best: f64| -> Option<ShapeCastHit> {
        let triangle = mesh.triangle(id);
        // A triangle further than a margin from all the knee-form sweeps
        // within `best` cannot be met (crate::prune): GJK would say so,
        // and the contact query confirm it, at far greater cost.
        let swept = match motion {
            Motion::Slide => Sweep {
                triangle: placed,
                sweep_x: best,
                y0: origin.y - width,
                y1: origin.y,
                radius: knee.dims().radius,
            },
            Motion::Push => Sweep {
                triangle: placed,
                sweep_x: 0.0,
                y0: origin.y - width,
                y1: origin.y + best,
                radius: knee.dims().radius,
            },
        };
        if prune && far_from_sweep(&swept, [triangle.a, triangle.b, triangle.c]) {
            return None;
        }
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
                if !overlap.is_some_and(|c| -c.dist > grazing) {
                    return None;
                }
                // GJK's cast reported no hit where the swept knee-form
                // seems to overlap the triangle: decide by the distance.
                match impact_by_bisection(&pos12, vel12, knee, &triangle, best) {
                    Ok(hit) => hit,
                    Err(()) => {
                        failure.set(Some(FailureReason::UnconfirmedMiss));
                        None
                    }
                }
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

/// How closely [`impact_by_bisection`] brackets the time of impact (mm of
/// travel). Its answer is as accurate as GJK's distance query near 0:
/// within about 5e-6 mm of the converged cast's along the contact normal
/// at part-sized coordinates (measured in this module's tests).
const BISECTION_TOL: f64 = 1e-9;

/// The first time (mm of travel, at most `max_t`) at which `knee` moving
/// the triangle by `vel12` per mm relative to it (their start poses
/// `pos12`, a translation) touches the triangle, found without GJK's cast:
/// for convex shapes in linear motion the distance between them is a
/// convex function of time, so a golden-section search finds a time at
/// which they meet (if any), and bisection between 0 and it the first such
/// time, to [`BISECTION_TOL`]. `Ok(None)` when the distance stays positive
/// up to `max_t` (no impact before it); an error when they already touch
/// at the start or no witness can be read.
///
/// This decides where GJK's cast reports no hit but the contact query on
/// the swept knee-form reports an overlap deeper than the grazing depth
/// (it was an [`FailureReason::UnconfirmedMiss`] before): either the cast
/// ran out of iterations on a nearly parallel pair, or the swept shape's
/// penetration depth (EPA on a long thin shape) is off while the two only
/// graze at `max_t` (measured on the wave: a minimum distance of 8e-8 mm
/// against a reported overlap above 1e-4 mm). Each step is a GJK distance
/// query, which converges where the cast and EPA do not.
fn impact_by_bisection(
    pos12: &Pose,
    vel12: Vector,
    knee: &KneeForm,
    triangle: &parry3d_f64::shape::Triangle,
    max_t: f64,
) -> Result<Option<ShapeCastHit>, ()> {
    let at = |t: f64| Pose::from_translation(pos12.translation + vel12 * t);
    let distance = |t: f64| distance_support_map_support_map(&at(t), knee, triangle);
    if distance(0.0) <= 0.0 || !max_t.is_finite() {
        return Err(());
    }
    // A time at which they meet: the distance's minimum on [0, max_t].
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (0.0, max_t);
    let mut meet = None;
    for _ in 0..200 {
        if distance(b) <= 0.0 {
            meet = Some(b);
            break;
        }
        let (c, d) = (b - golden * (b - a), a + golden * (b - a));
        let (dc, dd) = (distance(c), distance(d));
        if dc <= 0.0 {
            meet = Some(c);
            break;
        }
        if dd <= 0.0 {
            meet = Some(d);
            break;
        }
        if dc < dd {
            b = d;
        } else {
            a = c;
        }
        if b - a < BISECTION_TOL {
            break;
        }
    }
    let Some(meet) = meet else {
        // Apart all along (the distance is convex in time: its minimum
        // was found).
        return Ok(None);
    };
    // The first time they meet, between 0 (apart) and `meet` (touching).
    let (mut lo, mut hi) = (0.0, meet);
    while hi - lo > BISECTION_TOL {
        let mid = 0.5 * (lo + hi);
        if distance(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let ClosestPoints::WithinMargin(witness1, witness2) =
        closest_points_support_map_support_map(&at(lo), knee, triangle, f64::MAX)
    else {
        return Err(());
    };
    let normal1 = (at(lo).transform_point(witness2) - witness1).normalize_or_zero();
    Ok(Some(ShapeCastHit {
        time_of_impact: lo,
        witness1,
        witness2,
        normal1,
        normal2: -(pos12.rotation.inverse() * normal1),
        status: ShapeCastStatus::Converged,
        subshape1: 0,
        subshape2: 0,
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

    /// Where GJK's cast converges, the bisection on distances finds the
    /// same impact (time and witness), and it finds none where the cast
    /// finds none.
    #[test]
    fn impact_by_bisection_agrees_with_the_converged_cast() {
        let part = wavy();
        let mesh = part.mesh();
        let (mut hits, mut misses) = (0, 0);
        let mut worst_gap: f64 = 0.0;
        for angle in [-30.0, 0.0, 18.0] {
            let knee = KneeForm::new(KneeFormDims::default(), angle);
            for (x, z, level) in [(150.0, 0.0, -3.0), (40.0, -70.0, -1.0), (-100.0, 90.0, 2.0)] {
                let origin = Vector::new(x, level, z);
                let pos12 = Pose::from_translation(-origin);
                let vel12 = -Motion::Slide.dir();
                for id in (0..mesh.num_triangles() as u32).step_by(7) {
                    let triangle = mesh.triangle(id);
                    if distance_support_map_support_map(&pos12, &knee, &triangle) <= 0.0 {
                        // Already touching: no impact to compare.
                        continue;
                    }
                    let options = ShapeCastOptions {
                        max_time_of_impact: 200.0,
                        stop_at_penetration: false,
                        ..ShapeCastOptions::default()
                    };
                    let cast = cast_shapes_support_map_support_map(
                        &pos12, vel12, &knee, &triangle, options,
                    );
                    let ours = impact_by_bisection(&pos12, vel12, &knee, &triangle, 200.0);
                    let tangent = |n: Vector| n.dot(Motion::Slide.dir()).abs() < 0.1;
                    if cast.is_some_and(|c| tangent(c.normal1))
                        || matches!(ours, Ok(Some(o)) if tangent(o.normal1))
                    {
                        // A contact tangent to the motion (the side of the
                        // knee-form along an edge): its time is undefined
                        // to within the casts' accuracy over the whole
                        // graze.
                        continue;
                    }
                    match (cast, ours) {
                        (Some(c), Ok(Some(o))) if c.status == ShapeCastStatus::Converged => {
                            let gap = (c.time_of_impact - o.time_of_impact).abs()
                                * c.normal1.dot(Motion::Slide.dir()).abs();
                            // They differ by microns along the normal
                            // (measured up to 5.4e-6 mm at coordinates of
                            // a few hundred mm: the cast may stop short,
                            // the distance query reads 0 only within its
                            // own tolerance), parry's accuracy here.
                            assert!(gap < 1e-5, "{c:?} vs {o:?}");
                            worst_gap = worst_gap.max(gap);
                            assert!((c.witness2 - o.witness2).length() < 0.05, "{c:?} vs {o:?}");
                            hits += 1;
                        }
                        (None, Ok(None)) => misses += 1,
                        // An impact at the very end of the travel either
                        // side of it.
                        (Some(c), Ok(None)) if c.time_of_impact > 200.0 - 1e-6 => {}
                        (None, Ok(Some(o))) if o.time_of_impact > 200.0 - 1e-6 => {}
                        (c, o) => {
                            panic!("angle {angle} at {origin:?}, triangle {id}: {c:?} vs {o:?}")
                        }
                    }
                }
            }
        }
        assert!(
            hits >= 100 && misses >= 1000,
            "{hits} hits, {misses} misses"
        );
        eprintln!("{hits} hits (worst gap {worst_gap:e} mm), {misses} misses");
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
                    true,
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
                    let ours = cast(part.mesh(), &knee, origin, motion, 800.0, 1e-4, true).unwrap();
                    // The prune changes nothing, to the bit.
                    let all = cast(part.mesh(), &knee, origin, motion, 800.0, 1e-4, false).unwrap();
                    assert_eq!(
                        ours.map(|c| (c.travel.to_bits(), c.witness.to_array().map(f64::to_bits))),
                        all.map(|c| (c.travel.to_bits(), c.witness.to_array().map(f64::to_bits)))
                    );
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
