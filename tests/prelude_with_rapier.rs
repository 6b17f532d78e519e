//! A rapier user's reflex glob imports, `use rapier3d::prelude::*; use rapier_fvm::prelude::*;`,
//! compile without ambiguity or warning, and build and step a world of a ground, a rigid box and
//! a soft cube.
#![deny(warnings)]

use rapier_fvm::prelude::*;
use rapier3d::prelude::*;

/// Half-extent of the soft cube (m), and its height above the ground when released (m).
const CUBE_HALF: f64 = 0.1;
/// Half-extent of the rigid box (m).
const BOX_HALF: f32 = 0.05;

#[test]
fn both_preludes_glob_imported_build_and_step_a_rigid_box_on_a_soft_cube() -> Result<(), Error> {
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let cube =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(CUBE_HALF), [3, 3, 3])?, rubber)
            .translation(DVec3::new(0.0, CUBE_HALF, 0.0))
            .damping(RayleighDamping::stiffness_proportional(
                1e-3,
                rubber.lame(),
            )?)
            .build()?;
    let cube: DeformableBodyHandle = world.soft_bodies.insert(cube);
    let top = 2.0 * CUBE_HALF as f32;
    let (rigid_box, _collider) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, top + BOX_HALF + 0.02, 0.0)),
        ColliderBuilder::cuboid(BOX_HALF, BOX_HALF, BOX_HALF),
    );
    for _frame in 0..60 {
        for (_handle, outcome) in world.step() {
            outcome?;
        }
    }
    // After a second the box rests on the cube: its weight (about 10 N) on 0.04 m² of a 1 MPa
    // cube 0.2 m tall sinks it by about 0.05 mm, so its centre lies within 2 mm of the cube's top
    // plus its half-extent, and it has nearly stopped (1 cm/s).
    let rigid = &world.physics.bodies[rigid_box];
    let resting_height = top + BOX_HALF;
    assert!(
        (rigid.translation().y - resting_height).abs() < 2e-3,
        "box at {} m, resting height {resting_height} m",
        rigid.translation().y
    );
    assert!(
        rigid.linvel().length() < 1e-2,
        "box moving at {:?} m/s",
        rigid.linvel()
    );
    // The cube stays on the ground: no node more than 2 mm below it.
    let lowest = world.soft_bodies[cube]
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min);
    assert!(lowest > -2e-3, "lowest node at {lowest} m");
    Ok(())
}
