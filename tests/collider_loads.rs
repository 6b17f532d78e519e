//! The loads a deformable body exerts on colliders, read per frame from the coupling: on the
//! fixed ground (a collider without a rigid body) they balance the weight of what rests on it,
//! and on a rigid body's collider they equal the load the rigid body is handed.

use rapier_fvm::prelude::*;
use rapier3d::prelude::*;

/// A 0.2 m rubber cube (E = 1e6 Pa, 1000 kg/m³) resting on a half-space ground, with a 1 kg box
/// on it; returns the world after `frames` frames, and the handles.
fn settled(
    frames: usize,
) -> Result<(FvmWorld, ColliderHandle, ColliderHandle, RigidBodyHandle), Error> {
    let mut world = FvmWorld::default();
    let ground = world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.8),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [3; 3])?, rubber)
        .damping(RayleighDamping::stiffness_proportional(
            5e-3,
            rubber.lame(),
        )?)
        .translation(DVec3::new(0.3, 0.1, -0.2))
        .build()?;
    world.soft_bodies.insert(cube);
    let (carried, collider) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.3, 0.25, -0.2)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05).density(1000.0),
    );
    for _ in 0..frames {
        for (_, outcome) in world.step() {
            outcome?;
        }
    }
    Ok((world, ground, collider, carried))
}

#[test]
fn the_ground_collider_carries_the_weight_of_the_cube_and_the_box() -> Result<(), Error> {
    let (world, ground, _, _) = settled(180)?;
    let load = world
        .collider_loads()
        .iter()
        .find(|load| load.collider == ground)
        .expect("the cube touches the ground");
    // Cube 8 kg and box 1 kg, at rest after 3 s: the frame-mean reaction is their weight within
    // 1 % (the settled support measured in tests/coupling.rs is within 0.01 %).
    let weight = 9.0 * 9.81;
    assert!(
        (load.force.y - -weight).abs() < 0.01 * weight,
        "ground load {} N for a weight of {weight} N",
        load.force
    );
    assert!(load.force.x.abs() + load.force.z.abs() < 0.01 * weight);
    // Its torque about the world origin is that of the weight acting under the centre of mass,
    // at (0.3, 0, -0.2) m: τ = r × F, within 1 % of |r| |F|.
    let expected = DVec3::new(0.3, 0.0, -0.2).cross(load.force);
    let scale = 0.36f64.sqrt() * weight;
    assert!(
        (load.torque - expected).length() < 0.01 * scale,
        "torque {} N m, expected {expected} N m",
        load.torque
    );
    Ok(())
}

#[test]
fn a_rigid_body_collider_load_equals_the_rigid_load() -> Result<(), Error> {
    let (world, _, collider, carried) = settled(60)?;
    let on_collider = world
        .collider_loads()
        .iter()
        .find(|load| load.collider == collider)
        .expect("the box rests on the cube");
    let on_body = world
        .rigid_loads()
        .iter()
        .find(|load| load.rigid_body == carried)
        .expect("the box rests on the cube");
    // The same impulses summed two ways: equal to round-off (1e-9 of the load).
    let tolerance = 1e-9 * on_body.force.length();
    assert!(
        (on_collider.force - on_body.force).length() <= tolerance,
        "{} N on the collider, {} N on the body",
        on_collider.force,
        on_body.force
    );
    // The box weighs 9.81 N and rests: the cube holds it up.
    assert!(on_body.force.y > 0.5 * 9.81, "{}", on_body.force);
    Ok(())
}
