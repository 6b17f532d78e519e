//! What the deformable bodies exerted on the rigid world: the impulses (N s) and angular
//! impulses (N m s) their contacts and attachments handed over, summed per pair over a frame and
//! divided by it, `F = Σ J / dt`, `τ = Σ L / dt`. Rigid bodies are listed with the torque about
//! their centre of mass; colliders (with or without a rigid body, the fixed ground among them)
//! with the torque about the world origin.

use super::sleep::RestingLoads;
use crate::body::{DeformableBody, DeformableBodyHandle};
use crate::constraint::BodyConstraints;
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::geometry::ColliderHandle;
use rapier3d::glamx::DVec3;

/// The mean force and torque a deformable body exerted on a rigid body over a frame, through its
/// contacts and attachments (rigid bodies of every type: a fixed or kinematic body feels it too,
/// though it does not move).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
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

/// The mean force and torque a deformable body's contacts exerted on a collider over a frame:
/// any collider, a fixed ground without a rigid body as well as a body's.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct ColliderLoad {
    /// The deformable body.
    pub soft_body: DeformableBodyHandle,
    /// The collider.
    pub collider: ColliderHandle,
    /// The force (N).
    pub force: DVec3,
    /// The torque about the world origin (N m).
    pub torque: DVec3,
}

/// A load summed over a frame, found by its pair.
trait PairLoad: Copy {
    /// The pair: deformable body and what it pushed.
    type Pair: PartialEq;
    /// The deformable body and what it pushed.
    fn pair(&self) -> Self::Pair;
    /// The summed force (impulse while summing) and torque (angular impulse).
    fn sums(&mut self) -> (&mut DVec3, &mut DVec3);
}

impl PairLoad for RigidLoad {
    type Pair = (DeformableBodyHandle, RigidBodyHandle);
    fn pair(&self) -> Self::Pair {
        (self.soft_body, self.rigid_body)
    }
    fn sums(&mut self) -> (&mut DVec3, &mut DVec3) {
        (&mut self.force, &mut self.torque)
    }
}

impl PairLoad for ColliderLoad {
    type Pair = (DeformableBodyHandle, ColliderHandle);
    fn pair(&self) -> Self::Pair {
        (self.soft_body, self.collider)
    }
    fn sums(&mut self) -> (&mut DVec3, &mut DVec3) {
        (&mut self.force, &mut self.torque)
    }
}

/// Adds `load` (holding a substep's impulse and angular impulse) to its pair's total.
fn accumulate<L: PairLoad>(loads: &mut Vec<L>, mut load: L) {
    match loads.iter_mut().find(|other| other.pair() == load.pair()) {
        Some(total) => {
            let (impulse, angular) = load.sums();
            let (force, torque) = total.sums();
            *force += *impulse;
            *torque += *angular;
        }
        None => loads.push(load),
    }
}

/// Divides every summed impulse by `dt` (s).
fn divide<L: PairLoad>(loads: &mut [L], dt: f64) {
    let per_second = 1.0 / dt;
    for load in loads {
        let (force, torque) = load.sums();
        *force *= per_second;
        *torque *= per_second;
    }
}

/// The loads of a frame, gathered as impulses and turned into forces at its end.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct FrameLoads {
    rigid: Vec<RigidLoad>,
    colliders: Vec<ColliderLoad>,
}

impl FrameLoads {
    /// Forgets the last frame's loads.
    pub(crate) fn clear(&mut self) {
        self.rigid.clear();
        self.colliders.clear();
    }

    /// Adds what the deformable body `handle` (`body`, stepped against `constraints`) gave the
    /// rigid bodies and colliders it touched over a substep to the frame's totals.
    pub(crate) fn add_body(
        &mut self,
        handle: DeformableBodyHandle,
        body: &DeformableBody,
        constraints: &BodyConstraints,
    ) {
        for (rigid_body, impulse, angular_impulse) in constraints.rigid_impulses() {
            self.add_rigid(handle, rigid_body, impulse, angular_impulse);
        }
        for (collider, impulse, angular_impulse) in constraints.collider_impulses(body) {
            self.add_collider(handle, collider, impulse, angular_impulse);
        }
    }

    /// Adds what the sleeping deformable body `handle` keeps exerting, `loads` (N, N m), over a
    /// substep of `h` (s) to the frame's totals.
    pub(crate) fn add_resting(
        &mut self,
        handle: DeformableBodyHandle,
        loads: &RestingLoads,
        h: f64,
    ) {
        for &(rigid_body, force, torque) in &loads.rigid {
            self.add_rigid(handle, rigid_body, force * h, torque * h);
        }
        for &(collider, force, torque) in &loads.colliders {
            self.add_collider(handle, collider, force * h, torque * h);
        }
    }

    /// Adds a substep's impulse (N s) and angular impulse about the centre of mass (N m s) on a
    /// rigid body to the frame's total for the pair.
    pub(super) fn add_rigid(
        &mut self,
        soft_body: DeformableBodyHandle,
        rigid_body: RigidBodyHandle,
        impulse: DVec3,
        angular_impulse: DVec3,
    ) {
        let load = RigidLoad {
            soft_body,
            rigid_body,
            force: impulse,
            torque: angular_impulse,
        };
        accumulate(&mut self.rigid, load);
    }

    /// Adds a substep's impulse (N s) and angular impulse about the world origin (N m s) on a
    /// collider to the frame's total for the pair.
    pub(super) fn add_collider(
        &mut self,
        soft_body: DeformableBodyHandle,
        collider: ColliderHandle,
        impulse: DVec3,
        angular_impulse: DVec3,
    ) {
        let load = ColliderLoad {
            soft_body,
            collider,
            force: impulse,
            torque: angular_impulse,
        };
        accumulate(&mut self.colliders, load);
    }

    /// Turns the summed impulses into mean forces and torques over `dt` (s).
    pub(crate) fn finish(&mut self, dt: f64) {
        divide(&mut self.rigid, dt);
        divide(&mut self.colliders, dt);
    }

    /// Every rigid body's load.
    pub(crate) fn rigid(&self) -> &[RigidLoad] {
        &self.rigid
    }

    /// Every collider's load.
    pub(crate) fn colliders(&self) -> &[ColliderLoad] {
        &self.colliders
    }

    /// The force (N) and torque (N m) of one deformable–rigid pair; zero if they did not
    /// interact.
    pub(crate) fn on(&self, soft: DeformableBodyHandle, rigid: RigidBodyHandle) -> (DVec3, DVec3) {
        self.rigid
            .iter()
            .find(|load| load.pair() == (soft, rigid))
            .map_or((DVec3::ZERO, DVec3::ZERO), |load| (load.force, load.torque))
    }
}
