//! What the deformable bodies exerted on the rigid ones: the impulses (N s) and angular impulses
//! about the centre of mass (N m s) their contacts and attachments handed over, summed per pair
//! over a frame and divided by it, `F = Σ J / dt`, `τ = Σ L / dt`.

use crate::body::DeformableBodyHandle;
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::glamx::DVec3;

/// The mean force and torque a deformable body exerted on a rigid body over a frame, through its
/// contacts and attachments (rigid bodies of every type: a fixed or kinematic body feels it too,
/// though it does not move).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidLoad {
    /// The deformable body.
    pub soft_body: DeformableBodyHandle,
    /// The rigid body.
    pub rigid_body: RigidBodyHandle,
    /// The force (N).
    pub force: DVec3,
    /// The torque about the rigid body's centre of mass (N m).
    pub torque: DVec3,
}

/// The loads of a frame, gathered as impulses and turned into forces at its end.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrameLoads {
    loads: Vec<RigidLoad>,
}

impl FrameLoads {
    /// Forgets the last frame's loads.
    pub(crate) fn clear(&mut self) {
        self.loads.clear();
    }

    /// Adds a substep's impulse (N s) and angular impulse about the centre of mass (N m s) to the
    /// frame's total for the pair.
    pub(crate) fn add(
        &mut self,
        soft_body: DeformableBodyHandle,
        rigid_body: RigidBodyHandle,
        impulse: DVec3,
        angular_impulse: DVec3,
    ) {
        match self
            .loads
            .iter_mut()
            .find(|load| load.soft_body == soft_body && load.rigid_body == rigid_body)
        {
            Some(load) => {
                load.force += impulse;
                load.torque += angular_impulse;
            }
            None => self.loads.push(RigidLoad {
                soft_body,
                rigid_body,
                force: impulse,
                torque: angular_impulse,
            }),
        }
    }

    /// Turns the summed impulses into mean forces and torques over `dt` (s).
    pub(crate) fn finish(&mut self, dt: f64) {
        let per_second = 1.0 / dt;
        for load in &mut self.loads {
            load.force *= per_second;
            load.torque *= per_second;
        }
    }

    /// Every pair's load.
    pub(crate) fn all(&self) -> &[RigidLoad] {
        &self.loads
    }

    /// The force (N) and torque (N m) of one pair; zero if they did not interact.
    pub(crate) fn on(&self, soft: DeformableBodyHandle, rigid: RigidBodyHandle) -> (DVec3, DVec3) {
        self.loads
            .iter()
            .find(|load| load.soft_body == soft && load.rigid_body == rigid)
            .map_or((DVec3::ZERO, DVec3::ZERO), |load| (load.force, load.torque))
    }
}
