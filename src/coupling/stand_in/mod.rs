//! Rigid stand-ins: a deformable body allowed one ([`RigidStandIn`]) is stepped as a rapier
//! rigid body while its strain stays small, and as a deformable body again when the loads on it
//! rise.
//!
//! Predicted strain: a force `F` (N) on the body strains it by about `F / (E V^(2/3))` (`E` its
//! softest Young's modulus, `V` its volume: a column of its size under `F`), a strike at the
//! closing speed `v` by about `v / c` (`c` its slowest wave speed); see
//! `contacts::approaching` for the colliders about to meet it.
//!
//! - **Turning elastic.** After each rapier step of
//!   [`SoftCoupling::step`](super::SoftCoupling::step), a stand-in turns elastic when the mean force over the frame so far (its rapier contacts'
//!   normal impulses and the deformable bodies pushing it) with the weight and strike of the
//!   colliders about to meet it predicts a strain above its tolerance `ε_tol`, or another body
//!   allowed a stand-in comes within its reach (stand-ins do not stack: see
//!   `StandInSet::keep_apart`); at the start of a frame, when its state or loads were edited,
//!   it was attached, pinned, woken by hand or its stand-in taken away, or its rigid body left
//!   rapier's set. Its nodes take the rigid pose and velocity `vᵢ = V + ω × rᵢ` (an edited
//!   state is kept as edited), and its rigid body and collider leave rapier's sets.
//! - **Turning rigid.** At the start of a frame, an awake body allowed a stand-in, with no
//!   pinned node, attachment, load besides gravity or embedded mesh, no other body allowed a
//!   stand-in within the contact margin, free (it touched no collider in the last frame) or
//!   resting (no node faster than 1 cm/s), whose strain (see `shape`) and predicted strain are
//!   each at most `ε_tol / 2` (the margin keeps it from switching back and forth), turns
//!   rigid: a rapier dynamic body of its mass, centre and inertia tensor with the nodes'
//!   momentum, its collider the nodes' convex hull (refused for a body whose hull exceeds its
//!   volume by more than 1 %: rapier would collide with the hull), with the body's friction,
//!   restitution and collision groups.
//!
//! While it stands in, the body is neither detected nor stepped; after each rapier step its
//! nodes are carried by the rigid pose, `xᵢ = c + R rᵢ`, `vᵢ = V + ω × (xᵢ − c)`, and its rapier
//! contacts' normal impulses count in the loads as the body's. Other deformable bodies meet its collider
//! as any rapier collider. Switches happen only in `step`:
//! [`SoftCoupling::substep`](super::SoftCoupling::substep) carries stand-ins and switches none.

mod contacts;
mod shape;
mod start;

use super::RapierSets;
use super::bodies::BodyMap;
use super::loads::FrameLoads;
use super::reach::{Bounds, fastest_point, overlap, widen};
use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet, RigidStandIn};
use contacts::{Approach, approaching, bounds_of, contact_impulses};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderHandle, ColliderSet, NarrowPhase};
use rapier3d::glamx::DVec3;
use shape::softest;
use start::{Ready, ready, stand_in};

/// The speed (m/s) below which every node of a body in contact must move for it to turn rigid:
/// it rests on what it touches.
const RESTING_SPEED: f64 = 0.01;

/// One body standing in as a rigid body.
#[derive(Debug, Clone)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
struct StandIn {
    /// The rapier body, with its origin at the centre of mass.
    rigid: RigidBodyHandle,
    /// Its collider.
    collider: ColliderHandle,
    /// Each node's offset (m) from the centre of mass in the rigid body's frame.
    offsets: Vec<DVec3>,
    /// The stand-in it was given.
    settings: RigidStandIn,
    /// The body's state and load edits then.
    edits: (u64, u64),
    /// The normal impulses (N s) its rapier contacts exerted in the frame so far, summed in
    /// magnitude.
    pushed: f64,
    /// The time (s) of the frame so far.
    elapsed: f64,
    /// Whether the force on it over the frame so far predicted a strain above the tolerance.
    overloaded: bool,
    /// Whether it must turn elastic at the next frame (woken, attached or pinned by hand).
    released: bool,
}

