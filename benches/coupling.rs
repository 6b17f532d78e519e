//! What coupling soft bodies to rapier costs per frame of 1/60 s, side by side in one run:
//!
//! - (a) `soft_cube_alone`: the drop scene's soft cube (10 cm, stable Neo-Hookean, E = 1e5 Pa,
//!   ν = 0.3, 1000 kg/m³, 6 x 6 x 6 cells, Rayleigh damping 2e-3 s, as in `examples/drop.rs`)
//!   falling freely, stepped by the world's automatic integrator `coupling.substeps` times per
//!   frame at the coupling substep length: the soft step alone, without contacts or rapier.
//! - (b) `soft_cube_on_ground`: the same cube resting on a fixed half-space ground (friction 0.5)
//!   in an [`FvmWorld`]: contact detection, contacts enforced, and rapier's sub-cycled step.
//! - (c) `box_on_soft_block`: `examples/rigid_on_soft.rs`'s scene, a 2 kg rigid box (10 cm)
//!   resting 4 cm off-centre on a 20 cm soft block (E = 1e6 Pa, 4 x 4 x 4 cells) on the ground,
//!   in an [`FvmWorld`]: two-way contact with a dynamic rigid body.
//! - (d) `d_grasp`: `examples/grasp.rs`'s scene, a 5 cm soft cube (E = 1e5 Pa, 4 x 4 x 4 cells)
//!   squeezed by 2 mm a side between two position-based kinematic fingers (friction 1.0) and held
//!   10 cm above the ground: friction contacts carrying a soft body's weight. Its settling,
//!   closing and lifting (1.75 s) run outside the timing; the timed frames hold the fingers still
//!   at their final pose. Beside it, `d_grasp_cube_alone`: the same cube falling freely, stepped
//!   as in (a), for the ratio.
//! - (e) `e_soft_stack`: `examples/soft_stack.rs`'s kind of scene, two 10 cm soft cubes
//!   (E = 1e5 Pa, 4 x 4 x 4 cells) stacked on the ground: soft-soft contact, the two cubes
//!   stepped together. Beside it, `e_two_cubes_alone`: the same two cubes falling freely, each
//!   stepped as in (a).
//!
//! - (f) `f_soft_cube_asleep`: (b)'s cube once asleep (the default [`SleepSettings`]): what a
//!   body at rest costs when it is not stepped.
//!
//! Every other scene first runs 1 s of frames outside the timing, so that (b) and (c) measure
//! steady contact; bodies other than (f)'s never sleep, so that every frame steps them. Times
//! are per frame.

use criterion::{Criterion, criterion_group, criterion_main};
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};
use std::time::Duration;

/// Frames run before measuring (1 s at 60 frames per second).
const SETTLING_FRAMES: usize = 60;

/// A damped rubber cube of side `side` (m), `cells` cubes a side, Young's modulus `young` (Pa),
/// its centre at `centre` (m).
fn soft_cube(side: f64, cells: usize, young: f64, centre: DVec3) -> DeformableBody {
    let rubber =
        Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).expect("valid material");
    let mesh = mesh::cuboid(DVec3::splat(side / 2.0), [cells; 3]).expect("valid generator input");
    DeformableBodyBuilder::new(mesh, rubber)
        .damping(
            RayleighDamping::stiffness_proportional(2e-3, rubber.lame()).expect("valid damping"),
        )
        .translation(centre)
        .build()
        .expect("valid body")
}

/// The drop scene's cube with its centre at height `y` (m).
fn drop_cube(y: f64) -> DeformableBody {
    soft_cube(0.1, 6, 1e5, DVec3::new(0.0, y, 0.0))
}

/// A world with a fixed half-space ground of friction coefficient `friction`, whose bodies
/// never sleep.
fn world_on_ground(friction: f32) -> FvmWorld {
    let mut world = FvmWorld::default();
    world.coupling.sleep = SleepSettings::never();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(friction),
        None,
    );
    world
}

fn step(world: &mut FvmWorld) {
    for (_, outcome) in world.step() {
        outcome.expect("coupled frame");
    }
}

/// `examples/grasp.rs`'s cube (5 cm) with its centre at height `y` (m).
fn grasp_cube(y: f64) -> DeformableBody {
    let mut cube = soft_cube(0.05, 4, 1e5, DVec3::new(0.0, y, 0.0));
    cube.friction = 1.0;
    cube
}

