//! 2D bodies in contact with rapier2d's colliders, coupled two-way with its rigid bodies
//! (feature `dim2`). A frame of `dt` is cut into [`PlanarCoupling::substeps`] rapier steps of
//! `h = dt / substeps` (or as many as the contacts need, see below), and between them:
//!
//! 1. **Colliders.** Every non-sensor collider is seen where it is, moving with its rigid body's
//!    velocity.
//! 2. **Soft step.** Each body steps explicitly over `h` ([`super::step_explicit`]'s substeps),
//!    every node inside a collider pushed out by a penalty `f_n = max(0, k d − c v_n)` along the
//!    collider's outward normal (`d` the depth, `v_n` the approach speed, `c = 2 √(k m)`, the
//!    node's critical damping), and Coulomb friction `|f_t| ≤ μ f_n` against the relative
//!    sliding velocity (regularized below [`STICKING_SPEED`]). The contact stiffness is
//!    `k = (λ' + 2μ) t` of the body's material (`λ'` the plane model's), so that a node's
//!    contact frequency is that of its elements.
//!    Corners of polygonal colliders inside a body are pushed out through its boundary by the
//!    same penalty, the boundary segment's nodes taking the opposite force.
//!    Nodes glued to rigid bodies ([`PlanarCoupling::glue`]) are held to their anchors by
//!    damped springs of the same stiffness, `f = k (a − x) + c (v_a − v)` to the anchor `a`.
//!    A body within reach of no dynamic rigid body or collider corner, and glued to no dynamic
//!    rigid body, may instead take one backward Euler step over `h` with its contacts and glue
//!    in it ([`PlanarIntegrator`]; by
//!    default where the explicit step would need more than [`AUTOMATIC_SUBSTEPS`] substeps): a
//!    stiff 2 kg block (E = 10⁸ Pa, damped) resting on the ground takes 0.45 ms per frame
//!    (automatic) against 408 ms explicitly, the ground carrying its weight to the fifth digit
//!    both ways.
//! 3. **Exchange.** The opposite impulses, at the nodes, go to the dynamic rigid bodies, and
//!    are summed per collider into the frame's mean forces ([`PlanarCoupling::collider_forces`];
//!    the glue's per rigid body, [`PlanarCoupling::glue_force`]).
//! 4. **Rigid step.** rapier2d steps its world over `h`.
//!
//! A dynamic rigid body pressed by `n` nodes feels a stiffness `n k` that its own step, which
//! sees the soft body only through the impulses, integrates explicitly: stable for
//! `h < 2 √(m / (n k))`. The substeps are raised to keep `h` below half of that for the lightest
//! body the last frame's contacts held, so that no rigid body rings at the default settings.
//!
//! # Example: a box on a soft block on the ground
//! ```
//! use rapier2d::prelude::{ColliderBuilder, PhysicsWorld, RigidBodyBuilder};
//! use rapier_fvm::glamx::DVec2;
//! use rapier_fvm::material::{Material, MaterialModel};
//! use rapier_fvm::planar::coupling::PlanarCoupling;
//! use rapier_fvm::planar::{PlanarBodyBuilder, TriangleMesh};
//!
//! let mut world = PhysicsWorld::default();
//! let ground = world.bodies.insert(RigidBodyBuilder::fixed().translation([0.0, -0.5].into()));
//! let floor = ColliderBuilder::cuboid(2.0, 0.5).build();
//! let floor = world.colliders.insert_with_parent(floor, ground, &mut world.bodies);
//! let lid = world.bodies.insert(RigidBodyBuilder::dynamic().translation([0.0, 0.13].into()));
//! let shape = ColliderBuilder::cuboid(0.05, 0.025).density(100.0).build();
//! world.colliders.insert_with_parent(shape, lid, &mut world.bodies);
//! // A 0.2 m x 0.1 m block of rubber, 10 cm thick, resting on the ground.
//! let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
//! let mesh = TriangleMesh::rectangle(DVec2::new(0.2, 0.1), [10, 5])?;
//! let mut block = PlanarBodyBuilder::new(mesh, rubber).thickness(0.1).build()?;
//! for x in block.positions_mut() {
//!     *x += DVec2::new(-0.1, 0.0);
//! }
//! let mut bodies = vec![block];
//! let mut coupling = PlanarCoupling::default();
//! for _ in 0..60 {
//!     for report in coupling.step(&mut world, &mut bodies)? {
//!         report?;
//!     }
//! }
//! // The ground carries the block (2 kg) and the box (0.5 kg) once they settle.
//! assert!(coupling.force_on(floor).y < 0.0);
//! # Ok::<(), rapier_fvm::Error>(())
//! ```

