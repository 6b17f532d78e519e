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
//! - **Crossing**: a point outside a collider before and after the frame whose path over the
//!   frame, taken in the collider's frame (so that a moving collider is followed, its turning
//!   included, see the `collider_path` module), enters a solid shape through one face and leaves
//!   it through one facing away from it (a path longer than the tolerance), or goes through its
//!   surface to end deeper than the tolerance on the far side (a triangle mesh or height field,
//!   which has no interior): the point went through it.
//!
//! Crossings of other deformable bodies are the `crossing` module's; self-penetration is not
//! checked.

use super::collider_path::ColliderMotion;
use super::{PenetrationTarget, Penetrations};
use crate::body::{DeformableBody, DeformableBodyHandle};
use crate::contact::{contact_point_positions, nearest_point_on_triangle};
use crate::mesh::bounding_box;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Collider, ColliderHandle, ColliderSet};
use rapier3d::glamx::DVec3;
use rapier3d::parry::query::Ray;
use std::collections::HashMap;

/// A deformable body as the contact check sees it: the body, the nodes glued to rigid bodies,
/// its contact points now and at the end of the previous frame if known (m, each with the nodes
/// it interpolates) with the boxes holding them, and the tolerance (m).
pub(super) struct Checked<'a> {
    pub(super) body: &'a DeformableBody,
    pub(super) glued: Vec<(RigidBodyHandle, u32)>,
    pub(super) now: Vec<(DVec3, Vec<u32>)>,
    pub(super) before: Option<Vec<(DVec3, Vec<u32>)>>,
    /// The box (m) holding the contact points now.
    pub(super) bounds_now: (DVec3, DVec3),
    /// The box (m) holding them at the end of the previous frame, if known.
    pub(super) bounds_before: Option<(DVec3, DVec3)>,
    pub(super) tolerance: f64,
}

impl<'a> Checked<'a> {
    /// The check of `body` with `glued` nodes, whose nodes were at `previous` (m) at the end of
    /// the previous frame if known (ignored unless one per node), within `tolerance` (m).
    pub(super) fn new(
        body: &'a DeformableBody,
        glued: Vec<(RigidBodyHandle, u32)>,
        previous: Option<&[DVec3]>,
        tolerance: f64,
    ) -> Self {
        let before = previous
            .filter(|previous| previous.len() == body.positions().len())
            .map(|previous| contact_point_positions(body, previous));
        let now = contact_point_positions(body, body.positions());
        let bounds = |points: &[(DVec3, Vec<u32>)]| bounding_box(points.iter().map(|(x, _)| *x));
        Self {
            body,
            glued,
            bounds_now: bounds(&now),
            bounds_before: before.as_deref().map(bounds),
            now,
            before,
            tolerance,
        }
    }

    /// The longest distance (m) a contact point moved over the frame (zero if not known).
    fn longest_move(&self) -> f64 {
        let Some(before) = &self.before else {
            return 0.0;
        };
        (self.now.iter().zip(before))
            .map(|((to, _), (from, _))| (*to - *from).length())
            .fold(0.0, f64::max)
    }
}

/// Whether the boxes `(lo, hi)` (m) share no point.
pub(super) fn disjoint(a: (DVec3, DVec3), b: (DVec3, DVec3)) -> bool {
    a.0.cmpgt(b.1).any() || a.1.cmplt(b.0).any()
}

/// Records in `found` the body's points deeper than the tolerance in `colliders`, and those
/// that crossed one since the previous frame, in which the colliders made their `motions`.
///
/// A collider is passed over whole when its box, widened by how far a point's path in its frame
/// can lie from the point's end, misses the points' box: each place on the path is where the
/// point was at some instant, carried with the collider's motion from that instant to now, so it
/// lies within the point's own move plus that carry from its end, the carry largest at a corner
/// of a box holding the point's places (the carrying is affine, its length convex).
pub(super) fn against_colliders(
    checked: &Checked<'_>,
    colliders: &ColliderSet,
    bodies: &RigidBodySet,
    motions: &HashMap<ColliderHandle, ColliderMotion>,
    found: &mut Penetrations,
) {
    let (now_bounds, before_bounds) = (checked.bounds_now, checked.bounds_before);
    let longest_move = checked.longest_move();
    // The points' paths, one after another.
    let mut path = Vec::new();
    for (handle, collider) in colliders.iter() {
        if collider.is_sensor()
            || !checked
                .body
                .collision_groups
                .test(collider.collision_groups())
        {
            continue;
        }
        let aabb = collider.compute_aabb();
        let aabb = (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3());
        let motion = motions.get(&handle);
        // The points' places at the instants the paths are taken at lie within the box of
        // their ends (on straight lines between them).
        let carried = match (before_bounds, motion) {
            (Some(before), Some(motion)) => {
                let ends = (before.0.min(now_bounds.0), before.1.max(now_bounds.1));
                motion.longest_carry(ends)
            }
            _ => 0.0,
        };
        // The tolerance on top covers the single-precision poses' round-off in `crossed`.
        let reach = longest_move + carried + checked.tolerance;
        if disjoint((aabb.0 - reach, aabb.1 + reach), now_bounds) {
            continue;
        }
        let parent = collider.parent().filter(|h| bodies.get(*h).is_some());
        let glued: Vec<u32> = (checked.glued.iter())
            .filter(|(rigid, _)| Some(*rigid) == parent)
            .map(|(_, node)| *node)
            .collect();
        for (i, (x, nodes)) in checked.now.iter().enumerate() {
            if nodes.iter().any(|n| glued.contains(n)) {
                continue;
            }
            let depth = depth_in(collider, aabb, *x);
            if depth > checked.tolerance {
                found.add_penetration(depth, PenetrationTarget::Collider(handle));
            } else if let (Some(before), Some(motion)) = (&checked.before, motion)
                && depth <= 0.0
                && motion.may_meet((before[i].0, *x), checked.tolerance)
                && crossed(
                    (collider, aabb),
                    motion,
                    (before[i].0, *x),
                    &mut path,
                    checked.tolerance,
                )
            {
                found.crossed += 1;
                found
                    .first_crossed
                    .get_or_insert(PenetrationTarget::Collider(handle));
            }
        }
    }
}