/// Every stand-in, by deformable body.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(super) struct StandInSet {
    states: BodyMap<StandIn>,
}

impl StandInSet {
    /// Whether body `handle` stands in as a rigid body.
    pub(super) fn contains(&self, handle: DeformableBodyHandle) -> bool {
        self.states.get(handle).is_some()
    }

    /// The bodies standing in.
    pub(super) fn handles(&self) -> Vec<DeformableBodyHandle> {
        self.states.iter().map(|(handle, _)| handle).collect()
    }

    /// The rapier body body `handle` stands in as.
    pub(super) fn rigid_of(&self, handle: DeformableBodyHandle) -> Option<RigidBodyHandle> {
        self.states.get(handle).map(|s| s.rigid)
    }

    /// The deformable body the rapier body `rigid` stands in for.
    pub(super) fn soft_of(&self, rigid: RigidBodyHandle) -> Option<DeformableBodyHandle> {
        (self.states.iter()).find_map(|(handle, s)| (s.rigid == rigid).then_some(handle))
    }

    /// Makes body `handle` turn elastic at the next frame.
    pub(super) fn release(&mut self, handle: DeformableBodyHandle) {
        if let Some(state) = self.states.get_mut(handle) {
            state.released = true;
        }
    }

    /// After a rapier step of `h` (s) under `gravity` (m/s²): carries every stand-in's nodes by
    /// its rigid body, counts its rapier contacts' impulses into `loads` and into its push, and
    /// marks it overloaded when the mean force over the frame so far (its rapier contacts' and
    /// the deformable bodies' pushing it, `loads` holding impulses until the frame ends) with
    /// the weight and strike of the colliders about to meet it (within `margin`, m, and their
    /// travel) predicts a strain above its tolerance, or another body allowed a stand-in comes
    /// within its reach.
    pub(super) fn after_rapier_step(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        (bodies, colliders, narrow_phase): (&RigidBodySet, &ColliderSet, &NarrowPhase),
        loads: &mut FrameLoads,
        (h, gravity, margin): (f64, DVec3, f64),
    ) {
        let handles = self.handles();
        if handles.is_empty() {
            return;
        }
        for &handle in &handles {
            if let (Some(body), Some(state)) =
                (soft_bodies.get_mut(handle), self.states.get(handle))
                && let Some(rigid) = bodies.get(state.rigid)
            {
                carry(body, &state.offsets, rigid);
            }
        }
        // Another body that may stand in, within reach: they would stack (see `keep_apart`).
        let allowed: Vec<(DeformableBodyHandle, Bounds)> = (soft_bodies.iter())
            .filter(|(_, body)| body.rigid_stand_in.is_some())
            .map(|(handle, body)| (handle, widen(body.position_bounds(), margin)))
            .collect();
        for (handle, state) in self.states.iter_mut() {
            let (Some(body), Some(rigid)) = (soft_bodies.get(handle), bodies.get(state.rigid))
            else {
                continue;
            };
            let sets = (bodies, colliders, narrow_phase);
            let (pushed, magnitude) = contact_impulses(state.collider, sets);
            for push in pushed {
                loads.add_collider(handle, push.collider, push.impulse, push.angular_impulse);
                if let Some((rigid, angular)) = push.rigid {
                    loads.add_rigid(handle, rigid, push.impulse, angular);
                }
            }
            state.pushed += magnitude;
            state.elapsed += h;
            let by_soft: f64 = (loads.rigid().iter())
                .filter(|l| l.rigid_body == state.rigid && l.soft_body != handle)
                .map(|l| l.force.length())
                .sum();
            let own = Approach {
                bounds: (colliders.get(state.collider)).map_or(body.position_bounds(), bounds_of),
                speed: fastest_point(rigid, colliders, h),
                mass: body.total_mass(),
                groups: body.collision_groups,
                rigid: Some(state.rigid),
            };
            let (weight, strike) = approaching(&own, (bodies, colliders), (h, gravity, margin));
            let force = (state.pushed + by_soft) / state.elapsed + weight;
            state.overloaded |= strain_predicted(body, (force, strike)) > tolerance(state);
            let reach = widen(own.bounds, margin + 2.0 * own.speed * h);
            state.overloaded |= allowed
                .iter()
                .any(|&(other, other_bounds)| other != handle && overlap(reach, other_bounds));
        }
    }

