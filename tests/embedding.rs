//! Fine meshes embedded in a coarse simulation mesh ([`rapier_fvm::embedding`]): they follow
//! their elements exactly, collide with rapier colliders through their own surface, and the
//! impulses reach the simulation nodes with momentum exchanged exactly.

mod common;

use rapier_fvm::element::ElementShape;
use rapier_fvm::embedding::Embedding;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::integrate::IntegratorKind;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

fn rubber() -> Material {
    Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap()
}

/// Every element kind carrying a fine mesh: linear tetrahedra, curved quadratic tetrahedra (a
/// sphere, whose fine surface pokes out between the coarse curved faces) and a hexahedral cage.
fn carriers() -> Vec<(&'static str, DeformableBodyBuilder, TetMesh)> {
    let half = DVec3::new(0.2, 0.1, 0.1);
    vec![
        (
            "linear tetrahedra",
            DeformableBodyBuilder::new(mesh::cuboid(half, [2, 1, 1]).unwrap(), rubber()),
            mesh::cuboid(half, [12, 6, 6]).unwrap(),
        ),
        (
            "curved quadratic tetrahedra",
            DeformableBodyBuilder::quadratic(
                mesh::QuadraticTetMesh::sphere(0.1, 2).unwrap(),
                rubber(),
            ),
            mesh::sphere(0.1, 8).unwrap(),
        ),
        (
            "quadratic hexahedra",
            DeformableBodyBuilder::quadratic_hex(
                mesh::QuadraticHexMesh::cuboid(half, [2, 1, 1]).unwrap(),
                rubber(),
            ),
            mesh::cuboid(half, [12, 6, 6]).unwrap(),
        ),
    ]
}

/// At rest and under any homogeneous deformation of the nodes, each fine vertex is where the
/// deformation puts its rest position: every element kind reproduces linear fields exactly. The
/// weights sum to one. Tolerance 1e-12 m (round-off on 0.1 m; the Newton inversion of the curved
/// map converges to round-off).
#[test]
fn embedded_vertices_follow_their_elements_exactly() {
    let f = common::finite_homogeneous_deformation();
    for (name, builder, fine) in carriers() {
        let rest: Vec<DVec3> = fine.positions().to_vec();
        let mut body = builder
            .embedded(fine)
            .translation(DVec3::new(1.0, 2.0, 3.0))
            .build()
            .unwrap();
        let embedding: &Embedding = body.embedding().unwrap();
        for v in 0..rest.len() as u32 {
            let (_, weights) = embedding.stencil(v);
            assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{name}");
        }
        let at_rest = body.embedded_positions().unwrap();
        let worst_rest = rest
            .iter()
            .zip(&at_rest)
            .map(|(p, x)| (*p + DVec3::new(1.0, 2.0, 3.0)).distance(*x))
            .fold(0.0, f64::max);
        let node_rest = body.mesh().positions().to_vec();
        for (x, p) in body.positions_mut().iter_mut().zip(&node_rest) {
            *x = f * *p;
        }
        let deformed = body.embedded_positions().unwrap();
        let worst_deformed = rest
            .iter()
            .zip(&deformed)
            .map(|(p, x)| (f * *p).distance(*x))
            .fold(0.0, f64::max);
        println!("{name}: worst {worst_rest:.1e} m at rest, {worst_deformed:.1e} m deformed");
        assert!(worst_rest < 1e-12 && worst_deformed < 1e-12, "{name}");
    }
}

/// A fine vertex no element carries is refused, naming the vertex.
#[test]
fn a_vertex_outside_the_simulation_mesh_is_refused() {
    let coarse = mesh::cuboid(DVec3::splat(0.1), [1, 1, 1]).unwrap();
    let mut positions = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2])
        .unwrap()
        .positions()
        .to_vec();
    let tets = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2])
        .unwrap()
        .tets()
        .to_vec();
    positions[26] = DVec3::splat(0.5);
    let fine = TetMesh::new(positions, tets).unwrap();
    let error = DeformableBodyBuilder::new(coarse, rubber())
        .embedded(fine)
        .build()
        .unwrap_err();
    assert!(
        matches!(error, Error::OutsideSimulationMesh { vertex: 26, .. }),
        "{error}"
    );
}

