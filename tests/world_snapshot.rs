//! A copy of an `FvmWorld` taken mid-run (`clone`, the save and restore of resets and rollouts)
//! steps on exactly as the original does: bit for bit (tolerance 0), under the automatic and the
//! forced implicit integrator (whose kept factorization the copy carries too), with contacts,
//! a dynamic rigid body on a soft one and an attachment.

mod common;

use common::{assert_identical, run};
use rapier_fvm::prelude::*;
use rapier3d::prelude::*;

/// A soft block on the ground with a 1 kg box dropped on it, and a soft rod glued to a fixed
/// bar, stepped by `integrator` (`None`: automatic); returns the world and the bar.
fn scene(integrator: Option<IntegratorKind>) -> Result<(FvmWorld, RigidBodyHandle), Error> {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.8),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let damping = RayleighDamping::stiffness_proportional(2e-3, rubber.lame())?;
    let block = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [3; 3])?, rubber)
        .damping(damping)
        .translation(DVec3::new(0.0, 0.1, 0.0))
        .build()?;
    world.soft_bodies.insert(block);
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.02, 0.27, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05).density(1000.0),
    );
    let (bar, _) = world.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(1.0, 1.0, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.01, 0.01).sensor(true),
    );
    let rod_mesh = mesh::cuboid(DVec3::new(0.02, 0.1, 0.02), [1, 4, 1])?;
    let top = rod_mesh.nodes_where(|p| p.y >= 0.1 - 1e-9);
    let rod = DeformableBodyBuilder::new(rod_mesh, rubber)
        .damping(damping)
        .translation(DVec3::new(1.05, 0.9, 0.0))
        .build()?;
    let rod = world.soft_bodies.insert(rod);
    world.attach(rod, top, bar)?;
    Ok((world, bar))
}

#[test]
fn a_copied_world_steps_on_bit_identically() -> Result<(), Error> {
    for integrator in [None, Some(IntegratorKind::Implicit)] {
        let (mut original, bar) = scene(integrator)?;
        run(&mut original, 20)?;
        let mut copy = original.clone();
        run(&mut original, 25)?;
        run(&mut copy, 25)?;
        assert_identical(&original, &copy);
        // The copies followed the attachment: the rod hangs from the fixed bar with its weight
        // (0.32 kg, 3.14 N).
        let rod_weight = 1000.0 * 0.04 * 0.2 * 0.04 * 9.81;
        let pull = original
            .rigid_loads()
            .iter()
            .filter(|load| load.rigid_body == bar)
            .map(|load| load.force.y)
            .sum::<f64>();
        assert!(pull < -0.5 * rod_weight, "{:?}", original.rigid_loads());
    }
    Ok(())
}