    /// Turns elastic at once every stand-in [`StandInSet::after_rapier_step`] found overloaded:
    /// before the next soft substep, so that what rapier pressed on it meets its elasticity
    /// within a substep.
    pub(super) fn end_overloaded(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rapier: &mut RapierSets<'_>,
    ) {
        let overloaded: Vec<DeformableBodyHandle> = (self.states.iter())
            .filter(|(_, state)| state.overloaded)
            .map(|(handle, _)| handle)
            .collect();
        for handle in overloaded {
            self.end(handle, soft_bodies, rapier);
        }
    }

    /// At the start of a frame of coupling substeps of `h` (s): turns elastic the stand-ins that
    /// must (see the module's documentation), then turns rigid each body of `soft_bodies` that
    /// may (`eligible`: awake, no attachment) and whose strain, and the strain predicted by the
    /// mean forces its contacts exerted over the last frame (`loads`) and by the colliders about
    /// to meet it (within `margin`, m, and their travel), are at most half its tolerance.
    pub(super) fn switch(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rapier: &mut RapierSets<'_>,
        (loads, eligible): (&FrameLoads, impl Fn(DeformableBodyHandle) -> bool),
        (h, margin): (f64, f64),
    ) {
        let ending: Vec<DeformableBodyHandle> = (self.states.iter())
            .filter(|&(handle, state)| {
                state.overloaded
                    || rapier.bodies.get(state.rigid).is_none()
                    || soft_bodies
                        .get(handle)
                        .is_none_or(|body| must_end(body, state))
            })
            .map(|(handle, _)| handle)
            .collect();
        for &handle in &ending {
            self.end(handle, soft_bodies, rapier);
        }
        for state in self.states.values_mut() {
            (state.pushed, state.elapsed) = (0.0, 0.0);
        }
        let gravity = rapier.gravity.as_dvec3();
        let mut starting: Vec<(DeformableBodyHandle, Ready)> = Vec::new();
        for (handle, body) in soft_bodies.iter() {
            // A body that just turned elastic deforms under its loads before it may turn rigid
            // again: its strain, zero while carried, must first show them.
            if self.contains(handle)
                || ending.contains(&handle)
                || !eligible(handle)
                || !may_stand_in(body)
            {
                continue;
            }
            let own = Approach {
                bounds: body.position_bounds(),
                speed: body.fastest_node_speed(),
                mass: body.total_mass(),
                groups: body.collision_groups,
                rigid: None,
            };
            let sets = (&*rapier.bodies, &*rapier.colliders);
            let (weight, strike) = approaching(&own, sets, (h, gravity, margin));
            let pushed: Vec<f64> = (loads.colliders().iter())
                .filter(|l| l.soft_body == handle)
                .map(|l| l.force.length())
                .collect();
            // Free (touching nothing) or resting: a body sliding, rolling or bouncing on
            // something would turn rigid and elastic again at every touch.
            let free_or_resting = pushed.is_empty() || body.fastest_node_speed() <= RESTING_SPEED;
            let force = pushed.iter().sum::<f64>() + weight;
            if free_or_resting && let Some(ready) = ready(body, (force, strike)) {
                starting.push((handle, ready));
            }
        }
        Self::keep_apart(&mut starting, soft_bodies, margin);
        for (handle, ready) in starting {
            let state = stand_in(&mut soft_bodies[handle], ready, rapier);
            self.states.insert(handle, state);
        }
    }

