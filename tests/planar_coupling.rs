//! 2D bodies coupled with rapier2d (feature `dim2`): a rigid box dropped on a soft block on
//! the ground comes to rest with the ground carrying the weight of both, explicitly or (a
//! stiff block alone) implicitly.
#![cfg(feature = "dim2")]

use rapier_fvm::damping::RayleighDamping;
use rapier_fvm::glamx::DVec2;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::coupling::{PlanarCoupling, PlanarIntegrator};
use rapier_fvm::planar::{PlanarBody, PlanarBodyBuilder, PlaneModel, TriangleMesh};
use rapier2d::prelude::{
    ColliderBuilder, ColliderHandle, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
};

/// The ground (a fixed 4 m × 1 m slab whose top is at y = 0) in `world`: its collider.
fn ground(world: &mut PhysicsWorld) -> ColliderHandle {
    let slab = world
        .bodies
        .insert(RigidBodyBuilder::fixed().translation([0.0, -0.5].into()));
    let shape = ColliderBuilder::cuboid(2.0, 0.5).build();
    world
        .colliders
        .insert_with_parent(shape, slab, &mut world.bodies)
}

/// A 0.2 m × 0.1 m block of soft rubber (E = 100 kPa, 0.1 m thick, 2 kg, damped by a
/// stiffness time of 1 ms) half a millimetre above the ground, and its material.
fn rubber_block() -> (PlanarBody, Material) {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let damping = RayleighDamping::stiffness_proportional(1e-3, rubber.lame()).unwrap();
    let mesh = TriangleMesh::rectangle(DVec2::new(0.2, 0.1), [10, 5]).unwrap();
    let mut block = PlanarBodyBuilder::new(mesh, rubber)
        .plane(PlaneModel::PlaneStrain)
        .thickness(0.1)
        .damping(damping)
        .build()
        .unwrap();
    for x in block.positions_mut() {
        *x += DVec2::new(-0.1, 0.0005);
    }
    (block, rubber)
}

/// A 0.5 kg rigid box (10 cm × 5 cm) in `world` 2 cm above the top of the [`rubber_block`],
/// and the block: the box's handle and the block.
fn box_over_rubber_block(world: &mut PhysicsWorld) -> (RigidBodyHandle, PlanarBody) {
    let box_body = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().translation([0.0, 0.145].into()));
    world.colliders.insert_with_parent(
        ColliderBuilder::cuboid(0.05, 0.025).density(100.0).build(),
        box_body,
        &mut world.bodies,
    );
    (box_body, rubber_block().0)
}

/// A 0.2 m × 0.1 m block of soft rubber (E = 100 kPa, 0.1 m thick, 2 kg) resting on the
/// ground, a 0.5 kg rigid box dropped on it from 2 cm: after 3 s the ground carries the weight
/// of both, to 1 % (the tolerance; the contacts' damping and the sticking friction
/// leave only the creep of the regularized friction), the box rests on the block, and
/// nothing has moved through anything.
#[test]
fn a_box_dropped_on_a_soft_block_rests_with_the_ground_carrying_both() {
    let mut world = PhysicsWorld::default();
    let ground = ground(&mut world);
    let (box_body, block) = box_over_rubber_block(&mut world);
    let block_mass = block.total_mass();
    let mut bodies = vec![block];
    let mut coupling = PlanarCoupling::default();
    for _ in 0..180 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            report.unwrap();
        }
    }
    let box_mass = f64::from(world.bodies[box_body].mass());
    let weight = (block_mass + box_mass) * 9.81;
    let reaction = coupling.force_on(ground);
    let box_height = f64::from(world.bodies[box_body].translation().y);
    let top = bodies[0]
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::MIN, f64::max);
    let lowest = bodies[0]
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::MAX, f64::min);
    println!(
        "ground carries {:.4} N against {weight:.4} N; box at {box_height:.5} m over the block's top {top:.5} m; block's lowest node {lowest:.2e} m",
        -reaction.y
    );
    assert!(
        (-reaction.y / weight - 1.0).abs() < 1e-2,
        "{reaction} against {weight}"
    );
    assert!(reaction.x.abs() < 1e-2 * weight);
    assert!(
        (box_height - 0.025 - top).abs() < 2e-3,
        "box at {box_height}, block top {top}"
    );
    assert!(lowest > -1e-3, "the block sank {lowest} m into the ground");
    assert!(f64::from(world.bodies[box_body].linvel().length()) < 1e-2);
}

