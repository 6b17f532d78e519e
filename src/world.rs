//! [`FvmWorld`]: rapier's [`PhysicsWorld`] and a set of deformable bodies, advanced together
//! frame by frame by a [`SoftCoupling`] (see [`crate::coupling`] for the stages of a frame).
//!
//! It is a convenience: a program that keeps its own [`PhysicsPipeline`] and sets calls
//! [`SoftCoupling::step`] with them instead, and gets the same motion.

use crate::Error;
use crate::body::{DeformableBodyHandle, DeformableBodySet};
use crate::coupling::{
    Audit, AuditInput, ColliderLoad, FrameAudit, RapierSets, RigidLoad, SoftCoupling,
    SoftStepResults,
};
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::geometry::ColliderHandle;
use rapier3d::glamx::DVec3;
use rapier3d::pipeline::{
    CollisionPipeline, EventHandler, PhysicsHooks, PhysicsPipeline, PhysicsWorld,
};

/// Rigid and soft bodies in one world.
///
/// # Example
/// ```
/// use rapier3d::prelude::{ColliderBuilder, SharedShape};
/// use rapier_fvm::prelude::*;
/// use rapier_fvm::world::FvmWorld;
///
/// let mut world = FvmWorld::default();
/// world.physics.insert_collider(
///     ColliderBuilder::new(SharedShape::halfspace(rapier_fvm::glamx::Vec3::Y)).build(),
///     None,
/// );
/// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
/// let cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [2, 2, 2])?, rubber)
///     .translation(DVec3::new(0.0, 0.2, 0.0))
///     .build()?;
/// let handle = world.soft_bodies.insert(cube);
/// for _ in 0..30 {
///     for (_, outcome) in world.step() {
///         outcome?;
///     }
/// }
/// assert!(world.soft_bodies[handle].positions().iter().all(|x| x.y > -2e-3));
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
///
/// With the feature `serde-serialize`, a world also serializes, and one read back steps on as the
/// original, bit for bit (a binary format such as CBOR: rapier's state holds infinities, which
/// JSON cannot carry):
/// ```
/// # #[cfg(feature = "serde-serialize")] {
/// use rapier_fvm::prelude::*;
///
/// let mut world = FvmWorld::default();
/// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
/// world
///     .soft_bodies
///     .insert(DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [2; 3])?, rubber).build()?);
/// world.step();
/// let mut file = Vec::new();
/// ciborium::into_writer(&world, &mut file).expect("a world serializes");
/// let mut restored: FvmWorld = ciborium::from_reader(&file[..]).expect("and reads back");
/// world.step();
/// restored.step();
/// let (a, b) = (world.soft_bodies.iter().next(), restored.soft_bodies.iter().next());
/// assert_eq!(a.map(|(_, body)| body.positions()), b.map(|(_, body)| body.positions()));
/// # }
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct FvmWorld {
    /// The rapier world: rigid bodies, colliders, joints and the integration parameters, whose
    /// `dt` is the frame step (s) and whose `gravity` (m/s²) acts on the deformable bodies too.
    pub physics: PhysicsWorld,
    /// The deformable bodies.
    pub soft_bodies: DeformableBodySet,
    /// How the deformable bodies are stepped beside the rigid ones: integrator, contact
    /// settings, coupling substeps per frame.
    pub coupling: SoftCoupling,
}

impl Default for FvmWorld {
    fn default() -> Self {
        Self {
            physics: PhysicsWorld::default(),
            soft_bodies: DeformableBodySet::new(),
            coupling: SoftCoupling::default(),
        }
    }
}

/// A copy of the world to go back to (a reset, a rollout's branch point): every rigid and
/// deformable body, collider, joint and contact, the integrators' caches included, so that the
/// copy and the original step on identically, bit for bit. rapier's pipelines start anew: they
/// carry nothing from one step to the next but the last step's quarantine report.
impl Clone for FvmWorld {
    fn clone(&self) -> Self {
        let physics = &self.physics;
        Self {
            physics: PhysicsWorld {
                gravity: physics.gravity,
                integration_parameters: physics.integration_parameters,
                physics_pipeline: PhysicsPipeline::new(),
                collision_pipeline: CollisionPipeline::new(),
                islands: physics.islands.clone(),
                broad_phase: physics.broad_phase.clone(),
                narrow_phase: physics.narrow_phase.clone(),
                bodies: physics.bodies.clone(),
                colliders: physics.colliders.clone(),
                impulse_joints: physics.impulse_joints.clone(),
                multibody_joints: physics.multibody_joints.clone(),
                soft_bodies: physics.soft_bodies.clone(),
                ccd_solver: physics.ccd_solver.clone(),
            },
            soft_bodies: self.soft_bodies.clone(),
            coupling: self.coupling.clone(),
        }
    }
}

