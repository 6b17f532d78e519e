//! Sleeping: a deformable body at rest costs nearly nothing, as rapier's islands do.
//!
//! A body is still over a coupling substep when every node moves slower than
//! [`SleepSettings::speed_threshold`] `v` (m/s), and so does every rigid body its contacts and
//! attachments touch or whose colliders reach within its bounds (a dynamic body at every point of
//! its colliders' bounds, a kinematic one not moving at all). Still for
//! [`SleepSettings::time_until_sleep`] `T` (s) in a row, no node can be under an out-of-balance
//! acceleration above `2 v / T` (from rest it would have passed `v`): the body is in equilibrium
//! to within that. Bodies whose bounds (widened by the contact margin) overlap, or which touch
//! the same dynamic rigid body, fall asleep together, once all of them are still that long and
//! one of them rests on something (its contacts or attachments pushed on a collider or rigid
//! body while it was still, or it has a pinned node: a free body keeps its motion, however
//! slow); the dynamic rigid bodies they touch are put to sleep in rapier.
//!
//! A sleeping body is neither detected nor stepped: its nodes keep their positions at zero
//! velocity, and the mean loads it exerted while it was still count again in every substep (the
//! ground still carries its weight, see [`RestingLoads`]). It wakes, with the rigid bodies it rests with and the
//! sleeping bodies it overlaps, when its state is edited
//! ([`DeformableBody::positions_mut`], [`DeformableBody::velocities_mut`]) or one of its loads
//! is added or changed ([`DeformableBody::set_load`]), gravity changes, a
//! rigid body it rests with wakes in rapier, moves or leaves, a collider comes within (or leaves)
//! its bounds, one there moves or is moved (a fixed one set elsewhere by hand), an awake
//! deformable body comes within them, it is attached to
//! or detached from a rigid body, or [`SoftCoupling::wake_up`](super::SoftCoupling::wake_up) is
//! called (after changing its friction, say).

mod resting;
mod still;

pub(crate) use resting::RestingLoads;

use super::RigidSets;
use super::bodies::BodyMap;
use super::groups::Components;
use super::loads::FrameLoads;
use super::reach::{Bounds, body_reach, overlap, widen};
use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet};
use crate::constraint::BodyConstraints;
use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderHandle, ColliderSet};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use still::{colliders_within, partners_of, rested_together, rigid_disturbs, rigid_still};

/// When deformable bodies fall asleep (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct SleepSettings {
    /// The speed (m/s) below which a node, or a point of a rigid body, counts as still.
    pub speed_threshold: f64,
    /// How long (s) a body stays still before it falls asleep; infinite keeps every body awake
    /// ([`SleepSettings::never`]).
    pub time_until_sleep: f64,
}

impl Default for SleepSettings {
    /// Still below 1 mm/s for 0.5 s: out-of-balance accelerations below 4 mm/s².
    fn default() -> Self {
        Self {
            speed_threshold: 1e-3,
            time_until_sleep: 0.5,
        }
    }
}

impl SleepSettings {
    /// Bodies never fall asleep.
    pub fn never() -> Self {
        Self {
            time_until_sleep: f64::INFINITY,
            ..Self::default()
        }
    }
}

/// What a body fell asleep with, to tell when it must wake.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
struct Asleep {
    /// The body's state edits then.
    state_edits: u64,
    /// The body's load edits then.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    load_edits: u64,
    /// Gravity (m/s²) then.
    gravity: DVec3,
    /// The nodes' bounds (m).
    bounds: Bounds,
    /// The colliders within the bounds, with their poses, sorted by handle.
    colliders: Vec<(ColliderHandle, Pose)>,
    /// The rigid bodies its contacts and attachments touched.
    partners: Vec<RigidBodyHandle>,
    /// The loads it keeps exerting.
    loads: RestingLoads,
}

/// One body's sleep: how long it has been still (s), the impulses it exerted meanwhile, and what
/// it fell asleep with.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
struct SleepState {
    /// How long (s) it has been still.
    still_for: f64,
    /// The impulses it exerted meanwhile (N s, N m s).
    resting: RestingLoads,
    /// What it fell asleep with, while it sleeps.
    asleep: Option<Asleep>,
}