/// A soft disk (0.4 kg) flying at 2 m/s into a free 0.5 kg rigid box, without gravity: the
/// impulses the contacts exchange are equal and opposite, so the total linear momentum is kept
/// to 1e-5 (rapier2d's single precision) through the collision, and the box leaves with a
/// share of it.
#[test]
fn a_collision_keeps_the_total_momentum() {
    let mut world = PhysicsWorld {
        gravity: [0.0, 0.0].into(),
        ..Default::default()
    };
    let box_body = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().translation([0.2, 0.01].into()));
    world.colliders.insert_with_parent(
        ColliderBuilder::cuboid(0.05, 0.05).density(50.0).build(),
        box_body,
        &mut world.bodies,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mut disk = PlanarBodyBuilder::new(TriangleMesh::disk(0.05, 4).unwrap(), rubber)
        .plane(PlaneModel::PlaneStress)
        .thickness(0.05)
        .build()
        .unwrap();
    for v in disk.velocities_mut() {
        *v = DVec2::new(2.0, 0.0);
    }
    let mut bodies = vec![disk];
    let momentum = |world: &PhysicsWorld, bodies: &[PlanarBody]| {
        let rigid =
            world.bodies[box_body].linvel().as_dvec2() * f64::from(world.bodies[box_body].mass());
        rigid + bodies[0].linear_momentum()
    };
    let before = momentum(&world, &bodies);
    let mut coupling = PlanarCoupling::default();
    for _ in 0..30 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            report.unwrap();
        }
    }
    let after = momentum(&world, &bodies);
    let box_speed = f64::from(world.bodies[box_body].linvel().x);
    println!("momentum {before} → {after}; the box leaves at {box_speed:.4} m/s");
    assert!(
        (after - before).length() < 1e-5 * before.length(),
        "{before} → {after}"
    );
    assert!(box_speed > 0.5, "the box was not struck: {box_speed} m/s");
}

/// A 0.3 m × 5 cm strip of Young's modulus `young` (Pa, 1000 kg/m³, plane stress, 2 cm thick,
/// damped by a stiffness time `damping_time` in s) glued by its top edge to a fixed rigid body,
/// hung for `frames` frames under the default integrator: what the glue carries (N), the
/// strip's weight (N), the frames stepped implicitly and the fastest node's speed (m/s).
fn hanging_strip(young: f64, damping_time: f64, frames: usize) -> (f64, f64, usize, f64) {
    let mut world = PhysicsWorld::default();
    let hook = world
        .bodies
        .insert(RigidBodyBuilder::fixed().translation([0.0, 0.3].into()));
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap();
    let damping = RayleighDamping::stiffness_proportional(damping_time, material.lame()).unwrap();
    let mesh = TriangleMesh::rectangle(DVec2::new(0.05, 0.3), [2, 12]).unwrap();
    let strip = PlanarBodyBuilder::new(mesh, material)
        .plane(PlaneModel::PlaneStress)
        .thickness(0.02)
        .damping(damping)
        .build()
        .unwrap();
    let top = strip.nodes_on_line(DVec2::new(0.0, 0.3), DVec2::X, 1e-9);
    let weight = strip.total_mass() * 9.81;
    let mut bodies = vec![strip];
    let mut coupling = PlanarCoupling::default();
    coupling.glue(&world, &bodies, (0, &top), hook).unwrap();
    let mut implicit = 0;
    for _ in 0..frames {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            implicit += usize::from(report.unwrap().implicit);
        }
    }
    let held = -coupling.glue_force(hook).y;
    let speed = (bodies[0].velocities().iter()).fold(0.0f64, |m, v| m.max(v.length()));
    (held, weight, implicit, speed)
}

/// A 0.3 m rubber strip (E = 200 kPa, 2 ms stiffness time) glued by its top edge to a fixed
/// rigid body hangs under gravity, stepped explicitly (a soft body): after 3 s the glue carries
/// its weight to 1 % (the tolerance for the ground reaction), the strip at rest.
#[test]
fn a_glued_strip_hangs_with_the_glue_carrying_its_weight() {
    let (held, weight, implicit, speed) = hanging_strip(2e5, 2e-3, 180);
    println!("the glue carries {held:.5} N against {weight:.5} N; fastest node {speed:.2e} m/s");
    assert_eq!(implicit, 0);
    assert!(
        (held / weight - 1.0).abs() < 1e-2,
        "{held} against {weight}"
    );
    assert!(speed < 1e-3);
}