/// A one-cell cage of quadratic hexahedra carrying a fine cube of 6 x 6 x 6 cells rests on a
/// rapier ground through the fine surface, with the automatic, the explicit and the implicit
/// integrator: the contacts are on the fine vertices (the 49 of its bottom face, where the cage
/// has 9 nodes), the ground's reaction equals the weight within 1 % (the coupling tests' bound),
/// and no fine vertex is below the ground by more than 1 mm (the contact margin's scale).
#[test]
fn a_cage_carrying_a_fine_mesh_rests_on_a_rapier_ground() {
    for force in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let mut world = FvmWorld::default();
        world.coupling.integrator.force = force;
        let ground = world
            .physics
            .insert_collider(ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)), None);
        let material = rubber();
        let half = DVec3::splat(0.1);
        let cube = DeformableBodyBuilder::quadratic_hex(
            mesh::QuadraticHexMesh::cuboid(half, [1, 1, 1]).unwrap(),
            material,
        )
        .embedded(mesh::cuboid(half, [6, 6, 6]).unwrap())
        .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
        .translation(DVec3::new(0.0, 0.12, 0.0))
        .build()
        .unwrap();
        assert_eq!(cube.element_shape(), ElementShape::Hexahedron);
        let cube = world.soft_bodies.insert(cube);
        let reaction = common::settled_reaction(&mut world, cube, ground);
        let body = &world.soft_bodies[cube];
        let contacts = world.coupling.contacts(cube);
        let touching = contacts
            .iter()
            .filter(|c| matches!(c.at, BodyPoint::Embedded(_)))
            .count();
        assert_eq!(touching, contacts.len(), "contacts act on the fine mesh");
        let weight = body.total_mass() * 9.81;
        let lowest = body
            .embedded_positions()
            .unwrap()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        println!(
            "cage on the ground ({force:?}): {touching} fine contacts, reaction {reaction:.4} N \
             vs weight {weight:.4} N, lowest fine vertex {:.3} mm",
            lowest * 1e3
        );
        assert_eq!(touching, 49);
        assert!((reaction / weight - 1.0).abs() < 0.01);
        assert!(lowest > -1e-3);
    }
}

/// Zero gravity: a curved quadratic sphere carrying a fine sphere, at 1 m/s, hits a free rigid
/// ball off-centre with friction. The impulses on the fine surface are shared among the
/// simulation nodes by the embedding's weights, which sum to one, so the total linear and
/// angular momentum of the two bodies is kept. Tolerance 1e-6 of the initial momentum, as for
/// the linear cube in `tests/coupling.rs`: exact in f64 on the soft side, rapier keeps rigid
/// velocities in f32.
#[test]
fn an_embedded_surface_hitting_a_free_ball_conserves_momentum() {
    let radius = 0.05f32;
    let (mut world, ball) = common::ball_without_gravity(
        None,
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.2, 0.03, 0.0)),
        (0.5, radius),
    );
    let material = rubber();
    let mut sphere = DeformableBodyBuilder::quadratic(
        mesh::QuadraticTetMesh::sphere(0.06, 2).unwrap(),
        material,
    )
    .embedded(mesh::sphere(0.06, 8).unwrap())
    .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
    .build()
    .unwrap();
    for v in sphere.velocities_mut() {
        *v = DVec3::X;
    }
    let soft = world.soft_bodies.insert(sphere);
    let momenta = |world: &FvmWorld| common::soft_and_ball_momenta(world, soft, ball, radius);
    let (linear0, angular0) = momenta(&world);
    let mut fine_contacts = 0;
    for _ in 0..30 {
        for (handle, outcome) in world.step() {
            outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
        }
        fine_contacts += world
            .coupling
            .contacts(soft)
            .iter()
            .filter(|c| matches!(c.at, BodyPoint::Embedded(_)))
            .count();
    }
    let (linear, angular) = momenta(&world);
    let rigid = &world.physics.bodies[ball];
    println!(
        "ball: v = {:?} m/s, ω = {:?} rad/s; Δp = {:.2e}, ΔL = {:.2e} (of {:.3} kg m/s); \
         {fine_contacts} fine contacts over the frames",
        rigid.linvel(),
        rigid.angvel(),
        (linear - linear0).length(),
        (angular - angular0).length(),
        linear0.length()
    );
    assert!(fine_contacts > 0, "the contacts were on the fine surface");
    assert!(rigid.linvel().x > 0.3, "the ball was hit");
    assert!(rigid.angvel().length() > 0.1, "the ball was set spinning");
    let scale = linear0.length();
    assert!((linear - linear0).length() <= 1e-6 * scale);
    assert!((angular - angular0).length() <= 1e-6 * scale * 0.1);
}
