//! How far things reach over a step: the bounds of a body's nodes widened by what they can travel,
//! the fastest point of a rigid body, and whether two bounds overlap.

use crate::body::DeformableBody;
use crate::rigid::coming_velocity;
use rapier3d::dynamics::RigidBody;
use rapier3d::geometry::ColliderSet;
use rapier3d::glamx::DVec3;

/// An axis-aligned box, minimum and maximum corners (m).
pub(crate) type Bounds = (DVec3, DVec3);

/// `bounds` widened by `by` (m) on every side.
pub(crate) fn widen((low, high): Bounds, by: f64) -> Bounds {
    (low - DVec3::splat(by), high + DVec3::splat(by))
}

/// Whether two boxes overlap.
pub(crate) fn overlap(a: Bounds, b: Bounds) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

/// The fastest a point of `body` moves (m/s) over a step of `dt` (s), bounded by its centre of
/// mass's speed plus its turn rate times the farthest corner of its colliders' bounds.
pub(crate) fn fastest_point(body: &RigidBody, colliders: &ColliderSet, dt: f64) -> f64 {
    let (linvel, angvel) = coming_velocity(body, dt);
    let com = body.mass_properties().world_com.as_dvec3();
    let reach = (body.colliders().iter())
        .filter_map(|&handle| colliders.get(handle))
        .map(|collider| {
            let aabb = collider.compute_aabb();
            let centre = (aabb.mins.as_dvec3() + aabb.maxs.as_dvec3()) / 2.0;
            (centre - com).length() + f64::from(aabb.half_extents().length())
        })
        .fold(0.0, f64::max);
    linvel.length() + angvel.length() * reach
}

/// The bounds of `body`'s nodes widened by `margin` (m) and by twice what its fastest node can
/// travel over a step of `dt` (s) under `gravity` (m/s²), `2 (|v|max + |g| dt) dt`: the reach of
/// its contact detection.
pub(crate) fn body_reach(body: &DeformableBody, margin: f64, dt: f64, gravity: DVec3) -> Bounds {
    let travel = 2.0 * (body.fastest_node_speed() + gravity.length() * dt) * dt;
    widen(body.position_bounds(), margin + travel)
}
