//! [`FvmWorld`]: rapier's [`PhysicsWorld`] and a set of finite-volume soft bodies, advanced
//! together frame by frame.
//!
//! rapier offers no callback inside its step, so the frame is cut into
//! [`FvmWorld::coupling_substeps`] rapier steps, and the soft bodies step between them: each
//! detects its contacts with the colliders, steps (explicit or implicit, as the automatic
//! integrator chooses), and hands the impulses its contacts gave dynamic rigid bodies to rapier,
//! which then solves its own contacts and joints over the same interval. Sub-cycling keeps the
//! rigid bodies' view of the soft bodies one short substep old, which removes the friction
//! ratchet and the rocking that a single rapier step per frame shows. The frame's
//! `num_solver_iterations` are divided among the substeps (rounded up), so rapier's solver cost
//! per frame is about unchanged; its collision detection runs once per substep. A
//! position-based kinematic body told where to be at the end of the frame
//! (`set_next_kinematic_position`) gets there along the straight path (rotation by slerp), a
//! part per substep, rather than in the first substep.
//!
//! Soft bodies whose surfaces touch (their collision groups interacting) are stepped together by
//! the explicit integrator, in the substeps the least stable of them needs, whatever the
//! automatic choice: their contacts are solved in the same sweeps with both bodies' nodes, so
//! that momentum passes exactly from one to the other and a stack rests without creeping in.

use crate::Error;
use crate::body::{SoftBody, SoftBodyHandle, SoftBodySet};
use crate::contact::{self, BetweenContact, ContactSettings};
use crate::integrate::{AutomaticIntegrator, AutomaticReport};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet, RigidBodyType};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::pipeline::{EventHandler, PhysicsHooks, PhysicsWorld};

/// What stepping a soft body gave over a frame so far: nothing yet, its last report, or the
/// error that stopped it.
type Outcome = Option<Result<AutomaticReport, Error>>;

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
/// let cube = SoftBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [2, 2, 2])?, rubber)
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
pub struct FvmWorld {
    /// The rapier world: rigid bodies, colliders, joints and the integration parameters, whose
    /// `dt` is the frame step (s) and whose `gravity` (m/s²) acts on the soft bodies too.
    pub physics: PhysicsWorld,
    /// The soft bodies.
    pub soft_bodies: SoftBodySet,
    /// How soft bodies are stepped.
    pub integrator: AutomaticIntegrator,
    /// How soft contacts are detected and enforced.
    pub contact: ContactSettings,
    /// Rapier steps per frame, with the soft bodies stepped between them (at least 1).
    pub coupling_substeps: u32,
    /// What each soft body exerted on each rigid body over the last frame.
    loads: Vec<RigidLoad>,
}

/// The mean force and torque a soft body exerted on a rigid body over a frame, through its
/// contacts and attachments (rigid bodies of every type: a fixed or kinematic body feels it too,
/// though it does not move).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidLoad {
    /// The soft body.
    pub soft_body: SoftBodyHandle,
    /// The rigid body.
    pub rigid_body: RigidBodyHandle,
    /// The force (N).
    pub force: DVec3,
    /// The torque about the rigid body's centre of mass (N m).
    pub torque: DVec3,
}

impl Default for FvmWorld {
    fn default() -> Self {
        Self {
            physics: PhysicsWorld::default(),
            soft_bodies: SoftBodySet::new(),
            integrator: AutomaticIntegrator::default(),
            contact: ContactSettings::default(),
            coupling_substeps: 4,
            loads: Vec::new(),
        }
    }
}

/// Holds the rigid bodies `body` touches that rigid contacts support: within the soft step they
/// would otherwise fall freely, the ground that holds them acting only in rapier's step.
fn hold_supported_bodies(body: &mut crate::body::SoftBody, physics: &PhysicsWorld) {
    for proxy in &mut body.rigid_proxies {
        let supported = physics.bodies.get(proxy.handle).is_some_and(|rigid| {
            rigid.colliders().iter().any(|&collider| {
                physics
                    .narrow_phase
                    .contact_pairs_with(collider)
                    .any(|pair| pair.has_any_active_contact())
            })
        });
        if supported {
            proxy.hold();
        }
    }
}

