//! Rigid stand-ins ([`RigidStandIn`]): a stiff body whose strain stays small is stepped as a
//! rapier rigid body, keeps its momentum across the switch, carries a soft body resting on it,
//! and turns elastic when the loads on it rise.

mod common;

use common::ground_load;
use rapier_fvm::coupling::Audit;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

/// A stiff 20 x 10 x 6 cm plastic-like block (`E = 100 MPa`, 1000 kg/m³, 4 x 2 x 2 cells), damped,
/// its centre at `center`, allowed to stand in below a strain of 1e-4.
fn stiff_block(center: DVec3) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e8, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.1, 0.05, 0.03), [4, 2, 2]).unwrap();
    DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(1e-4, material.lame()).unwrap())
        .translation(center)
        .rigid_stand_in(1e-4)
        .build()
        .unwrap()
}

/// A world with the ground (friction 0.8) under gravity `g`.
fn world_with_ground(g: f32) -> FvmWorld {
    let mut world = FvmWorld::default();
    world.physics.gravity = Vec3::new(0.0, -g, 0.0);
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y))
            .friction(0.8)
            .build(),
        None,
    );
    world
}

/// Steps `world` one frame, checked by `audit`; panics on a refused step or a frame the audit
/// flags.
fn step_clean(world: &mut FvmWorld, audit: &mut rapier_fvm::coupling::Audit) {
    let results = world.step();
    for (handle, outcome) in &results {
        assert!(outcome.is_ok(), "{handle:?}: {outcome:?}");
    }
    let frame = audit.check_world(world, &results);
    assert!(frame.is_clean(), "{frame:#?}");
}

#[test]
fn the_tolerance_is_checked() {
    for bad in [0.0, -1e-3, 1.0, f64::NAN] {
        let material = Material::new(MaterialModel::Linear, 1e9, 0.3, 1000.0).unwrap();
        let built =
            DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [1; 3]).unwrap(), material)
                .rigid_stand_in(bad)
                .build();
        assert!(
            matches!(
                built,
                Err(Error::InvalidSetting {
                    parameter: "rigid_stand_in",
                    ..
                })
            ),
            "{bad}: {built:?}"
        );
    }
}

/// A free world (no gravity) holding the stiff block at 1 m height, moving at 0.2 m/s along x
/// and spinning at `omega` (rad/s) about its centre; returns its momentum, angular momentum and
/// kinetic energy before, after the first frame and after `frames` frames (each checked by the
/// audit).
fn spin(omega: DVec3, frames: usize) -> [(DVec3, DVec3, f64); 3] {
    let mut world = world_with_ground(0.0);
    let mut block = stiff_block(DVec3::new(0.0, 1.0, 0.0));
    let center = block.center_of_mass();
    for (x, v) in block
        .positions()
        .to_vec()
        .iter()
        .zip(block.velocities_mut())
    {
        *v = DVec3::new(0.2, 0.0, 0.0) + omega.cross(*x - center);
    }
    let soft = world.soft_bodies.insert(block);
    let moment = |world: &FvmWorld| {
        let body = &world.soft_bodies[soft];
        (
            body.linear_momentum(),
            body.angular_momentum(),
            body.kinetic_energy(),
        )
    };
    let before = moment(&world);
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let mut first = None;
    for _ in 0..frames {
        step_clean(&mut world, &mut audit);
        assert!(world.coupling.rigid_stand_in_of(soft).is_some());
        if first.is_none() {
            first = Some(moment(&world));
        }
    }
    [before, first.expect("a frame"), moment(&world)]
}

#[test]
fn a_body_turns_rigid_with_its_momentum() {
    // No gravity, no contact: the block turns rigid at the first frame with the nodes' momentum
    // and angular momentum (V = P / M, ω = I⁻¹ L), which rapier holds in f32. Spun about its
    // principal axis y (rapier's gyroscopic correction then nearly idle), after the switch and
    // the frame's four rapier steps both are what they were to 1e-6 (7 digits), and the kinetic
    // energy too (the nodes moved rigidly: no vibration to drop). Off its principal axes, rapier's
    // tumbling turns the angular momentum by 9.5e-5 in the frame (the next test).
    let [(p0, l0, k0), (p, l, k), _] = spin(DVec3::new(0.0, 5.0, 0.0), 1);
    assert!((p - p0).length() < 1e-6 * p0.length(), "{p} against {p0}");
    assert!((l - l0).length() < 1e-6 * l0.length(), "{l} against {l0}");
    assert!((k - k0).abs() < 1e-6 * k0, "{k} J against {k0} J");
}

