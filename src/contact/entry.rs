//! Continuous contact with colliders: a surface point that was outside a collider at the last
//! detection and is now inside it, or past it, entered by the face its path from there crosses,
//! and that face, not the nearest one, is its contact plane. Without it, a point pushed more than
//! half way into a thin wall (a plate, a box's side) within one step is found nearest to the far
//! face and pushed out through it, and a point carried right through in one step is found on the
//! far side: both end beyond the wall.
//!
//! The path is the straight segment from where the point was at the last detection, carried
//! along with the collider's motion since then (so that a moving collider is seen from its own
//! frame), to where it is now; its entry face is taken where the nearest face looks the other
//! way (elsewhere the two give the same plane). A point that was already inside at the last detection keeps the
//! plane it had then while its nearest face is on the other side of the collider. The explicit
//! sweeps, which re-project a point onto its collider every substep, keep its plane likewise
//! when the nearest face turns away from it.

use super::detect::nearest_surface_point;
use rapier3d::geometry::{Ray, Shape};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;

/// What the last detection saw of a point's contact with a collider: where the point was (m),
/// the collider's pose then, and the contact plane it was given (a point, m, and the outward
/// unit normal), and the stiffenings its load called for.
#[derive(Debug, Clone, Copy)]
pub(super) struct LastContact {
    pub(super) at: DVec3,
    pub(super) pose: Pose,
    pub(super) point: DVec3,
    pub(super) normal: DVec3,
    pub(super) stiffening: super::stiffening::Stiffening,
}

/// The contact plane of a point at `x` (m) against `shape` at `pose`: its surface point, the
/// outward unit normal there, and the signed distance of `x` from it (negative inside or
/// behind), given what the last detection saw of it (see the module documentation).
pub(super) fn entered_surface_point(
    shape: &dyn Shape,
    pose: &Pose,
    x: DVec3,
    last: Option<&LastContact>,
) -> Option<(DVec3, DVec3, f64)> {
    let nearest = nearest_surface_point(shape, pose, x);
    let Some(last) = last else {
        return nearest;
    };
    let from = carried(last, pose);
    let path = x - from;
    let length = path.length();
    if length > 0.0 {
        let ray = Ray::new(from.as_vec3(), (path / length).as_vec3());
        if let Some(hit) = shape.cast_ray_and_get_normal(pose, &ray, length as f32, true)
            && hit.time_of_impact > 0.0
        {
            let point = from + path * (f64::from(hit.time_of_impact) / length);
            let normal = hit.normal.as_dvec3().normalize_or_zero();
            // The entry face matters only where the nearest one looks the other way (past the
            // middle of a wall, or through it); elsewhere both give the same plane.
            let turned = nearest.is_none_or(|(_, nearest, _)| nearest.dot(normal) <= 0.0);
            if normal.dot(path) < 0.0 && turned {
                return Some((point, normal, (x - point).dot(normal)));
            }
        }
    }
    // Inside already at the last detection: its plane then, carried with the collider, while
    // the nearest face looks the other way.
    match nearest {
        Some((_, normal, distance)) if distance < 0.0 && normal.dot(last.normal) < 0.0 => {
            let point = carried_point(last.point, &last.pose, pose);
            let normal = (pose.rotation * last.pose.rotation.inverse() * last.normal.as_vec3())
                .as_dvec3()
                .normalize_or_zero();
            Some((point, normal, (x - point).dot(normal)))
        }
        other => other,
    }
}

/// Where the point of `last` would be now had it moved with the collider, now at `pose`.
fn carried(last: &LastContact, pose: &Pose) -> DVec3 {
    carried_point(last.at, &last.pose, pose)
}

/// `point` (m) fixed to a collider that moved from `before` to `now`.
fn carried_point(point: DVec3, before: &Pose, now: &Pose) -> DVec3 {
    now.transform_point(before.inverse_transform_point(point.as_vec3()))
        .as_dvec3()
}
