//! A rigid box resting on a soft block: a 2 kg rigid box (10 cm cube, density 2000 kg/m³,
//! friction 0.8) placed 4 cm off-centre on a 20 cm soft block (stable Neo-Hookean, E = 1e6 Pa,
//! ν = 0.3, 1000 kg/m³, 4 x 4 x 4 cells, stiffness-proportional Rayleigh damping 2e-3 s) that
//! stands on a fixed half-space ground (friction 0.8), in an [`FvmWorld`] at 60 frames per
//! second: how a rigid body rests on a soft one, and whether the support is honest (the ground
//! carries the whole weight) and steady (no jitter, no creep).
//!
//! After 2 s to settle, prints every 0.5 s of the next 5 s the box's centre height (mm), its
//! vertical speed (m/s), its sideways creep since the settling ended (µm) and the ground's
//! reaction averaged over the half-second's frames (N). Then the ground reaction averaged over
//! the 5 s against the total weight (N), the box's largest vertical speed (m/s), its creep (µm)
//! and how far its bottom sits below the block's rest top at 0.2 m (mm). Last line: one JSON
//! object.
//!
//! Run with `cargo run --release --example rigid_on_soft`.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, RigidBodyBuilder, RigidBodyHandle, SharedShape,
};

/// Frames per second (`FvmWorld`'s default frame step).
const FPS: usize = 60;
/// Settling time, then measuring time (s).
const SETTLE_S: usize = 2;
const MEASURE_S: usize = 5;
/// Frames per table row (0.5 s).
const ROW_FRAMES: usize = FPS / 2;
/// The block's side and the box's (m).
const BLOCK_SIDE: f64 = 0.2;
const BOX_SIDE: f64 = 0.1;

/// Steps the world one frame, failing on the first soft body that failed.
fn step(world: &mut FvmWorld) -> Result<(), Error> {
    for (_, outcome) in world.step() {
        outcome?;
    }
    Ok(())
}

/// The world, the ground's collider, the soft block's and the rigid box's handles.
struct Scene {
    world: FvmWorld,
    ground: ColliderHandle,
    block: DeformableBodyHandle,
    rigid_box: RigidBodyHandle,
}

/// The half side of the box (m).
const BOX_HALF: f32 = BOX_SIDE as f32 / 2.0;

/// The ground, the soft block on it and the rigid box placed off-centre on the block.
fn build_scene() -> Result<Scene, Error> {
    let mut world = FvmWorld::default();
    let ground = world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let block = DeformableBodyBuilder::new(
        mesh::cuboid(DVec3::splat(BLOCK_SIDE / 2.0), [4; 3])?,
        rubber,
    )
    .damping(RayleighDamping::stiffness_proportional(
        2e-3,
        rubber.lame(),
    )?)
    .translation(DVec3::new(0.0, BLOCK_SIDE / 2.0, 0.0))
    .friction(0.8)
    .build()?;
    let block = world.soft_bodies.insert(block);
    // Placed 0.5 mm above the block's top.
    let half = BOX_HALF;
    let (rigid_box, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(
            0.04,
            BLOCK_SIDE as f32 + half + 5e-4,
            0.0,
        )),
        ColliderBuilder::cuboid(half, half, half)
            .density(2000.0)
            .friction(0.8),
    );
    Ok(Scene {
        world,
        ground,
        block,
        rigid_box,
    })
}

/// What the measuring time found.
struct Measured {
    /// The box's position (m) when the measuring started.
    start: DVec3,
    /// The ground's reaction averaged over the measuring frames (N).
    reaction: f64,
    /// The box's largest vertical speed (m/s).
    fastest: f64,
}

/// The box's sideways distance (m) from `start`.
fn creep_from(start: DVec3, x: DVec3) -> f64 {
    DVec3::new(x.x - start.x, 0.0, x.z - start.z).length()
}