/// Every deformable body's sleep, by handle.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(super) struct SleepSet {
    states: BodyMap<SleepState>,
}

impl SleepSet {
    /// Drops the states of bodies no longer in `bodies`.
    pub(super) fn prune(&mut self, bodies: &DeformableBodySet) {
        self.states.prune(bodies);
    }

    /// Whether body `handle` is asleep.
    pub(super) fn is_asleep(&self, handle: DeformableBodyHandle) -> bool {
        self.states.get(handle).is_some_and(|s| s.asleep.is_some())
    }

    /// Wakes body `handle` (if asleep) and restarts its still time; the rigid bodies it rested
    /// with wake as its next step hands them impulses.
    pub(super) fn wake_up(&mut self, handle: DeformableBodyHandle) {
        self.states.remove(handle);
    }
}

impl SleepSet {
    /// Wakes every sleeping body of `soft_bodies` that something disturbed (see the module's
    /// documentation), with the sleeping bodies it overlaps or shares a rigid body with and the
    /// rigid bodies they rested with, before a substep of `h` (s) under `gravity` (m/s²); the
    /// bodies left asleep count their loads into `loads` again, but for those in `counted`
    /// (stepped over the whole frame, asleep since: their step's loads are the frame's). `margin`
    /// (m) widens bounds.
    pub(super) fn wake_disturbed(
        &mut self,
        soft_bodies: &DeformableBodySet,
        rigid: &mut RigidSets<'_>,
        (loads, counted): (&mut FrameLoads, &[DeformableBodyHandle]),
        settings: &SleepSettings,
        (h, gravity, margin): (f64, DVec3, f64),
    ) {
        let sleeping: Vec<(DeformableBodyHandle, &Asleep)> = (self.states.iter())
            .filter_map(|(handle, state)| state.asleep.as_ref().map(|a| (handle, a)))
            .collect();
        if sleeping.is_empty() {
            return;
        }
        let awake: Vec<Bounds> = (soft_bodies.iter())
            .filter(|(handle, _)| !self.is_asleep(*handle))
            .map(|(_, body)| body_reach(body, margin, h, gravity))
            .collect();
        let mut woken: Vec<bool> = (sleeping.iter())
            .map(|&(handle, asleep)| {
                let body = &soft_bodies[handle];
                let widened = widen(asleep.bounds, margin);
                body.state_edits() != asleep.state_edits
                    || body.load_edits != asleep.load_edits
                    || gravity != asleep.gravity
                    || awake.iter().any(|&other| overlap(widened, other))
                    || rigid_disturbs(asleep, widened, rigid, settings.speed_threshold, h)
            })
            .collect();
        // A woken body wakes those it rested with.
        let mut spreading = true;
        while spreading {
            spreading = false;
            for i in 0..sleeping.len() {
                for j in 0..sleeping.len() {
                    if woken[i]
                        && !woken[j]
                        && rested_together(sleeping[i].1, sleeping[j].1, rigid.bodies, margin)
                    {
                        woken[j] = true;
                        spreading = true;
                    }
                }
            }
        }
        let (wake, keep): (Vec<_>, Vec<_>) =
            (sleeping.iter().zip(&woken)).partition(|(_, woken)| **woken);
        for ((handle, asleep), _) in keep {
            if !counted.contains(handle) {
                loads.add_resting(*handle, &asleep.loads, h);
            }
        }
        let wake: Vec<(DeformableBodyHandle, Vec<RigidBodyHandle>)> = (wake.into_iter())
            .map(|((handle, asleep), _)| (*handle, asleep.partners.clone()))
            .collect();
        for (handle, partners) in wake {
            self.states.remove(handle);
            for partner in partners {
                if let Some(body) = rigid.bodies.get_mut(partner) {
                    body.wake_up(true);
                }
            }
        }
    }

