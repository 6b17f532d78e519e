//! The coupling layer between rapier's rigid bodies and the deformable bodies, run between rapier
//! steps on the caller's own sets.
//!
//! rapier offers no callback inside its step, so a frame of `dt` is cut into
//! [`SoftCoupling::substeps`] rapier steps of `h = dt / substeps`, and the deformable bodies step
//! between them. A body that needs no coupling (within its reach over the frame only fixed and
//! kinematic colliders: no dynamic rigid body, no other deformable body) steps once over the
//! whole frame, beside the substeps (on another thread with the `parallel` feature), which skip
//! it (`uncoupled`). One coupling substep, in order:
//!
//! 1. **Kinematic paths.** Each position-based kinematic body told where to be at the end of the
//!    frame is told the part of its straight path it reaches by the end of this substep.
//!    Sleeping bodies that something disturbed wake (see [`SleepSettings`]); those left asleep
//!    skip stages 2 to 5 and count the loads they rest with.
//! 2. **Contacts.** Each deformable body finds the colliders its surface can reach within `h`
//!    ([`BodyConstraints::detect_contacts`]), and
//!    the bodies find each other's surfaces.
//! 3. **Support.** Rigid bodies that rapier's narrow phase finds touching something move within
//!    the soft step as rapier's last step moved them (gravity and rapier's contacts and joints
//!    together, `pull.rs`), not by gravity alone: otherwise they would fall freely there, the
//!    ground that holds them acting only in rapier's step.
//! 4. **Soft step.** Bodies touching each other step together, so that their contacts are
//!    solved with both bodies' nodes, by the cheaper integrator (or the forced one): explicitly
//!    in the same sweeps, or as one implicit system; the others step alone by
//!    [`SoftCoupling::integrator`]. The explicit substeps carry
//!    the rigid bodies they touch along at the velocities the impulses leave them, as they move
//!    the nodes, so that a fast body sweeps through the nodes in its path within the soft step:
//!    a 2 cm ball at 30 m/s, 3 cm per coupling substep of a 1/240 s frame, meets the nodes it
//!    strikes instead of jumping past them in rapier's step. This costs nothing more when
//!    something is fast (no extra coupling substeps); detection reaches twice a collider's travel
//!    over the substep, up to 1 m.
//! 5. **Exchange.** The impulses the soft step gave dynamic rigid bodies are handed to rapier at
//!    the nodes, and summed into the frame's [`RigidLoad`]s. Bodies still long enough fall
//!    asleep, with the dynamic rigid bodies they touch. A body whose step was refused (in
//!    this substep or an earlier one of the frame) stays where it was, and the dynamic rigid
//!    bodies it touches or is glued to get the impulses a fixed obstacle would give them
//!    (`constraint::hold_partners`): they rest on it or hang from it instead of sinking into it
//!    during rapier's step.
//! 6. **Rigid step.** rapier steps the rigid bodies over `h`, with the frame's
//!    `num_solver_iterations` divided among the substeps (rounded up), so that its solver cost
//!    per frame is about unchanged. A dynamic body an implicit soft step moved is carried by it
//!    as that step assumed (`carry`: rapier's iterations, each integrating gravity over its
//!    share of `h`, would carry it `(n − 1)/(2n) |g| h²` less far down in `n` iterations).
//!
//! Sub-cycling keeps the rigid bodies' view of the deformable bodies one short substep old, which
//! removes the friction ratchet and the rocking that a single rapier step per frame shows.
//! [`SoftCoupling::step`] runs a whole frame, calling the caller's [`PhysicsPipeline`];
//! [`SoftCoupling::substep`] runs stages 2 to 5 alone, for a program that steps rapier itself.
//! [`FvmWorld`](crate::world::FvmWorld) is the same over a [`PhysicsWorld`](rapier3d::pipeline::PhysicsWorld).

mod audit;
mod bodies;
mod carry;
mod groups;
mod kinematic;
mod loads;
mod pull;
mod rapier_view;
mod reach;
mod sleep;
mod stand_in;
mod substep;
mod timing;
mod touches;
mod uncoupled;

