//! Soft and rigid bodies in one world ([`FvmWorld`]): momentum exchanged exactly, and support
//! without jitter or creep.

mod common;

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

fn rubber(young: f64) -> Material {
    Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap()
}

/// `body` with surface friction coefficient `friction`.
fn with_friction(mut body: DeformableBody, friction: f64) -> DeformableBody {
    body.friction = friction;
    body
}

/// A soft cube of side `side` (m) centred at `centre`, with damping time 2e-3 s.
fn soft_cube(side: f64, cells: usize, centre: DVec3, young: f64) -> DeformableBody {
    let material = rubber(young);
    DeformableBodyBuilder::new(
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
    // with friction, so that both linear and angular momentum are exchanged; under the automatic
    // choice (implicit: nothing but the cube holds the ball) and forced
    // implicit (the ball's impulses taken at the contact points' start, the cube's angular
    // momentum set to what it started with plus what the ball gave it there; without that ΔL
    // was 6.6e-5 kg m²/s, 660 times the bound). Tolerance 1e-6
    // of the initial momentum: the exchange is exact in f64 on the soft side, and rapier keeps
    // rigid velocities in f32 (relative rounding 6e-8 per operation).
    for integrator in [None, Some(IntegratorKind::Implicit)] {
        let radius = 0.05f32;
        let (mut world, ball) = common::ball_without_gravity(
            integrator,
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.2, 0.03, 0.0)),
            (0.5, radius),
        );
        let mut cube = soft_cube(0.1, 4, DVec3::ZERO, 1e5);
        for v in cube.velocities_mut() {
            *v = DVec3::X;
        }
        let soft = world.soft_bodies.insert(cube);
        let momenta = |world: &FvmWorld| common::soft_and_ball_momenta(world, soft, ball, radius);
        let (linear0, angular0) = momenta(&world);
        for _ in 0..30 {
            step(&mut world);
        }
        let (linear, angular) = momenta(&world);
        let rigid = &world.physics.bodies[ball];
        println!(
            "{integrator:?}: ball v = {:?} m/s, ω = {:?} rad/s; Δp = {:.2e}, ΔL = {:.2e} (of {:.3} kg m/s)",
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
}

#[test]
fn a_soft_bar_glued_to_a_free_ball_tumbles_with_its_momentum_kept() {
    // Zero gravity. A 10 cm soft bar (2 x 2 cm, E = 1e5 Pa) glued across its end face to a free
    // 0.5 kg ball just beyond it, the two moving at 1 m/s and turning at 5 rad/s about an axis
    // across the bar, 30 frames: the glue's springs exchange linear and angular momentum between
    // them all along. Under the automatic choice (which steps it implicitly) and forced
    // implicit, the ball takes its impulses at its anchors and the bar at its nodes where they
    // end each step, and the bar's angular momentum is then set to what it started with plus
    // what the ball gave it (without that, ΔL was 3.6e-5 N m s; with only the anchors' moment
    // given back, 8.5e-8, Newton's tolerance's share). Tolerance as for the cube hitting the
    // ball: 1e-6 of the initial momentum (times 10 cm for the angular one), the exchange being
    // exact in f64 on the soft side and rapier keeping rigid velocities in f32.
    for integrator in [None, Some(IntegratorKind::Implicit)] {
        let radius = 0.03f32;
        let spin = DVec3::new(0.0, 0.0, 5.0);
        let centre = DVec3::new(0.05 + f64::from(radius), 0.0, 0.0);
        let (mut world, ball) = common::ball_without_gravity(
            integrator,
            RigidBodyBuilder::dynamic()
                .translation(centre.as_vec3())
                .linvel((DVec3::X + spin.cross(centre)).as_vec3())
                .angvel(spin.as_vec3()),
            (0.5, radius),
        );
        let mesh = mesh::cuboid(DVec3::new(0.05, 0.01, 0.01), [5, 1, 1]).unwrap();
        let end = mesh.nodes_where(|p| p.x >= 0.05 - 1e-9);
        let mut bar = DeformableBodyBuilder::new(mesh, rubber(1e5))
            .build()
            .unwrap();
        let moving: Vec<DVec3> = (bar.positions().iter())
            .map(|x| DVec3::X + spin.cross(*x))
            .collect();
        bar.velocities_mut().copy_from_slice(&moving);
        let soft = world.soft_bodies.insert(bar);
        world.attach(soft, end, ball).unwrap();
        let momenta = |world: &FvmWorld| common::soft_and_ball_momenta(world, soft, ball, radius);
        let (linear0, angular0) = momenta(&world);
        for _ in 0..30 {
            step(&mut world);
        }
        let (linear, angular) = momenta(&world);
        println!(
            "{integrator:?}: Δp = {:.2e}, ΔL = {:.2e} (of {:.3} kg m/s, {:.2e} N m s)",
            (linear - linear0).length(),
            (angular - angular0).length(),
            linear0.length(),
            angular0.length()
        );
        let scale = linear0.length();
        assert!((linear - linear0).length() <= 1e-6 * scale);
        assert!((angular - angular0).length() <= 1e-6 * scale * 0.1);
    }
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
    let block = world.soft_bodies.insert(with_friction(
        soft_cube(0.2, 4, DVec3::new(0.0, 0.1, 0.0), 1e6),
        0.8,
    ));
    let (rigid_box, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.04, 0.2505, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05)
            .density(2000.0)
            .friction(0.8),
    );
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
        reaction += -world.contact_force_on(block, ground).unwrap().0.y;
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
    // 5.4 cm); tolerance 5 %. The rope's bending stiffness, clamped at the top and glued across
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
    let rope = DeformableBodyBuilder::new(mesh, material)
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
    world.attach(rope, bottom, ball).unwrap();
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

#[test]
fn a_rigid_plate_on_a_soft_block_sinks_by_m_g_h_over_e_a() {
    // A 4.08 kg rigid plate covering the whole top of a 20 cm soft block (E = 1e6 Pa, ν = 0.3),
    // all contacts frictionless, so that the block is in uniaxial stress. The plate's extra load
    // shortens the block by m g H / (E A) = 0.2 mm (strain 1e-3, where the Neo-Hookean law is
    // linear to 0.1 %): the sink is the top face's height settled without the plate minus with
    // it, each averaged over the last 0.5 s of 2 s, which removes the block's own weight (in
    // linear elasticity the two loads superpose exactly). Tolerance 5 %, the issue's; measured
    // +1.76 %.
    let (side, young) = (0.2, 1e6);
    let area = side * side;
    let plate_mass = 1e-3 * young * area / 9.81;
    // The top face's height and the force the block exerts on the plate (N), both averaged.
    let settled = |with_plate: bool| {
        let mut world = FvmWorld::default();
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.0),
            None,
        );
        let block = world.soft_bodies.insert(with_friction(
            soft_cube(side, 4, DVec3::new(0.0, side / 2.0, 0.0), young),
            0.0,
        ));
        let plate = with_plate.then(|| {
            // 30 x 2 x 30 cm, overhanging the block on every side.
            let (half_width, half_thickness) = (0.15f32, 0.01f32);
            let volume = 8.0 * half_width * half_width * half_thickness;
            world
                .physics
                .insert(
                    RigidBodyBuilder::dynamic().translation(Vec3::new(
                        0.0,
                        side as f32 + half_thickness,
                        0.0,
                    )),
                    ColliderBuilder::cuboid(half_width, half_thickness, half_width)
                        .density(plate_mass as f32 / volume)
                        .friction(0.0),
                )
                .0
        });
        let top = world.soft_bodies[block]
            .mesh()
            .nodes_where(|p| p.y >= side / 2.0 - 1e-9);
        let (mut height, mut support, mut samples) = (0.0, DVec3::ZERO, 0);
        for frame in 0..120 {
            step(&mut world);
            if frame >= 90 {
                let positions = world.soft_bodies[block].positions();
                height +=
                    top.iter().map(|&n| positions[n as usize].y).sum::<f64>() / top.len() as f64;
                if let Some(plate) = plate {
                    support += world.load_on(block, plate).0;
                }
                samples += 1;
            }
        }
        let samples = f64::from(samples);
        (height / samples, support / samples)
    };
    let ((free_top, _), (loaded_top, support)) = (settled(false), settled(true));
    // The block carries the plate: the force on it balances its weight (within 1 %, as the
    // ground's reaction in the support test).
    let weight = plate_mass * 9.81;
    println!("support of the plate {support:?} N vs its weight {weight:.3} N");
    assert!((support.y / weight - 1.0).abs() < 0.01);
    assert!(support.x.abs().max(support.z.abs()) < 1e-3 * weight);
    let sink = free_top - loaded_top;
    let expected = plate_mass * 9.81 * side / (young * area);
    println!(
        "sink {:.4} mm vs m g H / (E A) = {:.4} mm ({:+.2} %)",
        sink * 1e3,
        expected * 1e3,
        100.0 * (sink / expected - 1.0)
    );
    assert!((sink / expected - 1.0).abs() < 0.05);
}