    /// Leaves out of `starting` every body within `margin` (m) of another deformable body that
    /// may stand in: stand-ins do not stack. rapier holds light bodies on one another with
    /// overlaps of a millimetre or so, which the elastic contacts turn into energy when the
    /// bodies turn elastic again (a pile of six 0.7 kg bricks gained 0.19 J so): bodies allowed
    /// stand-ins that touch stay elastic.
    fn keep_apart(
        starting: &mut Vec<(DeformableBodyHandle, Ready)>,
        soft_bodies: &DeformableBodySet,
        margin: f64,
    ) {
        let bounds = |handle| widen(soft_bodies[handle].position_bounds(), margin);
        let allowed: Vec<DeformableBodyHandle> = (soft_bodies.iter())
            .filter(|(_, body)| body.rigid_stand_in.is_some())
            .map(|(handle, _)| handle)
            .collect();
        starting.retain(|&(handle, _)| {
            !(allowed.iter())
                .any(|&other| other != handle && overlap(bounds(handle), bounds(other)))
        });
    }

    /// Turns body `handle` elastic: its nodes take the rigid motion (unless its state was
    /// edited), and its rigid body and collider leave rapier's sets.
    fn end(
        &mut self,
        handle: DeformableBodyHandle,
        soft_bodies: &mut DeformableBodySet,
        rapier: &mut RapierSets<'_>,
    ) {
        let Some(state) = self.states.get(handle).cloned() else {
            return;
        };
        self.states.remove(handle);
        if let (Some(body), Some(rigid)) =
            (soft_bodies.get_mut(handle), rapier.bodies.get(state.rigid))
            && (body.state_edits(), body.load_edits) == state.edits
        {
            carry(body, &state.offsets, rigid);
            // The last elastic step's history is not this state's.
            body.mark_state_edited();
        }
        rapier.bodies.remove(
            state.rigid,
            rapier.islands,
            rapier.colliders,
            rapier.impulse_joints,
            rapier.multibody_joints,
            rapier.rapier_soft_bodies,
            true,
        );
    }
}

/// The tolerance of a stand-in (dimensionless).
fn tolerance(state: &StandIn) -> f64 {
    state.settings.strain_tolerance
}

/// Whether the stand-in `state` of `body` must end whatever the loads: the body's state or loads
/// edited, a node pinned, its stand-in taken away or changed, or released by hand.
fn must_end(body: &DeformableBody, state: &StandIn) -> bool {
    state.released
        || (body.state_edits(), body.load_edits) != state.edits
        || body.rigid_stand_in != Some(state.settings)
        || body.pinned.iter().any(|&p| p)
}

/// The strain (dimensionless) predicted in `body` by the force `force` (N) on it and a strike
/// at `strike` (m/s, see [`approaching`]): `F / (E V^(2/3))` (a column of its size under `F`)
/// plus `v / c` (a bar struck at `v`), with `E` and `c` its softest Young's modulus and wave
/// speed.
fn strain_predicted(body: &DeformableBody, (force, strike): (f64, f64)) -> f64 {
    let (young, wave_speed) = softest(body);
    let volume = body.deformed_volume().abs();
    force / (young * volume.powf(2.0 / 3.0)) + strike / wave_speed
}

/// Whether `body` may stand in at all: allowed one, no pinned node, no load besides gravity, no
/// embedded mesh, a state a step can take.
fn may_stand_in(body: &DeformableBody) -> bool {
    body.rigid_stand_in.is_some()
        && !body.pinned.iter().any(|&p| p)
        && body.loads.is_empty()
        && body.embedding().is_none()
        && body.check_state().is_ok()
}

/// Sets `body`'s nodes to the rigid motion of `rigid` with the `offsets` (m) from its centre of
/// mass in its frame: `xᵢ = c + R rᵢ`, `vᵢ = V + ω × R rᵢ`.
fn carry(body: &mut DeformableBody, offsets: &[DVec3], rigid: &rapier3d::dynamics::RigidBody) {
    let center = rigid.translation().as_dvec3();
    let rotation = rigid.rotation().as_dquat();
    let (linvel, angvel) = (rigid.linvel().as_dvec3(), rigid.angvel().as_dvec3());
    for ((x, v), &r) in (body.positions.iter_mut())
        .zip(body.velocities.iter_mut())
        .zip(offsets)
    {
        let turned = rotation * r;
        *x = center + turned;
        *v = linvel + angvel.cross(turned);
    }
}
