//! Soft and rigid bodies in one world ([`FvmWorld`]): momentum exchanged exactly, and support
//! without jitter or creep.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

fn rubber(young: f64) -> Material {
    Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap()
}

/// A soft cube of side `side` (m) centred at `centre`, with damping time 2e-3 s.
fn soft_cube(side: f64, cells: usize, centre: DVec3, young: f64) -> SoftBody {
    let material = rubber(young);
    SoftBodyBuilder::new(
        mesh::cuboid(DVec3::splat(side / 2.0), [cells; 3]).unwrap(),
        material,
    )
    .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
    .translation(centre)
    .build()
    .unwrap()
}

fn step(world: &mut FvmWorld) {
    for (handle, outcome) in world.step() {
        outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
    }
}

#[test]
fn a_soft_cube_hitting_a_free_ball_conserves_momentum() {
    // Zero gravity. A 10 cm soft cube (1 kg) at 1 m/s hits a free 0.5 kg rigid ball off-centre,
    // with friction, so that both linear and angular momentum are exchanged. Tolerance 1e-6 of
    // the initial momentum: the exchange is exact in f64 on the soft side, and rapier keeps
    // rigid velocities in f32 (relative rounding 6e-8 per operation).
    let mut world = FvmWorld::default();
    world.physics.gravity = Vec3::ZERO;
    let radius = 0.05f32;
    let density = 0.5 / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3));
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.2, 0.03, 0.0)),
        ColliderBuilder::ball(radius).density(density).friction(0.5),
    );
    let mut cube = soft_cube(0.1, 4, DVec3::ZERO, 1e5);
    for v in cube.velocities_mut() {
        *v = DVec3::X;
    }
    let soft = world.soft_bodies.insert(cube);
    let momenta = |world: &FvmWorld| {
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
    };
    let (linear0, angular0) = momenta(&world);
    for _ in 0..30 {
        step(&mut world);
    }
    let (linear, angular) = momenta(&world);
    let rigid = &world.physics.bodies[ball];
    println!(
        "ball: v = {:?} m/s, ω = {:?} rad/s; Δp = {:.2e}, ΔL = {:.2e} (of {:.3} kg m/s)",
        rigid.linvel(),
        rigid.angvel(),
        (linear - linear0).length(),
        (angular - angular0).length(),
        linear0.length()
    );
    assert!(rigid.linvel().x > 0.5, "the ball was hit");
    assert!(rigid.angvel().length() > 0.1, "the ball was set spinning");
    let scale = linear0.length();
    assert!((linear - linear0).length() <= 1e-6 * scale);
    assert!((angular - angular0).length() <= 1e-6 * scale * 0.1);
}

#[test]
fn a_box_resting_on_a_soft_block_is_supported_without_jitter_or_creep() {
    // A 2 kg rigid box (10 cm) placed off-centre on a 20 cm soft block (8 kg, E = 1e6 Pa) on a
    // fixed ground. After 2 s to settle: the ground's reaction equals the total weight within
    // 1 %, the box's vertical speed stays below 1 mm/s over the next 5 s, and it creeps
    // sideways by less than 1 mm over those 5 s (the tolerances the coupling promises: a resting
    // box must neither jitter nor walk).
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let block = world
        .soft_bodies
        .insert(soft_cube(0.2, 4, DVec3::new(0.0, 0.1, 0.0), 1e6));
    let (rigid_box, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.04, 0.2505, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05)
            .density(2000.0)
            .friction(0.8),
    );
    // Contact impulses are those of the last soft step, one coupling substep long.
    let h = f64::from(world.physics.integration_parameters.dt) / f64::from(world.coupling_substeps);
    for _ in 0..120 {
        step(&mut world);
    }
    let ground = world.physics.colliders.iter().next().unwrap().0;
    let weight = (world.soft_bodies[block].total_mass()
        + f64::from(world.physics.bodies[rigid_box].mass()))
        * 9.81;
    let start = world.physics.bodies[rigid_box].translation().as_dvec3();
    let (mut reaction, mut fastest) = (0.0, 0.0f64);
    let frames = 300;
    for _ in 0..frames {
        step(&mut world);
        reaction += -world.soft_bodies[block]
            .contact_force_on(ground, h)
            .unwrap()
            .0
            .y;
        fastest = fastest.max(world.physics.bodies[rigid_box].linvel().y.abs() as f64);
    }
    let end = world.physics.bodies[rigid_box].translation().as_dvec3();
    println!("box moved by {:?} m", end - start);
    let reaction = reaction / frames as f64;
    let creep = DVec3::new(end.x - start.x, 0.0, end.z - start.z).length();
    println!(
        "ground reaction {reaction:.3} N vs weight {weight:.3} N; box vertical speed ≤ {fastest:.2e} m/s; creep {:.3} mm in 5 s",
        creep * 1e3
    );
    assert!((reaction / weight - 1.0).abs() < 0.01);
    assert!(fastest < 1e-3);
    assert!(creep < 1e-3);
}

