//! Material constants: Lamé parameters and the rejection of unphysical values.

use rapier_fvm::prelude::*;

#[test]
fn lame_parameters_follow_the_textbook_formulas() {
    let (e, nu) = (2.1e11, 0.29);
    let lame = LameParameters::from(YoungPoisson::new(e, nu).unwrap());
    assert!((lame.lambda - e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))).abs() < 1e-3);
    assert!((lame.mu - e / (2.0 * (1.0 + nu))).abs() < 1e-3);
    // Negative Poisson's ratio gives a negative λ but a positive bulk modulus λ + 2μ/3.
    let auxetic = LameParameters::from(YoungPoisson::new(1e6, -0.5).unwrap());
    assert!(auxetic.lambda < 0.0 && auxetic.lambda + 2.0 * auxetic.mu / 3.0 > 0.0);
}

#[test]
fn unphysical_constants_are_typed_errors() {
    let bad = [
        (0.0, 0.3, 1000.0, "young_modulus"),
        (-1e6, 0.3, 1000.0, "young_modulus"),
        (f64::NAN, 0.3, 1000.0, "young_modulus"),
        (1e6, 0.5, 1000.0, "poisson_ratio"),
        (1e6, 0.7, 1000.0, "poisson_ratio"),
        (1e6, -1.0, 1000.0, "poisson_ratio"),
        (1e6, f64::NAN, 1000.0, "poisson_ratio"),
        (1e6, 0.3, 0.0, "density"),
        (1e6, 0.3, f64::INFINITY, "density"),
    ];
    for (e, nu, rho, name) in bad {
        match Material::new(MaterialModel::StableNeoHookean, e, nu, rho) {
            Err(Error::InvalidMaterial { parameter, .. }) => assert_eq!(parameter, name),
            other => {
                panic!("E={e}, nu={nu}, rho={rho}: expected an error on {name}, got {other:?}")
            }
        }
    }
    assert!(Material::new(MaterialModel::Linear, 1e6, 0.4999, 1000.0).is_ok());
    assert!(Material::new(MaterialModel::Linear, 1e6, -0.99, 1000.0).is_ok());
}

#[test]
fn damping_that_would_inject_energy_is_rejected() {
    assert!(matches!(
        RayleighDamping::new(0.0, -1.0),
        Err(Error::InvalidMaterial {
            parameter: "psi",
            ..
        })
    ));
    assert!(matches!(
        RayleighDamping::new(-1.0, 1.0),
        Err(Error::InvalidMaterial {
            parameter: "phi",
            ..
        })
    ));
    // A negative φ is allowed while the bulk viscosity φ + 2ψ/3 stays non-negative (as λ < 0 is
    // allowed for auxetic materials).
    assert!(RayleighDamping::new(-0.5, 1.0).is_ok());
    let lame = LameParameters {
        lambda: 1.0,
        mu: 2.0,
    };
    assert!(matches!(
        RayleighDamping::stiffness_proportional(-1e-3, lame),
        Err(Error::InvalidMaterial {
            parameter: "beta",
            ..
        })
    ));
}
