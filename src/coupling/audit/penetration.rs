//! The contact side of the audit: where a deformable body's contact points (its boundary nodes,
//! or its embedded mesh's boundary vertices) are after a frame relative to the colliders and the
//! other deformable bodies.
//!
//! - **Penetration**: a point inside a non-sensor collider whose collision groups interact with
//!   the body's (not one of a rigid body the point is glued to) deeper than the tolerance, the
//!   depth being the distance to the collider's surface (parry's point projection); or inside
//!   another deformable body's tetrahedra deeper than the tolerance below its boundary; or a
//!   convex collider whose centre lies that deep inside the body's own tetrahedra (a rigid body
//!   that went in between the contact points).
//! - **Crossing**: a point outside a collider before and after the frame whose straight path over
//!   the frame, taken in the collider's frame (so that a moving collider is followed), runs
//!   through the collider's interior for longer than the tolerance (a solid shape), or through
//!   its surface to end deeper than the tolerance on the far side (a triangle mesh or height
//!   field, which has no interior): the point went through it.
//!
//! Crossings of other deformable bodies are the `crossing` module's; self-penetration is not
//! checked.

use super::{PenetrationTarget, Penetrations};
use crate::body::{DeformableBody, DeformableBodyHandle};
use crate::contact::{contact_point_positions, nearest_point_on_triangle};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Collider, ColliderHandle, ColliderSet};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::parry::query::Ray;
use std::collections::HashMap;

/// A deformable body as the contact check sees it: the body, the nodes glued to rigid bodies,
/// its positions (m) at the end of the previous frame if known, and the tolerance (m).
pub(super) struct Checked<'a> {
    pub(super) body: &'a DeformableBody,
    pub(super) glued: Vec<(RigidBodyHandle, u32)>,
    pub(super) previous: Option<&'a [DVec3]>,
    pub(super) tolerance: f64,
}

/// Records in `found` the body's points deeper than the tolerance in `colliders`, and those
/// that crossed one since the previous frame, whose colliders were at `poses` then.
pub(super) fn against_colliders(
    checked: &Checked<'_>,
    colliders: &ColliderSet,
    bodies: &RigidBodySet,
    poses: &HashMap<ColliderHandle, Pose>,
    found: &mut Penetrations,
) {
    let body = checked.body;
    let now = contact_point_positions(body, body.positions());
    let before = checked
        .previous
        .filter(|previous| previous.len() == body.positions().len())
        .map(|previous| contact_point_positions(body, previous));
    for (handle, collider) in colliders.iter() {
        if collider.is_sensor() || !body.collision_groups.test(collider.collision_groups()) {
            continue;
        }
        let parent = collider.parent().filter(|h| bodies.get(*h).is_some());
        let glued: Vec<u32> = (checked.glued.iter())
            .filter(|(rigid, _)| Some(*rigid) == parent)
            .map(|(_, node)| *node)
            .collect();
        for (i, (x, nodes)) in now.iter().enumerate() {
            if nodes.iter().any(|n| glued.contains(n)) {
                continue;
            }
            let depth = depth_in(collider, *x);
            if depth > checked.tolerance {
                found.add_penetration(depth, PenetrationTarget::Collider(handle));
            } else if let (Some(before), Some(pose)) = (&before, poses.get(&handle))
                && depth <= 0.0
                && crossed(collider, pose, before[i].0, *x, checked.tolerance)
            {
                found.crossed += 1;
                found
                    .first_crossed
                    .get_or_insert(PenetrationTarget::Collider(handle));
            }
        }
    }
}

/// How deep (m) `x` lies inside `collider` (zero or less outside): its distance to the surface.
fn depth_in(collider: &Collider, x: DVec3) -> f64 {
    let aabb = collider.compute_aabb();
    let (lo, hi) = (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3());
    if x.cmplt(lo).any() || x.cmpgt(hi).any() {
        return 0.0;
    }
    let projection = collider
        .shape()
        .project_point(collider.position(), x.as_vec3(), false);
    if projection.is_inside {
        (projection.point.as_dvec3() - x).length()
    } else {
        0.0
    }
}