/// A free 0.2 kg rigid bar glued to a soft block, the pair thrown spinning without gravity:
/// the glue's impulses are equal and opposite, so the total linear momentum is kept to 1e-5.
#[test]
fn a_glued_pair_keeps_its_momentum() {
    let mut world = PhysicsWorld {
        gravity: [0.0, 0.0].into(),
        ..Default::default()
    };
    let bar = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().translation([0.05, 0.11].into()));
    world.colliders.insert_with_parent(
        ColliderBuilder::cuboid(0.05, 0.01)
            .density(200.0)
            .sensor(true)
            .build(),
        bar,
        &mut world.bodies,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mut block = PlanarBodyBuilder::new(
        TriangleMesh::rectangle(DVec2::new(0.1, 0.1), [4, 4]).unwrap(),
        rubber,
    )
    .thickness(0.05)
    .build()
    .unwrap();
    let positions = block.positions().to_vec();
    for (v, x) in block.velocities_mut().iter_mut().zip(positions) {
        *v = DVec2::new(1.0, 0.5) + (x - DVec2::splat(0.05)).perp() * 3.0;
    }
    let top = block.nodes_on_line(DVec2::new(0.0, 0.1), DVec2::X, 1e-9);
    let mut bodies = vec![block];
    let mut coupling = PlanarCoupling::default();
    coupling.glue(&world, &bodies, (0, &top), bar).unwrap();
    let momentum = |world: &PhysicsWorld, bodies: &[PlanarBody]| {
        let rigid = &world.bodies[bar];
        rigid.linvel().as_dvec2() * f64::from(rigid.mass()) + bodies[0].linear_momentum()
    };
    let before = momentum(&world, &bodies);
    for _ in 0..60 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            report.unwrap();
        }
    }
    let after = momentum(&world, &bodies);
    let bar_speed = world.bodies[bar].linvel().length();
    println!("momentum {before} → {after}; the bar moves at {bar_speed:.3} m/s");
    assert!(
        (after - before).length() < 1e-5 * before.length(),
        "{before} → {after}"
    );
    assert!(bar_speed > 0.5, "the bar was not carried: {bar_speed} m/s");
    assert!(matches!(
        coupling.glue(&world, &bodies, (1, &top), bar),
        Err(rapier_fvm::Error::UnknownDeformableBody)
    ));
}

/// How deep (m) `p` lies inside `body`'s boundary where it is now, zero outside.
fn depth_inside(body: &PlanarBody, p: DVec2) -> f64 {
    let x = body.positions();
    let mut crossings = 0;
    let mut nearest = f64::MAX;
    for &[a, b] in body.boundary() {
        let (a, b) = (x[a as usize], x[b as usize]);
        if (a.y > p.y) != (b.y > p.y) && a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) > p.x {
            crossings += 1;
        }
        let s = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        nearest = nearest.min(p.distance(a + (b - a) * s));
    }
    if crossings % 2 == 1 { nearest } else { 0.0 }
}