impl FvmWorld {
    /// The mean force and torque each deformable body exerted on each rigid body it touched or
    /// is attached to, over the last frame; see [`SoftCoupling::rigid_loads`].
    pub fn rigid_loads(&self) -> &[RigidLoad] {
        self.coupling.rigid_loads()
    }

    /// The mean force and torque (about the world origin) each deformable body's contacts
    /// exerted on each collider over the last frame, the ground included; see
    /// [`SoftCoupling::collider_loads`].
    pub fn collider_loads(&self) -> &[ColliderLoad] {
        self.coupling.collider_loads()
    }

    /// The mean force (N) and torque about its centre of mass (N m) deformable body `soft`
    /// exerted on rigid body `rigid` over the last frame; zero if they did not interact.
    pub fn load_on(&self, soft: DeformableBodyHandle, rigid: RigidBodyHandle) -> (DVec3, DVec3) {
        self.coupling.load_on(soft, rigid)
    }

    /// Glues `nodes` of the deformable body `soft` to the rigid body `rigid` where they are now;
    /// see [`SoftCoupling::attach`].
    ///
    /// # Errors
    /// Those of [`SoftCoupling::attach`]; nothing is attached then.
    pub fn attach(
        &mut self,
        soft: DeformableBodyHandle,
        nodes: impl IntoIterator<Item = u32>,
        rigid: RigidBodyHandle,
    ) -> Result<(), Error> {
        self.coupling
            .attach(&self.soft_bodies, soft, nodes, rigid, &self.physics.bodies)
    }

    /// The mean force (N) and torque about the world origin (N m) the contacts of the deformable
    /// body `soft` exerted on `collider` over its last step (the frame's last coupling substep,
    /// or the whole frame for a body that needed no coupling); see
    /// [`SoftCoupling::contact_force_on`].
    ///
    /// # Errors
    /// Those of [`SoftCoupling::contact_force_on`].
    pub fn contact_force_on(
        &self,
        soft: DeformableBodyHandle,
        collider: ColliderHandle,
    ) -> Result<(DVec3, DVec3), Error> {
        self.coupling
            .contact_force_on(&self.soft_bodies, soft, collider)
    }

    /// Advances the world by one frame (`physics.integration_parameters.dt`), without hooks or
    /// events; see [`FvmWorld::step_with_events`].
    pub fn step(&mut self) -> SoftStepResults {
        self.step_with_events(&(), &())
    }

    /// Advances the world by one frame, passing `hooks` and `events` to rapier: one
    /// [`SoftCoupling::step`] on the world's own sets. Returns, per deformable body, the report
    /// of its last substep or the first error it met; a body whose step was refused keeps the
    /// state it had before that substep for the rest of the frame, holding the rigid bodies it
    /// touches as a fixed obstacle would.
    pub fn step_with_events(
        &mut self,
        hooks: &dyn PhysicsHooks,
        events: &dyn EventHandler,
    ) -> SoftStepResults {
        let physics = &mut self.physics;
        let rapier = RapierSets {
            gravity: physics.gravity,
            integration_parameters: &physics.integration_parameters,
            islands: &mut physics.islands,
            broad_phase: &mut physics.broad_phase,
            narrow_phase: &mut physics.narrow_phase,
            bodies: &mut physics.bodies,
            colliders: &mut physics.colliders,
            impulse_joints: &mut physics.impulse_joints,
            multibody_joints: &mut physics.multibody_joints,
            rapier_soft_bodies: &mut physics.soft_bodies,
            ccd_solver: &mut physics.ccd_solver,
        };
        self.coupling.step(
            &mut physics.physics_pipeline,
            rapier,
            &mut self.soft_bodies,
            hooks,
            events,
        )
    }
}

/// The audit of a world (see [`crate::coupling::Audit`]), here so that the coupling layer does not
/// reach up to the world.
impl<'a> AuditInput<'a> {
    /// What the audit reads of `world`.
    pub fn of_world(world: &'a FvmWorld) -> Self {
        Self {
            soft_bodies: &world.soft_bodies,
            coupling: &world.coupling,
            bodies: &world.physics.bodies,
            colliders: &world.physics.colliders,
            gravity: world.physics.gravity.as_dvec3(),
            dt: f64::from(world.physics.integration_parameters.dt),
            solver_iterations: world.physics.integration_parameters.num_solver_iterations,
        }
    }
}

impl Audit {
    /// [`Audit::restart`] on `world`.
    pub fn restart_world(&mut self, world: &FvmWorld) {
        self.restart(AuditInput::of_world(world));
    }

    /// [`Audit::check`] on `world`.
    pub fn check_world(&mut self, world: &FvmWorld, results: &SoftStepResults) -> FrameAudit {
        self.check(AuditInput::of_world(world), results)
    }
}
