//! What a stand-in's rapier contacts exerted in a rapier step: per collider it touched, the
//! impulse `J = Σ Jₙ n` (N s) of the normal impulses rapier's solver applied at the contact points
//! `p` and its angular impulse `Σ p × Jₙ n` about the world origin (N m s), or about the centre of
//! mass of the collider's dynamic rigid body; and the sum of their magnitudes `Σ |Jₙ|`, which
//! predicts the stand-in's strain. Friction impulses are not counted (rapier keeps them in a
//! tangent basis of its own). And what the colliders about to meet a body will do to it
//! ([`approaching`]).

use crate::coupling::reach::{Bounds, fastest_point, overlap, widen};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderHandle, ColliderSet, InteractionGroups, NarrowPhase};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::parry::query;
use rapier3d::parry::shape::Cuboid;

/// One collider's share of a stand-in's contact impulses over a rapier step.
pub(super) struct ContactImpulse {
    /// The collider pushed.
    pub(super) collider: ColliderHandle,
    /// Its dynamic rigid body, with the angular impulse about its centre of mass (N m s).
    pub(super) rigid: Option<(RigidBodyHandle, DVec3)>,
    /// The impulse on it (N s).
    pub(super) impulse: DVec3,
    /// The angular impulse on it about the world origin (N m s).
    pub(super) angular_impulse: DVec3,
}

/// The impulses the collider `own` exerted through rapier's contacts in the step `narrow_phase`
/// holds, per collider touched, and the sum of their magnitudes (N s).
pub(super) fn contact_impulses(
    own: ColliderHandle,
    (bodies, colliders, narrow_phase): (&RigidBodySet, &ColliderSet, &NarrowPhase),
) -> (Vec<ContactImpulse>, f64) {
    let mut pushed = Vec::new();
    let mut magnitude = 0.0;
    for pair in narrow_phase.contact_pairs_with(own) {
        let (first, other) = if pair.collider1 == own {
            (true, pair.collider2)
        } else {
            (false, pair.collider1)
        };
        let (Some(pose1), Some(other_collider)) = (
            colliders.get(pair.collider1).map(|c| *c.position()),
            colliders.get(other),
        ) else {
            continue;
        };
        let (mut impulse, mut angular_impulse) = (DVec3::ZERO, DVec3::ZERO);
        for manifold in pair.solver_manifolds() {
            // rapier's normal points from collider 1 to collider 2.
            let sign = if first { 1.0 } else { -1.0 };
            let normal = manifold.data.normal.as_dvec3() * sign;
            let local = manifold.subshape_pos1().copied();
            for point in &manifold.points {
                let j = f64::from(point.data.impulse);
                let p1 = local.map_or(point.local_p1, |pose| pose * point.local_p1);
                let p = (pose1 * p1).as_dvec3();
                impulse += normal * j;
                angular_impulse += p.cross(normal * j);
                magnitude += j.abs();
            }
        }
        if impulse == DVec3::ZERO {
            continue;
        }
        let rigid = (other_collider.parent())
            .and_then(|handle| bodies.get(handle).map(|body| (handle, body)))
            .map(|(handle, body)| {
                let com = body.center_of_mass().as_dvec3();
                (handle, angular_impulse - com.cross(impulse))
            });
        pushed.push(ContactImpulse {
            collider: other,
            rigid,
            impulse,
            angular_impulse,
        });
    }
    (pushed, magnitude)
}

/// A body about to stand in or standing in, as [`approaching_force`] sees it.
pub(super) struct Approach {
    /// Its bounds (m).
    pub(super) bounds: Bounds,
    /// Its fastest point's speed (m/s).
    pub(super) speed: f64,
    /// Its mass (kg).
    pub(super) mass: f64,
    /// Its collision groups.
    pub(super) groups: InteractionGroups,
    /// Its rigid body, while it stands in.
    pub(super) rigid: Option<RigidBodyHandle>,
}