/// A 0.5 kg box dropped corner-first (turned 45°) from 5 cm onto a soft block whose nodes are
/// 2 cm apart: its corner presses the block's boundary between the nodes instead of passing
/// between them. It never lies deeper inside the deformed boundary than an undamped penalty
/// spring would let it at the impact speed, `v √(m/k)` = 6.0 mm (`v` = 0.99 m/s, `k` = 1.35e4
/// N/m; the contact's damping and the block's give keep it below; a corner the nodes alone
/// resisted would sink until nodes came inside the box, about a node spacing), and the box
/// comes to rest with the ground carrying both weights to 1 %.
#[test]
fn a_box_landing_on_a_corner_does_not_pass_between_nodes() {
    let mut world = PhysicsWorld::default();
    let ground = ground(&mut world);
    let half = 0.03f32;
    let start = 0.1 + 0.05 + half * 2f32.sqrt();
    let falling = RigidBodyBuilder::dynamic()
        .translation([0.01, start].into())
        .rotation(std::f32::consts::FRAC_PI_4);
    let box_body = world.bodies.insert(falling);
    let shape = ColliderBuilder::cuboid(half, half)
        .density(0.5 / 0.0036)
        .build();
    world
        .colliders
        .insert_with_parent(shape, box_body, &mut world.bodies);
    let (block, rubber) = rubber_block();
    let block_mass = block.total_mass();
    let mut bodies = vec![block];
    let mut coupling = PlanarCoupling::default();
    let mut deepest = 0.0f64;
    for _ in 0..180 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            report.unwrap();
        }
        let rigid = &world.bodies[box_body];
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let corner = rigid
                .position()
                .transform_point([x * half, y * half].into())
                .as_dvec2();
            deepest = deepest.max(depth_inside(&bodies[0], corner));
        }
    }
    let box_mass = f64::from(world.bodies[box_body].mass());
    let weight = (block_mass + box_mass) * 9.81;
    let reaction = coupling.force_on(ground);
    let impact = (2.0 * 9.81 * 0.05f64).sqrt();
    let stiffness = (rubber.lame().lambda + 2.0 * rubber.lame().mu) * 0.1;
    let spring_peak = impact * (box_mass / stiffness).sqrt();
    println!(
        "a corner lay at most {:.3} mm inside the block (an undamped penalty spring: {:.3} mm); ground {:.4} N against {weight:.4} N",
        deepest * 1e3,
        spring_peak * 1e3,
        -reaction.y
    );
    assert!(
        deepest < spring_peak,
        "a corner lay {deepest} m inside the block"
    );
    assert!(
        (-reaction.y / weight - 1.0).abs() < 1e-2,
        "{reaction} against {weight}"
    );
}

/// A box turned 45° flying corner-first at 2 m/s into a free soft block, without gravity: the
/// corner's force and the boundary nodes' are equal and opposite, so linear momentum is kept
/// to 1e-5 (rapier2d's single precision); their arms differ by the depth along the normal, so
/// only friction's share moves angular momentum (about the origin): without friction it is
/// kept to 1e-4 (measured 1.3e-6, rapier2d's single precision), with the default friction to
/// 1e-2 (measured 3.0e-4).
#[test]
fn a_corner_first_collision_keeps_the_momentum() {
    for friction in [0.0, 0.5] {
        let mut world = PhysicsWorld {
            gravity: [0.0, 0.0].into(),
            ..Default::default()
        };
        let flying = RigidBodyBuilder::dynamic()
            .translation([-0.1, 0.06].into())
            .rotation(std::f32::consts::FRAC_PI_4)
            .linvel([2.0, 0.0].into());
        let box_body = world.bodies.insert(flying);
        let shape = ColliderBuilder::cuboid(0.03, 0.03)
            .density(0.5 / 0.0036)
            .build();
        world
            .colliders
            .insert_with_parent(shape, box_body, &mut world.bodies);
        let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
        let mesh = TriangleMesh::rectangle(DVec2::new(0.1, 0.1), [5, 5]).unwrap();
        let block = PlanarBodyBuilder::new(mesh, rubber)
            .thickness(0.05)
            .build()
            .unwrap();
        let mut bodies = vec![block];
        let mut coupling = PlanarCoupling::default();
        coupling.friction = friction;
        let totals = |world: &PhysicsWorld, bodies: &[PlanarBody]| {
            let rigid = &world.bodies[box_body];
            let (m, c, v) = (
                f64::from(rigid.mass()),
                rigid.center_of_mass().as_dvec2(),
                rigid.linvel().as_dvec2(),
            );
            let spin = f64::from(rigid.mass_properties().effective_angular_inertia())
                * f64::from(rigid.angvel());
            let linear = v * m + bodies[0].linear_momentum();
            (
                linear,
                m * c.perp_dot(v) + spin + bodies[0].angular_momentum(),
            )
        };
        let (p0, l0) = totals(&world, &bodies);
        for _ in 0..30 {
            for report in coupling.step(&mut world, &mut bodies).unwrap() {
                report.unwrap();
            }
        }
        let (p1, l1) = totals(&world, &bodies);
        let block_speed = bodies[0].linear_momentum().length() / bodies[0].total_mass();
        println!(
            "friction {friction}: momentum {p0} → {p1}, angular {l0:.6e} → {l1:.6e}; block at {block_speed:.3} m/s"
        );
        assert!((p1 - p0).length() < 1e-5 * p0.length(), "{p0} → {p1}");
        let tolerance = if friction == 0.0 { 1e-4 } else { 1e-2 };
        assert!((l1 - l0).abs() < tolerance * l0.abs(), "{l0} → {l1}");
        assert!(block_speed > 0.3, "the block was not struck");
    }
}

