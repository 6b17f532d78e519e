//! Shared fixtures for the integration tests: the reference cantilever and its closed-form values.
#![allow(dead_code)]

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, SharedShape};

/// Beam length (m), cross-section side (m), density (kg/m³) and gravity (m/s²) of the reference
/// cantilever.
pub const LENGTH: f64 = 1.0;
pub const SIDE: f64 = 0.1;
pub const DENSITY: f64 = 1000.0;
pub const GRAVITY: f64 = 9.81;

/// The reference cantilever along +x from x = 0 (clamped) to x = L, centred on the x axis, with
/// `cells` cubes along x, y, z; returns the body and the node at the centre of the free end.
pub fn cantilever(cells: [usize; 3], material: Material) -> (DeformableBody, usize) {
    damped_cantilever(cells, material, None)
}

/// [`cantilever`] with optional Rayleigh damping.
pub fn damped_cantilever(
    cells: [usize; 3],
    material: Material,
    damping: Option<RayleighDamping>,
) -> (DeformableBody, usize) {
    cantilever_with(cells, material, damping, VolumetricTreatment::PerElement)
}

/// [`cantilever`] with optional Rayleigh damping and a choice of volumetric treatment.
pub fn cantilever_with(
    cells: [usize; 3],
    material: Material,
    damping: Option<RayleighDamping>,
    treatment: VolumetricTreatment,
) -> (DeformableBody, usize) {
    let half = DVec3::new(LENGTH / 2.0, SIDE / 2.0, SIDE / 2.0);
    let mesh = mesh::cuboid(half, cells).unwrap();
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let tip = mesh.nearest_node(DVec3::new(half.x, 0.0, 0.0)) as usize;
    let mut builder = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .volumetric(treatment);
    if let Some(damping) = damping {
        builder = builder.damping(damping);
    }
    (builder.build().unwrap(), tip)
}

/// Second moment of area of the square section (m⁴).
pub fn second_moment() -> f64 {
    SIDE.powi(4) / 12.0
}

/// Static tip deflection (m) of the cantilever under its own weight, Timoshenko beam theory:
/// `q L⁴ / (8 E I) + q L² / (2 κ G A)` with Cowper's shear coefficient for a rectangle,
/// `κ = 10 (1 + ν) / (12 + 11 ν)`.
pub fn timoshenko_tip_deflection(young_modulus: f64, poisson_ratio: f64) -> f64 {
    let area = SIDE * SIDE;
    let q = DENSITY * area * GRAVITY;
    let shear_modulus = young_modulus / (2.0 * (1.0 + poisson_ratio));
    let kappa = 10.0 * (1.0 + poisson_ratio) / (12.0 + 11.0 * poisson_ratio);
    q * LENGTH.powi(4) / (8.0 * young_modulus * second_moment())
        + q * LENGTH.powi(2) / (2.0 * kappa * shear_modulus * area)
}

/// First bending frequency (Hz) of the cantilever, Euler–Bernoulli:
/// `0.5596 / L² sqrt(E I / (ρ A))`.
pub fn euler_bernoulli_first_frequency(young_modulus: f64) -> f64 {
    0.5596 / LENGTH.powi(2) * (young_modulus * second_moment() / (DENSITY * SIDE * SIDE)).sqrt()
}

/// Gravity along -y (m/s²).
pub fn gravity() -> DVec3 {
    DVec3::new(0.0, -GRAVITY, 0.0)
}

/// A deterministic pseudo-random number in [-1, 1) (a 64-bit linear congruential generator).
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    pub fn vector(&mut self) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next())
    }
}

/// All four constitutive models.
pub const MODELS: [MaterialModel; 4] = [
    MaterialModel::Linear,
    MaterialModel::StVenantKirchhoff,
    MaterialModel::Corotated,
    MaterialModel::StableNeoHookean,
];

/// The rotation-invariant (objective) models.
pub const OBJECTIVE_MODELS: [MaterialModel; 3] = [
    MaterialModel::StVenantKirchhoff,
    MaterialModel::Corotated,
    MaterialModel::StableNeoHookean,
];