use super::body::PlanarBody;
use super::colliders::{ColliderView, colliders_of};
use super::corners::corner_inside;
use super::dynamics::{PlanarStepReport, advance, explicit_substeps};
use super::glue::{GlueView, GluedNode};
use super::implicit_contact::step_in_contact;
use crate::Error;
use rapier2d::dynamics::RigidBodyHandle;
use rapier2d::geometry::ColliderHandle;
use rapier2d::glamx::DVec2;
use rapier2d::pipeline::PhysicsWorld;

/// Below this sliding speed (m/s) friction is viscous, `μ f_n v_t / STICKING_SPEED`, instead of
/// Coulomb's `μ f_n`: it holds a loaded contact at rest but lets it creep at that speed's scale.
pub const STICKING_SPEED: f64 = 1e-3;

/// The most coupling substeps a frame takes.
const MAX_SUBSTEPS: u32 = 256;

/// Explicit substeps per coupling substep above which [`PlanarIntegrator::Automatic`] steps a
/// body implicitly. Measured on one core: an explicit substep costs about 60 ns per triangle,
/// an implicit step 1 µs per triangle for a body at rest and 24 µs for a disk rolling on a
/// slope (Newton following its changing contacts); 400 substeps is where the second costs as
/// much.
pub const AUTOMATIC_SUBSTEPS: f64 = 400.0;

/// How the bodies step between rapier2d's steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum PlanarIntegrator {
    /// Symplectic Euler in substeps below the stability limit, with every contact kind.
    Explicit,
    /// One backward Euler step per coupling substep, contacts with colliders and glue to
    /// fixed or kinematic rigid bodies in it (the penalty and the glue's springs as potentials,
    /// friction lagged), for a body whose reach over the substep meets no dynamic rigid body and
    /// no collider's corner and which is glued to no dynamic rigid body; any other body steps
    /// explicitly (the step's report says which).
    Implicit,
    /// Implicit where [`PlanarIntegrator::Implicit`] would be and the explicit step would
    /// need more than [`AUTOMATIC_SUBSTEPS`] substeps (its contacts' stiffness counted),
    /// explicit otherwise, and explicit where an implicit step fails (Newton's method does not
    /// converge).
    #[default]
    Automatic,
}

/// How 2D bodies step beside rapier2d's rigid bodies, and what they exerted on its colliders
/// over the last frame.
#[derive(Debug, Clone)]
pub struct PlanarCoupling {
    /// The fewest rapier steps per frame (at least 1); more are taken when the contacts with
    /// light rigid bodies need them (see the module's documentation).
    pub substeps: u32,
    /// The friction coefficient between bodies and colliders.
    pub friction: f64,
    /// How the bodies step; default automatic.
    pub integrator: PlanarIntegrator,
    /// The mean force (N) the bodies exerted on each collider over the last frame.
    forces: Vec<(ColliderHandle, DVec2)>,
    /// The stiffest contact (N/m per kg of rigid body) of the last frame.
    stiffness_per_mass: f64,
    /// Nodes glued to rigid bodies.
    glued: Vec<GluedNode>,
    /// The mean force (N) the glued nodes exerted on each rigid body over the last frame.
    glue_forces: Vec<(RigidBodyHandle, DVec2)>,
}

impl Default for PlanarCoupling {
    fn default() -> Self {
        Self {
            substeps: 4,
            friction: 0.5,
            integrator: PlanarIntegrator::Automatic,
            forces: Vec::new(),
            stiffness_per_mass: 0.0,
            glued: Vec::new(),
            glue_forces: Vec::new(),
        }
    }
}

/// What a body's contacts exerted on each collider over a step: forces (N) and torques about
/// the collider's rigid body's centre of mass (N m) summed over the explicit substeps, and the
/// most nodes pressing on it at once.
struct Exchange {
    force: Vec<DVec2>,
    torque: Vec<f64>,
    pressing: Vec<usize>,
}

impl Exchange {
    fn new(colliders: usize) -> Self {
        Self {
            force: vec![DVec2::ZERO; colliders],
            torque: vec![0.0; colliders],
            pressing: vec![0; colliders],
        }
    }