    /// Counts how long body `handle` (`body`, stepped against `constraints` over `h` s, `stepped`
    /// if its step succeeded) has been still, and sums the impulses it exerted meanwhile: their
    /// mean is what it keeps exerting asleep (its weight, to within the momentum its nodes may
    /// have changed by, `2 m v`, over the time `T`). Call before the impulses go to rapier.
    pub(super) fn observe(
        &mut self,
        (handle, body, constraints): (DeformableBodyHandle, &DeformableBody, &BodyConstraints),
        (bodies, colliders): (&RigidBodySet, &ColliderSet),
        settings: &SleepSettings,
        (h, stepped, margin): (f64, bool, f64),
    ) {
        let speed = settings.speed_threshold;
        let still = stepped
            && body.velocities.iter().all(|v| v.length() < speed)
            && partners_of(constraints).iter().all(|&partner| {
                (bodies.get(partner)).is_some_and(|b| rigid_still(b, colliders, speed, h))
            })
            && colliders_within(
                widen(body.position_bounds(), margin),
                colliders,
                bodies,
                speed,
                h,
            )
            .1;
        let state = self.states.entry(handle);
        if still {
            state.still_for += h;
            state.resting.add_substep(body, constraints);
        } else {
            state.still_for = 0.0;
            state.resting = RestingLoads::default();
        }
    }

    /// Puts to sleep, after a substep of `h` (s) under `gravity` (m/s²), every group of awake
    /// bodies of `soft_bodies` (bounds widened by `margin` (m) overlapping, or touching the same
    /// dynamic rigid body; their constraints from `constraints`) that have all been still long
    /// enough, one of them resting on something, with the dynamic rigid bodies they touch. Bodies
    /// `standing` in as rigid bodies are rapier's to put to sleep, and keep none awake.
    pub(super) fn settle<'c>(
        &mut self,
        (soft_bodies, standing): (&mut DeformableBodySet, &[DeformableBodyHandle]),
        constraints: impl Fn(DeformableBodyHandle) -> Option<&'c BodyConstraints>,
        rigid: &mut RigidSets<'_>,
        settings: &SleepSettings,
        (h, gravity, margin): (f64, DVec3, f64),
    ) {
        let ready = |state: &SleepState| {
            state.still_for >= settings.time_until_sleep && state.asleep.is_none()
        };
        if !self.states.iter().any(|(_, state)| ready(state)) {
            return;
        }
        let awake: Vec<(DeformableBodyHandle, Bounds, Vec<RigidBodyHandle>)> = (soft_bodies.iter())
            .filter(|(handle, _)| !self.is_asleep(*handle) && !standing.contains(handle))
            .map(|(handle, body)| {
                let partners = constraints(handle).map(partners_of).unwrap_or_default();
                (handle, widen(body.position_bounds(), margin), partners)
            })
            .collect();
        let mut components = Components::new(awake.len());
        for (i, a) in awake.iter().enumerate() {
            for (j, b) in awake.iter().enumerate().skip(i + 1) {
                let shared = a.2.iter().any(|p| {
                    b.2.contains(p) && rigid.bodies.get(*p).is_some_and(RigidBody::is_dynamic)
                });
                if overlap(a.1, b.1) || shared {
                    components.join(i, j);
                }
            }
        }
        for group in components.groups() {
            let all_ready = group
                .iter()
                .all(|&i| self.states.get(awake[i].0).is_some_and(ready));
            let resting = group.iter().any(|&i| {
                soft_bodies[awake[i].0].pinned.iter().any(|&p| p)
                    || (self.states.get(awake[i].0)).is_some_and(|s| s.resting.bears_load())
            });
            if !(all_ready && resting) {
                continue;
            }
            for &i in &group {
                let (handle, _, ref partners) = awake[i];
                let body = &mut soft_bodies[handle];
                body.velocities.fill(DVec3::ZERO);
                let bounds = body.position_bounds();
                let widened = widen(bounds, margin);
                let speed = settings.speed_threshold;
                let (colliders, _) =
                    colliders_within(widened, rigid.colliders, rigid.bodies, speed, h);
                for &partner in partners {
                    if let Some(rigid_body) = rigid.bodies.get_mut(partner)
                        && rigid_body.is_dynamic()
                    {
                        rigid_body.sleep();
                    }
                }
                let state = self.states.entry(handle);
                state.asleep = Some(Asleep {
                    state_edits: body.state_edits(),
                    load_edits: body.load_edits,
                    gravity,
                    bounds,
                    colliders,
                    partners: partners.clone(),
                    loads: std::mem::take(&mut state.resting).per_second(state.still_for),
                });
            }
        }
    }
}