/// Vertical tip deflection (m) of an inextensible, shear-rigid cantilever of `length` (m) under
/// its own weight at any rotation (the elastica), given its weight per length over its bending
/// stiffness, `load = q / (E I)` (1/m³): along the arc length `s`, `θ'' = -load (L - s) cos θ`
/// with `θ(0) = 0` (clamped) and `θ'(L) = 0` (free end), and the deflection `y' = sin θ`. Solved by
/// shooting on `θ'(0)`, integrating `(θ, θ', y)` with fourth-order Runge–Kutta in 2000 steps,
/// and bisecting on the sign of `θ'(L)`.
pub fn elastica_tip_deflection(load: f64, length: f64) -> f64 {
    elastica_tip_deflection_in(load, length, 2000)
}

/// [`elastica_tip_deflection`] with `steps` Runge–Kutta steps.
pub fn elastica_tip_deflection_in(load: f64, length: f64, steps: usize) -> f64 {
    let ds = length / steps as f64;
    // The state (θ, θ', y) and its rate at arc length `s`.
    let rate = |s: f64, [theta, curvature, _]: [f64; 3]| {
        [curvature, -load * (length - s) * theta.cos(), theta.sin()]
    };
    let step = |s: f64, state: [f64; 3], k: [f64; 3], h: f64| {
        rate(s, std::array::from_fn(|i| state[i] + h * k[i]))
    };
    // Integrates from the clamp with curvature `k0`; returns (θ'(L), tip deflection).
    let shoot = |k0: f64| {
        let mut state = [0.0, k0, 0.0];
        for i in 0..steps {
            let s = i as f64 * ds;
            let k1 = rate(s, state);
            let k2 = step(s + 0.5 * ds, state, k1, 0.5 * ds);
            let k3 = step(s + 0.5 * ds, state, k2, 0.5 * ds);
            let k4 = step(s + ds, state, k3, ds);
            state = std::array::from_fn(|j| {
                state[j] + ds / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
            });
        }
        (state[1], state[2])
    };
    // θ'(L) grows with θ'(0) = k0 from negative (k0 = 0) to positive (k0 = load L², twice the
    // largest clamp curvature load L²/2).
    let (mut low, mut high) = (0.0, load * length * length);
    for _ in 0..100 {
        let mid = 0.5 * (low + high);
        if shoot(mid).0 < 0.0 {
            low = mid
        } else {
            high = mid
        }
    }
    shoot(0.5 * (low + high)).1
}

/// Places every node of `body` at `map(p)` moving at `rate(p)`, `p` its rest position, and
/// returns the internal forces (N per node) there.
pub fn forces_under(
    body: &mut DeformableBody,
    map: impl Fn(DVec3) -> DVec3,
    rate: impl Fn(DVec3) -> DVec3,
) -> Vec<DVec3> {
    let rest = body.mesh().positions().to_vec();
    for (n, p) in rest.iter().enumerate() {
        body.positions_mut()[n] = map(*p);
        body.velocities_mut()[n] = rate(*p);
    }
    body.internal_forces().to_vec()
}

/// Hangs `rod` (placed 0.1 m below (0.05, 0.5, 0) m) by its nodes `root` from a position-based
/// kinematic body that is driven around a horizontal 5 cm circle centred on the y axis once a
/// second, for 120 frames of an [`FvmWorld`](rapier_fvm::world::FvmWorld) stepped by
/// `integrator` (`None`: automatic). Returns the largest distance (m) of a glued node from where
/// the path puts its anchor.
pub fn glued_path_error(
    rod: DeformableBody,
    root: &[u32],
    integrator: Option<IntegratorKind>,
) -> f64 {
    use rapier_fvm::glamx::Vec3;
    use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};

    let mut world = rapier_fvm::world::FvmWorld::default();
    world.coupling.integrator.force = integrator;
    let (radius, period) = (GLUED_PATH_RADIUS as f32, 1.0f32);
    let start = Vec3::new(radius, 0.5, 0.0);
    let (driver, _) = world.physics.insert(
        RigidBodyBuilder::kinematic_position_based().translation(start),
        ColliderBuilder::ball(0.01).sensor(true),
    );
    let rod = world.soft_bodies.insert(rod);
    world.attach(rod, root.iter().copied(), driver).unwrap();
    let offsets: Vec<DVec3> = root
        .iter()
        .map(|&n| world.soft_bodies[rod].positions()[n as usize] - start.as_dvec3())
        .collect();
    let dt = world.physics.integration_parameters.dt;
    let mut worst = 0.0f64;
    for frame in 1..=120 {
        let angle = std::f32::consts::TAU * frame as f32 * dt / period;
        let centre = Vec3::new(radius * angle.cos(), 0.5, radius * angle.sin());
        world.physics.bodies[driver].set_next_kinematic_translation(centre);
        for (handle, outcome) in world.step() {
            outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
        }
        let body = &world.soft_bodies[rod];
        for (&n, offset) in root.iter().zip(&offsets) {
            let target = centre.as_dvec3() + *offset;
            worst = worst.max(body.positions()[n as usize].distance(target));
        }
    }
    worst
}

