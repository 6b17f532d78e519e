//! What counts as still for sleeping, and what disturbs a sleeping body: the rigid bodies it
//! rests with, the colliders within its bounds.

use super::Asleep;
use crate::constraint::BodyConstraints;
use crate::coupling::RigidSets;
use crate::coupling::reach::{Bounds, fastest_point, overlap, widen};
use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodySet, RigidBodyType};
use rapier3d::geometry::{ColliderHandle, ColliderSet};
use rapier3d::math::Pose;

/// Whether `body` is still for a deformable body resting with it: fixed, sleeping, or moving
/// slower than `speed` (m/s) everywhere (a kinematic one not at all) over a step of `dt` (s).
pub(super) fn rigid_still(body: &RigidBody, colliders: &ColliderSet, speed: f64, dt: f64) -> bool {
    match body.body_type() {
        RigidBodyType::Fixed => true,
        RigidBodyType::Dynamic => body.is_sleeping() || fastest_point(body, colliders, dt) < speed,
        _ => fastest_point(body, colliders, dt) == 0.0,
    }
}

/// The non-sensor colliders whose bounds, widened by their travel over `dt` (s), overlap
/// `bounds`, with their poses, sorted by handle, and whether all their rigid bodies are still
/// (see [`rigid_still`]).
pub(super) fn colliders_within(
    bounds: Bounds,
    colliders: &ColliderSet,
    bodies: &RigidBodySet,
    speed: f64,
    dt: f64,
) -> (Vec<(ColliderHandle, Pose)>, bool) {
    let mut within = Vec::new();
    let mut still = true;
    for (handle, collider) in colliders.iter().filter(|(_, c)| !c.is_sensor()) {
        let aabb = collider.compute_aabb();
        let parent = collider.parent().and_then(|parent| bodies.get(parent));
        let travel = parent.map_or(0.0, |body| 2.0 * fastest_point(body, colliders, dt) * dt);
        let reach = widen((aabb.mins.as_dvec3(), aabb.maxs.as_dvec3()), travel);
        if overlap(bounds, reach) {
            within.push((handle, *collider.position()));
            still &= parent.is_none_or(|body| rigid_still(body, colliders, speed, dt));
        }
    }
    within.sort_unstable_by_key(|(handle, _)| handle.into_raw_parts());
    (within, still)
}

/// The rigid bodies `constraints` touch or are glued to, sorted and without repeats.
pub(super) fn partners_of(constraints: &BodyConstraints) -> Vec<RigidBodyHandle> {
    let mut partners: Vec<RigidBodyHandle> = (constraints.rigid_impulses())
        .map(|(handle, ..)| handle)
        .chain(constraints.attachments().iter().map(|a| a.body))
        .collect();
    partners.sort_unstable_by_key(|handle| handle.into_raw_parts());
    partners.dedup();
    partners
}

/// Whether the rigid world disturbs a body asleep with `asleep` within `widened` bounds over a
/// step of `dt` (s): a rigid body it rested with woke in rapier, moves or left, a collider came
/// within its bounds, left them or was moved there (a fixed one set elsewhere by hand), or one
/// there moves faster than `speed` (m/s).
pub(super) fn rigid_disturbs(
    asleep: &Asleep,
    widened: Bounds,
    rigid: &RigidSets<'_>,
    speed: f64,
    dt: f64,
) -> bool {
    let (within, still) = colliders_within(widened, rigid.colliders, rigid.bodies, speed, dt);
    !still
        || within != asleep.colliders
        || asleep.partners.iter().any(|&partner| {
            rigid.bodies.get(partner).is_none_or(|body| {
                (body.is_dynamic() && !body.is_sleeping())
                    || !rigid_still(body, rigid.colliders, 0.0, dt)
            })
        })
}

/// Whether two sleeping bodies rested together: their bounds, widened by `margin` (m), overlap,
/// or they touched the same dynamic rigid body of `bodies`.
pub(super) fn rested_together(a: &Asleep, b: &Asleep, bodies: &RigidBodySet, margin: f64) -> bool {
    overlap(widen(a.bounds, margin), widen(b.bounds, margin))
        || (a.partners.iter())
            .any(|p| b.partners.contains(p) && bodies.get(*p).is_some_and(RigidBody::is_dynamic))
}