/// Settles, prints the header and first row, then measures, printing every [`ROW_FRAMES`].
fn run(scene: &mut Scene) -> Result<Measured, Error> {
    let world = &mut scene.world;
    for _ in 0..SETTLE_S * FPS {
        step(world)?;
    }
    let start = world.physics.bodies[scene.rigid_box]
        .translation()
        .as_dvec3();
    println!(
        "{:>6} {:>12} {:>16} {:>11} {:>14}",
        "t (s)", "box y (mm)", "box v_y (m/s)", "creep (µm)", "reaction (N)"
    );
    println!(
        "{:>6.2} {:>12.4} {:>16.3e} {:>11.3} {:>14}",
        SETTLE_S as f64,
        start.y * 1e3,
        world.physics.bodies[scene.rigid_box].linvel().y,
        0.0,
        "-"
    );
    let (mut reaction_sum, mut row_sum, mut fastest) = (0.0, 0.0, 0.0f64);
    for frame in 1..=MEASURE_S * FPS {
        step(world)?;
        let reaction = -world.contact_force_on(scene.block, scene.ground)?.0.y;
        reaction_sum += reaction;
        row_sum += reaction;
        let rigid = &world.physics.bodies[scene.rigid_box];
        let vertical_speed = f64::from(rigid.linvel().y);
        fastest = fastest.max(vertical_speed.abs());
        if frame % ROW_FRAMES == 0 {
            let x = rigid.translation().as_dvec3();
            println!(
                "{:>6.2} {:>12.4} {:>16.3e} {:>11.3} {:>14.3}",
                (SETTLE_S * FPS + frame) as f64 / FPS as f64,
                x.y * 1e3,
                vertical_speed,
                creep_from(start, x) * 1e6,
                row_sum / ROW_FRAMES as f64
            );
            row_sum = 0.0;
        }
    }
    Ok(Measured {
        start,
        reaction: reaction_sum / (MEASURE_S * FPS) as f64,
        fastest,
    })
}

/// Prints the reaction against the weight, the speed, creep, sink and tilt, then the JSON line.
fn print_summary(scene: &Scene, measured: &Measured) {
    let world = &scene.world;
    let g = world.physics.gravity.as_dvec3().length();
    let box_mass = f64::from(world.physics.bodies[scene.rigid_box].mass());
    let weight = (world.soft_bodies[scene.block].total_mass() + box_mass) * g;
    let (reaction, fastest) = (measured.reaction, measured.fastest);
    let pose = world.physics.bodies[scene.rigid_box].position();
    let creep = creep_from(measured.start, pose.translation.as_dvec3());
    // The centre of the box's bottom face, below the block's rest top.
    let bottom = pose
        .transform_point(Vec3::new(0.0, -BOX_HALF, 0.0))
        .as_dvec3();
    let sink = BLOCK_SIDE - bottom.y;
    let tilt = (pose.rotation * Vec3::Y).as_dvec3().angle_between(DVec3::Y);
    println!(
        "ground reaction {reaction:.3} N vs weight {weight:.3} N ({:+.3} %); box vertical speed ≤ {fastest:.2e} m/s; creep {:.3} µm in {MEASURE_S} s; box bottom {:.3} mm below the block's rest top, tilted {:.3}°",
        100.0 * (reaction / weight - 1.0),
        creep * 1e6,
        sink * 1e3,
        tilt.to_degrees()
    );
    println!(
        "{{\"ground_reaction_n\": {reaction:.4}, \"weight_n\": {weight:.4}, \"reaction_error\": {:.3e}, \"max_vertical_speed_m_s\": {fastest:.3e}, \"creep_um\": {:.4}, \"sink_mm\": {:.4}, \"tilt_deg\": {:.4}}}",
        reaction / weight - 1.0,
        creep * 1e6,
        sink * 1e3,
        tilt.to_degrees()
    );
}

fn main() -> Result<(), Error> {
    let mut scene = build_scene()?;
    let measured = run(&mut scene)?;
    print_summary(&scene, &measured);
    Ok(())
}