/// The groups of `count` bodies that the contacts `between` them link (directly or through
/// others), each with its contacts re-indexed to positions in the group: bodies that must step
/// together. A body touching no other is a group of its own.
fn touching_groups(
    count: usize,
    between: Vec<BetweenContact>,
) -> Vec<(Vec<usize>, Vec<BetweenContact>)> {
    let mut root: Vec<usize> = (0..count).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for contact in &between {
        let (a, b) = (
            find(&mut root, contact.node_body),
            find(&mut root, contact.triangle_body),
        );
        root[a.max(b)] = a.min(b);
    }
    let mut groups: Vec<(Vec<usize>, Vec<BetweenContact>)> = Vec::new();
    let mut group_of = vec![usize::MAX; count];
    let mut slot_of = vec![0; count];
    for (i, slot) in slot_of.iter_mut().enumerate() {
        let r = find(&mut root, i);
        if group_of[r] == usize::MAX {
            group_of[r] = groups.len();
            groups.push((Vec::new(), Vec::new()));
        }
        let group = &mut groups[group_of[r]].0;
        *slot = group.len();
        group.push(i);
    }
    for mut contact in between {
        let g = group_of[find(&mut root, contact.node_body)];
        contact.node_body = slot_of[contact.node_body];
        contact.triangle_body = slot_of[contact.triangle_body];
        groups[g].1.push(contact);
    }
    groups
}

/// Adds a substep's impulse (N s) and angular impulse about the centre of mass (N m s) to the
/// frame's total for the pair; [`FvmWorld::step_with_events`] divides the totals by the frame.
fn add_load(
    loads: &mut Vec<RigidLoad>,
    soft_body: SoftBodyHandle,
    rigid_body: RigidBodyHandle,
    impulse: DVec3,
    angular_impulse: DVec3,
) {
    match loads
        .iter_mut()
        .find(|load| load.soft_body == soft_body && load.rigid_body == rigid_body)
    {
        Some(load) => {
            load.force += impulse;
            load.torque += angular_impulse;
        }
        None => loads.push(RigidLoad {
            soft_body,
            rigid_body,
            force: impulse,
            torque: angular_impulse,
        }),
    }
}

/// A position-based kinematic body's motion over a frame: from its pose to the one it was told
/// to reach.
struct KinematicPath {
    handle: RigidBodyHandle,
    from: Pose,
    to: Pose,
}

impl KinematicPath {
    /// The paths of the position-based kinematic bodies of `bodies` that are told to move.
    fn all(bodies: &RigidBodySet) -> Vec<Self> {
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
    fn advance(&self, bodies: &mut RigidBodySet, fraction: f32) {
        if let Some(body) = bodies.get_mut(self.handle) {
            body.set_next_kinematic_position(self.from.lerp(&self.to, fraction));
        }
    }
}

impl FvmWorld {
    /// The mean force and torque each soft body exerted on each rigid body it touched or is
    /// attached to, over the last frame (the impulses it handed over, divided by the frame's
    /// `dt`). Colliders without a rigid body (fixed ground) are not listed: see
    /// [`SoftBody::contact_force_on`](crate::body::SoftBody::contact_force_on).
    pub fn rigid_loads(&self) -> &[RigidLoad] {
        &self.loads
    }

    /// The mean force (N) and torque about its centre of mass (N m) soft body `soft` exerted on
    /// rigid body `rigid` over the last frame; zero if they did not interact.
    pub fn load_on(&self, soft: SoftBodyHandle, rigid: RigidBodyHandle) -> (DVec3, DVec3) {
        self.loads
            .iter()
            .find(|load| load.soft_body == soft && load.rigid_body == rigid)
            .map_or((DVec3::ZERO, DVec3::ZERO), |load| (load.force, load.torque))
    }