/// A stiff block (E = 10⁸ Pa damped by a 1 ms stiffness time, 0.2 m × 0.1 m, 10 cm thick,
/// 2 kg) dropped from 1 mm on the ground under the default integrator
/// (`PlanarIntegrator::Automatic`): its explicit step would need about 17 000 substeps, so it
/// steps implicitly (one backward Euler step per coupling substep, its contacts with the ground
/// in it; no dynamic body, corner or glue in reach), every frame; after 1 s the ground carries
/// the block's weight to 1 % (the 2D issue's tolerance), the block at rest on it.
#[test]
fn an_implicit_block_rests_on_the_ground_carrying_its_weight() {
    let mut world = PhysicsWorld::default();
    let ground = ground(&mut world);
    let stiff = Material::new(MaterialModel::StableNeoHookean, 1e8, 0.3, 1000.0).unwrap();
    let mesh = TriangleMesh::rectangle(DVec2::new(0.2, 0.1), [10, 5]).unwrap();
    let damping = RayleighDamping::stiffness_proportional(1e-3, stiff.lame()).unwrap();
    let mut block = PlanarBodyBuilder::new(mesh, stiff)
        .plane(PlaneModel::PlaneStrain)
        .thickness(0.1)
        .damping(damping)
        .build()
        .unwrap();
    for x in block.positions_mut() {
        *x += DVec2::new(-0.1, 0.001);
    }
    let weight = block.total_mass() * 9.81;
    let mut bodies = vec![block];
    let mut coupling = PlanarCoupling::default();
    assert_eq!(coupling.integrator, PlanarIntegrator::Automatic);
    let mut implicit = 0;
    for _ in 0..60 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            implicit += usize::from(report.unwrap().implicit);
        }
    }
    let reaction = -coupling.force_on(ground).y;
    let speed = (bodies[0].velocities().iter()).fold(0.0f64, |m, v| m.max(v.length()));
    println!(
        "implicit: the ground carries {reaction:.5} N of {weight:.5} N; fastest node {speed:.2e} m/s"
    );
    assert_eq!(implicit, 60);
    assert!(
        (reaction / weight - 1.0).abs() < 0.01,
        "{reaction} N against {weight} N"
    );
    assert!(speed < 1e-3, "{speed} m/s");
}

/// With the implicit integrator, the block under a dynamic box steps explicitly (a staggered
/// implicit step would freeze the box during it), and the box still rests on it with the
/// ground carrying both.
#[test]
fn a_block_under_a_dynamic_box_steps_explicitly_under_the_implicit_integrator() {
    let mut world = PhysicsWorld::default();
    let ground = ground(&mut world);
    let (box_body, block) = box_over_rubber_block(&mut world);
    let block_mass = block.total_mass();
    let mut bodies = vec![block];
    let mut coupling = PlanarCoupling::default();
    coupling.integrator = PlanarIntegrator::Implicit;
    for _ in 0..180 {
        for report in coupling.step(&mut world, &mut bodies).unwrap() {
            assert!(!report.unwrap().implicit);
        }
    }
    let weight = (block_mass + f64::from(world.bodies[box_body].mass())) * 9.81;
    let reaction = -coupling.force_on(ground).y;
    assert!(
        (reaction / weight - 1.0).abs() < 0.01,
        "{reaction} N against {weight} N"
    );
}

/// The same strip, stiff (E = 10⁸ Pa damped by a 1 ms stiffness time), under the default
/// integrator: its explicit step would need thousands of substeps and a fixed body's glue can
/// be in an implicit step, so every frame is implicit, and after 1 s the glue carries the
/// strip's weight to 1 % (the 2D issue's tolerance) with the strip at rest.
#[test]
fn a_stiff_strip_hangs_from_its_glue_in_implicit_steps() {
    let started = std::time::Instant::now();
    let (held, weight, implicit, speed) = hanging_strip(1e8, 1e-3, 60);
    let seconds = started.elapsed().as_secs_f64();
    println!(
        "implicit glue carries {held:.5} N of {weight:.5} N in {seconds:.3} s; fastest node {speed:.2e} m/s"
    );
    assert_eq!(implicit, 60);
    assert!(
        (held / weight - 1.0).abs() < 0.01,
        "{held} N against {weight} N"
    );
    assert!(speed < 1e-3, "{speed} m/s");
}
