//! What a sleeping body keeps exerting: the impulses it gave rigid bodies and colliders while it
//! was still, summed, then their mean forces and torques over that time. Its nodes' momentum
//! changed by at most `2 m v` meanwhile (`v` the speed threshold), so over the time `T` the mean
//! balances its weight and the loads on it to within `2 m v / T`.

use crate::body::DeformableBody;
use crate::constraint::BodyConstraints;
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::geometry::ColliderHandle;
use rapier3d::glamx::DVec3;

/// Loads a body exerted on rigid bodies (torque about their centre of mass) and on colliders
/// (about the world origin): impulses (N s, N m s) summed over the time it has been still, then
/// their mean forces (N) and torques (N m) over that time once it sleeps.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct RestingLoads {
    pub(crate) rigid: Vec<(RigidBodyHandle, DVec3, DVec3)>,
    pub(crate) colliders: Vec<(ColliderHandle, DVec3, DVec3)>,
}

/// Adds `(key, impulse, angular)` to the entry of `key` in `sums`.
fn accumulate<K: PartialEq>(
    sums: &mut Vec<(K, DVec3, DVec3)>,
    (key, impulse, angular): (K, DVec3, DVec3),
) {
    match sums.iter_mut().find(|(k, ..)| *k == key) {
        Some((_, total, angular_total)) => {
            *total += impulse;
            *angular_total += angular;
        }
        None => sums.push((key, impulse, angular)),
    }
}

impl RestingLoads {
    /// Adds the impulses `body` gave through `constraints` over a substep.
    pub(super) fn add_substep(&mut self, body: &DeformableBody, constraints: &BodyConstraints) {
        for load in constraints.rigid_impulses() {
            accumulate(&mut self.rigid, load);
        }
        for load in constraints.collider_impulses(body) {
            accumulate(&mut self.colliders, load);
        }
    }

    /// The summed impulses as mean forces and torques over `time` (s).
    pub(super) fn per_second(mut self, time: f64) -> Self {
        for (_, force, torque) in &mut self.rigid {
            *force /= time;
            *torque /= time;
        }
        for (_, force, torque) in &mut self.colliders {
            *force /= time;
            *torque /= time;
        }
        self
    }
}

impl RestingLoads {
    /// Whether the body pushed on something.
    pub(super) fn bears_load(&self) -> bool {
        (self.rigid.iter().map(|&(_, force, _)| force))
            .chain(self.colliders.iter().map(|&(_, force, _)| force))
            .any(|force| force != DVec3::ZERO)
    }
}