pub use audit::{
    Audit, AuditInput, AuditSettings, BodyAudit, EnergyCheck, FrameAudit, PenetrationTarget,
    Penetrations,
};
pub use loads::{ColliderLoad, RigidLoad};
pub use sleep::SleepSettings;
pub use timing::FrameTiming;

use crate::Error;
use crate::body::{DeformableBodyHandle, DeformableBodySet};
use crate::constraint::BodyConstraints;
use crate::contact::{ContactSettings, NodeContact};
use crate::integrate::{AutomaticIntegrator, AutomaticReport};
use bodies::LinkSet;
use carry::{CarriedMotion, RapierCarry};
use kinematic::KinematicPath;
use loads::FrameLoads;
use pull::RapierPull;
use rapier3d::dynamics::{
    CCDSolver, ImpulseJointSet, IntegrationParameters, IslandManager, MultibodyJointSet,
    RigidBodyHandle, RigidBodySet,
};
use rapier3d::geometry::{BroadPhaseBvh, ColliderHandle, ColliderSet, NarrowPhase};
use rapier3d::glamx::DVec3;
use rapier3d::math::Vector;
use rapier3d::pipeline::{EventHandler, PhysicsHooks, PhysicsPipeline};
use sleep::SleepSet;
use stand_in::StandInSet;
use touches::RigidTouches;
use uncoupled::Uncoupled;

/// Each deformable body's result over a frame: the report of its last substep, or the first
/// error it met (a body whose step was refused keeps the state it had before that substep for the
/// rest of the frame, holding the rigid bodies it touches as a fixed obstacle would).
pub type SoftStepResults = Vec<(DeformableBodyHandle, Result<AutomaticReport, Error>)>;

/// What stepping a body gave over a frame so far: nothing yet, its last report, or the error that
/// stopped it.
type Outcome = Option<Result<AutomaticReport, Error>>;

/// The part of a rapier world a soft substep reads and writes: the rigid bodies (their poses
/// and velocities read, contact impulses applied), the colliders the surfaces touch, and the
/// narrow phase (which rigid bodies rest on something).
pub struct RigidSets<'a> {
    /// The rigid bodies.
    pub bodies: &'a mut RigidBodySet,
    /// The colliders.
    pub colliders: &'a ColliderSet,
    /// The narrow phase of the last rapier step.
    pub narrow_phase: &'a NarrowPhase,
}

/// Everything rapier's [`PhysicsPipeline::step`] takes, borrowed from the caller's own sets, so
/// that [`SoftCoupling::step`] can run rapier's substeps between its soft ones.
pub struct RapierSets<'a> {
    /// Gravity (m/s²), acting on the deformable bodies too.
    pub gravity: Vector,
    /// The frame's parameters: `dt` (s) is the frame step; the substeps use a copy with `dt`
    /// and `num_solver_iterations` divided.
    pub integration_parameters: &'a IntegrationParameters,
    /// rapier's island manager.
    pub islands: &'a mut IslandManager,
    /// rapier's broad phase.
    pub broad_phase: &'a mut BroadPhaseBvh,
    /// rapier's narrow phase.
    pub narrow_phase: &'a mut NarrowPhase,
    /// The rigid bodies.
    pub bodies: &'a mut RigidBodySet,
    /// The colliders.
    pub colliders: &'a mut ColliderSet,
    /// The impulse joints.
    pub impulse_joints: &'a mut ImpulseJointSet,
    /// The multibody joints.
    pub multibody_joints: &'a mut MultibodyJointSet,
    /// rapier's own (built-in) soft bodies, which its step takes; an empty set if unused.
    pub rapier_soft_bodies: &'a mut rapier3d::dynamics::SoftBodySet,
    /// rapier's continuous collision detection solver.
    pub ccd_solver: &'a mut CCDSolver,
}

