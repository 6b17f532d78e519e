//! An `FvmWorld` written mid-run (CBOR: rapier's state holds infinities, which JSON cannot carry)
//! and read back steps on exactly as the original does,
//! bit for bit (tolerance 0), under the automatic integrator and under forced implicit BDF2
//! steps (whose two-step history and kept factorization the file carries), with contacts, a
//! dynamic rigid body on a soft one, an attachment, loads (a pressure and a cable), a quadratic
//! body, an embedded mesh and a stiff brick standing in as a rigid body (written in flight,
//! landing after); a
//! file that breaks a body's rules is refused with the error a new body would get, never a panic.

mod common;

use common::{assert_identical, run};
use rapier_fvm::prelude::*;
use rapier3d::prelude::*;
use serde_json::Value;

/// A soft block on the ground with a box dropped on it, a soft rod glued to a fixed bar, and a
/// quadratic cube carrying an embedded mesh, stepped by `integrator` (`None`: automatic).
fn scene(integrator: Option<IntegratorKind>) -> Result<FvmWorld, Error> {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.coupling.integrator.implicit.scheme = ImplicitScheme::Bdf2;
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.8),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let damping = RayleighDamping::stiffness_proportional(2e-3, rubber.lame())?;
    let block_mesh = mesh::cuboid(DVec3::splat(0.1), [3; 3])?;
    let side = block_mesh.surface_triangles_where(|p| p.x >= 0.1 - 1e-9);
    // Its lower layer of cells three times as stiff and twice as dense, so that region
    // materials are in the file.
    let positions = block_mesh.positions();
    let lower: Vec<u32> = (0..block_mesh.tet_count() as u32)
        .filter(|&t| {
            let tet = block_mesh.tets()[t as usize];
            tet.iter()
                .all(|&n| positions[n as usize].y <= -0.1 / 3.0 + 1e-9)
        })
        .collect();
    assert!(!lower.is_empty());
    let hard_rubber = Material::new(MaterialModel::StableNeoHookean, 3e6, 0.3, 2000.0)?;
    let mut block = DeformableBodyBuilder::new(block_mesh, rubber)
        .region_material(lower, hard_rubber)
        .damping(damping)
        .translation(DVec3::new(0.0, 0.1, 0.0))
        .build()?;
    // A follower pressure on one side, its value changed once, so that the loads and the work
    // of their changes are in the file.
    let push = block.add_load(Load::Pressure {
        triangles: side,
        pressure: 1e3,
    })?;
    block.set_load(push, LoadValue::Scalar(2e3))?;
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
    let tendon = rod_mesh.nodes_where(|p| p.x <= -0.02 + 1e-9 && p.z <= -0.02 + 1e-9);
    let mut rod = DeformableBodyBuilder::new(rod_mesh, rubber)
        .damping(damping)
        .translation(DVec3::new(1.05, 0.9, 0.0))
        .build()?;
    rod.add_load(Load::Cable {
        path: tendon,
        tension: 0.5,
    })?;
    let rod = world.soft_bodies.insert(rod);
    world.attach(rod, top, bar)?;
    let coarse = mesh::QuadraticTetMesh::from_linear(&mesh::cuboid(DVec3::splat(0.05), [1; 3])?)?;
    let cube = DeformableBodyBuilder::quadratic(coarse, rubber)
        .damping(damping)
        .embedded(mesh::cuboid(DVec3::splat(0.05), [3; 3])?)
        .translation(DVec3::new(-0.5, 0.3, 0.0))
        .build()?;
    world.soft_bodies.insert(cube);
    let stiff = Material::new(MaterialModel::StableNeoHookean, 1e8, 0.35, 1190.0)?;
    let brick = DeformableBodyBuilder::new(
        mesh::cuboid(DVec3::new(0.06, 0.03, 0.04), [3, 2, 2])?,
        stiff,
    )
    .damping(RayleighDamping::stiffness_proportional(1e-4, stiff.lame())?)
    .translation(DVec3::new(-1.5, 0.8, 0.0))
    .linvel(DVec3::new(0.5, 0.5, 0.0))
    .angvel(DVec3::new(1.0, 3.0, 0.0))
    .rigid_stand_in(1e-3)
    .build()?;
    world.soft_bodies.insert(brick);
    Ok(world)
}