/// Squeezes a 5 cm soft cube (E = 1e5 Pa, 0.125 kg) resting on the ground between two
/// position-based kinematic fingers (friction 1) by `squeeze` (m) per side, lifts it 10 cm at
/// 0.1 m/s and holds it, with `integrator` forced if given. Returns how far the cube slipped
/// down the fingers during lift and hold (m), its lowest node's height at the end (m), and the
/// deepest any node was inside a finger (m).
fn grasp(squeeze: f64, integrator: Option<IntegratorKind>) -> (f64, f64, f64) {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    let (half, finger_half) = (0.025, 0.005);
    let cube = world.soft_bodies.insert(with_friction(
        soft_cube(2.0 * half, 4, DVec3::new(0.0, half, 0.0), 1e5),
        1.0,
    ));
    let fingers: Vec<_> = [-1.0, 1.0]
        .map(|side: f64| {
            let x = side * (half + finger_half + 2e-3);
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
        })
        .into();
    let dt = f64::from(world.physics.integration_parameters.dt);
    let (close, lift, hold) = (0.5, 1.0, 0.5);
    let (mut deepest, mut lift_start) = (0.0f64, None);
    let frames = ((0.25 + close + lift + hold) / dt).round() as usize;
    for frame in 1..=frames {
        let t = frame as f64 * dt - 0.25;
        let closing = (t / close).clamp(0.0, 1.0);
        let lifting = ((t - close) / lift).clamp(0.0, 1.0);
        for (finger, side) in fingers.iter().zip([-1.0, 1.0]) {
            let x = side * (half + finger_half + 2e-3 - (2e-3 + squeeze) * closing);
            let y = half + 0.1 * lifting;
            world.physics.bodies[*finger]
                .set_next_kinematic_translation(Vec3::new(x as f32, y as f32, 0.0));
        }
        if t >= close && lift_start.is_none() {
            lift_start = Some((
                world.soft_bodies[cube].center_of_mass().y,
                f64::from(world.physics.bodies[fingers[0]].translation().y),
            ));
        }
        step(&mut world);
        for finger in &fingers {
            let collider = world.physics.bodies[*finger].colliders()[0];
            let collider = &world.physics.colliders[collider];
            for x in world.soft_bodies[cube].positions() {
                let projection =
                    collider
                        .shape()
                        .project_point(collider.position(), x.as_vec3(), false);
                if projection.is_inside {
                    deepest = deepest.max((projection.point.as_dvec3() - *x).length());
                }
            }
        }
    }
    let (cube_start, finger_start) = lift_start.unwrap();
    let body = &world.soft_bodies[cube];
    let finger_rise = f64::from(world.physics.bodies[fingers[0]].translation().y) - finger_start;
    let slip = finger_rise - (body.center_of_mass().y - cube_start);
    let lowest = body
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min);
    (slip, lowest, deepest)
}

