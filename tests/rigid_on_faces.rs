//! Rigid shapes against the faces of soft bodies, under the automatic integrator and under forced
//! implicit steps: rounded ones (balls, cones: no vertices) pressing between the nodes of a
//! coarse soft body are held by its faces through their closest points, a box striking a
//! block corner-first exchanges momentum (exactly in the explicit sweeps), and a board that
//! rapier's ground holds at its foot rests leaning on a block (under forced explicit steps too).

mod common;

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

/// A 20 cm soft block (E = 1e6 Pa, ν = 0.3, 1000 kg/m³, friction 0.8, damping time 2e-3 s) of
/// `cells`³ cells, its bottom face at height `bottom` (m).
fn coarse_block(cells: usize, bottom: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mut body = DeformableBodyBuilder::new(
        mesh::cuboid(DVec3::splat(0.1), [cells; 3]).unwrap(),
        material,
    )
    .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
    .translation(DVec3::new(0.0, bottom + 0.1, 0.0))
    .build()
    .unwrap();
    body.friction = 0.8;
    body
}

fn step(world: &mut FvmWorld) {
    for (handle, outcome) in world.step() {
        outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
    }
}

/// The world of each tested integrator: automatic, and forced implicit.
fn worlds() -> [(&'static str, FvmWorld); 2] {
    let mut implicit = FvmWorld::default();
    implicit.coupling.integrator.force = Some(IntegratorKind::Implicit);
    [("automatic", FvmWorld::default()), ("implicit", implicit)]
}

#[test]
fn a_small_ball_rests_on_the_faces_of_a_coarse_soft_block() {
    // A steel ball of radius 1.5 cm (0.113 kg) on the 20 cm block of 2 x 2 x 2 cells (its top
    // face's nodes 10 cm apart), dropped from 1 mm above the face within one of its triangles:
    // no node lies under it, and a ball has no vertex, so only the face's triangles can hold it,
    // through the ball's point deepest below each (its support point). Settled for 3 s, it must
    // rest on the surface as the small box of `tests/coupling.rs` does, with the same bounds:
    // sunk below the face at most the contact margin plus 1 mm, vertical speed below 1 mm/s, the
    // block carrying its weight within 1 % (static equilibrium). Without the faces' support the
    // ball falls between the nodes into the block.
    for (name, mut world) in worlds() {
        world.coupling.substeps = 16;
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
            None,
        );
        let block = world.soft_bodies.insert(coarse_block(2, 0.0));
        let radius = 0.015f32;
        let (ball, _) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.07, 0.2 + radius + 1e-3, 0.025)),
            ColliderBuilder::ball(radius).density(8000.0).friction(0.8),
        );
        let mass = f64::from(world.physics.bodies[ball].mass());
        let (fastest, support) = common::settle_on(&mut world, block, ball, 180);
        let centre = world.physics.bodies[ball].translation();
        let bottom = f64::from(centre.y - radius);
        // The block's top face under the ball: the mean height of its top nodes.
        let face = common::mean_height_of_nodes_above(&world.soft_bodies[block], 0.1 - 1e-9);
        let weight = mass * 9.81;
        println!(
            "{name}: ball bottom {:.3} mm vs face {:.3} mm (sunk {:.3} mm), at x {:.2} z {:.2} \
             mm; vertical speed <= {fastest:.2e} m/s; support {support:.4} N vs weight \
             {weight:.4} N",
            bottom * 1e3,
            face * 1e3,
            (face - bottom) * 1e3,
            centre.x * 1e3,
            centre.z * 1e3,
        );
        assert!(
            face - bottom < world.coupling.contact.margin + 1e-3,
            "{name}"
        );
        assert!(fastest < 1e-3, "{name}");
        assert!((support / weight - 1.0).abs() < 0.01, "{name}");
    }
}

