//! Inverted elements: a body crushed flat, one with a node pushed through the opposite face, and a
//! tetrahedron turned inside out recover positive volume with the inversion-robust models
//! (stable Neo-Hookean, corotated with the sign-fixed rotation, St. Venant–Kirchhoff with the
//! continued principal strains below its compression threshold). Inverted elements are counted in
//! every step report.

mod common;

use common::Lcg;
use rapier_fvm::prelude::*;

const ROBUST: [MaterialModel; 3] = [
    MaterialModel::StableNeoHookean,
    MaterialModel::Corotated,
    MaterialModel::StVenantKirchhoff,
];

fn soft_cube(model: MaterialModel) -> DeformableBody {
    let material = Material::new(model, 1e5, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::splat(0.1), [4, 4, 4]).unwrap();
    DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
        .build()
        .unwrap()
}

/// Runs backward Euler frames of 1/60 s without gravity; returns the inverted count per frame.
fn recover(body: &mut DeformableBody, frames: usize) -> Vec<usize> {
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    (0..frames)
        .map(|_| {
            common::implicit_frame_without_gravity(body, &mut constraints, &mut workspace)
                .inverted_elements
        })
        .collect()
}

#[test]
fn a_cube_crushed_flat_recovers() {
    for model in ROBUST {
        let mut body = soft_cube(model);
        let mut rng = Lcg(2);
        for x in body.positions_mut() {
            x.z = 1e-4 * rng.next();
        }
        let crushed = body.inverted_tet_count();
        let history = recover(&mut body, 120);
        let volume = body.deformed_volume() / body.mesh().volume();
        println!(
            "{model:?}: {crushed} of {} tets inverted after crushing; {:?} over the first frames; volume now {volume:.4} of rest",
            body.mesh().tet_count(),
            &history[..6]
        );
        assert!(crushed > 0);
        assert_eq!(
            *history.last().unwrap(),
            0,
            "{model:?} still has inverted elements"
        );
        assert!((volume - 1.0).abs() < 0.01, "{model:?}: volume {volume}");
    }
}

#[test]
fn a_node_pushed_through_its_opposite_face_recovers() {
    for model in ROBUST {
        let mut body = soft_cube(model);
        // The centre node, pushed 1.5 cells along +x: through the faces of its neighbours.
        let centre = body.mesh().nearest_node(DVec3::ZERO) as usize;
        body.positions_mut()[centre].x += 0.075;
        let pushed = body.inverted_tet_count();
        let history = recover(&mut body, 60);
        println!(
            "{model:?}: {pushed} inverted after the push, {} at the end",
            history.last().unwrap()
        );
        assert!(pushed > 0);
        assert_eq!(*history.last().unwrap(), 0);
        // The shape returns; the body as a whole keeps the centre of mass the push moved.
        let displacement = |n: usize| body.positions()[n] - body.mesh().positions()[n];
        let mean =
            (0..body.node_count()).map(displacement).sum::<DVec3>() / body.node_count() as f64;
        let misplaced = (displacement(centre) - mean).length();
        println!("{model:?}: centre node {misplaced:.2e} m from its place in the recovered shape");
        assert!(misplaced < 1e-3);
    }
}

#[test]
fn a_tetrahedron_turned_inside_out_recovers_with_the_explicit_integrator_too() {
    for model in ROBUST {
        let material = Material::new(model, 1e5, 0.3, 1000.0).unwrap();
        let mesh = TetMesh::new(
            vec![DVec3::ZERO, DVec3::X * 0.1, DVec3::Y * 0.1, DVec3::Z * 0.1],
            vec![[0, 1, 2, 3]],
        )
        .unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, material)
            .damping(RayleighDamping::stiffness_proportional(1e-3, material.lame()).unwrap())
            .build()
            .unwrap();
        // Node 3 mirrored through the opposite face: volume -V.
        body.positions_mut()[3].z = -0.1;
        assert_eq!(body.inverted_tet_count(), 1);
        let mut last = 1;
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for _ in 0..120 {
            last = SymplecticEuler::default()
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    DVec3::ZERO,
                )
                .unwrap()
                .inverted_elements;
        }
        let volume = body.deformed_volume() / body.mesh().volume();
        println!("{model:?}: single tet volume {volume:.4} of rest after 2 s");
        assert_eq!(last, 0);
        assert!((volume - 1.0).abs() < 0.01);
    }
}