#[test]
fn a_ball_hanging_from_a_soft_rope_swings_with_the_pendulum_period() {
    // A 0.5 m soft rope (1 x 1 cm, E = 1e6 Pa, clamped at the top) with a 1 kg rigid ball
    // (r = 5 cm) glued 1 cm below its end, released 5° from the vertical. The period of the
    // swing (three periods timed from the ball's crossings) is compared with the compound
    // pendulum's, 2π sqrt(I / (M g d)), for the rope's length as it hangs stretched (by about
    // 4 cm); tolerance 5 %. The rope's bending stiffness, clamped at the top and glued across
    // its end face to the ball, shortens the period (measured -1.2 %; -4.9 % for a 2 x 2 cm
    // rope), and the 5° amplitude lengthens it by 0.05 %.
    let mut world = FvmWorld::default();
    let angle = 5f64.to_radians();
    let tilt = DQuat::from_rotation_z(angle);
    let (length, radius, gap) = (0.5, 0.05f64, 0.01);
    let material = rubber(1e6);
    let mesh = mesh::cuboid(DVec3::new(0.005, length / 2.0, 0.005), [2, 40, 2]).unwrap();
    let top = mesh.nodes_where(|p| p.y >= length / 2.0 - 1e-9);
    let bottom = mesh.nodes_where(|p| p.y <= -length / 2.0 + 1e-9);
    let rope = SoftBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
        .orientation(tilt)
        .translation(tilt * DVec3::new(0.0, -length / 2.0, 0.0))
        .pinned_nodes(top)
        .build()
        .unwrap();
    let ball_mass = 1.0;
    let density = ball_mass / (4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
    let centre = tilt * DVec3::new(0.0, -(length + gap + radius), 0.0);
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(centre.as_vec3()),
        ColliderBuilder::ball(radius as f32).density(density as f32),
    );
    let rope = world.soft_bodies.insert(rope);
    world.soft_bodies[rope]
        .attach(bottom, ball, &world.physics.bodies)
        .unwrap();
    let dt = f64::from(world.physics.integration_parameters.dt);
    let (mut crossings, mut previous_x, mut distance) = (Vec::new(), centre.x, Vec::new());
    for frame in 1..=400 {
        step(&mut world);
        let x = world.physics.bodies[ball].translation().as_dvec3();
        distance.push(x.length());
        if previous_x > 0.0 && x.x <= 0.0 {
            // Linear interpolation of the downward crossing of x = 0.
            crossings.push((frame as f64 - x.x.abs() / (previous_x - x.x)) * dt);
        }
        previous_x = x.x;
    }
    assert!(crossings.len() >= 4, "only {} crossings", crossings.len());
    let period = (crossings[3] - crossings[0]) / 3.0;
    let arm = distance.iter().sum::<f64>() / distance.len() as f64;
    let rope_mass = world.soft_bodies[rope].total_mass();
    let rope_length = arm - gap - radius;
    let inertia = ball_mass * (arm * arm + 0.4 * radius * radius)
        + rope_mass * rope_length * rope_length / 3.0;
    let moment = ball_mass * arm + rope_mass * rope_length / 2.0;
    let expected = 2.0 * std::f64::consts::PI * (inertia / (moment * 9.81)).sqrt();
    println!(
        "period {period:.4} s vs compound pendulum {expected:.4} s ({:+.2} %), arm {arm:.4} m",
        100.0 * (period / expected - 1.0)
    );
    assert!((period / expected - 1.0).abs() < 0.05);
}