#[test]
fn a_body_standing_in_moves_as_rapiers_rigid_bodies_do() {
    // Over 2 s (120 frames of four rapier steps), rapier integrates the free body: spun about
    // its principal axis y, rapier's f32 gyroscopic correction spins it up by 4.8e-5 (measured);
    // spun off its principal axes it tumbles, with the size of the angular momentum and the
    // kinetic energy kept to 1e-4 and its direction turned by up to 0.46 % (measured; a
    // deformable step keeps both to round-off). The tolerances are those of rapier's rigid
    // bodies: 1e-4 along the principal axis, 1e-3 in size and 1 % in direction off it.
    let [(p0, l0, k0), _, (p, l, k)] = spin(DVec3::new(0.0, 5.0, 0.0), 120);
    assert!((p - p0).length() < 1e-6 * p0.length(), "{p} against {p0}");
    assert!((l - l0).length() < 1e-4 * l0.length(), "{l} against {l0}");
    assert!((k - k0).abs() < 1e-4 * k0, "{k} J against {k0} J");
    let [(p0, l0, k0), _, (p, l, k)] = spin(DVec3::new(1.0, 5.0, 0.5), 120);
    assert!((p - p0).length() < 1e-6 * p0.length(), "{p} against {p0}");
    assert!(
        (l.length() - l0.length()).abs() < 1e-3 * l0.length(),
        "{l} against {l0}"
    );
    assert!((l - l0).length() < 1e-2 * l0.length(), "{l} against {l0}");
    assert!((k - k0).abs() < 1e-3 * k0, "{k} J against {k0} J");
}

#[test]
fn a_block_standing_in_carries_a_soft_body_and_turns_elastic_under_a_heavy_box() {
    // The stiff block (1.2 kg) rests on the ground; its strain under its own weight,
    // ρ g L / E ≈ 1e-5, is below half of 1e-4: it stands in from the first frame. A rubber cube
    // (1.1 kg, E = 100 kPa) let go 1 mm above its left half meets its collider, and the block
    // still stands in (10.8 N predicts 1e-5). After 1.5 s the ground carries both weights,
    // within 1 % (rapier's contacts and the cube's, settled; measured 0.04 %). A 20 kg box let
    // go 1 mm above its right half predicts F / (E V^(2/3)) ≈ 1.7e-4 > 1e-4 at rest
    // (E V^(2/3) = 1.1 MN), more as it comes: the block turns elastic before it lands, stays
    // elastic under it (its strain there, 3.6e-4, is above half the tolerance), and the pile
    // holds. Every frame is clean in the audit (no energy gained, no penetration, switches
    // included).
    let mut world = world_with_ground(9.81);
    let block = world
        .soft_bodies
        .insert(stiff_block(DVec3::new(0.0, 0.0501, 0.0)));
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1100.0).unwrap();
    let cube =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .translation(DVec3::new(-0.05, 0.1512, 0.0))
            .build()
            .unwrap();
    let cube = world.soft_bodies.insert(cube);
    let mut audit = Audit::default();
    audit.restart_world(&world);
    for _ in 0..90 {
        step_clean(&mut world, &mut audit);
        assert!(world.coupling.rigid_stand_in_of(block).is_some());
    }
    let weight =
        9.81 * (world.soft_bodies[block].total_mass() + world.soft_bodies[cube].total_mass());
    let load = ground_load(&world);
    assert!(
        (load + weight).abs() < 0.01 * weight,
        "{load} N against {weight} N"
    );
    let top = world.soft_bodies[block]
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::MIN, f64::max);
    let bottom = world.soft_bodies[cube]
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::MAX, f64::min);
    assert!(
        (bottom - top).abs() < 2e-3,
        "the cube's bottom {bottom} m on the block's top {top} m"
    );
    let heavy = RigidBodyBuilder::dynamic()
        .translation(Vec3::new(0.05, 0.141, 0.0))
        .build();
    let heavy = world.physics.bodies.insert(heavy);
    let collider = ColliderBuilder::cuboid(0.045, 0.04, 0.03)
        .mass(20.0)
        .build();
    (world.physics.colliders).insert_with_parent(collider, heavy, &mut world.physics.bodies);
    audit.restart_world(&world);
    let mut elastic_at = None;
    for frame in 0..90 {
        step_clean(&mut world, &mut audit);
        if elastic_at.is_none() && world.coupling.rigid_stand_in_of(block).is_none() {
            elastic_at = Some(frame);
        }
    }
    assert!(elastic_at.is_some(), "the block stood in under 20 kg");
    assert!(
        world.coupling.rigid_stand_in_of(block).is_none(),
        "the block turned rigid again under the box (its strain there, 3.6e-4, is above 5e-5)"
    );
    let box_y = f64::from(world.physics.bodies[heavy].translation().y);
    assert!(box_y > 0.1 + 0.04 - 2e-3, "the box sank to {box_y} m");
}

#[test]
fn a_pinned_body_never_stands_in() {
    let mut world = world_with_ground(9.81);
    // The stiff block with its first node pinned: stiff and strained nowhere, but held.
    let material = Material::new(MaterialModel::StableNeoHookean, 1e9, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.1, 0.05, 0.03), [4, 2, 2]).unwrap();
    let block = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(0.0, 0.5, 0.0))
        .pinned_nodes([0])
        .rigid_stand_in(1e-4)
        .build()
        .unwrap();
    let soft = world.soft_bodies.insert(block);
    for _ in 0..10 {
        world.step();
        assert!(world.coupling.rigid_stand_in_of(soft).is_none());
    }
}