#[test]
fn a_world_read_back_steps_on_bit_identically() -> Result<(), Error> {
    for integrator in [None, Some(IntegratorKind::Implicit)] {
        let mut original = scene(integrator)?;
        run(&mut original, 20)?;
        let standing_in = (original.soft_bodies.iter())
            .filter(|(handle, _)| original.coupling.rigid_stand_in_of(*handle).is_some())
            .count();
        assert_eq!(standing_in, 1, "the brick stands in, in flight");
        let mut file = Vec::new();
        ciborium::into_writer(&original, &mut file).expect("a world serializes");
        let mut restored: FvmWorld = ciborium::from_reader(&file[..]).expect("and reads back");
        assert_identical(&original, &restored);
        run(&mut original, 25)?;
        run(&mut restored, 25)?;
        println!(
            "{integrator:?}: {} bytes of CBOR, identical after 25 more frames",
            file.len()
        );
        assert_identical(&original, &restored);
    }
    Ok(())
}

/// The JSON of the scene's first deformable body.
fn first_body(world: &Value) -> Value {
    world["soft_bodies"]["slots"][0]["body"].clone()
}

/// The error reading a world back gives after `edit` changed its first deformable body's JSON
/// (the world not stepped yet, so that JSON holds all of it).
fn refusal(edit: impl Fn(&mut Value)) -> String {
    let world = scene(None).expect("the scene builds");
    let mut json = serde_json::to_value(&world).expect("a world serializes");
    let mut body = first_body(&json);
    edit(&mut body);
    json["soft_bodies"]["slots"][0]["body"] = body;
    match serde_json::from_value::<FvmWorld>(json) {
        Ok(_) => panic!("the edited world was accepted"),
        Err(error) => error.to_string(),
    }
}

/// A change to a body's JSON.
type Edit = Box<dyn Fn(&mut Value)>;

#[test]
fn a_file_breaking_a_bodys_rules_is_refused_with_a_typed_error() {
    // Each message is the one `TetMesh::new`, `Material::new` or the builder gives a new body.
    let cases: [(&str, Edit, &str); 7] = [
        (
            "a tetrahedron naming a node the mesh lacks",
            Box::new(|b| b["mesh"]["tets"][3][1] = Value::from(100_000)),
            "node",
        ),
        (
            "a NaN rest coordinate (JSON null)",
            Box::new(|b| b["mesh"]["positions"][5][0] = Value::Null),
            "",
        ),
        (
            "a negative density",
            Box::new(|b| b["material"]["density"] = Value::from(-1000.0)),
            "density",
        ),
        (
            "a state of the wrong length",
            Box::new(|b| {
                b["velocities"]
                    .as_array_mut()
                    .expect("velocities are a list")
                    .pop();
            }),
            "63 values were given for a body of 64 nodes",
        ),
        (
            "a pinned node beyond the mesh",
            Box::new(|b| b["pinned"] = Value::from(vec![1_000_000])),
            "node",
        ),
        (
            "a region material on an element beyond the mesh",
            Box::new(|b| b["region_materials"][0][0][0] = Value::from(1_000_000)),
            "element 1000000 does not exist: the body has 135 elements",
        ),
        (
            "a region material of another Poisson's ratio",
            Box::new(|b| {
                b["region_materials"][0][1]["elasticity"]["poisson_ratio"] = Value::from(0.4)
            }),
            "a region's material must have its body's Poisson's ratio",
        ),
    ];
    for (what, edit, expected) in cases {
        let message = refusal(edit);
        println!("{what}: {message}");
        assert!(message.contains(expected), "{what}: {message}");
    }
}

#[test]
fn a_set_whose_count_disagrees_with_its_bodies_is_refused() {
    let world = scene(None).expect("the scene builds");
    let mut json = serde_json::to_value(&world).expect("a world serializes");
    json["soft_bodies"]["len"] = Value::from(7);
    let error = serde_json::from_value::<FvmWorld>(json)
        .err()
        .expect("refused");
    println!("{error}");
    assert!(error.to_string().contains("body count"));
}