/// The radius (m) of [`glued_path_error`]'s circle.
pub const GLUED_PATH_RADIUS: f64 = 0.05;

/// A large homogeneous deformation gradient for patch tests: 20 % stretch, 10 % shear, then a
/// 40 degree rotation.
pub fn finite_homogeneous_deformation() -> DMat3 {
    let stretch_shear = DMat3::from_cols(
        DVec3::new(1.2, 0.0, 0.0),
        DVec3::new(0.1, 0.9, 0.0),
        DVec3::new(0.0, 0.05, 1.1),
    );
    let rotation =
        DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 40f64.to_radians());
    rotation * stretch_shear
}

/// A homogeneous deformation rate `Ḟ` (1/s) for damping patch tests: stretching and shearing.
pub fn homogeneous_deformation_rate() -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.5, -0.2, 0.1),
        DVec3::new(0.3, -0.4, 0.0),
        DVec3::new(0.0, 0.2, 0.6),
    )
}

/// A world without gravity, `integrator` forced (or automatic), holding the dynamic rigid body
/// `body` with a ball collider of `radius` (m) weighing `mass` (kg), friction 0.5; returns the
/// world and the ball's handle.
pub fn ball_without_gravity(
    integrator: Option<IntegratorKind>,
    body: rapier3d::prelude::RigidBodyBuilder,
    (mass, radius): (f32, f32),
) -> (FvmWorld, rapier3d::prelude::RigidBodyHandle) {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.gravity = Vec3::ZERO;
    let density = mass / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3));
    let collider = ColliderBuilder::ball(radius).density(density).friction(0.5);
    let ball = world.physics.insert(body, collider).0;
    (world, ball)
}

/// The total linear momentum (kg m/s) and angular momentum about the origin (kg m²/s) of the soft
/// body `soft` and the rigid ball `ball` of radius `radius` (m) in `world`.
pub fn soft_and_ball_momenta(
    world: &rapier_fvm::world::FvmWorld,
    soft: DeformableBodyHandle,
    ball: rapier3d::prelude::RigidBodyHandle,
    radius: f32,
) -> (DVec3, DVec3) {
    let body = &world.soft_bodies[soft];
    let rigid = &world.physics.bodies[ball];
    let mass = f64::from(rigid.mass());
    let inertia = 0.4 * mass * f64::from(radius).powi(2);
    let (x, v) = (rigid.translation().as_dvec3(), rigid.linvel().as_dvec3());
    let linear = body.linear_momentum() + v * mass;
    let soft_angular: DVec3 = body
        .positions()
        .iter()
        .zip(body.velocities())
        .zip(body.masses())
        .map(|((x, v), m)| x.cross(*v) * *m)
        .sum();
    let angular = soft_angular + x.cross(v) * mass + rigid.angvel().as_dvec3() * inertia;
    (linear, angular)
}

/// One backward Euler frame of 1/60 s of `body` without gravity, with its `constraints` and
/// solver `workspace`: the frame's report.
pub fn implicit_frame_without_gravity(
    body: &mut DeformableBody,
    constraints: &mut BodyConstraints,
    workspace: &mut SolverWorkspace,
) -> ImplicitReport {
    ImplicitIntegrator::default()
        .step(body, constraints, workspace, 1.0 / 60.0, DVec3::ZERO)
        .unwrap()
}