/// How deep (m) `x` lies inside `collider`, whose box is `(lo, hi)` (m), (zero or less
/// outside): its distance to the surface.
fn depth_in(collider: &Collider, (lo, hi): (DVec3, DVec3), x: DVec3) -> f64 {
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

/// Whether the point that moved from `from` to `to` (m) while `collider` (whose box is `aabb`,
/// m) made its `motion` went through it: the point's path in the collider's frame
/// ([`ColliderMotion::path_into`], written into `path`), longer than `tolerance` (m), entered a
/// solid shape through one face and left it through one facing away from it, or went through a
/// surface without interior (a triangle mesh or height field) to end beyond the tolerance from
/// it.
fn crossed(
    (collider, aabb): (&Collider, (DVec3, DVec3)),
    motion: &ColliderMotion,
    (from, to): (DVec3, DVec3),
    path: &mut Vec<DVec3>,
    tolerance: f64,
) -> bool {
    let pose = collider.position();
    motion.path_into((from, to), path);
    let bounds = bounding_box(path.iter().copied());
    if disjoint(bounds, aabb) {
        return false;
    }
    let shape = collider.shape();
    let length: f64 = path.windows(2).map(|s| (s[1] - s[0]).length()).sum();
    // A point inside at the start was a penetration then, not a crossing now.
    if length <= tolerance
        || shape
            .project_point(pose, path[0].as_vec3(), false)
            .is_inside
    {
        return false;
    }
    // The first time (m along the path from its start) the segments of `path`, in order, meet
    // the shape's surface, with the surface's normal there.
    let first_hit = |path: &mut dyn Iterator<Item = (DVec3, DVec3)>| {
        let mut walked = 0.0;
        for (a, b) in path {
            let ray = Ray::new(a.as_vec3(), (b - a).as_vec3());
            if let Some(hit) = shape.cast_ray_and_get_normal(pose, &ray, 1.0, false) {
                return Some((
                    walked + f64::from(hit.time_of_impact) * (b - a).length(),
                    hit,
                ));
            }
            walked += (b - a).length();
        }
        None
    };
    let forward = || path.windows(2).map(|s| (s[0], s[1]));
    let Some((entry, entry_hit)) = first_hit(&mut forward()) else {
        return false;
    };
    if shape.as_trimesh().is_some() || shape.as_heightfield().is_some() {
        // A surface without interior: through it, and now beyond the tolerance from it.
        let projection = shape.project_point(pose, to.as_vec3(), false);
        return (projection.point.as_dvec3() - to).length() > tolerance;
    }
    let mut backward = path.windows(2).rev().map(|s| (s[1], s[0]));
    let Some((exit, exit_hit)) = first_hit(&mut backward) else {
        return false;
    };
    // In through one face and out through one facing away from it: to the far side.
    entry + exit < length && entry_hit.normal.dot(exit_hit.normal) < 0.0
}

/// Records in `found` the points of `checked` that lie inside the tetrahedra of `other` deeper
/// than the tolerance below its boundary.
pub(super) fn against_soft(
    checked: &Checked<'_>,
    other: &DeformableBody,
    other_handle: DeformableBodyHandle,
    found: &mut Penetrations,
) {
    let bounds = other.position_bounds();
    if !checked.body.collision_groups.test(other.collision_groups)
        || disjoint(bounds, checked.bounds_now)
    {
        return;
    }
    for (point, _) in &checked.now {
        if let Some(depth) = depth_inside(other, bounds, *point)
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
