//! The audit's crossing of deformable bodies: a contact point of one body that went through
//! another over the frame. The point was outside the other body (or within the tolerance below
//! its surface) before the frame and is so now (deeper, it is a penetration); its straight path over the frame, taken relative to the other body's motion (its
//! start carried along with the other body's centre of mass, so that a body moving along with
//! the point is followed), is longer than the tolerance, enters the other body's boundary
//! through one triangle and leaves it through one facing away from it (the two outward normals
//! opposed): it passed from one side of the other body to the other, through it. A point sliding
//! along the other body's surface enters and leaves, if at all, through faces that look the same
//! way, and is not counted.
//!
//! The other body is taken where its nodes are at the end of the frame: a body that turned or
//! deformed much within the frame is followed only in its mean translation.

use super::PenetrationTarget;
use super::Penetrations;
use super::penetration::{Checked, depth_inside, disjoint};
use crate::body::{DeformableBody, DeformableBodyHandle};
use rapier3d::glamx::DVec3;

/// Records in `found` the contact points of `checked` that went through `other` (handle
/// `other_handle`) over the frame, `other` having had its nodes at `other_before` (m) at the
/// frame's start.
pub(super) fn through_soft(
    checked: &Checked<'_>,
    (other, other_handle): (&DeformableBody, DeformableBodyHandle),
    other_before: &[DVec3],
    found: &mut Penetrations,
) {
    let (Some(before), Some(before_bounds)) = (&checked.before, checked.bounds_before) else {
        return;
    };
    if !checked.body.collision_groups.test(other.collision_groups)
        || other_before.len() != other.positions().len()
    {
        return;
    }
    let bounds = other.position_bounds();
    let (lo, hi) = (bounds.0 - checked.tolerance, bounds.1 + checked.tolerance);
    let carried = centre_of_mass(other, other.positions()) - centre_of_mass(other, other_before);
    // Every path lies in the box of its ends.
    let starts = (before_bounds.0 + carried, before_bounds.1 + carried);
    let ends = checked.bounds_now;
    if disjoint((starts.0.min(ends.0), starts.1.max(ends.1)), (lo, hi)) {
        return;
    }
    for ((to, _), (from, _)) in checked.now.iter().zip(before) {
        let from = *from + carried;
        if disjoint((from.min(*to), from.max(*to)), (lo, hi)) {
            continue;
        }
        if went_through(other, bounds, (from, *to), checked.tolerance) {
            found.crossed += 1;
            found
                .first_crossed
                .get_or_insert(PenetrationTarget::SoftBody(other_handle));
        }
    }
}

/// Whether the path from `from` to `to` (m), longer than `tolerance` (m), runs through `other`
/// (its nodes within `bounds`, m) from one side to the other, neither end deeper inside it than
/// `tolerance`.
fn went_through(
    other: &DeformableBody,
    bounds: (DVec3, DVec3),
    (from, to): (DVec3, DVec3),
    tolerance: f64,
) -> bool {
    let path = to - from;
    let deep = |x: DVec3| depth_inside(other, bounds, x).is_some_and(|depth| depth > tolerance);
    if path.length() <= tolerance || deep(from) || deep(to) {
        return false;
    }
    // Each cast starts `tolerance` outside its end, so that an end on (or just below) the
    // surface meets the face it lies on.
    let back = tolerance / path.length();
    let reach = 1.0 + 2.0 * back;
    let (Some(entry), Some(exit)) = (
        other.cast_ray(from - path * back, path, reach),
        other.cast_ray(to + path * back, -path, reach),
    ) else {
        return false;
    };
    entry.time_of_impact + exit.time_of_impact < reach && entry.normal.dot(exit.normal) < 0.0
}

/// The centre of mass (m) of `body` with its nodes at `positions` (m).
fn centre_of_mass(body: &DeformableBody, positions: &[DVec3]) -> DVec3 {
    let masses = body.masses();
    let total: f64 = masses.iter().sum();
    let moment = (positions.iter().zip(masses)).fold(DVec3::ZERO, |sum, (x, m)| sum + *x * *m);
    moment / total
}