/// Sets every node of `body` moving at a random velocity (seed `seed`, up to 1 m/s per axis),
/// takes ten free steps of 1/60 s without gravity (implicit or explicit), and returns the change
/// of linear momentum and the scale it is measured against (kg m/s): the larger of the initial
/// momentum and the sum of the nodes' momentum magnitudes at the end.
pub fn free_momentum_change(body: &mut DeformableBody, seed: u64, implicit: bool) -> (f64, f64) {
    let mut rng = Lcg(seed);
    for v in body.velocities_mut() {
        *v = rng.vector();
    }
    let before = body.linear_momentum();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..10 {
        if implicit {
            implicit_frame_without_gravity(body, &mut constraints, &mut workspace);
        } else {
            SymplecticEuler::default()
                .step(
                    body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    DVec3::ZERO,
                )
                .unwrap();
        }
    }
    let change = (body.linear_momentum() - before).length();
    let scale: f64 = body
        .masses()
        .iter()
        .zip(body.velocities())
        .map(|(m, v)| m * v.length())
        .sum();
    (change, scale.max(before.length()))
}

/// The ratio of the largest force on an `interior` node to the largest on a boundary node.
pub fn interior_ratio(forces: &[DVec3], interior: &[bool]) -> f64 {
    let (mut inner, mut boundary) = (0.0f64, 0.0f64);
    for (f, &is_inner) in forces.iter().zip(interior) {
        if is_inner {
            inner = inner.max(f.length());
        } else {
            boundary = boundary.max(f.length());
        }
    }
    assert!(boundary > 0.0, "the deformation must load the boundary");
    inner / boundary
}

/// Steps `world` 150 frames for `body` to settle on `ground`, then 60 more, and returns the
/// ground's mean upward reaction on the body over those 60 (N).
pub fn settled_reaction(
    world: &mut rapier_fvm::world::FvmWorld,
    body: DeformableBodyHandle,
    ground: rapier3d::prelude::ColliderHandle,
) -> f64 {
    let step = |world: &mut rapier_fvm::world::FvmWorld| {
        for (_, outcome) in world.step() {
            outcome.unwrap();
        }
    };
    for _ in 0..150 {
        step(world);
    }
    let frames = 60;
    let mut reaction = 0.0;
    for _ in 0..frames {
        step(world);
        reaction -= world.contact_force_on(body, ground).unwrap().0.y;
    }
    reaction / f64::from(frames)
}

/// `ω_max` (rad/s) of `M⁻¹K` at rest by power iteration, using the linear model's forces
/// (`K u = -f(x0 + u)` exactly for the linear model), pinned nodes excluded.
pub fn highest_angular_frequency(body: &mut DeformableBody) -> f64 {
    let rest = body.positions().to_vec();
    let masses = body.masses().to_vec();
    let mut rng = Lcg(1);
    let mut u: Vec<DVec3> = (0..rest.len()).map(|_| rng.vector()).collect();
    let mut eigenvalue: f64 = 0.0;
    for _ in 0..50_000 {
        let norm = u.iter().map(|a| a.length_squared()).sum::<f64>().sqrt();
        let scale = 1e-6 / norm;
        for (n, x) in body.positions_mut().iter_mut().enumerate() {
            *x = rest[n] + u[n] * scale;
        }
        let forces = body.internal_forces().to_vec();
        let next: Vec<DVec3> = (0..rest.len())
            .map(|n| {
                if body.is_pinned(n) {
                    DVec3::ZERO
                } else {
                    -forces[n] / masses[n] / scale
                }
            })
            .collect();
        eigenvalue = next.iter().zip(&u).map(|(a, b)| a.dot(*b)).sum::<f64>() / norm.powi(2);
        let next_norm = next.iter().map(|a| a.length_squared()).sum::<f64>().sqrt();
        u = next.iter().map(|a| *a / next_norm).collect();
        // The Rayleigh quotient rises monotonically to ω²; stop once it has settled.
        if (next_norm / norm - eigenvalue).abs() <= 1e-9 * eigenvalue {
            break;
        }
    }
    body.positions_mut().copy_from_slice(&rest);
    eigenvalue.sqrt()
}

