//! Implicit contact stiffness follows the load (`ContactSettings::resting_depth`): a light node
//! carrying a heavy body, or a node whose penalty an absurdly long step has made feeble, rests
//! no deeper than the resting depth behind the collider it presses on, while the reaction still
//! balances the weight.
//!
//! The first scene: a 10 cm block (4 cells a side, E = 1e7 Pa, ν = 0.3, 1000 kg/m³: 1 kg, its 25 bottom
//! nodes of 1.3 to 13 g) on the ground, under a 100 kg rigid box as wide as its top, at 1/30 s
//! frames of forced implicit steps, one coupling substep per frame. The penalty
//! `penalty_factor m/h²` of a bottom node is then 1.2e3 to 1.2e4 N/m; the bottom nodes carry
//! about 40 N each, which holds them up to 10 mm deep without the stiffening (measured below).

mod common;

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};

/// Frames of the run (2 s at 1/30 s): the box settles in about one.
const FRAMES: usize = 60;
/// The box's mass (kg) and the block's (kg).
const BOX_MASS: f64 = 100.0;
const BLOCK_MASS: f64 = 1.0;

/// Runs the scene with `resting_depth` (m); returns the deepest any block node went below the
/// ground over the run (m) and the ground's mean reaction over the last frame (N, upward).
fn run(resting_depth: f64) -> (f64, f64) {
    let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
    world.physics.integration_parameters.dt = 1.0 / 30.0;
    world.coupling.substeps = 1;
    world.coupling.contact.resting_depth = resting_depth;
    let ground = world.physics.colliders.iter().next().unwrap().0;
    let material = Material::new(MaterialModel::StableNeoHookean, 1e7, 0.3, 1000.0).unwrap();
    let block =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .translation(DVec3::new(0.0, 0.05, 0.0))
            .build()
            .unwrap();
    let block = world.soft_bodies.insert(block);
    let half = 0.05f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.1 + half + 5e-4, 0.0)),
        ColliderBuilder::cuboid(half, half, half)
            .density(BOX_MASS as f32 / (8.0 * half * half * half))
            .friction(0.8),
    );
    let mut deepest = 0.0f64;
    for frame in 0..FRAMES {
        for (_, outcome) in world.step() {
            outcome.unwrap_or_else(|error| panic!("frame {frame}: {error}"));
        }
        let lowest = (world.soft_bodies[block].positions().iter())
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        deepest = deepest.max(-lowest);
    }
    let reaction = (world.collider_loads().iter())
        .filter(|load| load.collider == ground)
        .map(|load| -load.force.y)
        .sum();
    (deepest, reaction)
}

#[test]
fn a_light_node_under_a_heavy_box_rests_within_the_resting_depth() {
    let weight = (BOX_MASS + BLOCK_MASS) * 9.81;
    let settings = ContactSettings::default();
    let (deepest, reaction) = run(settings.resting_depth);
    println!(
        "resting depth {:.1} mm: deepest {:.3} mm, ground reaction {reaction:.2} N \
         for a weight of {weight:.2} N",
        settings.resting_depth * 1e3,
        deepest * 1e3
    );
    // The stiffening's contract, with 2 % of the depth for the f32 ground plane's rounding.
    assert!(
        deepest <= 1.02 * settings.resting_depth,
        "deepest {deepest} m"
    );
    // At rest the ground carries the box and the block: within 1 % (the box settles within
    // the first frames; the block's damping leaves a fraction of a percent of ringing).
    assert!(
        (reaction - weight).abs() < 0.01 * weight,
        "reaction {reaction} N, weight {weight} N"
    );
    // Without the stiffening (a resting depth no load reaches) the same nodes sink by the
    // penalty's own compliance: the test above is not met by chance.
    let (soft_deepest, _) = run(1e9);
    println!("without stiffening: deepest {:.3} mm", soft_deepest * 1e3);
    assert!(
        soft_deepest > 5.0 * settings.resting_depth,
        "deepest {soft_deepest} m"
    );
}

#[test]
fn a_cube_on_the_ground_stays_on_it_through_frames_of_a_thousand_seconds() {
    // A 10 cm cube (4 cells a side, E = 1e6 Pa, 1 kg) resting on the ground, three implicit
    // frames of 1000 s: the penalty `penalty_factor m/h²` of a 2 g node at h = 250 s is 3e-5 N/m,
    // and the frame's gravity drop `g h²` is 6e5 m; without the stiffening the cube sank 1042 m
    // through the ground in the first frame. It must stay on the ground, no node deeper than the
    // resting depth (2 % for the f32 ground's rounding) and none lifted above its rest height.
    let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
    world.physics.integration_parameters.dt = 1000.0;
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let cube =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
            .translation(DVec3::new(0.0, 0.05, 0.0))
            .build()
            .unwrap();
    let cube = world.soft_bodies.insert(cube);
    let resting_depth = world.coupling.contact.resting_depth;
    for frame in 0..3 {
        for (_, outcome) in world.step() {
            outcome.unwrap_or_else(|error| panic!("frame {frame}: {error}"));
        }
        let heights = world.soft_bodies[cube].positions().iter().map(|x| x.y);
        let (lowest, highest) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
        println!("frame {frame}: lowest {lowest:.4e} m, highest {highest:.6} m");
        assert!(lowest >= -1.02 * resting_depth, "frame {frame}: {lowest} m");
        assert!(highest <= 0.1, "frame {frame}: {highest} m");
    }
}
