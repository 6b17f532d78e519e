//! The sweep's scenes, each built as a world: the material grid's (a cantilever, a dropped cube,
//! stepped one coupling substep per frame) and the partner, impact, wall and ν < 0 scenes
//! (rapier's default four coupling substeps per frame).

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

/// The scenes of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scene {
    /// The clamped reference beam (L = 1 m, 0.1 x 0.1 m, 20 x 2 x 2 cells) under its own weight.
    Cantilever,
    /// A 10 cm cube (4 x 4 x 4 cells) striking the ground at 3.13 m/s (a 0.5 m drop), released
    /// 1 mm above it.
    DroppedCube,
    /// A 4 cm rigid box of this mass (kg) placed 0.5 mm above a 10 cm soft block (E = 1e9 Pa for
    /// boxes under 1 kg, 1e6 Pa above) on the ground.
    BoxOnBlock(f64),
    /// A 2 cm rigid ball of this many times a 20 g soft rope's mass glued under the rope's end,
    /// the rope clamped at the top, its E set for a static stretch of 1 %.
    BallOnRope(f64),
    /// A 2 cm rigid ball of 100 g at 30 m/s into a 10 cm soft block (E = 1e6 Pa) on the ground.
    FastBall,
    /// A 10 cm soft cube (E = 1e6 Pa) striking the ground at this speed (m/s), released 1 mm
    /// above it.
    FastCube(f64),
    /// A 10 cm soft cube (E = 1e9 Pa at 100 m/s, 1e6 Pa below) flung at this speed (m/s) at a
    /// fixed 2 mm wall 1 mm away, without gravity.
    ThinWall(f64),
    /// A 10 cm cube (E = 1e5 Pa) of this negative Poisson's ratio dropped as `DroppedCube`.
    NegativePoisson(f64),
}

/// A built case: the world, its soft body and the node whose deflection beam theory predicts.
pub struct Built {
    pub world: FvmWorld,
    pub soft: DeformableBodyHandle,
    pub tip: Option<usize>,
}

/// A world with frame step `dt` (s) and `integrator` forced (or automatic); with a fixed ground
/// half-space (friction 0.5) if `ground`.
fn world(dt: f64, integrator: Option<IntegratorKind>, ground: bool) -> FvmWorld {
    let mut world = FvmWorld::default();
    world.physics.integration_parameters.dt = dt as f32;
    world.coupling.integrator.force = integrator;
    if ground {
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
            None,
        );
    }
    world
}

/// A cube of half-side `half` (m), 4 cells a side, of `material`, centred at `centre` (m),
/// moving at `velocity` (m/s).
fn cube(material: Material, centre: DVec3, velocity: DVec3) -> Result<DeformableBody, Error> {
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3])?, material)
        .translation(centre)
        .linvel(velocity)
        .build()
}

/// The stable Neo-Hookean material of the sweep (ρ = 1000 kg/m³).
fn neo_hookean(young: f64, poisson: f64) -> Result<Material, Error> {
    Material::new(MaterialModel::StableNeoHookean, young, poisson, 1000.0)
}

/// Builds `scene` of the material grid with (`young` (Pa), `poisson`), or a partner scene
/// (whose material is its own), for frame step `dt` (s) and `integrator`.
pub fn build(
    scene: Scene,
    young: f64,
    poisson: f64,
    dt: f64,
    integrator: Option<IntegratorKind>,
) -> Result<Built, Error> {
    let drop = DVec3::new(0.0, -(2.0 * 9.81 * 0.5f64).sqrt(), 0.0);
    let above = |gap: f64| DVec3::new(0.0, 0.05 + gap, 0.0);
    let (mut world, body, tip) = match scene {
        Scene::Cantilever => {
            let half = DVec3::new(0.5, 0.05, 0.05);
            let mesh = mesh::cuboid(half, [20, 2, 2])?;
            let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
            let tip = mesh.nearest_node(DVec3::new(half.x, 0.0, 0.0)) as usize;
            let body = DeformableBodyBuilder::new(mesh, neo_hookean(young, poisson)?)
                .translation(DVec3::new(half.x, 0.0, 0.0))
                .pinned_nodes(clamped)
                .build()?;
            (world(dt, integrator, false), body, Some(tip))
        }
        Scene::DroppedCube => {
            let body = cube(neo_hookean(young, poisson)?, above(1e-3), drop)?;
            (world(dt, integrator, true), body, None)
        }
        Scene::NegativePoisson(nu) => {
            let body = cube(neo_hookean(1e5, nu)?, above(1e-3), drop)?;
            (world(dt, integrator, true), body, None)
        }
        Scene::FastCube(speed) => {
            let velocity = DVec3::new(0.0, -speed, 0.0);
            let body = cube(neo_hookean(1e6, 0.3)?, above(1e-3), velocity)?;
            (world(dt, integrator, true), body, None)
        }
        Scene::ThinWall(speed) => {
            let young = if speed >= 100.0 { 1e9 } else { 1e6 };
            let mut world = world(dt, integrator, false);
            world.physics.gravity = Vec3::ZERO;
            world
                .physics
                .insert_collider(ColliderBuilder::cuboid(0.001, 0.5, 0.5), None);
            let centre = DVec3::new(-0.052, 0.0, 0.0);
            let body = cube(neo_hookean(young, 0.3)?, centre, DVec3::X * speed)?;
            (world, body, None)
        }
        Scene::BoxOnBlock(mass) => return box_on_block(dt, integrator, mass),
        Scene::FastBall => return fast_ball(dt, integrator),
        Scene::BallOnRope(ratio) => return ball_on_rope(dt, integrator, ratio),
    };
    if matches!(scene, Scene::Cantilever | Scene::DroppedCube) {
        world.coupling.substeps = 1;
    }
    let soft = world.soft_bodies.insert(body);
    Ok(Built { world, soft, tip })
}

