//! Patch tests: on a mesh with a distorted interior, a homogeneous deformation imposed on every
//! node leaves zero force on the interior nodes, because a constant stress field is in equilibrium
//! and the finite-volume forces reproduce it exactly. Tolerance 1e-9 of the largest boundary
//! force: the exact answer is zero and the computation loses only round-off (~1e-14).

mod common;

use common::{Lcg, MODELS};
use rapier_fvm::prelude::*;

/// A 4 x 4 x 4-cell box whose interior nodes are moved randomly by up to 30 % of a cell.
fn distorted_box() -> TetMesh {
    let half = 0.2;
    let regular = mesh::cuboid(DVec3::splat(half), [4, 4, 4]).unwrap();
    let cell = 2.0 * half / 4.0;
    let mut rng = Lcg(7);
    let positions = regular
        .positions()
        .iter()
        .map(|p| {
            let interior = p.abs().max_element() < half - 1e-9;
            if interior {
                *p + rng.vector() * (0.3 * cell)
            } else {
                *p
            }
        })
        .collect();
    TetMesh::new(positions, regular.tets().to_vec()).expect("the distortion keeps every tet valid")
}

fn is_interior(p: DVec3) -> bool {
    p.abs().max_element() < 0.2 - 1e-9
}

/// Largest interior force over largest boundary force after imposing `x = map(p)`, `v = rate(p)`.
fn interior_force_ratio(
    model: MaterialModel,
    damping: Option<RayleighDamping>,
    map: impl Fn(DVec3) -> DVec3,
    rate: impl Fn(DVec3) -> DVec3,
) -> f64 {
    let mesh = distorted_box();
    let material = Material::new(model, 1e7, 0.3, 1000.0).unwrap();
    let mut builder = DeformableBodyBuilder::new(mesh.clone(), material);
    if let Some(damping) = damping {
        builder = builder.damping(damping);
    }
    let forces = common::forces_under(&mut builder.build().unwrap(), map, rate);
    let (mut interior, mut boundary) = (0.0f64, 0.0f64);
    for (p, f) in mesh.positions().iter().zip(&forces) {
        if is_interior(*p) {
            interior = interior.max(f.length());
        } else {
            boundary = boundary.max(f.length());
        }
    }
    assert!(
        boundary > 0.0,
        "the imposed deformation must load the boundary"
    );
    interior / boundary
}

#[test]
fn linear_patch_test_small_affine_displacement() {
    // u = A p + b with a general small A (stretch, shear and a small rotation).
    let a = DMat3::from_cols(
        DVec3::new(1.0e-3, 0.4e-3, -0.2e-3),
        DVec3::new(-0.3e-3, -0.5e-3, 0.7e-3),
        DVec3::new(0.6e-3, 0.1e-3, 0.8e-3),
    );
    let b = DVec3::new(0.01, -0.02, 0.03);
    let ratio = interior_force_ratio(
        MaterialModel::Linear,
        None,
        |p| p + a * p + b,
        |_| DVec3::ZERO,
    );
    println!("linear patch test: interior/boundary force = {ratio:.2e}");
    assert!(ratio < 1e-9);
}

#[test]
fn every_model_passes_the_patch_test_under_a_finite_homogeneous_deformation() {
    let f = common::finite_homogeneous_deformation();
    for model in MODELS {
        let ratio = interior_force_ratio(model, None, |p| f * p + DVec3::X, |_| DVec3::ZERO);
        println!("{model:?} finite patch test: interior/boundary force = {ratio:.2e}");
        assert!(ratio < 1e-9, "{model:?}: {ratio:e}");
    }
}

#[test]
fn damping_passes_the_patch_test_under_a_homogeneous_strain_rate() {
    let f = DMat3::from_cols(
        DVec3::new(1.1, 0.05, 0.0),
        DVec3::new(0.0, 0.95, 0.02),
        DVec3::new(0.03, 0.0, 1.0),
    );
    let f_dot = common::homogeneous_deformation_rate();
    let damping = RayleighDamping::new(2e4, 1e4).unwrap();
    for model in MODELS {
        let ratio = interior_force_ratio(model, Some(damping), |p| f * p, |p| f_dot * p);
        assert!(ratio < 1e-9, "{model:?}: {ratio:e}");
    }
}
