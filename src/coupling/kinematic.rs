//! A position-based kinematic body told where to be at the end of a frame
//! (`set_next_kinematic_position`) gets there along the straight path, `x(s) = lerp(x₀, x₁, s)`
//! with the rotation by slerp, a part per coupling substep, rather than in the first substep.

use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet, RigidBodyType};
use rapier3d::math::Pose;

/// A position-based kinematic body's motion over a frame: from its pose to the one it was told
/// to reach.
pub(crate) struct KinematicPath {
    handle: RigidBodyHandle,
    from: Pose,
    to: Pose,
}

impl KinematicPath {
    /// The paths of the position-based kinematic bodies of `bodies` that are told to move.
    pub(crate) fn all(bodies: &RigidBodySet) -> Vec<Self> {
        bodies
            .iter()
            .filter(|(_, body)| {
                body.body_type() == RigidBodyType::KinematicPositionBased
                    && body.position() != body.next_position()
            })
            .map(|(handle, body)| Self {
                handle,
                from: *body.position(),
                to: *body.next_position(),
            })
            .collect()
    }

    /// Tells the body to reach `fraction` of its path by the end of the coming rapier step.
    pub(crate) fn advance(&self, bodies: &mut RigidBodySet, fraction: f32) {
        if let Some(body) = bodies.get_mut(self.handle) {
            body.set_next_kinematic_position(self.from.lerp(&self.to, fraction));
        }
    }
}
