//! Sleeping ([`SleepSettings`]): a body at rest stops being stepped, still carries its weight,
//! and wakes when something touches it, its state is edited or a rigid body it rests with moves;
//! a free body never sleeps, however slow.

mod common;

use common::ground_load;
use rapier_fvm::coupling::Audit;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle, SharedShape};

/// A 10 cm rubber block (1.1 kg) of 3x3x3 cells, damped, resting 0.1 mm above the ground of a
/// fresh world.
fn block_on_ground() -> (FvmWorld, DeformableBodyHandle) {
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y))
            .friction(0.8)
            .build(),
        None,
    );
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1100.0).unwrap();
    let block =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .translation(DVec3::new(0.0, 0.0501, 0.0))
            .build()
            .unwrap();
    let handle = world.soft_bodies.insert(block);
    (world, handle)
}

/// Steps `world` one frame; returns whether `soft` was stepped (it has a result).
fn step(world: &mut FvmWorld, soft: DeformableBodyHandle) -> bool {
    let mut stepped = false;
    for (handle, outcome) in world.step() {
        outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
        stepped |= handle == soft;
    }
    stepped
}

/// Steps `world` until `soft` is asleep, at most `frames` frames; returns the frames taken.
fn until_asleep(world: &mut FvmWorld, soft: DeformableBodyHandle, frames: usize) -> usize {
    for frame in 1..=frames {
        step(world, soft);
        if world.coupling.is_sleeping(soft) {
            return frame;
        }
    }
    panic!("not asleep after {frames} frames");
}

#[test]
fn a_block_at_rest_falls_asleep_stays_put_and_still_carries_its_weight() {
    // Settled (nodes slower than 1 mm/s) for 0.5 s, the block sleeps: no step, positions
    // bit-identical, and the ground still carries its weight m g, within 1 % (the load of its
    // last substep, when its nodes' out-of-balance accelerations were below 2 v/T = 4 mm/s²,
    // 4e-4 of g).
    let (mut world, soft) = block_on_ground();
    let frames = until_asleep(&mut world, soft, 300);
    let weight = world.soft_bodies[soft].total_mass() * 9.81;
    let at_sleep = world.soft_bodies[soft].positions().to_vec();
    for _ in 0..60 {
        assert!(!step(&mut world, soft), "a sleeping body is not stepped");
        let load = ground_load(&world);
        assert!(
            (load + weight).abs() < 0.01 * weight,
            "{load} N against {weight} N"
        );
    }
    assert_eq!(world.soft_bodies[soft].positions(), &at_sleep[..]);
    assert!(
        world.soft_bodies[soft]
            .velocities()
            .iter()
            .all(|v| *v == DVec3::ZERO)
    );
    // The same block kept awake: where sleep left it is where it settles, to 0.05 mm (a
    // twentieth of the contact margin: sleep must not move where a body rests by more than
    // what contact detection resolves).
    let (mut awake, other) = block_on_ground();
    awake.coupling.sleep = SleepSettings::never();
    for _ in 0..frames + 60 {
        assert!(step(&mut awake, other));
    }
    let apart = (at_sleep.iter().zip(awake.soft_bodies[other].positions()))
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    println!("asleep after {frames} frames; {apart:.2e} m from the awake block 1 s later");
    assert!(apart < 5e-5, "{apart} m");
}

#[test]
fn a_box_dropped_on_a_sleeping_block_wakes_it_and_both_come_to_rest() {
    // A 0.2 kg rigid box (4 cm) dropped flat from 10 cm above the sleeping block wakes it
    // before it arrives (its collider comes within the block's bounds), lands on it without
    // passing into it (its bottom no deeper than 5 mm into the top: the block carries 0.2 kg on
    // 16 cm² of a 1e5 Pa rubber, a strain of 1.2 %, 1.2 mm, doubled by the impact, plus
    // margin), and both fall asleep again, the box in rapier too, the ground carrying both
    // weights within 1 %.
    let (mut world, soft) = block_on_ground();
    until_asleep(&mut world, soft, 300);
    let half = 0.02f32;
    let (dropped, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.22, 0.0)),
        ColliderBuilder::cuboid(half, half, half)
            .mass(0.2)
            .friction(0.8),
    );
    let top = 0.1001;
    let (mut woke, mut lowest, mut frames) = (false, f64::INFINITY, 0);
    while !(woke && world.coupling.is_sleeping(soft)) {
        assert!(frames < 600, "not asleep again after {frames} frames");
        step(&mut world, soft);
        frames += 1;
        woke |= !world.coupling.is_sleeping(soft);
        let y = f64::from(world.physics.bodies[dropped].translation().y);
        lowest = lowest.min(y - f64::from(half));
    }
    assert!(lowest > top - 5e-3, "the box sank to {lowest} m");
    let at = world.physics.bodies[dropped].translation();
    assert!(
        world.physics.bodies[dropped].is_sleeping(),
        "the box sleeps with the block: {at:?}"
    );
    step(&mut world, soft);
    let weight = (world.soft_bodies[soft].total_mass() + 0.2) * 9.81;
    let load = ground_load(&world);
    println!(
        "box's lowest point {lowest:.4} m; woken and asleep again {frames} frames after the drop; ground {load:.4} N"
    );
    assert!(
        (load + weight).abs() < 0.01 * weight,
        "{load} N against {weight} N"
    );
}