    /// The contact forces (N per node) on `body` against `colliders`, with stiffness `k` (N/m)
    /// and friction `mu`, their opposites added to the colliders' sums.
    fn contact_forces(
        &mut self,
        body: &PlanarBody,
        colliders: &[ColliderView],
        (k, mu): (f64, f64),
    ) -> Vec<DVec2> {
        let mut forces = vec![DVec2::ZERO; body.positions().len()];
        let mut pressing = vec![0usize; colliders.len()];
        for (node, (x, v)) in body.positions().iter().zip(body.velocities()).enumerate() {
            for (c, view) in colliders.iter().enumerate() {
                let Some((depth, normal)) = view.penetration(*x) else {
                    continue;
                };
                let relative = *v - view.velocity_at(*x);
                let damping = 2.0 * (k * body.masses()[node]).sqrt();
                let (force, normal_force) = penalty((k, damping, mu), depth, normal, relative);
                forces[node] += force;
                let arm = view.parent.map_or(DVec2::ZERO, |(_, com, ..)| *x - com);
                self.force[c] -= force;
                self.torque[c] -= arm.perp_dot(force);
                pressing[c] += usize::from(normal_force > 0.0);
            }
        }
        self.corner_forces(body, colliders, (k, mu), (&mut forces, &mut pressing));
        for (most, now) in self.pressing.iter_mut().zip(pressing) {
            *most = (*most).max(now);
        }
        forces
    }

    /// Adds the forces of the colliders' corners inside `body` to the nodes' `forces` (N), their
    /// opposites to the colliders' sums, and counts the pressing ones in `pressing`.
    fn corner_forces(
        &mut self,
        body: &PlanarBody,
        colliders: &[ColliderView],
        (k, mu): (f64, f64),
        (forces, pressing): (&mut [DVec2], &mut [usize]),
    ) {
        let (x, v) = (body.positions(), body.velocities());
        let (low, high) = bounds_of(x);
        for (c, view) in colliders.iter().enumerate() {
            for &p in &view.corners {
                if p.cmplt(low).any() || p.cmpgt(high).any() {
                    continue;
                }
                let Some(corner) = corner_inside(body, p) else {
                    continue;
                };
                let [a, b] = corner.segment.map(|n| n as usize);
                let s = corner.s;
                let soft_velocity = v[a] * (1.0 - s) + v[b] * s;
                let relative = view.velocity_at(p) - soft_velocity;
                let mass = 0.5 * (body.masses()[a] + body.masses()[b]);
                let damping = 2.0 * (k * mass).sqrt();
                let (force, normal_force) =
                    penalty((k, damping, mu), corner.depth, corner.normal, relative);
                forces[a] -= force * (1.0 - s);
                forces[b] -= force * s;
                let arm = view.parent.map_or(DVec2::ZERO, |(_, com, ..)| p - com);
                self.force[c] += force;
                self.torque[c] += arm.perp_dot(force);
                pressing[c] += usize::from(normal_force > 0.0);
            }
        }
    }
}

/// The penalty force (N) on a point `depth` (m) inside along the outward `normal`, moving at
/// `relative` (m/s) against what it presses on, with stiffness `k` (N/m), damping `c` (N s/m)
/// and friction `mu`: `max(0, k d − c v_n)` along the normal, Coulomb friction against the
/// sliding (viscous below [`STICKING_SPEED`]); and its normal part (N).
fn penalty(
    (k, damping, mu): (f64, f64, f64),
    depth: f64,
    normal: DVec2,
    relative: DVec2,
) -> (DVec2, f64) {
    let approach = relative.dot(normal);
    let normal_force = (k * depth - damping * approach).max(0.0);
    let sliding = relative - normal * approach;
    let speed = sliding.length();
    let friction = if speed > 0.0 {
        -sliding * (mu * normal_force * (speed / STICKING_SPEED).min(1.0) / speed)
    } else {
        DVec2::ZERO
    };
    (normal * normal_force + friction, normal_force)
}

/// The bounding box (m) of `points`.
fn bounds_of(points: &[DVec2]) -> (DVec2, DVec2) {
    (points.iter()).fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(low, high), p| {
        (low.min(*p), high.max(*p))
    })
}