/// What the colliders about to meet `own` will do to it: each (but a sensor, one of its own,
/// or one its groups ignore) whose bounds come within `margin` (m) plus twice what the two can
/// travel in a step of `h` (s) adds the weight it carries or bears, `m |g|` for a dynamic rigid
/// body of mass `m` on `own` of mass `M`, `own`'s weight `M |g|` for a fixed or kinematic one
/// (N), and may strike it at the closing speed `|Δv|` (the fastest points' speeds summed): a bar
/// struck at `v` strains by about `v / c` (`c` its wave speed), by a body of mass `m` by
/// `(μ / M) v / c` with `μ = m M / (m + M)` (`μ = M` for a fixed one). Returns the weight (N)
/// and the largest `(μ / M) |Δv|` (m/s). rapier's contacts stop a falling body at once and hold
/// a heavy body on a light one poorly (a 20 kg box sank 0.7 mm into a 1.2 kg block in its
/// landing frame): a stand-in turns elastic before such a meeting, not after it.
pub(super) fn approaching(
    own: &Approach,
    (bodies, colliders): (&RigidBodySet, &ColliderSet),
    (h, gravity, margin): (f64, DVec3, f64),
) -> (f64, f64) {
    let g = gravity.length();
    let (mut weight, mut strike) = (0.0, 0.0_f64);
    for (_, collider) in colliders.iter() {
        let parent = collider
            .parent()
            .and_then(|p| bodies.get(p).map(|b| (p, b)));
        if collider.is_sensor()
            || !collider.collision_groups().test(own.groups)
            || parent
                .is_some_and(|(p, b)| Some(p) == own.rigid || (b.is_dynamic() && b.is_sleeping()))
        {
            continue;
        }
        // A fixed body does not move; an unbounded shape (a half-space) has no fastest point.
        let other_speed = (parent.filter(|(_, b)| !b.is_fixed()))
            .map_or(0.0, |(_, b)| fastest_point(b, colliders, h));
        let other_speed = if other_speed.is_finite() {
            other_speed
        } else {
            0.0
        };
        let speed = own.speed + other_speed;
        if !within(collider, own.bounds, margin + 2.0 * speed * h) {
            continue;
        }
        let (carried, share) = match parent.filter(|(_, b)| b.is_dynamic()) {
            Some((_, body)) => {
                let m = f64::from(body.mass());
                (m * g, m / (m + own.mass))
            }
            None => (own.mass * g, 1.0),
        };
        weight += carried;
        strike = strike.max(share * speed);
    }
    (weight, strike)
}

/// Whether `collider` comes within `reach` (m) of the box `bounds`: to a half-space, the
/// distance of the box's nearest corner (parry's bounds and distance do not measure it); to
/// another shape, their bounds first, then parry's distance (a pair it cannot measure counts as
/// within).
fn within(collider: &rapier3d::geometry::Collider, bounds: Bounds, reach: f64) -> bool {
    if let Some(half_space) = collider.shape().as_halfspace() {
        let pose = collider.position();
        let normal = (pose.rotation * half_space.normal).as_dvec3();
        let origin = pose.translation.as_dvec3();
        let corners = (0..8).map(|k: u32| {
            DVec3::new(
                if k & 1 == 0 { bounds.0.x } else { bounds.1.x },
                if k & 2 == 0 { bounds.0.y } else { bounds.1.y },
                if k & 4 == 0 { bounds.0.z } else { bounds.1.z },
            )
        });
        let nearest = corners
            .map(|c| normal.dot(c - origin))
            .fold(f64::INFINITY, f64::min);
        return nearest <= reach;
    }
    if !overlap(widen(bounds_of(collider), reach), bounds) {
        return false;
    }
    let half = ((bounds.1 - bounds.0) / 2.0).as_vec3();
    let centre = Pose::from_translation(((bounds.0 + bounds.1) / 2.0).as_vec3());
    let gap = query::distance(
        &centre,
        &Cuboid::new(half),
        collider.position(),
        collider.shape(),
    );
    gap.map_or(true, |gap| f64::from(gap.distance) <= reach)
}

/// A collider's bounds (m).
pub(super) fn bounds_of(collider: &rapier3d::geometry::Collider) -> Bounds {
    let aabb = collider.compute_aabb();
    (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::geometry::{ColliderBuilder, SharedShape};
    use rapier3d::glamx::Vec3;

    #[test]
    fn a_half_space_is_within_reach_of_a_box_above_it() {
        let ground = ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).build();
        let above = |gap: f64| (DVec3::new(0.1, gap, 0.1), DVec3::new(0.3, gap + 0.1, 0.2));
        assert!(within(&ground, above(0.004), 0.005));
        assert!(!within(&ground, above(0.006), 0.005));
    }
}