#[test]
fn editing_a_sleeping_body_or_pushing_the_box_it_carries_wakes_it() {
    // A 0.3 kg box resting on the block sleeps with it (in rapier too); an impulse on the box
    // wakes the block, which moves again. Then, asleep once more, a velocity written into the
    // block wakes it and it rises.
    let (mut world, soft) = block_on_ground();
    let (box_body, _): (RigidBodyHandle, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.121, 0.0)),
        ColliderBuilder::cuboid(0.02, 0.02, 0.02)
            .mass(0.3)
            .friction(0.8),
    );
    until_asleep(&mut world, soft, 600);
    assert!(world.physics.bodies[box_body].is_sleeping());
    world.physics.bodies[box_body].apply_impulse(Vec3::new(0.3, 0.0, 0.0), true);
    let at_sleep = world.soft_bodies[soft].positions().to_vec();
    assert!(step(&mut world, soft), "the pushed box wakes the block");
    assert_ne!(world.soft_bodies[soft].positions(), &at_sleep[..]);
    until_asleep(&mut world, soft, 600);
    let bottom = |world: &FvmWorld| {
        (world.soft_bodies[soft].positions().iter()).fold(f64::INFINITY, |low, x| low.min(x.y))
    };
    let before = bottom(&world);
    for v in world.soft_bodies[soft].velocities_mut() {
        *v = DVec3::new(0.0, 0.5, 0.0);
    }
    assert!(step(&mut world, soft), "an edited body wakes");
    assert!(bottom(&world) > before + 1e-3, "it rose");
}

#[test]
fn a_free_body_drifting_slower_than_the_threshold_never_sleeps_and_keeps_its_momentum() {
    // Without gravity a block drifting and turning slowly (every node below 1 mm/s), 0.1 mm
    // above the ground and leaving it (contacts found, none pushing): it stays awake for 2 s and keeps its linear and angular momentum to 1e-9 of
    // their values (round-off over 480 substeps of an undamped rigid motion).
    let (mut world, soft) = block_on_ground();
    world.physics.gravity = Vec3::ZERO;
    let body = &mut world.soft_bodies[soft];
    let centre = body.center_of_mass();
    let positions = body.positions().to_vec();
    for (v, x) in body.velocities_mut().iter_mut().zip(&positions) {
        *v = DVec3::new(0.0, 5e-4, 0.0) + DVec3::new(0.0, 0.0, 5e-3).cross(*x - centre);
    }
    let (p0, l0) = (body.linear_momentum(), body.angular_momentum());
    for _ in 0..120 {
        assert!(step(&mut world, soft));
        assert!(!world.coupling.is_sleeping(soft));
    }
    let body = &world.soft_bodies[soft];
    let (dp, dl) = (body.linear_momentum() - p0, body.angular_momentum() - l0);
    println!(
        "momentum change: linear {:.2e}, angular {:.2e}",
        dp.length() / p0.length(),
        dl.length() / l0.length()
    );
    assert!(dp.length() < 1e-9 * p0.length(), "{dp}");
    assert!(dl.length() < 1e-9 * l0.length(), "{dl}");
}

#[test]
fn a_block_hanging_from_a_kinematic_bar_sleeps_and_follows_it_when_it_moves() {
    // The block's top nodes glued to a kinematic bar, no ground: it hangs still and sleeps
    // (resting on its attachment, the bar carrying its weight within 1 %); the bar then moves
    // up 5 cm over 0.5 s, which wakes the block, and it follows (its top within 1 mm of 5 cm
    // higher once the bar stops: the glued nodes follow the bar's path).
    let mut world = FvmWorld::default();
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1100.0).unwrap();
    let block =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .build()
            .unwrap();
    let soft = world.soft_bodies.insert(block);
    let (bar, _) = world.physics.insert(
        RigidBodyBuilder::kinematic_position_based().translation(Vec3::new(0.0, 0.06, 0.0)),
        ColliderBuilder::cuboid(0.06, 0.01, 0.06).sensor(true),
    );
    let top: Vec<u32> = (world.soft_bodies[soft].positions().iter().enumerate())
        .filter(|(_, x)| x.y > 0.0499)
        .map(|(i, _)| i as u32)
        .collect();
    world.attach(soft, top.iter().copied(), bar).unwrap();
    until_asleep(&mut world, soft, 600);
    let weight = world.soft_bodies[soft].total_mass() * 9.81;
    step(&mut world, soft);
    let (pull, _) = world.load_on(soft, bar);
    assert!(
        (pull.y + weight).abs() < 0.01 * weight,
        "{pull} against {weight} N"
    );
    let height = |world: &FvmWorld| world.soft_bodies[soft].positions()[top[0] as usize].y;
    let before = height(&world);
    let mut woke = false;
    for frame in 1..=60 {
        let y = 0.06 + 0.05 * (f64::from(frame) / 30.0).min(1.0);
        world.physics.bodies[bar].set_next_kinematic_translation(Vec3::new(0.0, y as f32, 0.0));
        step(&mut world, soft);
        woke |= !world.coupling.is_sleeping(soft);
    }
    assert!(woke, "the moving bar woke the block");
    let risen = height(&world) - before;
    println!(
        "bar pull {:.4} N for {weight:.4} N; top rose {risen:.5} m",
        pull.y
    );
    assert!((risen - 0.05).abs() < 1e-3, "{risen} m");
}