/// The contact stiffness (N/m) of `body`'s nodes: `(λ' + 2μ) t`, the plane model's P-wave
/// modulus (plane stress `λ' = λ*`) times the rest thickness.
fn contact_stiffness(body: &PlanarBody) -> f64 {
    let lame = body.material().lame();
    let lambda = match body.plane() {
        super::PlaneModel::PlaneStrain => lame.lambda,
        super::PlaneModel::PlaneStress => {
            2.0 * lame.lambda * lame.mu / (lame.lambda + 2.0 * lame.mu)
        }
    };
    (lambda + 2.0 * lame.mu) * body.thickness()
}

impl PlanarCoupling {
    /// The mean force (N) the bodies exerted on each collider over the last frame.
    pub fn collider_forces(&self) -> &[(ColliderHandle, DVec2)] {
        &self.forces
    }

    /// Glues `nodes` of `bodies[body]`, where they are, to the rigid body `rigid` of `world`
    /// (each held to a point fixed in the rigid body by a damped spring of the body's contact
    /// stiffness, the rigid body taking the opposite force); the glue holds while both exist
    /// (glue to a rigid body removed from the world is dropped at the next step).
    ///
    /// # Errors
    /// [`Error::UnknownDeformableBody`] for a body index out of range,
    /// [`Error::UnknownRigidBody`], [`Error::NodeOutOfRange`]; nothing is glued then.
    pub fn glue(
        &mut self,
        world: &PhysicsWorld,
        bodies: &[PlanarBody],
        (body, nodes): (usize, &[usize]),
        rigid: RigidBodyHandle,
    ) -> Result<(), Error> {
        let planar = bodies.get(body).ok_or(Error::UnknownDeformableBody)?;
        let glued = GluedNode::new_all(world, (body, planar), nodes, rigid)?;
        self.glued.extend(glued);
        Ok(())
    }

    /// The mean force (N) the glued nodes exerted on `rigid` over the last frame.
    pub fn glue_force(&self, rigid: RigidBodyHandle) -> DVec2 {
        (self.glue_forces.iter())
            .filter(|(h, _)| *h == rigid)
            .map(|(_, f)| *f)
            .sum()
    }

    /// The mean force (N) the bodies exerted on `collider` over the last frame.
    pub fn force_on(&self, collider: ColliderHandle) -> DVec2 {
        (self.forces.iter())
            .filter(|(h, _)| *h == collider)
            .map(|(_, f)| *f)
            .sum()
    }

    /// The substeps the next frame of `dt` (s) takes: [`PlanarCoupling::substeps`], or more
    /// if the last frame's stiffest contact per kilogram of rigid body needs them.
    fn substeps_for(&self, dt: f64) -> u32 {
        // Half of the stable step 2/ω, ω² = n k / m.
        let needed = (dt * self.stiffness_per_mass.sqrt()).ceil();
        let needed = if needed.is_finite() {
            needed.min(f64::from(MAX_SUBSTEPS)) as u32
        } else {
            1
        };
        self.substeps.max(1).max(needed).min(MAX_SUBSTEPS)
    }