/// Moves every node of `body` by a pseudo-random offset of up to `amplitude` (m) per axis
/// (seed `seed`), then steps it explicitly, without gravity, for `frames` frames of 1/60 s at the
/// automatic substep. Returns the largest relative change of kinetic + elastic energy at the
/// frames' ends and the longest substep taken (s).
pub fn explicit_energy_change(
    body: &mut DeformableBody,
    seed: u64,
    amplitude: f64,
    frames: usize,
) -> (f64, f64) {
    let mut rng = Lcg(seed);
    for x in body.positions_mut() {
        *x += rng.vector() * amplitude;
    }
    let initial = body.elastic_energy() + body.kinetic_energy();
    let (mut worst, mut longest): (f64, f64) = (0.0, 0.0);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..frames {
        let report = SymplecticEuler::default()
            .step(
                body,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                DVec3::ZERO,
            )
            .unwrap();
        longest = longest.max(1.0 / 60.0 / f64::from(report.substeps));
        let energy = body.elastic_energy() + body.kinetic_energy();
        worst = worst.max((energy / initial - 1.0).abs());
    }
    (worst, longest)
}

/// Steps `world` by `frames` frames.
pub fn run(world: &mut FvmWorld, frames: usize) -> Result<(), Error> {
    for _ in 0..frames {
        for (_, outcome) in world.step() {
            outcome?;
        }
    }
    Ok(())
}

/// Asserts that two worlds hold the same state, bit for bit.
pub fn assert_identical(a: &FvmWorld, b: &FvmWorld) {
    assert_eq!(a.soft_bodies.len(), b.soft_bodies.len());
    assert_eq!(a.physics.bodies.len(), b.physics.bodies.len());
    for ((ha, body_a), (hb, body_b)) in a.soft_bodies.iter().zip(b.soft_bodies.iter()) {
        assert_eq!(ha, hb);
        assert_eq!(body_a.positions(), body_b.positions(), "{ha:?}");
        assert_eq!(body_a.velocities(), body_b.velocities(), "{ha:?}");
        assert_eq!(body_a.masses(), body_b.masses(), "{ha:?}");
        assert_eq!(body_a.loads(), body_b.loads(), "{ha:?}");
        assert_eq!(
            body_a.load_potential_energy().to_bits(),
            body_b.load_potential_energy().to_bits(),
            "{ha:?}"
        );
    }
    for ((ha, rigid_a), (hb, rigid_b)) in a.physics.bodies.iter().zip(b.physics.bodies.iter()) {
        assert_eq!(ha, hb);
        assert_eq!(rigid_a.position(), rigid_b.position(), "{ha:?}");
        assert_eq!(rigid_a.linvel(), rigid_b.linvel(), "{ha:?}");
        assert_eq!(rigid_a.angvel(), rigid_b.angvel(), "{ha:?}");
    }
    assert_eq!(a.rigid_loads(), b.rigid_loads());
}

/// A foam block of `model` (E = 10 kPa, ν = 0.3, 100 kg/m³, 20 x 10 x 20 cm in 4 x 2 x 4 cells)
/// resting on the ground plane y = 0, inserted into `world`.
pub fn insert_foam_block(world: &mut FvmWorld, model: MaterialModel) -> DeformableBodyHandle {
    let material = Material::new(model, 1e4, 0.3, 100.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.1, 0.05, 0.1), [4, 2, 4]).unwrap();
    let foam = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(0.0, 0.05, 0.0))
        .build()
        .unwrap();
    world.soft_bodies.insert(foam)
}

/// A world with a fixed ground half-space below y = 0 (friction 0.8) and `integrator` forced
/// (or the automatic choice).
pub fn world_with_ground(integrator: Option<IntegratorKind>) -> FvmWorld {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    world
}

/// The mean height (m) now of the nodes of `body` whose rest height is at least `rest_height`
/// (m): where a flat top face is, under what rests on it.
pub fn mean_height_of_nodes_above(body: &DeformableBody, rest_height: f64) -> f64 {
    let nodes = body.mesh().nodes_where(|p| p.y >= rest_height);
    nodes
        .iter()
        .map(|&n| body.positions()[n as usize].y)
        .sum::<f64>()
        / nodes.len() as f64
}