#[cfg(feature = "serde-serialize")]
#[test]
fn a_sleeping_world_restored_from_its_bytes_sleeps_and_wakes_as_the_original() {
    // Saved asleep, read back: both stay asleep, then a velocity written into each wakes both,
    // and 30 frames later their nodes are bit-identical.
    let (mut world, soft) = block_on_ground();
    until_asleep(&mut world, soft, 300);
    let mut bytes = Vec::new();
    ciborium::into_writer(&world, &mut bytes).expect("a world serializes");
    let mut restored: FvmWorld = ciborium::from_reader(&bytes[..]).expect("and reads back");
    for w in [&mut world, &mut restored] {
        assert!(!step(w, soft));
        assert!(w.coupling.is_sleeping(soft));
        w.soft_bodies[soft].velocities_mut()[0] = DVec3::new(0.0, 0.1, 0.0);
        for _ in 0..30 {
            step(w, soft);
        }
    }
    assert_eq!(
        world.soft_bodies[soft].positions(),
        restored.soft_bodies[soft].positions()
    );
}

#[test]
fn the_audit_counts_a_sleeping_body_s_energy_so_waking_it_gains_nothing() {
    // Stepped implicitly, a resting block holds energy in its contact penalties (its bottom
    // nodes a little inside the ground's plane). Asleep, it is not stepped; woken by hand, its
    // next implicit frames hold that energy again. The audit must see no gain over the sleep
    // and the waking: a sleeping body keeps the energy it was last measured with.
    let (mut world, soft) = block_on_ground();
    world.coupling.integrator.force = Some(IntegratorKind::Implicit);
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let mut frame = |world: &mut FvmWorld| {
        let results = world.step();
        let found = audit.check_world(world, &results);
        let check = found
            .system
            .expect("every frame after the first is checked");
        assert!(!check.gained(), "{check:?}");
    };
    while !world.coupling.is_sleeping(soft) {
        frame(&mut world);
    }
    for _ in 0..10 {
        frame(&mut world);
    }
    world.coupling.wake_up(soft);
    for _ in 0..10 {
        frame(&mut world);
    }
}

#[test]
fn moving_a_fixed_platform_by_hand_wakes_the_block_sleeping_on_it() {
    // The block rests on a fixed 2 cm slab (a rigid body of its own, top at y = 0) and sleeps.
    // The slab is then set 0.8 mm lower by hand: still within the block's bounds widened by the
    // 1 mm contact margin, so no collider came or left, but one moved. The block wakes, falls
    // and rests on the slab again: its lowest node 0.8 mm lower than before, to 0.1 mm.
    let (mut world, soft) = block_on_ground();
    let ground: Vec<_> = world.physics.colliders.iter().map(|(h, _)| h).collect();
    for handle in ground {
        world.physics.remove_collider(handle);
    }
    let (slab, _) = world.physics.insert(
        RigidBodyBuilder::fixed().translation(Vec3::new(0.0, -0.01, 0.0)),
        ColliderBuilder::cuboid(0.2, 0.01, 0.2).friction(0.8),
    );
    until_asleep(&mut world, soft, 300);
    let bottom = |world: &FvmWorld| {
        (world.soft_bodies[soft].positions().iter()).fold(f64::INFINITY, |low, x| low.min(x.y))
    };
    let before = bottom(&world);
    world.physics.bodies[slab].set_translation(Vec3::new(0.0, -0.0108, 0.0), true);
    assert!(step(&mut world, soft), "the moved slab wakes the block");
    until_asleep(&mut world, soft, 600);
    let lowered = before - bottom(&world);
    println!("the block's bottom went down {lowered:.6} m with the slab");
    assert!((lowered - 8e-4).abs() < 1e-4, "{lowered} m");
}