    /// Advances `world` and `bodies` by one frame of `world.integration_parameters.dt` (s),
    /// under the world's gravity: per body the report of its last soft step, or its first
    /// error (the body then stays where that step found it and touches nothing after).
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a frame step that is not positive and finite (nothing
    /// is stepped).
    pub fn step(
        &mut self,
        world: &mut PhysicsWorld,
        bodies: &mut [PlanarBody],
    ) -> Result<Vec<Result<PlanarStepReport, Error>>, Error> {
        let frame_dt = world.integration_parameters.dt;
        let dt = f64::from(frame_dt);
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidTimeStep {
                dt,
                reason: "a frame step must be positive and finite",
            });
        }
        let substeps = self.substeps_for(dt);
        let h = dt / f64::from(substeps);
        let gravity = world.gravity.as_dvec2();
        // None until a body's first soft step, which every body takes (one substep at least).
        let mut reports: Vec<Option<Result<PlanarStepReport, Error>>> = vec![None; bodies.len()];
        let mut impulses: Vec<(ColliderHandle, DVec2)> = Vec::new();
        let mut stiffest = 0.0f64;
        world.integration_parameters.dt = h as f32;
        self.glued
            .retain(|g| world.bodies.get(g.rigid).is_some() && g.body < bodies.len());
        let mut glue_impulses: Vec<(RigidBodyHandle, DVec2)> = Vec::new();
        for _ in 0..substeps {
            let colliders = colliders_of(world);
            let glue = GlueView::all(&self.glued, world);
            let (total, glue_total) = self.soft_step(
                bodies,
                &mut reports,
                (&colliders, &glue),
                (h, gravity),
                &mut stiffest,
            );
            for (view, (impulse, angular)) in glue.iter().zip(glue_total) {
                glue_impulses.push((view.rigid, impulse));
                if view.dynamic {
                    let rigid = &mut world.bodies[view.rigid];
                    rigid.apply_impulse(impulse.as_vec2(), true);
                    rigid.apply_torque_impulse(angular as f32, true);
                }
            }
            for (view, (impulse, angular)) in
                colliders.iter().zip(total.force.iter().zip(&total.torque))
            {
                impulses.push((view.handle, *impulse));
                if let (true, Some((handle, ..))) = (view.dynamic, view.parent) {
                    let rigid = &mut world.bodies[handle];
                    rigid.apply_impulse(impulse.as_vec2(), true);
                    rigid.apply_torque_impulse(*angular as f32, true);
                }
            }
            world.step();
        }
        world.integration_parameters.dt = frame_dt;
        self.stiffness_per_mass = stiffest;
        self.forces = mean_forces(impulses, dt);
        self.glue_forces = mean_forces(glue_impulses, dt);
        Ok(reports.into_iter().flatten().collect())
    }

    /// Steps each body of `bodies` not refused earlier in the frame (its `reports`) by `h` (s)
    /// under `gravity` (m/s²) against `colliders` and held by its `glue`: the impulses (N s) and
    /// angular impulses (N m s) the contacts gave each collider and the glue each glued node's
    /// rigid body, and `stiffest` raised to the stiffest contact or glue per kilogram of dynamic
    /// rigid body (N/m/kg).
    fn soft_step(
        &self,
        bodies: &mut [PlanarBody],
        reports: &mut [Option<Result<PlanarStepReport, Error>>],
        (colliders, glue): (&[ColliderView], &[GlueView]),
        (h, gravity): (f64, DVec2),
        stiffest: &mut f64,
    ) -> (Exchange, Vec<(DVec2, f64)>) {
        let mut total = Exchange::new(colliders.len());
        let mut glue_total = vec![(DVec2::ZERO, 0.0); glue.len()];
        for (index, (body, report)) in bodies.iter_mut().zip(reports).enumerate() {
            if matches!(report, Some(Err(_))) {
                continue;
            }
            let (k, mu) = (contact_stiffness(body), self.friction);
            let lightest = body.masses().iter().copied().fold(f64::INFINITY, f64::min);
            if let Some(stepped) = self.implicit_step(
                (body, index),
                (colliders, glue),
                (k, mu, lightest),
                (h, gravity),
                (&mut total, &mut glue_total),
            ) {
                *report = Some(stepped);
                continue;
            }
            let loads = vec![DVec2::ZERO; body.positions().len()];
            let mut exchange = Exchange::new(colliders.len());
            let mut glue_sums = vec![(DVec2::ZERO, 0.0); glue.len()];
            let mut forces = |b: &PlanarBody| {
                let mut forces = exchange.contact_forces(b, colliders, (k, mu));
                for (view, sum) in glue
                    .iter()
                    .zip(&mut glue_sums)
                    .filter(|(g, _)| g.body == index)
                {
                    let (force, at) = view.force(b, k);
                    forces[view.node] += force;
                    sum.0 -= force;
                    sum.1 -= (at - view.centre).perp_dot(force);
                }
                Some(forces)
            };
            let stepped = advance(body, h, (gravity, &loads), k / lightest, &mut forces);
            let Ok(stepped) = report.insert(stepped) else {
                continue;
            };
            let dt = stepped.substep_dt;
            let pieces = (exchange.force.iter())
                .zip(&exchange.torque)
                .zip(&exchange.pressing);
            for (c, ((force, torque), pressing)) in pieces.enumerate() {
                total.force[c] += *force * dt;
                total.torque[c] += torque * dt;
                *stiffest = stiffest.max(*pressing as f64 * k / colliders[c].mass);
            }
            let mut glued_to: Vec<(RigidBodyHandle, usize, f64)> = Vec::new();
            for ((view, sum), impulse) in glue.iter().zip(&glue_sums).zip(&mut glue_total) {
                if view.body == index {
                    impulse.0 += sum.0 * dt;
                    impulse.1 += sum.1 * dt;
                    match glued_to.iter_mut().find(|(rigid, ..)| *rigid == view.rigid) {
                        Some((_, count, _)) => *count += 1,
                        None => glued_to.push((view.rigid, 1, view.mass)),
                    }
                }
            }
            for (_, count, mass) in glued_to {
                *stiffest = stiffest.max(count as f64 * k / mass);
            }
        }
        (total, glue_total)
    }
}

