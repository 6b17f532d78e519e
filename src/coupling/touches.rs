//! The pairs of dynamic rigid bodies rapier's own contacts held together in any rapier step of
//! the last frame: the energy the rigid bodies a deformable body touches exchange with other
//! rigid bodies, which the audit must count with them (a box falling onto a ball that rests
//! against a soft block hands the ball its energy through rapier, not through the block).

use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderSet, NarrowPhase};

/// The dynamic rigid bodies in contact with each other over a frame, each pair once.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct RigidTouches {
    pairs: Vec<(RigidBodyHandle, RigidBodyHandle)>,
}

impl RigidTouches {
    /// Forgets the last frame's pairs.
    pub(crate) fn clear(&mut self) {
        self.pairs.clear();
    }

    /// Adds the pairs of dynamic rigid bodies whose colliders `narrow_phase` (rapier's last step)
    /// holds in active contact: contacts with fixed or kinematic bodies and colliders without a
    /// body are not exchanges between the bodies the audit weighs.
    pub(crate) fn record(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
    ) {
        let dynamic_parent = |collider| {
            let parent = colliders.get(collider)?.parent()?;
            bodies.get(parent)?.is_dynamic().then_some(parent)
        };
        for pair in narrow_phase.contact_pairs() {
            if !pair.has_any_active_contact() {
                continue;
            }
            let (Some(a), Some(b)) = (
                dynamic_parent(pair.collider1),
                dynamic_parent(pair.collider2),
            ) else {
                continue;
            };
            let ordered = if a.0 <= b.0 { (a, b) } else { (b, a) };
            if a != b && !self.pairs.contains(&ordered) {
                self.pairs.push(ordered);
            }
        }
    }

    /// The pairs recorded since the last [`RigidTouches::clear`].
    pub(crate) fn pairs(&self) -> &[(RigidBodyHandle, RigidBodyHandle)] {
        &self.pairs
    }
}
