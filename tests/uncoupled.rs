//! Bodies that need no coupling step once per frame: a soft cube alone on a fixed ground, in a
//! world of four coupling substeps, takes one implicit solve per frame, carries its weight, and
//! rests as deep in the ground as its penalties, as stiff as a coupling substep's, say, as does
//! the same cube a dynamic rigid ball beside it puts back in the substeps; a soft body within
//! its reach does that too.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

/// A world with a fixed ground below y = 0 (friction 0.8), the implicit integrator forced, four
/// coupling substeps (the default), and a 10 cm rubber cube (E = 1e5 Pa, 1000 kg/m³, 4 x 4 x 4
/// cells, damped) resting on the ground with its centre at `x` (m).
fn cube_on_ground(x: f64) -> (FvmWorld, DeformableBodyHandle) {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = Some(IntegratorKind::Implicit);
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let handle = world.soft_bodies.insert(cube(x));
    (world, handle)
}

/// The cube of [`cube_on_ground`] at `x` (m).
fn cube(x: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
        .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
        .translation(DVec3::new(x, 0.05, 0.0))
        .build()
        .unwrap()
}

/// Steps `world` `frames` frames; returns, for body `soft`, the length (s) of the implicit
/// substeps of each frame.
fn step(world: &mut FvmWorld, soft: DeformableBodyHandle, frames: usize) -> Vec<f64> {
    let mut lengths = Vec::new();
    for _ in 0..frames {
        for (handle, outcome) in world.step() {
            let report = outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
            if handle == soft {
                lengths.push(report.implicit.expect("forced implicit").substep_dt);
            }
        }
    }
    lengths
}

/// `Σ m d` (kg m) over the nodes of `body` below the ground's plane y = 0, each of mass `m`
/// (kg) and depth `d` (m).
fn mass_weighted_depth(body: &DeformableBody) -> f64 {
    (body.positions().iter().zip(body.masses()))
        .filter(|(x, _)| x.y < 0.0)
        .map(|(x, m)| -x.y * m)
        .sum()
}

#[test]
fn a_cube_alone_on_a_fixed_ground_steps_once_per_frame_and_carries_its_weight() {
    let (mut world, handle) = cube_on_ground(0.0);
    world.coupling.sleep = SleepSettings::never();
    let frame = f64::from(world.physics.integration_parameters.dt);
    for length in step(&mut world, handle, 90) {
        assert_eq!(length, frame, "one implicit substep per frame");
    }
    // The mean support over 30 frames is the weight less the momentum the body gained over them
    // (it is at rest after 1.5 s, damped): 0.5 % covers what is left of its settling.
    let weight = world.soft_bodies[handle].total_mass() * 9.81;
    let mut support = 0.0;
    for _ in 0..30 {
        step(&mut world, handle, 1);
        support -= world
            .collider_loads()
            .iter()
            .map(|l| l.force.y)
            .sum::<f64>()
            / 30.0;
    }
    println!("support {support:.5} N, weight {weight:.5} N");
    assert!(
        (support - weight).abs() < 5e-3 * weight,
        "support {support} N, weight {weight} N"
    );
}

#[test]
fn a_cube_stepped_once_per_frame_rests_as_deep_as_in_the_coupling_substeps() {
    let (mut alone, alone_cube) = cube_on_ground(0.0);
    // The same cube with a rigid ball resting on the ground 3 mm from its side: within its
    // reach over a frame, so that it steps in the four coupling substeps.
    let (mut beside, beside_cube) = cube_on_ground(0.0);
    let ball = beside
        .physics
        .bodies
        .insert(RigidBodyBuilder::dynamic().translation(Vec3::new(0.073, 0.02, 0.0)));
    beside
        .physics
        .insert_collider(ColliderBuilder::ball(0.02).density(1000.0), Some(ball));
    let frame = f64::from(alone.physics.integration_parameters.dt);
    let substeps = f64::from(beside.coupling.substeps);
    let alone_lengths = step(&mut alone, alone_cube, 60);
    let beside_lengths = step(&mut beside, beside_cube, 60);
    assert!(alone_lengths.iter().all(|&h| h == frame));
    assert!(beside_lengths.iter().all(|&h| h == frame / substeps));
    // At rest the ground's penalties, `k = penalty_factor m / h²` per node with `h` the coupling
    // substep (dt/4) in both, carry the weight: `Σ k d = W`, so `Σ m d = W h² / penalty_factor`,
    // to within what is left of the settling after 1 s (0.1 %; measured: 5 digits). A whole
    // frame's `m/ĥ²` would make it 16 times that.
    let h = frame / substeps;
    for (world, cube) in [(&alone, alone_cube), (&beside, beside_cube)] {
        let body = &world.soft_bodies[cube];
        let expected = body.total_mass() * 9.81 * h * h / world.coupling.contact.penalty_factor;
        let found = mass_weighted_depth(body);
        println!("Σ m d {found:.4e} kg m, W h²/penalty_factor {expected:.4e} kg m");
        assert!(
            (found - expected).abs() < 1e-3 * expected,
            "Σ m d {found:e} kg m, expected {expected:e} kg m"
        );
    }
}

#[test]
fn two_soft_cubes_within_reach_of_each_other_step_in_the_coupling_substeps() {
    let (mut world, first) = cube_on_ground(0.0);
    // 3 mm apart: not touching, but within each other's reach over a frame.
    let second = world.soft_bodies.insert(cube(0.103));
    let frame = f64::from(world.physics.integration_parameters.dt);
    let substeps = f64::from(world.coupling.substeps);
    for _ in 0..10 {
        for (handle, outcome) in world.step() {
            let report = outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
            assert!(handle == first || handle == second);
            assert_eq!(report.implicit.unwrap().substep_dt, frame / substeps);
        }
    }
}

#[test]
fn a_cube_stepped_once_per_frame_carries_its_weight_through_the_frame_it_falls_asleep() {
    // The frame a body stepped whole falls asleep in, its step's loads are the frame's: the
    // substeps after it must not add its resting loads on top (the showcase's finger squeeze
    // read 30.4 N for 17.4 N in that frame). Set on the ground at rest, after a third of a
    // second every frame's support is the weight to 1 % (asleep, its mean over the still half
    // second: within 2 m v / T).
    let (mut world, handle) = cube_on_ground(0.0);
    let weight = world.soft_bodies[handle].total_mass() * 9.81;
    let mut fell_asleep = None;
    for frame in 0..150 {
        step(&mut world, handle, 1);
        let support: f64 = -world
            .collider_loads()
            .iter()
            .map(|l| l.force.y)
            .sum::<f64>();
        if frame >= 20 {
            assert!(
                (support - weight).abs() < 0.01 * weight,
                "frame {frame}: support {support} N for {weight} N"
            );
        }
        if fell_asleep.is_none() && world.coupling.is_sleeping(handle) {
            fell_asleep = Some(frame);
        }
    }
    println!("asleep from frame {fell_asleep:?}");
    assert!(
        fell_asleep.is_some_and(|frame| frame > 20),
        "{fell_asleep:?}"
    );
}