#[test]
fn two_kinematic_fingers_lift_a_soft_cube_by_friction() {
    // Squeezed by 2 mm per side (8 % strain), the cube must rise with the fingers: it is lifted
    // clear of the ground (its lowest node above 5 cm after a 10 cm lift), slips less than 1 mm
    // down the fingers (its own elastic sag hanging from them is about ρ g L²/E = 0.25 mm), and
    // no node is ever deeper inside a finger than the contact margin plus 1 mm (no tunnelling).
    let margin = ContactSettings::default().margin;
    for integrator in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let (slip, lowest, deepest) = grasp(2e-3, integrator);
        println!(
            "{integrator:?}: slip {:.3} mm, lowest node {:.2} mm, deepest in a finger {:.3} mm",
            slip * 1e3,
            lowest * 1e3,
            deepest * 1e3
        );
        assert!(slip.abs() < 1e-3);
        assert!(lowest > 0.05);
        assert!(deepest < margin + 1e-3);
    }
}

#[test]
fn a_soft_beam_glued_to_a_box_on_the_ground_leaves_the_box_at_rest() {
    // A 2 kg rigid box (10 cm) stands on the ground carrying a 20 cm soft beam (4 x 4 cm,
    // E = 1e6 Pa, 0.32 kg) glued by its end face to the box's side: the beam sags (about 1.5 cm
    // at the tip, clear of the ground) and the box takes its weight and moment on its base. After 2 s to settle, the box's angular speed must
    // stay below 1e-3 rad/s over the next 3 s (the bound: no rocking from the coupling),
    // with the automatic choice (implicit, for this heavily damped beam) and explicit.
    for integrator in [None, Some(IntegratorKind::Explicit)] {
        let mut world = FvmWorld::default();
        world.coupling.integrator.force = integrator;
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
            None,
        );
        let half = 0.05;
        let (rigid_box, _) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, half, 0.0)),
            ColliderBuilder::cuboid(half, half, half)
                .density(2000.0)
                .friction(0.8),
        );
        let material = rubber(1e6);
        let mesh = mesh::cuboid(DVec3::new(0.1, 0.02, 0.02), [10, 2, 2]).unwrap();
        let root = mesh.nodes_where(|p| p.x <= -0.1 + 1e-9);
        let beam = DeformableBodyBuilder::new(mesh, material)
            .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
            .translation(DVec3::new(half as f64 + 0.1, half as f64, 0.0))
            .build()
            .unwrap();
        let beam = world.soft_bodies.insert(beam);
        world.attach(beam, root, rigid_box).unwrap();
        for _ in 0..120 {
            step(&mut world);
        }
        let mut fastest = 0.0f32;
        for _ in 0..180 {
            step(&mut world);
            fastest = fastest.max(world.physics.bodies[rigid_box].angvel().length());
        }
        let lowest = world.soft_bodies[beam]
            .positions()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        println!(
            "{integrator:?}: box angular speed ≤ {fastest:.2e} rad/s over 3 s; beam's lowest point {:.1} mm",
            lowest * 1e3
        );
        assert!(lowest > 0.0, "the beam must hang free");
        assert!(fastest < 1e-3);
    }
}

