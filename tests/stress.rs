//! Per-tetrahedron Cauchy stress against closed forms: uniaxial stretch with free lateral faces,
//! rigid rotation, and inverted elements.

use rapier_fvm::prelude::*;

const E: f64 = 2e6;
const NU: f64 = 0.3;

fn cube(model: MaterialModel) -> DeformableBody {
    let material = Material::new(model, E, NU, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::splat(0.05), [3, 3, 3]).unwrap();
    DeformableBodyBuilder::new(mesh, material).build().unwrap()
}

/// Moves every node to `map(rest position)`.
fn deform(body: &mut DeformableBody, map: impl Fn(DVec3) -> DVec3) {
    let rest = body.mesh().positions().to_vec();
    for (x, p) in body.positions_mut().iter_mut().zip(rest) {
        *x = map(p);
    }
}

/// The analytic uniaxial field `x = (1 + ε) p_x, (1 - ν ε) p_y, (1 - ν ε) p_z` makes the linear
/// model's small-strain stress exactly `E ε` along x and zero elsewhere (free lateral faces). The
/// Cauchy stress `σ = P Fᵀ / det F` of that `P` is `E ε / (1 - ν ε)²` along x: the closed form is
/// checked to 1e-9 relative (round-off of `F - I`, about 1e-16 / ε = 1e-12), and it differs from
/// the engineering `E ε` by the change of area, `2 ν ε` relative.
#[test]
fn uniaxial_stretch_of_a_linear_cube_gives_e_epsilon() {
    for strain in [1e-4, -2e-3] {
        let mut body = cube(MaterialModel::Linear);
        let lateral = 1.0 - NU * strain;
        deform(&mut body, |p| {
            p * DVec3::new(1.0 + strain, lateral, lateral)
        });
        let axial = E * strain;
        let expected = axial / (lateral * lateral);
        for sigma in body.cauchy_stresses() {
            assert!(
                (sigma.x_axis.x - expected).abs() <= 1e-9 * axial.abs(),
                "{sigma}"
            );
            assert!((sigma.x_axis.x - axial).abs() <= 2.1 * NU * strain.abs() * axial.abs());
            let others = sigma - DMat3::from_diagonal(DVec3::new(sigma.x_axis.x, 0.0, 0.0));
            assert!(
                others
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|c| *c <= 1e-9 * axial.abs())
            );
            let von_mises = DeformableBody::von_mises(&sigma);
            assert!((von_mises - sigma.x_axis.x.abs()).abs() <= 1e-9 * axial.abs());
        }
    }
}

/// A rigid rotation by 1 rad about a skew axis plus a translation leaves the rotation-invariant
/// models stress-free: to 1e-9 E, the round-off of the polar decomposition and of `F`.
#[test]
fn rigid_rotation_produces_no_stress() {
    let rotation = DQuat::from_scaled_axis(DVec3::new(0.6, -0.3, 0.74));
    for model in [
        MaterialModel::StVenantKirchhoff,
        MaterialModel::Corotated,
        MaterialModel::StableNeoHookean,
    ] {
        let mut body = cube(model);
        deform(&mut body, |p| rotation * p + DVec3::new(0.3, 1.0, -2.0));
        for sigma in body.cauchy_stresses() {
            let largest = sigma.abs().to_cols_array().into_iter().fold(0.0, f64::max);
            assert!(largest <= 1e-9 * E, "{model:?}: {sigma}");
        }
    }
}

/// Mirroring the body inverts every element; the stresses stay finite (the Kirchhoff stress is
/// returned for `det F <= 0`).
#[test]
fn inverted_elements_give_finite_stress() {
    for model in [MaterialModel::StableNeoHookean, MaterialModel::Corotated] {
        let mut body = cube(model);
        deform(&mut body, |p| p * DVec3::new(-1.0, 1.0, 1.0));
        assert_eq!(body.inverted_tet_count(), body.mesh().tet_count());
        let stresses = body.cauchy_stresses();
        assert!(stresses.iter().all(|s| s.is_finite()));
        assert!(
            stresses
                .iter()
                .all(|s| DeformableBody::von_mises(s).is_finite())
        );
    }
}