#[test]
fn a_coarse_soft_block_rests_on_small_fixed_rounded_pedestals() {
    // The 20 cm block of 3 x 3 x 3 cells (8 kg; its bottom nodes 6.7 cm apart) rests on four
    // fixed balls of radius 1 cm, or on the points of four cones (radius 1 cm, height 2 cm), at
    // (±1.5, ±1.5) cm under its centre with nothing else below: no node of the block lies above a
    // pedestal (the pedestals reach 2.5 cm from the axis, the nearest nodes are 3.3 cm away), so
    // only the block's bottom triangles, pressed by the pedestals' support points, can hold it.
    // Settled for 1.5 s, as the cube pedestal of `tests/coupling.rs`, with its bounds: the
    // pedestals carry the block's weight within 1 % (static equilibrium), and the block stays on
    // them (its centre above their tops by more than a quarter of its side, where it starts half
    // a side above). Without the triangles' support the pedestals pass between the nodes.
    let pedestals = [
        ("balls", SharedShape::ball(0.01)),
        ("cones", SharedShape::cone(0.01, 0.01)),
    ];
    let top = 0.02;
    for (shape_name, shape) in pedestals {
        for (name, mut world) in worlds() {
            let feet: Vec<_> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
                .map(|(x, z)| {
                    world.physics.insert_collider(
                        ColliderBuilder::new(shape.clone())
                            .translation(Vec3::new(0.015 * x, 0.01, 0.015 * z))
                            .friction(0.8),
                        None,
                    )
                })
                .into();
            let block = world.soft_bodies.insert(coarse_block(3, top + 5e-4));
            let weight = world.soft_bodies[block].total_mass() * 9.81;
            let support = common::settle_on_colliders(&mut world, &feet, 90);
            let centre = world.soft_bodies[block].center_of_mass();
            println!(
                "{shape_name}, {name}: centre {:.3} mm above the pedestals, {:.3} mm off their \
                 axis; support {support:.4} N vs weight {weight:.4} N",
                (centre.y - top) * 1e3,
                centre.x.hypot(centre.z) * 1e3
            );
            assert!(
                (support / weight - 1.0).abs() < 0.01,
                "{shape_name}, {name}"
            );
            assert!(centre.y - top > 0.05, "{shape_name}, {name}");
        }
    }
}

#[test]
fn a_rigid_box_striking_a_soft_block_corner_first_exchanges_momentum() {
    // Zero gravity. A free steel cube of 4 cm (0.512 kg), turned so that one corner leads, at
    // 1 m/s into a 10 cm soft block (1 kg, E = 1e5 Pa, 4 x 4 x 4 cells, at rest) off its centre
    // line, with friction: its corner meets the block's face between nodes first, then its edges
    // and faces. Linear momentum is conserved under both integrators (tolerance 1e-6 of the
    // initial momentum: exact in f64 on the soft side, rapier keeps rigid velocities in f32).
    // Angular momentum about the origin, to the same 1e-6 (times the block's 10 cm) under both:
    // the explicit sweeps apply both sides' impulses at the triangle's point; an implicit step
    // gives the rigid body its impulses where its contact points began the step and the soft
    // body where they end it, and then sets the soft body's angular momentum to what it started
    // with plus what the cube gave it, counted at the cube's points
    // (`constraint::partner_angular_impulse`). Without that it was off by 1.68e-4 N m s, bounded by how
    // far a point of the cube travels in a frame times the impulse the cube received (6.9e-3).
    // The cube's inertia is isotropic, m a²/6, whatever its orientation.
    for (name, mut world) in worlds() {
        world.physics.gravity = Vec3::ZERO;
        let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
        let mut block =
            DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
                .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
                .build()
                .unwrap();
        block.friction = 0.5;
        let soft = world.soft_bodies.insert(block);
        let half = 0.02f32;
        let turn = rapier_fvm::glamx::Quat::from_rotation_z(std::f32::consts::FRAC_PI_4)
            * rapier_fvm::glamx::Quat::from_rotation_x(0.6155);
        let (cube, _) = world.physics.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vec3::new(-0.09, 0.015, 0.01))
                .rotation(turn.to_scaled_axis())
                .linvel(Vec3::new(1.0, 0.0, 0.0)),
            ColliderBuilder::cuboid(half, half, half)
                .density(8000.0)
                .friction(0.5),
        );
        let mass = f64::from(world.physics.bodies[cube].mass());
        let momenta = |world: &FvmWorld| {
            let body = &world.soft_bodies[soft];
            let rigid = &world.physics.bodies[cube];
            let inertia = mass * f64::from(2.0 * half).powi(2) / 6.0;
            let (x, v) = (rigid.translation().as_dvec3(), rigid.linvel().as_dvec3());
            let soft_angular: DVec3 = (body.positions().iter().zip(body.velocities()))
                .zip(body.masses())
                .map(|((x, v), m)| x.cross(*v) * *m)
                .sum();
            (
                body.linear_momentum() + v * mass,
                soft_angular + x.cross(v) * mass + rigid.angvel().as_dvec3() * inertia,
            )
        };
        let (linear0, angular0) = momenta(&world);
        for _ in 0..30 {
            step(&mut world);
        }
        let (linear, angular) = momenta(&world);
        let rigid = &world.physics.bodies[cube];
        let scale = linear0.length();
        let angular_bound = 1e-6 * scale * 0.1;
        println!(
            "{name}: cube v = {:?} m/s, ω = {:?} rad/s; Δp = {:.2e} (of {scale:.3} kg m/s), \
             ΔL = {:.2e} N m s (bound {angular_bound:.1e})",
            rigid.linvel(),
            rigid.angvel(),
            (linear - linear0).length(),
            (angular - angular0).length(),
        );
        assert!(rigid.linvel().x < 0.9, "{name}: the cube struck the block");
        assert!(
            rigid.angvel().length() > 0.1,
            "{name}: the cube was set turning"
        );
        assert!((linear - linear0).length() <= 1e-6 * scale, "{name}");
        assert!((angular - angular0).length() <= angular_bound, "{name}");
    }
}