#[test]
fn nodes_glued_to_a_kinematic_body_follow_its_prescribed_path() {
    // Pins that move on a prescribed path: the top of a 20 cm soft rod (E = 1e6 Pa, 2 x 2 cm)
    // hanging from a position-based kinematic body driven around a 5 cm circle once a second
    // (0.31 m/s), 2 s at 60 Hz. Every glued node must stay where the path puts its anchor.
    // Bound 0.1 mm: the explicit attachment is a velocity constraint with a fifth of the drift
    // corrected per substep (measured: below a micrometre), and the implicit one a spring of
    // stiffness penalty_factor m/h² (about 6e4 N/m on these nodes) that gives under the loads
    // at the rod's root: its weight and the bending moment of its swing, a few newtons per
    // node (measured: 0.084 mm).
    for integrator in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let material = rubber(1e6);
        let mesh = mesh::cuboid(DVec3::new(0.01, 0.1, 0.01), [1, 10, 1]).unwrap();
        let root = mesh.nodes_where(|p| p.y >= 0.1 - 1e-9);
        let rod = DeformableBodyBuilder::new(mesh, material)
            .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
            .translation(DVec3::new(common::GLUED_PATH_RADIUS, 0.4, 0.0))
            .build()
            .unwrap();
        let worst = common::glued_path_error(rod, &root, integrator);
        println!(
            "{integrator:?}: glued nodes' largest distance from the path {:.4} mm",
            worst * 1e3
        );
        assert!(worst < 1e-4);
    }
}