impl RapierSets<'_> {
    /// One rapier step with `parameters` (a substep's).
    fn step_rapier(
        &mut self,
        pipeline: &mut PhysicsPipeline,
        parameters: &IntegrationParameters,
        hooks: &dyn PhysicsHooks,
        events: &dyn EventHandler,
    ) {
        pipeline.step(
            self.gravity,
            parameters,
            self.islands,
            self.broad_phase,
            self.narrow_phase,
            self.bodies,
            self.colliders,
            self.impulse_joints,
            self.multibody_joints,
            self.rapier_soft_bodies,
            self.ccd_solver,
            hooks,
            events,
        );
    }
}

/// How deformable bodies are stepped beside rapier's rigid bodies, and what they exerted on them
/// over the last frame.
#[derive(Debug, Clone)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct SoftCoupling {
    /// How the deformable bodies are stepped.
    pub integrator: AutomaticIntegrator,
    /// How their contacts are detected and enforced.
    pub contact: ContactSettings,
    /// rapier steps per frame, with the deformable bodies stepped between them (at least 1: zero
    /// is refused by [`SoftCoupling::step`]); a body that needs no coupling steps once per frame
    /// (see the module's documentation).
    pub substeps: u32,
    /// When bodies at rest fall asleep (see [`SleepSettings`]).
    pub sleep: SleepSettings,
    /// What each deformable body exerted on each rigid body over the last frame or substep.
    loads: FrameLoads,
    /// The dynamic rigid bodies rapier's contacts held together over the last frame.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    touches: RigidTouches,
    /// What rapier's last step did to the rigid bodies its contacts hold.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    pull: RapierPull,
    /// The velocity changes of the rigid bodies implicit steps carried over the last frame.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    carried: CarriedMotion,
    /// Each deformable body's constraints and solver caches, by handle.
    links: LinkSet,
    /// Each deformable body's sleep, by handle.
    sleeping: SleepSet,
    /// The bodies standing in as rapier rigid bodies, by handle.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    stand_ins: StandInSet,
    /// Where the last frame's time went (not saved: wall-clock times).
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    timing: FrameTiming,
}

impl Default for SoftCoupling {
    fn default() -> Self {
        Self {
            integrator: AutomaticIntegrator::default(),
            contact: ContactSettings::default(),
            substeps: 4,
            sleep: SleepSettings::default(),
            loads: FrameLoads::default(),
            touches: RigidTouches::default(),
            pull: RapierPull::default(),
            carried: CarriedMotion::default(),
            links: LinkSet::default(),
            sleeping: SleepSet::default(),
            stand_ins: StandInSet::default(),
            timing: FrameTiming::default(),
        }
    }
}