/// `examples/grasp.rs`'s scene after its settling (0.25 s), closing (0.5 s, the fingers moving
/// in from 2 mm off the cube's faces to 2 mm into them) and lifting (10 cm over 1 s): the cube
/// held in the air by the still fingers.
fn held_grasp() -> FvmWorld {
    let mut world = world_on_ground(0.5);
    let (half, finger_half, gap, squeeze) = (0.025, 0.005, 2e-3, 2e-3);
    world.soft_bodies.insert(grasp_cube(half));
    let sides = [-1.0, 1.0];
    let fingers = sides.map(|side: f64| {
        let x = side * (half + finger_half + gap);
        world
            .physics
            .insert(
                RigidBodyBuilder::kinematic_position_based().translation(Vec3::new(
                    x as f32,
                    half as f32,
                    0.0,
                )),
                ColliderBuilder::cuboid(finger_half as f32, 0.02, 0.02).friction(1.0),
            )
            .0
    });
    let dt = f64::from(world.physics.integration_parameters.dt);
    let (settle, close, lift) = (0.25, 0.5, 1.0);
    for frame in 1..=((settle + close + lift) / dt).round() as usize {
        let t = frame as f64 * dt - settle;
        let closing = (t / close).clamp(0.0, 1.0);
        let lifting = ((t - close) / lift).clamp(0.0, 1.0);
        for (finger, side) in fingers.iter().zip(sides) {
            let x = side * (half + finger_half + gap - (gap + squeeze) * closing);
            let y = half + 0.1 * lifting;
            world.physics.bodies[*finger]
                .set_next_kinematic_translation(Vec3::new(x as f32, y as f32, 0.0));
        }
        step(&mut world);
    }
    world
}

fn coupling_frame(c: &mut Criterion) {
    // (b) The cube resting on the ground.
    let mut on_ground = world_on_ground(0.5);
    on_ground.soft_bodies.insert(drop_cube(0.05));
    // (c) The box on the soft block.
    let mut box_on_block = world_on_ground(0.8);
    let mut block = soft_cube(0.2, 4, 1e6, DVec3::new(0.0, 0.1, 0.0));
    block.friction = 0.8;
    box_on_block.soft_bodies.insert(block);
    box_on_block.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.04, 0.2505, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05)
            .density(2000.0)
            .friction(0.8),
    );
    // (d) The grasp, held.
    let mut grasp = held_grasp();
    // (e) Two soft cubes stacked on the ground, and the same two falling freely.
    let mut stack = world_on_ground(0.5);
    stack
        .soft_bodies
        .insert(soft_cube(0.1, 4, 1e5, DVec3::new(0.0, 0.05, 0.0)));
    stack
        .soft_bodies
        .insert(soft_cube(0.1, 4, 1e5, DVec3::new(0.0, 0.151, 0.0)));
    let mut pair_alone = [
        (
            soft_cube(0.1, 4, 1e5, DVec3::new(0.0, 0.5, 0.0)),
            SolverWorkspace::new(),
        ),
        (
            soft_cube(0.1, 4, 1e5, DVec3::new(0.0, 0.7, 0.0)),
            SolverWorkspace::new(),
        ),
    ];
    // (f) The resting cube, asleep.
    let mut asleep = world_on_ground(0.5);
    asleep.coupling.sleep = SleepSettings::default();
    let cube = asleep.soft_bodies.insert(drop_cube(0.05));
    while !asleep.coupling.is_sleeping(cube) {
        step(&mut asleep);
    }
    // (a) The cube alone, stepped as the world steps its soft bodies; and the grasp's cube.
    let mut alone = (drop_cube(0.55), SolverWorkspace::new());
    let mut grasp_alone = (grasp_cube(0.5), SolverWorkspace::new());
    let integrator = on_ground.coupling.integrator;
    let substeps = on_ground.coupling.substeps;
    let h = f64::from(on_ground.physics.integration_parameters.dt) / f64::from(substeps);
    let gravity = on_ground.physics.gravity.as_dvec3();
    let frame_alone = |(body, workspace): &mut (DeformableBody, SolverWorkspace)| {
        for _ in 0..substeps {
            integrator
                .step(body, &mut BodyConstraints::new(), workspace, h, gravity)
                .expect("soft step");
        }
    };
    for _ in 0..SETTLING_FRAMES {
        frame_alone(&mut alone);
        frame_alone(&mut grasp_alone);
        step(&mut on_ground);
        step(&mut box_on_block);
        step(&mut stack);
    }

    let mut group = c.benchmark_group("coupling_frame_1_60");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    group.bench_function("a_soft_cube_alone", |b| b.iter(|| frame_alone(&mut alone)));
    group.bench_function("b_soft_cube_on_ground", |b| b.iter(|| step(&mut on_ground)));
    group.bench_function("c_box_on_soft_block", |b| {
        b.iter(|| step(&mut box_on_block))
    });
    group.bench_function("d_grasp", |b| b.iter(|| step(&mut grasp)));
    group.bench_function("d_grasp_cube_alone", |b| {
        b.iter(|| frame_alone(&mut grasp_alone))
    });
    group.bench_function("e_soft_stack", |b| b.iter(|| step(&mut stack)));
    group.bench_function("e_two_cubes_alone", |b| {
        b.iter(|| pair_alone.iter_mut().for_each(frame_alone))
    });
    group.bench_function("f_soft_cube_asleep", |b| b.iter(|| step(&mut asleep)));
    group.finish();
}

criterion_group!(benches, coupling_frame);
criterion_main!(benches);