#[test]
fn a_small_box_rests_on_the_faces_of_a_coarse_soft_block() {
    // A 3 cm steel box (0.216 kg) on a 20 cm soft block (E = 1e6 Pa) of 2 x 2 x 2 cells, placed
    // between the top face's nodes (10 cm apart), within one of its triangles: only its corners
    // meet the soft face. Held by them, it must rest on the surface: sunk below the face at most the contact margin plus
    // 1 mm (the drop bound), vertical speed below 1 mm/s (the jitter bound), the
    // block carrying its weight within 1 % (the support bound, read through
    // `load_on`). No node of the block lies under it: node contacts alone could not hold it.
    // On its corners the box rings at about 110 Hz (contact stiffness about E times the cell,
    // 1e5 N/m, over its mass): explicit steps in the default 4 coupling substeps a frame
    // (240 Hz) cannot follow it and left it jittering at about 3 cm/s (16 substeps, 960 Hz,
    // did). At the default settings the automatic choice steps the block implicitly, the box
    // (which only the block holds) in its solve, and it rests.
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let block = world.soft_bodies.insert(with_friction(
        soft_cube(0.2, 2, DVec3::new(0.0, 0.1, 0.0), 1e6),
        0.8,
    ));
    let half = 0.015f32;
    let (rigid_box, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.07, 0.2 + half + 1e-3, 0.025)),
        ColliderBuilder::cuboid(half, half, half)
            .density(8000.0)
            .friction(0.8),
    );
    let mass = f64::from(world.physics.bodies[rigid_box].mass());
    let (fastest, support) = common::settle_on(&mut world, block, rigid_box, 180);
    let bottom = f64::from(world.physics.bodies[rigid_box].translation().y - half);
    // The block's top face under the box: the mean height of its top nodes.
    let face = common::mean_height_of_nodes_above(&world.soft_bodies[block], 0.1 - 1e-9);
    let weight = mass * 9.81;
    println!(
        "box bottom {:.3} mm vs face {:.3} mm (sunk {:.3} mm); vertical speed <= {fastest:.2e} m/s; \
         support {support:.4} N vs weight {weight:.4} N",
        bottom * 1e3,
        face * 1e3,
        (face - bottom) * 1e3
    );
    assert!(face - bottom < world.coupling.contact.margin + 1e-3);
    assert!(fastest < 1e-3);
    assert!((support / weight - 1.0).abs() < 0.01);
}

#[test]
fn a_coarse_soft_block_rests_on_the_corners_of_a_small_pedestal() {
    // A 20 cm soft block (E = 1e6 Pa, ν = 0.3, 1000 kg/m³, 8 kg) of 3 x 3 x 3 cells rests on a
    // fixed 3 cm cube centred under it, with nothing else below: no node of the block lies above
    // the pedestal (its bottom nodes are 6.7 cm apart; the pedestal's top spans ±1.5 cm), so only
    // the pedestal's four top corners, pressing on the block's bottom triangles, can hold it.
    // Settled for 1.5 s, under the automatic integrator (explicit while rigid corners touch the
    // body) and under forced implicit steps (whose corner penalties push the triangles): the
    // pedestal carries the block's weight within 1 % (static equilibrium; the support bound of
    // the contact tests), read through the collider loads; the block stays on it (its centre
    // above the pedestal by more than a quarter of its side, where it starts half a side above);
    // and the two integrators settle it at the same height within 0.5 mm (the same elastostatic
    // state, up to the implicit penalty's micrometre penetration and what the damping has not
    // yet taken out).
    let mut heights = Vec::new();
    for force in [None, Some(IntegratorKind::Implicit)] {
        let mut world = FvmWorld::default();
        world.coupling.integrator.force = force;
        let half = 0.015f32;
        let pedestal = world.physics.insert_collider(
            ColliderBuilder::cuboid(half, half, half)
                .translation(Vec3::new(0.0, half, 0.0))
                .friction(0.8),
            None,
        );
        let top = 2.0 * f64::from(half);
        let block = world.soft_bodies.insert(with_friction(
            soft_cube(0.2, 3, DVec3::new(0.0, top + 5e-4 + 0.1, 0.0), 1e6),
            0.8,
        ));
        let weight = world.soft_bodies[block].total_mass() * 9.81;
        let support = common::settle_on_colliders(&mut world, &[pedestal], 90);
        let centre = world.soft_bodies[block].center_of_mass();
        println!(
            "forced {force:?}: centre {:.3} mm above the pedestal, {:.3} mm off its axis; \
             support {support:.4} N vs weight {weight:.4} N",
            (centre.y - top) * 1e3,
            centre.x.hypot(centre.z) * 1e3
        );
        assert!((support / weight - 1.0).abs() < 0.01);
        assert!(centre.y - top > 0.05);
        heights.push(centre.y);
    }
    assert!((heights[0] - heights[1]).abs() < 5e-4);
}