#[test]
fn a_board_leaning_on_a_soft_block_rests_and_its_push_reaches_the_ground() {
    // A 50 g rigid board (1 x 8 x 4 cm, friction 0.8) stands on the ground (friction 0.5)
    // tilted 20° from the vertical, 0.5 mm short of a side face of the 20 cm block of 4³ cells,
    // onto which it tips: rapier's ground contact holds its foot, the block its top corners (a
    // rigid body that rapier's own contacts also hold, which the soft step moves as rapier's
    // last step did). Default coupling, 2 s, kept awake, under the automatic choice, forced
    // implicit and forced explicit steps. The board must come to rest leaning (speed below
    // 1 mm/s, its tilt within 1e-4 rad over the last second, still pushing on the block), the
    // audit must stay clean (no energy gain above 0.1 %, no penetration past its tolerance),
    // and the block's balance must put the board's push into its ground reaction: the ground
    // carries the block's weight plus the vertical part of the board's push (1 %: the f32
    // ground, the damped ringing). Measured before the soft step moved held bodies as rapier
    // did: forced implicit, the board balanced the same way but still moved at 2.2 mm/s after
    // 2 s, the implicit step pushing it away and rapier's pulling it back in turn.
    let mut explicit = FvmWorld::default();
    explicit.coupling.integrator.force = Some(IntegratorKind::Explicit);
    let [automatic, implicit] = worlds();
    for (name, world) in [automatic, implicit, ("explicit", explicit)] {
        lean_a_board_on_a_block(name, world);
    }
}

/// The board of [`a_board_leaning_on_a_soft_block_rests_and_its_push_reaches_the_ground`] in
/// `world` (integrator `name`), checked as that test says.
fn lean_a_board_on_a_block(name: &str, mut world: FvmWorld) {
    world.coupling.sleep = SleepSettings::never();
    let ground = world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    let block = world.soft_bodies.insert(coarse_block(4, 0.0));
    let (w, l, tilt) = (0.005f32, 0.04f32, 20f32.to_radians());
    let (sin, cos) = tilt.sin_cos();
    // Turned by `tilt` about z, the lowest corner (local (−w, −l)) on the ground and the top
    // corner (−w, l) 0.5 mm from the face x = 0.1.
    let centre = Vec3::new(0.1005 + w * cos + l * sin, w * sin + l * cos, 0.0);
    let (board, _) = world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(centre)
            .rotation(Vec3::new(0.0, 0.0, tilt)),
        ColliderBuilder::cuboid(w, l, 0.02)
            .density(0.05 / (8.0 * w * l * 0.02))
            .friction(0.8),
    );
    let mut audit = rapier_fvm::coupling::Audit::default();
    audit.restart_world(&world);
    let mut flagged = Vec::new();
    let mut tilt_at_one_second = 0.0;
    for frame in 0..120 {
        let results = world.step();
        if !audit.check_world(&world, &results).is_clean() {
            flagged.push(frame);
        }
        for (_, outcome) in results {
            outcome.unwrap_or_else(|error| panic!("{name}, frame {frame}: {error}"));
        }
        if frame == 59 {
            tilt_at_one_second = world.physics.bodies[board].rotation().to_scaled_axis().z;
        }
    }
    let rigid = &world.physics.bodies[board];
    let (turned, speed) = (rigid.rotation().to_scaled_axis().z, rigid.linvel().length());
    let (push, _) = world.load_on(block, board);
    let block_weight = 9.81 * world.soft_bodies[block].total_mass();
    let reaction: f64 = (world.collider_loads().iter())
        .filter(|load| load.collider == ground)
        .map(|load| -load.force.y)
        .sum();
    println!(
        "{name}: push on the board {push:?} N; ground reaction {reaction:.5} N for {:.5}; \
         tilt {turned:.5} rad (at 1 s {tilt_at_one_second:.5}); speed {speed:.2e} m/s; \
         flagged frames {flagged:?}",
        block_weight + push.y
    );
    assert!(flagged.is_empty(), "{name}: {flagged:?}");
    assert!(push.x > 0.0, "{name}");
    assert!(
        (reaction - (block_weight + push.y)).abs() < 0.01 * block_weight,
        "{name}"
    );
    assert!(speed < 1e-3, "{name}: {speed} m/s");
    assert!((turned - tilt_at_one_second).abs() < 1e-4, "{name}");
}