    /// One coupling substep of `h` (s) of the soft bodies whose `outcomes` are not yet an error:
    /// each finds its contacts with the colliders, bodies touching each other are grouped and
    /// stepped together, the others alone, and the impulses they gave rigid bodies go to rapier
    /// and to the frame's loads. Each body's outcome becomes its last report or its error.
    fn step_soft_bodies(
        &mut self,
        outcomes: &mut [(SoftBodyHandle, Outcome)],
        h: f64,
        gravity: DVec3,
    ) {
        for (handle, outcome) in outcomes.iter_mut() {
            if matches!(outcome, Some(Err(_))) {
                continue;
            }
            let physics = &self.physics;
            if let Err(error) = self.soft_bodies[*handle].detect_contacts(
                &physics.colliders,
                &physics.bodies,
                h,
                gravity,
                &self.contact,
            ) {
                *outcome = Some(Err(error));
            }
        }
        let live: Vec<SoftBodyHandle> = outcomes
            .iter()
            .filter(|(_, outcome)| !matches!(outcome, Some(Err(_))))
            .map(|(handle, _)| *handle)
            .collect();
        let between = {
            let bodies: Vec<&SoftBody> = live.iter().map(|&h| &self.soft_bodies[h]).collect();
            contact::detect_between(&bodies, &self.contact, h, gravity)
        };
        for (group, mut contacts) in touching_groups(live.len(), between) {
            let handles: Vec<SoftBodyHandle> = group.iter().map(|&i| live[i]).collect();
            let physics = &mut self.physics;
            let mut bodies = self.soft_bodies.get_many_mut(&handles);
            for body in bodies.iter_mut() {
                hold_supported_bodies(body, physics);
            }
            let stepped: Vec<Result<AutomaticReport, Error>> = if let [body] = &mut bodies[..] {
                vec![self.integrator.step(body, h, gravity)]
            } else {
                match self
                    .integrator
                    .step_together(&mut bodies, &mut contacts, h, gravity)
                {
                    Ok(reports) => reports.into_iter().map(Ok).collect(),
                    Err(error) => vec![Err(error); bodies.len()],
                }
            };
            for ((handle, body), result) in handles.iter().zip(bodies).zip(stepped) {
                if result.is_ok() {
                    for (rigid_body, impulse, angular_impulse) in body.rigid_impulses() {
                        add_load(
                            &mut self.loads,
                            *handle,
                            rigid_body,
                            impulse,
                            angular_impulse,
                        );
                    }
                    body.transfer_contact_impulses(&mut physics.bodies);
                }
                if let Some((_, outcome)) = outcomes.iter_mut().find(|(h, _)| h == handle) {
                    *outcome = Some(result);
                }
            }
        }
    }

    /// Advances the world by one frame (`physics.integration_parameters.dt`), without hooks or
    /// events; see [`FvmWorld::step_with_events`].
    pub fn step(&mut self) -> Vec<(SoftBodyHandle, Result<AutomaticReport, Error>)> {
        self.step_with_events(&(), &())
    }

    /// Advances the world by one frame, passing `hooks` and `events` to rapier. Returns, per
    /// soft body, the report of its last substep or the first error it met; a body whose step
    /// failed keeps the state it had before that substep and skips the rest of the frame. A frame
    /// of `dt = 0` (a pause) only lets rapier apply changes, and steps no soft body.
    pub fn step_with_events(
        &mut self,
        hooks: &dyn PhysicsHooks,
        events: &dyn EventHandler,
    ) -> Vec<(SoftBodyHandle, Result<AutomaticReport, Error>)> {
        let substeps = self.coupling_substeps.max(1);
        let frame = self.physics.integration_parameters;
        self.loads.clear();
        if frame.dt <= 0.0 {
            self.physics.step_with_events(hooks, events);
            return Vec::new();
        }
        let h = f64::from(frame.dt) / f64::from(substeps);
        let gravity = self.physics.gravity.as_dvec3();
        let mut outcomes: Vec<(SoftBodyHandle, Outcome)> = self
            .soft_bodies
            .iter()
            .map(|(handle, _)| (handle, None))
            .collect();
        self.physics.integration_parameters.dt = frame.dt / substeps as f32;
        self.physics.integration_parameters.num_solver_iterations = frame
            .num_solver_iterations
            .div_ceil(substeps as usize)
            .max(1);
        let paths = KinematicPath::all(&self.physics.bodies);
        for substep in 1..=substeps {
            for path in &paths {
                path.advance(&mut self.physics.bodies, substep as f32 / substeps as f32);
            }
            self.step_soft_bodies(&mut outcomes, h, gravity);
            self.physics.step_with_events(hooks, events);
        }
        self.physics.integration_parameters = frame;
        let per_second = 1.0 / f64::from(frame.dt);
        for load in &mut self.loads {
            load.force *= per_second;
            load.torque *= per_second;
        }
        outcomes
            .into_iter()
            .filter_map(|(handle, outcome)| outcome.map(|outcome| (handle, outcome)))
            .collect()
    }
}