#[test]
fn a_frame_of_negative_or_undefined_length_or_no_substeps_is_refused_and_moves_nothing() {
    // A frame step of -1 s or NaN, or zero coupling substeps, has no meaning: every deformable
    // body's result is the error, and nothing moves, rapier's bodies included (a pause, dt = 0,
    // stays a pause). Exact comparison: nothing may have been integrated.
    let cases: [(f32, u32, &str); 3] = [
        (-1.0, 4, "time step"),
        (f32::NAN, 4, "time step"),
        (1.0 / 60.0, 0, "substeps"),
    ];
    for (dt, substeps, named) in cases {
        let mut world = FvmWorld::default();
        world.physics.integration_parameters.dt = dt;
        world.coupling.substeps = substeps;
        let (ball, _) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 1.0, 0.0)),
            ColliderBuilder::ball(0.05),
        );
        let cube = world
            .soft_bodies
            .insert(soft_cube(0.1, 2, DVec3::new(0.5, 0.5, 0.0), 1e5));
        let before = world.soft_bodies[cube].positions().to_vec();
        let results = world.step();
        assert_eq!(results.len(), 1);
        let error = results[0].1.as_ref().expect_err("the frame is refused");
        println!("dt {dt}, {substeps} substeps: {error}");
        assert!(error.to_string().contains(named), "{error}");
        assert_eq!(world.soft_bodies[cube].positions(), &before[..]);
        assert_eq!(
            world.physics.bodies[ball].translation(),
            Vec3::new(0.0, 1.0, 0.0)
        );
    }
}

#[test]
fn the_frame_timing_counts_a_block_under_a_box_as_stepped_with_a_rigid_partner() {
    // A box resting on a soft block, stepped implicitly: after it lands, every frame's soft
    // steps are implicit steps with a dynamic rigid partner, in the four coupling substeps,
    // with rapier's steps and the contacts' detection beside them; nothing is counted as
    // explicit or as stepped without a partner.
    let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
    world.coupling.sleep = SleepSettings::never();
    world
        .soft_bodies
        .insert(soft_cube(0.1, 3, DVec3::new(0.0, 0.05, 0.0), 1e5));
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.1205, 0.0)),
        ColliderBuilder::cuboid(0.02, 0.02, 0.02).density(1000.0),
    );
    for _ in 0..10 {
        step(&mut world);
    }
    let timing = *world.coupling.last_frame_timing();
    println!("{timing:?}");
    assert!(timing.implicit_with_rigid_partners > 0.0);
    assert_eq!(timing.implicit_without_rigid_partners, 0.0);
    assert_eq!(timing.explicit_with_rigid_partners, 0.0);
    assert_eq!(timing.explicit_without_rigid_partners, 0.0);
    assert_eq!(timing.soft_steps(), timing.implicit_with_rigid_partners);
    assert!(timing.contact_detection > 0.0 && timing.rapier_steps > 0.0);
}