/// Whether the point that was at `from` (m) when `collider` was at `then` went through it on its
/// way to `to` (m), a path longer than `tolerance` (m).
fn crossed(collider: &Collider, then: &Pose, from: DVec3, to: DVec3, tolerance: f64) -> bool {
    let pose = collider.position();
    // Where the point started, carried along with the collider's motion over the frame.
    let from = pose
        .transform_point(then.inverse_transform_point(from.as_vec3()))
        .as_dvec3();
    let path = to - from;
    let shape = collider.shape();
    // A point inside at the start was a penetration then, not a crossing now.
    if path.length() <= tolerance || shape.project_point(pose, from.as_vec3(), false).is_inside {
        return false;
    }
    let forward = Ray::new(from.as_vec3(), path.as_vec3());
    if shape.as_trimesh().is_some() || shape.as_heightfield().is_some() {
        if shape.cast_ray(pose, &forward, 1.0, false).is_none() {
            return false;
        }
        // A surface without interior: through it, and now beyond the tolerance from it.
        let projection = shape.project_point(pose, to.as_vec3(), false);
        return (projection.point.as_dvec3() - to).length() > tolerance;
    }
    let backward = Ray::new(to.as_vec3(), (-path).as_vec3());
    let (Some(entry), Some(exit)) = (
        shape.cast_ray_and_get_normal(pose, &forward, 1.0, false),
        shape.cast_ray_and_get_normal(pose, &backward, 1.0, false),
    ) else {
        return false;
    };
    // In through one face and out through one facing away from it: to the far side.
    entry.time_of_impact + exit.time_of_impact < 1.0 && entry.normal.dot(exit.normal) < 0.0
}

/// Records in `found` the points of `checked` that lie inside the tetrahedra of `other` deeper
/// than the tolerance below its boundary.
pub(super) fn against_soft(
    checked: &Checked<'_>,
    other: &DeformableBody,
    other_handle: DeformableBodyHandle,
    found: &mut Penetrations,
) {
    if !checked.body.collision_groups.test(other.collision_groups) {
        return;
    }
    let (body, bounds) = (checked.body, other.position_bounds());
    for (point, _) in contact_point_positions(body, body.positions()) {
        if let Some(depth) = depth_inside(other, bounds, point)
            && depth > checked.tolerance
        {
            found.add_penetration(depth, PenetrationTarget::SoftBody(other_handle));
        }
    }
}

/// Records in `found` the colliders inside the body of `checked`: a convex collider (not a
/// sensor, interacting with the body, of no rigid body a node of it is glued to) whose centre
/// (its frame's origin, when inside the shape) lies inside the body's tetrahedra deeper than the
/// tolerance below its boundary, the depth being the centre's (a lower bound of the collider's
/// own): a rigid body that went into the soft one between its contact points.
pub(super) fn colliders_inside(
    checked: &Checked<'_>,
    colliders: &ColliderSet,
    found: &mut Penetrations,
) {
    let (body, bounds) = (checked.body, checked.body.position_bounds());
    for (handle, collider) in colliders.iter() {
        let parent = collider.parent();
        let glued = (checked.glued.iter()).any(|(rigid, _)| Some(*rigid) == parent);
        if glued || collider.is_sensor() || !body.collision_groups.test(collider.collision_groups())
        {
            continue;
        }
        let (shape, pose) = (collider.shape(), collider.position());
        if shape.as_support_map().is_none() || !shape.contains_point(pose, pose.translation) {
            continue;
        }
        if let Some(depth) = depth_inside(body, bounds, pose.translation.as_dvec3())
            && depth > checked.tolerance
        {
            found.add_penetration(depth, PenetrationTarget::Collider(handle));
        }
    }
}

/// How deep (m) `point` lies inside `body`, whose nodes lie within `(lo, hi)` (m): its distance
/// to the boundary if it is within one of the body's tetrahedra, `None` otherwise.
pub(super) fn depth_inside(
    body: &DeformableBody,
    (lo, hi): (DVec3, DVec3),
    point: DVec3,
) -> Option<f64> {
    if point.cmplt(lo).any() || point.cmpgt(hi).any() {
        return None;
    }
    let x = body.positions();
    let inside = body.mesh().tets().iter().any(|tet| {
        let [a, b, c, d] = tet.map(|n| x[n as usize]);
        contains(a, b, c, d, point)
    });
    if !inside {
        return None;
    }
    let depth = (body.surface.triangles.iter())
        .filter_map(|t| nearest_point_on_triangle(t.map(|n| x[n as usize]), point))
        .map(|(_, nearest)| (nearest - point).length())
        .fold(f64::INFINITY, f64::min);
    depth.is_finite().then_some(depth)
}

/// Whether `p` lies inside the tetrahedron `a b c d` (m) of either orientation, or on its
/// boundary.
fn contains(a: DVec3, b: DVec3, c: DVec3, d: DVec3, p: DVec3) -> bool {
    let volume = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| (b - a).cross(c - a).dot(d - a);
    let whole = volume(a, b, c, d);
    if whole == 0.0 {
        return false;
    }
    [
        volume(p, b, c, d),
        volume(a, p, c, d),
        volume(a, b, p, d),
        volume(a, b, c, p),
    ]
    .iter()
    .all(|part| part * whole.signum() >= 0.0)
}