/// A 10 cm block (E = `young`, ν = 0.3, 1 kg, lightly damped) resting on the ground of `world`.
fn block(world: &mut FvmWorld, young: f64) -> Result<DeformableBodyHandle, Error> {
    let material = neo_hookean(young, 0.3)?;
    let body = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3])?, material)
        .damping(RayleighDamping::stiffness_proportional(
            2e-3,
            material.lame(),
        )?)
        .translation(DVec3::new(0.0, 0.05, 0.0))
        .friction(0.8)
        .build()?;
    Ok(world.soft_bodies.insert(body))
}

/// [`Scene::BoxOnBlock`].
fn box_on_block(dt: f64, integrator: Option<IntegratorKind>, mass: f64) -> Result<Built, Error> {
    let mut world = world(dt, integrator, true);
    let soft = block(&mut world, if mass < 1.0 { 1e9 } else { 1e6 })?;
    let half = 0.02f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.01, 0.1 + half + 5e-4, 0.0)),
        ColliderBuilder::cuboid(half, half, half)
            .density(mass as f32 / (8.0 * half * half * half))
            .friction(0.8),
    );
    Ok(Built {
        world,
        soft,
        tip: None,
    })
}

/// [`Scene::FastBall`].
fn fast_ball(dt: f64, integrator: Option<IntegratorKind>) -> Result<Built, Error> {
    let mut world = world(dt, integrator, true);
    let soft = block(&mut world, 1e6)?;
    let radius = 0.01f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vec3::new(0.0, 0.1 + radius + 1e-3, 0.0))
            .linvel(Vec3::new(0.0, -30.0, 0.0)),
        ColliderBuilder::ball(radius)
            .density(0.1 / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3)))
            .restitution(0.0),
    );
    Ok(Built {
        world,
        soft,
        tip: None,
    })
}

/// [`Scene::BallOnRope`].
fn ball_on_rope(dt: f64, integrator: Option<IntegratorKind>, ratio: f64) -> Result<Built, Error> {
    let mut world = world(dt, integrator, false);
    let (length, side, rope_mass) = (0.2, 0.01, 0.02);
    let ball_mass = ratio * rope_mass;
    let young = (ball_mass + rope_mass / 2.0) * 9.81 / (0.01 * side * side);
    let material = Material::new(
        MaterialModel::StableNeoHookean,
        young,
        0.3,
        rope_mass / (length * side * side),
    )?;
    let mesh = mesh::cuboid(DVec3::new(side / 2.0, length / 2.0, side / 2.0), [2, 20, 2])?;
    let top = mesh.nodes_where(|p| p.y >= length / 2.0 - 1e-9);
    let bottom = mesh.nodes_where(|p| p.y <= -length / 2.0 + 1e-9);
    let rope = DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(
            0.01,
            material.lame(),
        )?)
        .translation(DVec3::new(0.0, -length / 2.0, 0.0))
        .pinned_nodes(top)
        .build()?;
    let radius = 0.01f64;
    let density = ball_mass / (4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(
            0.0,
            -(length + radius + 1e-3) as f32,
            0.0,
        )),
        ColliderBuilder::ball(radius as f32).density(density as f32),
    );
    let soft = world.soft_bodies.insert(rope);
    world.attach(soft, bottom, ball)?;
    Ok(Built {
        world,
        soft,
        tip: None,
    })
}
