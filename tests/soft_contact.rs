//! Self-contact: a body made of two separate cubes lands on itself only with self-contact on,
//! and its two halves colliding in zero gravity conserve the body's momentum.

use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, SharedShape, Vector};

const SIDE: f64 = 0.1;

fn rubber(young: f64) -> Material {
    Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap()
}

fn world_on_ground(friction: f32) -> (FvmWorld, ColliderHandle) {
    let mut world = FvmWorld::default();
    let ground = world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(friction),
        None,
    );
    (world, ground)
}

fn step(world: &mut FvmWorld) {
    for (handle, outcome) in world.step() {
        outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
    }
}

/// The mean height (m) of the body's nodes whose rest height is `rest_y` (m, in the mesh's own
/// frame).
fn mean_height_of_layer(body: &SoftBody, rest_y: f64) -> f64 {
    let layer = body.mesh().nodes_where(|p| (p.y - rest_y).abs() < 1e-9);
    layer
        .iter()
        .map(|&n| body.positions()[n as usize].y)
        .sum::<f64>()
        / layer.len() as f64
}

/// Two cubes of side `SIDE`, 4 cells a side, one on top of the other with a gap `gap` (m), as one
/// mesh; the lower one's centre at the origin.
fn two_cubes_one_mesh(gap: f64) -> TetMesh {
    let cube = mesh::cuboid(DVec3::splat(SIDE / 2.0), [4; 3]).unwrap();
    let offset = cube.node_count() as u32;
    let mut positions = cube.positions().to_vec();
    positions.extend(
        cube.positions()
            .iter()
            .map(|p| *p + DVec3::new(0.0, SIDE + gap, 0.0)),
    );
    let mut tets = cube.tets().to_vec();
    tets.extend(cube.tets().iter().map(|t| t.map(|n| n + offset)));
    TetMesh::new(positions, tets).unwrap()
}

#[test]
fn a_body_of_two_separate_cubes_lands_on_itself_only_with_self_contact() {
    // Two 10 cm rubber cubes (E = 1e5 Pa, ν = 0.3, 1000 kg/m³) 2 mm apart, one above the other,
    // as a single body on the ground (friction 0.5 everywhere), settled for 2 s at the default
    // 60 Hz frames. With self-contact the upper cube rests on the lower one: no more overlap than
    // the contact margin plus 1 mm (the bound for a drop), and the ground carries the
    // whole weight within 1 % (the support bound). Without it the upper cube falls
    // through to the ground.
    let young = 1e5;
    let material = rubber(young);
    for self_contact in [true, false] {
        let (mut world, ground) = world_on_ground(0.5);
        let body = SoftBodyBuilder::new(two_cubes_one_mesh(2e-3), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .translation(DVec3::new(0.0, SIDE / 2.0, 0.0))
            .friction(0.5)
            .self_contact(self_contact)
            .build()
            .unwrap();
        let handle = world.soft_bodies.insert(body);
        let frame = f64::from(world.physics.integration_parameters.dt);
        let frames = (2.0 / frame).round() as usize;
        let (mut reaction, mut averaged) = (0.0, 0);
        for index in 0..frames {
            step(&mut world);
            if index >= frames - 60 {
                let substep = frame / f64::from(world.coupling_substeps);
                let (force, _) = world.soft_bodies[handle]
                    .contact_force_on(ground, substep)
                    .unwrap();
                reaction -= force.y;
                averaged += 1;
            }
        }
        let reaction = reaction / f64::from(averaged);
        let b = &world.soft_bodies[handle];
        let half = b.node_count() / 2;
        let upper_lowest = b.positions()[half..]
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        let lower_top = mean_height_of_layer(b, SIDE / 2.0);
        let weight = 2.0 * 9.81 * 1000.0 * SIDE.powi(3);
        println!(
            "self-contact {self_contact}: upper cube's lowest node {:.3} mm, lower cube's top \
             {:.3} mm, ground reaction {reaction:.4} N vs {weight:.4} N",
            upper_lowest * 1e3,
            lower_top * 1e3
        );
        if self_contact {
            assert!(lower_top - upper_lowest < world.contact.margin + 1e-3);
            assert!((reaction / weight - 1.0).abs() < 0.01);
        } else {
            assert!(upper_lowest < lower_top - SIDE / 2.0);
        }
    }
}

#[test]
fn the_halves_of_a_body_colliding_in_zero_gravity_conserve_its_momentum() {
    // The two cubes of the test above, side by side along x, 2 mm apart, the left one moving at
    // 1 m/s toward the right one and 0.3 m/s sideways (an off-centre impact, so that angular
    // momentum is exchanged too), in zero gravity for 0.5 s. Self-contact impulses act between
    // nodes of the same body and sum to zero by construction (the barycentric weights sum to
    // one): the body's linear momentum is conserved to round-off; bound 1e-6 relative, the
    // issue's for momentum exchange.
    // The angular momentum changes by the impulses' lever-arm mismatch: a node acts on its
    // contact point while the two are within the contact margin of each other, so the change is
    // bounded by the margin times the impulse exchanged (the right cube's final momentum).
    let mut world = FvmWorld::default();
    world.physics.gravity = Vector::ZERO;
    let cube = mesh::cuboid(DVec3::splat(SIDE / 2.0), [4; 3]).unwrap();
    let offset = cube.node_count() as u32;
    let mut positions = cube.positions().to_vec();
    positions.extend(
        cube.positions()
            .iter()
            .map(|p| *p + DVec3::new(SIDE + 2e-3, 0.03, 0.0)),
    );
    let mut tets = cube.tets().to_vec();
    tets.extend(cube.tets().iter().map(|t| t.map(|n| n + offset)));
    let material = rubber(1e5);
    let handle = world.soft_bodies.insert(
        SoftBodyBuilder::new(TetMesh::new(positions, tets).unwrap(), material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .self_contact(true)
            .build()
            .unwrap(),
    );
    let left = offset as usize;
    for v in &mut world.soft_bodies[handle].velocities_mut()[..left] {
        *v = DVec3::new(1.0, 0.0, 0.3);
    }
    let momenta = |body: &SoftBody| {
        body.positions()
            .iter()
            .zip(body.velocities())
            .zip(body.masses())
            .fold((DVec3::ZERO, DVec3::ZERO), |(p, l), ((x, v), m)| {
                (p + *v * *m, l + x.cross(*v * *m))
            })
    };
    let (p0, l0) = momenta(&world.soft_bodies[handle]);
    let mut touched = false;
    for _ in 0..30 {
        step(&mut world);
        touched |= !world.soft_bodies[handle].contacts().is_empty();
    }
    let body = &world.soft_bodies[handle];
    let (p1, l1) = momenta(body);
    let right_mass: f64 = body.masses()[left..].iter().sum();
    let right_speed = body.velocities()[left..]
        .iter()
        .zip(&body.masses()[left..])
        .map(|(v, m)| v.x * m)
        .sum::<f64>()
        / right_mass;
    println!(
        "linear momentum change {:.3e} of {:.3} kg m/s; angular {:.3e} kg m²/s, bound {:.3e}; \
         right cube's speed {:.3} m/s",
        (p1 - p0).length(),
        p0.length(),
        (l1 - l0).length(),
        world.contact.margin * right_mass * right_speed,
        right_speed
    );
    assert!(touched, "the halves never met");
    // The impact happened: the right cube was set moving.
    assert!(right_speed > 0.1);
    assert!((p1 - p0).length() <= 1e-6 * p0.length());
    assert!((l1 - l0).length() <= world.contact.margin * right_mass * right_speed);
}