impl PlanarCoupling {
    /// Steps `body` (number `index`) implicitly over `h` (s) under `gravity` (m/s²) if the
    /// integrator asks it and [`steps_alone`] allows (contact stiffness `k` (N/m), friction
    /// `mu`, its lightest node `lightest` (kg) for the explicit step's cost), adding its
    /// impulses (N s) on the colliders to `total`: the step's outcome, or `None` if the body
    /// is to step explicitly (also where [`PlanarIntegrator::Automatic`]'s implicit step
    /// failed, the body left as it was).
    fn implicit_step(
        &self,
        (body, index): (&mut PlanarBody, usize),
        (colliders, glue): (&[ColliderView], &[GlueView]),
        (k, mu, lightest): (f64, f64, f64),
        (h, gravity): (f64, DVec2),
        (total, glue_total): (&mut Exchange, &mut [(DVec2, f64)]),
    ) -> Option<Result<PlanarStepReport, Error>> {
        let wanted = match self.integrator {
            PlanarIntegrator::Explicit => false,
            PlanarIntegrator::Implicit => true,
            PlanarIntegrator::Automatic => {
                explicit_substeps(body, h, k / lightest) > AUTOMATIC_SUBSTEPS
            }
        };
        if !(wanted && steps_alone(body, index, (colliders, glue), h)) {
            return None;
        }
        let anchored: Vec<(usize, &GlueView)> = (glue.iter().enumerate())
            .filter(|(_, g)| g.body == index)
            .collect();
        match step_in_contact(body, (colliders, &anchored), (k, mu), (h, gravity)) {
            Ok((stepped, impulses, glue_impulses)) => {
                for (sum, impulse) in total.force.iter_mut().zip(impulses) {
                    *sum += impulse;
                }
                for (g, impulse) in glue_impulses {
                    glue_total[g].0 += impulse;
                }
                Some(Ok(stepped))
            }
            Err(_) if self.integrator == PlanarIntegrator::Automatic => None,
            Err(error) => Some(Err(error)),
        }
    }
}

/// Whether `body` (number `index`) can step implicitly over `h` (s): within its reach (its
/// bounding box grown by its fastest node's travel over `h` and a tenth of its size) lies no
/// dynamic collider and no collider corner, and no node of it is glued to a dynamic rigid body.
fn steps_alone(
    body: &PlanarBody,
    index: usize,
    (colliders, glue): (&[ColliderView], &[GlueView]),
    h: f64,
) -> bool {
    if glue.iter().any(|g| g.body == index && g.dynamic) {
        return false;
    }
    let (low, high) = bounds_of(body.positions());
    let fastest = (body.velocities().iter()).fold(0.0f64, |m, v| m.max(v.length()));
    let grow = DVec2::splat(fastest * h + 0.1 * (high - low).max_element());
    let (low, high) = (low - grow, high + grow);
    let overlaps = |(a, b): (DVec2, DVec2)| !(b.cmplt(low).any() || a.cmpgt(high).any());
    colliders.iter().all(|view| {
        let near = overlaps(view.bounds);
        let corner_near = (view.corners.iter()).any(|p| overlaps((*p, *p)));
        !(near && (view.dynamic || corner_near))
    })
}

/// The impulses (N s) per key, summed and over `dt` (s): mean forces (N).
fn mean_forces<K: PartialEq>(impulses: Vec<(K, DVec2)>, dt: f64) -> Vec<(K, DVec2)> {
    let mut forces: Vec<(K, DVec2)> = Vec::new();
    for (handle, impulse) in impulses {
        match forces.iter_mut().find(|(h, _)| *h == handle) {
            Some((_, sum)) => *sum += impulse / dt,
            None => forces.push((handle, impulse / dt)),
        }
    }
    forces
}