impl SoftCoupling {
    /// Advances rigid and deformable bodies by one frame (`integration_parameters.dt`, s): the
    /// bodies that need no coupling over the whole frame, then the [`SoftCoupling::substeps`]
    /// coupling substeps of the module's documentation, each a soft step of the others then one
    /// `pipeline` step on the caller's `rapier` sets with `hooks` and `events`.
    /// A frame of `dt = 0` (a pause) only lets rapier apply changes, and steps no deformable
    /// body. A negative or non-finite `dt`, or zero [`SoftCoupling::substeps`], steps nothing,
    /// rapier included, and every deformable body's result is the error
    /// ([`Error::InvalidTimeStep`], [`Error::InvalidSetting`]). A body whose state a step cannot
    /// take (a position or velocity made NaN, infinite or absurd through the raw slices, see
    /// [`DeformableBody::check_state`](crate::body::DeformableBody::check_state)) is not stepped and its result is that error, every frame
    /// until its state is fixed.
    pub fn step(
        &mut self,
        pipeline: &mut PhysicsPipeline,
        mut rapier: RapierSets<'_>,
        soft_bodies: &mut DeformableBodySet,
        hooks: &dyn PhysicsHooks,
        events: &dyn EventHandler,
    ) -> SoftStepResults {
        let frame = *rapier.integration_parameters;
        let last_loads = std::mem::take(&mut self.loads);
        self.touches.clear();
        self.carried.begin_frame();
        self.timing = FrameTiming::default();
        if let Some(error) = self.frame_error(frame.dt) {
            return refused(soft_bodies, &error);
        }
        if frame.dt == 0.0 {
            let started = std::time::Instant::now();
            rapier.step_rapier(pipeline, &frame, hooks, events);
            self.timing.rapier_steps = started.elapsed().as_secs_f64();
            self.record_touches(&rapier);
            return Vec::new();
        }
        let substeps = self.substeps;
        let h = f64::from(frame.dt) / f64::from(substeps);
        let gravity = rapier.gravity.as_dvec3();
        self.links.prune(soft_bodies);
        self.sleeping.prune(soft_bodies);
        let frame_dt = f64::from(frame.dt);
        let (sleeping, links) = (&self.sleeping, &self.links);
        let eligible = |handle| {
            !sleeping.is_asleep(handle)
                && links
                    .get(handle)
                    .is_none_or(|l| l.constraints.attachments.is_empty())
        };
        let reach = (h, self.contact.margin);
        (self.stand_ins).switch(soft_bodies, &mut rapier, (&last_loads, eligible), reach);
        let mut outcomes = unstepped(soft_bodies);
        let paths = KinematicPath::all(rapier.bodies);
        let alone = if substeps > 1 {
            let rigid = RigidSets {
                bodies: rapier.bodies,
                colliders: rapier.colliders,
                narrow_phase: rapier.narrow_phase,
            };
            let started = std::time::Instant::now();
            let alone = self.find_uncoupled(soft_bodies, &rigid, &outcomes, (frame_dt, gravity));
            self.timing.contact_detection += started.elapsed().as_secs_f64();
            alone
        } else {
            Vec::new()
        };
        let mut uncoupled = Uncoupled::take(&alone, soft_bodies, &mut self.links);
        let (integrator, settings) = (self.integrator, self.contact);
        let substepping = (pipeline, &mut rapier, (hooks, events));
        let coupled = (&mut outcomes[..], &alone[..], &paths[..]);
        let stepped = if uncoupled.is_empty() {
            self.coupling_substeps(substepping, soft_bodies, coupled, (h, gravity));
            Vec::new()
        } else {
            let (stepped, ()) = crate::parallel::both(
                || uncoupled.step((&integrator, &settings), (frame_dt, gravity)),
                || self.coupling_substeps(substepping, soft_bodies, coupled, (h, gravity)),
            );
            stepped
        };
        let rigid = RigidSets {
            bodies: rapier.bodies,
            colliders: rapier.colliders,
            narrow_phase: rapier.narrow_phase,
        };
        let steps = (uncoupled, stepped);
        self.finish_uncoupled(
            soft_bodies,
            rigid,
            &mut outcomes,
            steps,
            (frame_dt, h, gravity),
        );
        self.loads.finish(frame_dt);
        results(outcomes)
    }

    /// The coupling substeps of a frame (see the module's documentation), each a soft step of
    /// `h` (s) under `gravity` (m/s²) of every body but those `skip`ped, then one rapier step
    /// with `pipeline` on the `rapier` sets with the `hooks` and `events`; the kinematic bodies
    /// follow their `paths`, and each body's `outcomes` records its last report or first error.
    fn coupling_substeps(
        &mut self,
        (pipeline, rapier, (hooks, events)): (
            &mut PhysicsPipeline,
            &mut RapierSets<'_>,
            (&dyn PhysicsHooks, &dyn EventHandler),
        ),
        soft_bodies: &mut DeformableBodySet,
        (outcomes, skip, paths): (
            &mut [(DeformableBodyHandle, Outcome)],
            &[DeformableBodyHandle],
            &[KinematicPath],
        ),
        (h, gravity): (f64, DVec3),
    ) {
        let frame = *rapier.integration_parameters;
        let substeps = self.substeps;
        let mut substep_parameters = frame;
        substep_parameters.dt = frame.dt / substeps as f32;
        substep_parameters.num_solver_iterations =
            iterations_per_substep(frame.num_solver_iterations, substeps);
        for substep in 1..=substeps {
            for path in paths {
                path.advance(rapier.bodies, substep as f32 / substeps as f32);
            }
            let rigid = RigidSets {
                bodies: rapier.bodies,
                colliders: rapier.colliders,
                narrow_phase: rapier.narrow_phase,
            };
            let carried = self.step_soft_bodies(soft_bodies, rigid, outcomes, skip, (h, gravity));
            let iterations = substep_parameters.num_solver_iterations;
            let carry = RapierCarry::lead(&carried, rapier.bodies, gravity, (h, iterations));
            let started = std::time::Instant::now();
            rapier.step_rapier(pipeline, &substep_parameters, hooks, events);
            self.timing.rapier_steps += started.elapsed().as_secs_f64();
            carry.settle(rapier.bodies);
            self.record_touches(rapier);
            let sets = (&*rapier.bodies, &*rapier.colliders, &*rapier.narrow_phase);
            let reach = (h, gravity, self.contact.margin);
            (self.stand_ins).after_rapier_step(soft_bodies, sets, &mut self.loads, reach);
            self.stand_ins.end_overloaded(soft_bodies, rapier);
        }
    }