/// Steps `world` `frames` frames (panicking on a refused step) and returns, over the last 60,
/// the rigid body `rigid`'s largest vertical speed (m/s) and the mean vertical force (N) the
/// deformable body `soft` exerted on it.
pub fn settle_on(
    world: &mut FvmWorld,
    soft: DeformableBodyHandle,
    rigid: rapier3d::prelude::RigidBodyHandle,
    frames: usize,
) -> (f32, f64) {
    let (mut fastest, mut support) = (0.0f32, 0.0);
    for frame in 0..frames {
        for (handle, outcome) in world.step() {
            outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
        }
        if frame + 60 >= frames {
            fastest = fastest.max(world.physics.bodies[rigid].linvel().y.abs());
            support += world.load_on(soft, rigid).0.y / 60.0;
        }
    }
    (fastest, support)
}

/// Steps `world` `frames` frames (panicking on a refused step) and returns the mean upward force
/// (N) the deformable bodies' contacts exerted on the `colliders` together over the last 30.
pub fn settle_on_colliders(
    world: &mut FvmWorld,
    colliders: &[rapier3d::prelude::ColliderHandle],
    frames: usize,
) -> f64 {
    let mut support = 0.0;
    for frame in 0..frames {
        for (handle, outcome) in world.step() {
            outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
        }
        if frame + 30 >= frames {
            let load: f64 = (world.collider_loads().iter())
                .filter(|load| colliders.contains(&load.collider))
                .map(|load| -load.force.y)
                .sum();
            support += load / 30.0;
        }
    }
    support
}

/// Linear momentum (kg m/s), angular momentum about the origin (kg m²/s), and the momentum
/// scale `Σ m |v|` (kg m/s) of a body.
pub fn momenta(body: &DeformableBody) -> (DVec3, DVec3, f64) {
    let (mut linear, mut angular, mut scale) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for ((x, v), m) in body
        .positions()
        .iter()
        .zip(body.velocities())
        .zip(body.masses())
    {
        linear += *v * *m;
        angular += x.cross(*v) * *m;
        scale += m * v.length();
    }
    (linear, angular, scale)
}

/// A 20 x 5 x 5 cm bar along x (stable Neo-Hookean, E = 1e6 Pa, ν = 0.3, 1000 kg/m³, stiffness
/// damping 2e-3 s, 8 x 2 x 2 cells) centred at `centre` (m), to be built, and its hinge: the
/// nodes along the top edge of its −x end.
pub fn bar_with_hinge(centre: DVec3) -> (DeformableBodyBuilder, Vec<u32>) {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.1, 0.025, 0.025), [8, 2, 2]).unwrap();
    let hinge = mesh.nodes_where(|p| p.x < -0.0999 && p.y > 0.0249);
    let builder = DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
        .translation(centre);
    (builder, hinge)
}

/// Glues the `hinge` nodes of the soft body `handle` to a fixed rigid body (a sensor 1 x 1 x 6 cm
/// centred at `axle`, m), the axle they turn about, and returns it.
pub fn glue_to_fixed_axle(
    world: &mut FvmWorld,
    handle: DeformableBodyHandle,
    hinge: &[u32],
    axle: Vec3,
) -> rapier3d::prelude::RigidBodyHandle {
    let (fixed, _) = world.physics.insert(
        rapier3d::prelude::RigidBodyBuilder::fixed().translation(axle),
        ColliderBuilder::cuboid(0.005, 0.005, 0.03).sensor(true),
    );
    world.attach(handle, hinge.iter().copied(), fixed).unwrap();
    fixed
}

/// The vertical force (N) the deformable bodies exert on the colliders without a rigid body
/// (the ground) over the last frame: negative, they push it down.
pub fn ground_load(world: &FvmWorld) -> f64 {
    (world.collider_loads().iter())
        .filter(|load| world.physics.colliders[load.collider].parent().is_none())
        .map(|load| load.force.y)
        .sum()
}