    /// Records the dynamic rigid bodies the `rapier` step that just ran holds in contact.
    fn record_touches(&mut self, rapier: &RapierSets<'_>) {
        (self.touches).record(rapier.bodies, rapier.colliders, rapier.narrow_phase);
    }

    /// Why a frame of `dt` (s) cannot be stepped, if it cannot: a negative or non-finite step, or
    /// zero coupling substeps.
    fn frame_error(&self, dt: f32) -> Option<Error> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Some(Error::InvalidTimeStep {
                dt: f64::from(dt),
                reason: "a frame step must be non-negative and finite (zero pauses)",
            });
        }
        (self.substeps == 0).then_some(Error::InvalidSetting {
            parameter: "substeps",
            value: 0.0,
            reason: "a frame needs at least one coupling substep",
        })
    }

    /// Steps every deformable body by `h` (s) under `gravity` (m/s²) against the rigid world as
    /// it is (stages 2 to 5 of the module's documentation), for a program that runs its own
    /// rapier step of `h` right after. [`SoftCoupling::rigid_loads`] then holds this substep's
    /// loads. That rapier step should run one solver iteration
    /// (`IntegrationParameters::num_solver_iterations = 1`) when an implicit step moves dynamic
    /// rigid bodies: with `n`, rapier carries each of them `(n − 1)/(2n) |g| h²` less far down
    /// than the soft step assumed, which [`SoftCoupling::step`] corrects and this call cannot.
    pub fn substep(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rigid: RigidSets<'_>,
        h: f64,
        gravity: DVec3,
    ) -> SoftStepResults {
        self.loads.clear();
        self.touches.clear();
        self.carried.begin_frame();
        self.timing = FrameTiming::default();
        (self.touches).record(rigid.bodies, rigid.colliders, rigid.narrow_phase);
        self.links.prune(soft_bodies);
        self.sleeping.prune(soft_bodies);
        let sets = (&*rigid.bodies, rigid.colliders, rigid.narrow_phase);
        let reach = (h, gravity, self.contact.margin);
        (self.stand_ins).after_rapier_step(soft_bodies, sets, &mut self.loads, reach);
        let mut outcomes = unstepped(soft_bodies);
        self.step_soft_bodies(soft_bodies, rigid, &mut outcomes, &[], (h, gravity));
        if h > 0.0 {
            self.loads.finish(h);
        }
        results(outcomes)
    }

    /// Where the last [`SoftCoupling::step`] (or [`SoftCoupling::substep`]) spent its time, in
    /// wall-clock seconds: the deformable bodies' steps by integrator and rigid partners,
    /// contact detection and rapier's steps (see [`FrameTiming`]). A program's profile of its
    /// scene; nothing depends on it.
    pub fn last_frame_timing(&self) -> &FrameTiming {
        &self.timing
    }

    /// The mean force and torque each deformable body exerted on each rigid body it touched or
    /// is attached to, over the last frame of [`SoftCoupling::step`] (or the last
    /// [`SoftCoupling::substep`]): the impulses it handed over divided by the time. Colliders
    /// without a rigid body (fixed ground) are in [`SoftCoupling::collider_loads`].
    pub fn rigid_loads(&self) -> &[RigidLoad] {
        self.loads.rigid()
    }

    /// The mean force and torque (about the world origin) each deformable body's contacts
    /// exerted on each collider they touched over the last frame of [`SoftCoupling::step`] (or
    /// the last [`SoftCoupling::substep`]): colliders without a rigid body, such as the ground,
    /// included.
    pub fn collider_loads(&self) -> &[ColliderLoad] {
        self.loads.colliders()
    }

    /// The pairs of dynamic rigid bodies rapier's own contacts held together in any rapier step
    /// of the last frame of [`SoftCoupling::step`] (for [`SoftCoupling::substep`], in the rapier
    /// step before it): energy the rigid bodies exchange among themselves, not with the
    /// deformable bodies.
    pub(crate) fn rigid_touches(&self) -> &[(RigidBodyHandle, RigidBodyHandle)] {
        self.touches.pairs()
    }

    /// The change of linear velocity (m/s) of the dynamic rigid body `rigid` over the coupling
    /// substeps of the last frame (or the last [`SoftCoupling::substep`]) in which implicit soft
    /// steps carried it, rapier's contacts not holding it: their impulses and its fall.
    pub(crate) fn carried_velocity_change(&self, rigid: RigidBodyHandle) -> DVec3 {
        self.carried.of(rigid)
    }

    /// How many frames of [`SoftCoupling::step`] (and calls of [`SoftCoupling::substep`]) have
    /// begun: whether a step ran between two looks at the coupling.
    pub(crate) fn frames_begun(&self) -> u64 {
        self.carried.frames()
    }

    /// The mean force (N) and torque about its centre of mass (N m) deformable body `soft`
    /// exerted on rigid body `rigid` over the last frame; zero if they did not interact.
    pub fn load_on(&self, soft: DeformableBodyHandle, rigid: RigidBodyHandle) -> (DVec3, DVec3) {
        self.loads.on(soft, rigid)
    }

    /// Glues `nodes` of the deformable body `soft` of `soft_bodies` to the rigid body `rigid` of
    /// `rigid_bodies` where they are now (see [`BodyConstraints::attach`]); the attachments act
    /// from the next substep.
    ///
    /// # Errors
    /// [`Error::UnknownDeformableBody`] if `soft` is not in `soft_bodies`, then those of
    /// [`BodyConstraints::attach`]; nothing is attached then.
    pub fn attach(
        &mut self,
        soft_bodies: &DeformableBodySet,
        soft: DeformableBodyHandle,
        nodes: impl IntoIterator<Item = u32>,
        rigid: RigidBodyHandle,
        rigid_bodies: &RigidBodySet,
    ) -> Result<(), Error> {
        let body = soft_bodies.get(soft).ok_or(Error::UnknownDeformableBody)?;
        self.sleeping.wake_up(soft);
        self.stand_ins.release(soft);
        self.links
            .entry(soft)
            .constraints
            .attach(body, nodes, rigid, rigid_bodies)
    }

    /// Removes every attachment of the deformable body `soft` to the rigid body `rigid`.
    pub fn detach(&mut self, soft: DeformableBodyHandle, rigid: RigidBodyHandle) {
        self.sleeping.wake_up(soft);
        self.stand_ins.release(soft);
        if let Some(links) = self.links.get_mut(soft) {
            links.constraints.detach(rigid);
        }
    }

    /// Whether the deformable body `soft` is asleep (see [`SleepSettings`]): not stepped, at
    /// rest, until something disturbs it.
    pub fn is_sleeping(&self, soft: DeformableBodyHandle) -> bool {
        self.sleeping.is_asleep(soft)
    }

    /// Wakes the deformable body `soft` if it is asleep, and restarts the time it must stay still
    /// before it sleeps again: call it after changing what a step reads that the coupling does
    /// not watch (its friction, say). Editing its positions or velocities wakes it by itself.
    /// A body standing in as a rigid body turns elastic at the next frame.
    pub fn wake_up(&mut self, soft: DeformableBodyHandle) {
        self.sleeping.wake_up(soft);
        self.stand_ins.release(soft);
    }

    /// The rapier rigid body the deformable body `soft` stands in as (see
    /// [`RigidStandIn`](crate::body::RigidStandIn)), while it does.
    pub fn rigid_stand_in_of(&self, soft: DeformableBodyHandle) -> Option<RigidBodyHandle> {
        self.stand_ins.rigid_of(soft)
    }

    /// The deformable body the rapier rigid body `rigid` stands in for, if it is a stand-in:
    /// a program listing rapier's bodies skips those.
    pub fn stand_in_for(&self, rigid: RigidBodyHandle) -> Option<DeformableBodyHandle> {
        self.stand_ins.soft_of(rigid)
    }

    /// The contacts, rigid corners and attachments of the deformable body `soft` as the last
    /// substep left them; `None` for a body never attached nor stepped.
    pub fn constraints(&self, soft: DeformableBodyHandle) -> Option<&BodyConstraints> {
        self.links.get(soft).map(|links| &links.constraints)
    }

    /// The contacts the deformable body `soft` had in the last substep (empty if none).
    pub fn contacts(&self, soft: DeformableBodyHandle) -> &[NodeContact] {
        self.constraints(soft)
            .map_or(&[], BodyConstraints::contacts)
    }

    /// The mean force (N) and torque about the world origin (N m) the contacts of the deformable
    /// body `soft` of `soft_bodies` exerted on `collider` over the body's last step (the frame's
    /// last coupling substep, or the whole frame for a body that needed no coupling); see
    /// [`BodyConstraints::contact_force_on`]. Zero for a body never stepped or without contacts.
    /// [`SoftCoupling::collider_loads`] holds the mean over the whole frame.
    ///
    /// # Errors
    /// [`Error::UnknownDeformableBody`] if `soft` is not in `soft_bodies`.
    pub fn contact_force_on(
        &self,
        soft_bodies: &DeformableBodySet,
        soft: DeformableBodyHandle,
        collider: ColliderHandle,
    ) -> Result<(DVec3, DVec3), Error> {
        let body = soft_bodies.get(soft).ok_or(Error::UnknownDeformableBody)?;
        match self.links.get(soft).filter(|links| links.last_step > 0.0) {
            Some(links) => (links.constraints).contact_force_on(body, collider, links.last_step),
            None => Ok((DVec3::ZERO, DVec3::ZERO)),
        }
    }
}

/// The solver iterations (at least one) rapier runs in each of `substeps` coupling substeps of a
/// frame given `frame_iterations`: the frame's share, rounded up, so that its solver cost per
/// frame is about unchanged. Each iteration of rapier's TGS solver integrates positions over its
/// share of the substep.
pub(crate) fn iterations_per_substep(frame_iterations: usize, substeps: u32) -> usize {
    frame_iterations.div_ceil(substeps.max(1) as usize).max(1)
}

/// Every body of `soft_bodies` with `error`: a frame refused before anything moved.
fn refused(soft_bodies: &DeformableBodySet, error: &Error) -> SoftStepResults {
    soft_bodies
        .iter()
        .map(|(handle, _)| (handle, Err(error.clone())))
        .collect()
}

/// Every body of `soft_bodies`, not stepped yet.
fn unstepped(soft_bodies: &DeformableBodySet) -> Vec<(DeformableBodyHandle, Outcome)> {
    soft_bodies
        .iter()
        .map(|(handle, _)| (handle, None))
        .collect()
}

/// The outcomes of the bodies that were stepped.
fn results(outcomes: Vec<(DeformableBodyHandle, Outcome)>) -> SoftStepResults {
    outcomes
        .into_iter()
        .filter_map(|(handle, outcome)| outcome.map(|outcome| (handle, outcome)))
        .collect()
}
