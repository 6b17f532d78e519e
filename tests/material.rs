//! Material constants (Lamé parameters, the rejection of unphysical values) and every model's
//! energy over the admissible Poisson's ratios: non-negative under compression down to a point,
//! shear and inversion, zero with zero stress at rest, the linear law at small strain; and an
//! auxetic cube squeezed in free fall that springs back instead of collapsing.

mod common;

use common::Lcg;
use rapier_fvm::material::{
    Corotated, HyperelasticModel, LinearElastic, StVenantKirchhoff, StableNeoHookean,
};
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;

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

/// Poisson's ratios of the sweeps, from nearly -1 to nearly 1/2.
const POISSON: [f64; 8] = [-0.99, -0.9, -0.5, -0.1, 0.0, 0.3, 0.45, 0.49];
/// Stretches `s` of the sweep's compressions, down to a point.
const STRETCHES: [f64; 6] = [1.0, 0.9, 0.5, 0.1, 0.01, 0.0];

/// The Lamé parameters at `E = 1 MPa` and Poisson's ratio `nu`.
fn lame(nu: f64) -> LameParameters {
    YoungPoisson::new(1e6, nu).unwrap().into()
}

/// Energy density (J/m³) and first Piola–Kirchhoff stress (Pa) of every model at `f`.
fn every_model(lame: LameParameters, f: &DMat3) -> [(&'static str, f64, DMat3); 4] {
    fn of(model: &impl HyperelasticModel, f: &DMat3) -> (f64, DMat3) {
        (model.energy_density(f), model.first_piola(f))
    }
    let models = [
        ("linear", of(&LinearElastic(lame), f)),
        ("StVK", of(&StVenantKirchhoff(lame), f)),
        ("corotated", of(&Corotated(lame), f)),
        ("stable Neo-Hookean", of(&StableNeoHookean::new(lame), f)),
    ];
    models.map(|(name, (energy, stress))| (name, energy, stress))
}

/// The sweep's deformation gradients for a stretch `s`: uniform compression `s I`, uniaxial
/// compression, shear on top of uniform compression, an element turned inside out through one
/// stretch and one through all three, and a rotated inverted element with unequal stretches.
fn sweep_gradients(s: f64) -> [(&'static str, DMat3); 6] {
    let rotation = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 2.0) / 3.0, 0.8);
    [
        ("uniform", DMat3::from_diagonal(DVec3::splat(s))),
        ("uniaxial", DMat3::from_diagonal(DVec3::new(s, 1.0, 1.0))),
        (
            "shear + compression",
            DMat3::from_cols(DVec3::X * s, DVec3::new(0.5, s, 0.0), DVec3::Z * s),
        ),
        ("inverted", DMat3::from_diagonal(DVec3::new(1.0, 1.0, -s))),
        ("inverted through", DMat3::from_diagonal(DVec3::splat(-s))),
        (
            "inverted, rotated",
            rotation * DMat3::from_diagonal(DVec3::new(1.2, 0.4 + s, -0.5 * s)),
        ),
    ]
}

#[test]
fn every_energy_is_non_negative_for_every_poisson_ratio() {
    // Every model, every admissible ν and every deformation of the sweep: Ψ >= 0. The energies are
    // sums of a few terms each at most (|λ| + μ)(3 + ‖F‖²)² in size (‖F‖² up to 3.7 here), each
    // rounded to a relative 2.2e-16, so round-off is allowed 1e-14 of that scale (50 ulps); the
    // energies tested against it are of order μ or exactly zero. The stable Neo-Hookean energy at
    // F = 0 is |λ|/2 in closed form (λ/2 for ν >= 0, and -λ/2 with the compression term of ν < 0),
    // to 1e-12 of μ.
    for nu in POISSON {
        let lame = lame(nu);
        // Per model, the lowest Ψ/μ away from rest and where.
        let mut lowest = [(f64::INFINITY, "", 0.0); 4];
        for s in STRETCHES {
            for (case, f) in sweep_gradients(s) {
                let size: f64 = f.to_cols_array().iter().map(|x| x * x).sum();
                let scale = (lame.lambda.abs() + lame.mu) * (3.0 + size).powi(2);
                for (m, (model, energy, _)) in every_model(lame, &f).into_iter().enumerate() {
                    assert!(
                        energy >= -1e-14 * scale,
                        "{model}, ν = {nu}, {case}, s = {s}: Ψ = {energy:e} J/m³"
                    );
                    if f != DMat3::IDENTITY && energy / lame.mu < lowest[m].0 {
                        lowest[m] = (energy / lame.mu, case, s);
                    }
                }
            }
        }
        let collapsed = StableNeoHookean::new(lame).energy_density(&DMat3::ZERO);
        let [linear, stvk, corotated, neo] =
            lowest.map(|(e, case, s)| format!("{e:.2e} ({case}, s = {s})"));
        println!(
            "ν = {nu:5}: lowest Ψ/μ linear {linear}, StVK {stvk}, corotated {corotated}, stable Neo-Hookean {neo}; stable Neo-Hookean Ψ(0) = {collapsed:.6e} J/m³, |λ|/2 = {:.6e}",
            lame.lambda.abs() / 2.0
        );
        assert!((collapsed - lame.lambda.abs() / 2.0).abs() <= 1e-12 * lame.mu);
        // At a given J = det F the stable Neo-Hookean energy is least for F = J^(1/3) I (its
        // I_C = tr(FᵀF) term is least there), so Ψ(s I) >= 0 for all s is Ψ >= 0 for all F: on a
        // grid of 1e-3 over s in [-2, 2], J in [-8, 8].
        let neo = StableNeoHookean::new(lame);
        for i in -2000..=2000 {
            let f = DMat3::from_diagonal(DVec3::splat(f64::from(i) * 1e-3));
            let scale = (lame.lambda.abs() + lame.mu) * (3.0 + 3.0 * f.x_axis.x.powi(2)).powi(2);
            let energy = neo.energy_density(&f);
            assert!(
                energy >= -1e-14 * scale,
                "ν = {nu}, F = {i}e-3 I: Ψ = {energy:e}"
            );
        }
    }
}

#[test]
fn every_model_rests_without_energy_or_stress() {
    // At F = I every model's energy and stress vanish exactly: each is a polynomial in F - I, or
    // (corotated) in F - R with R = I exactly for F = I.
    for nu in POISSON {
        for (model, energy, stress) in every_model(lame(nu), &DMat3::IDENTITY) {
            assert_eq!(energy, 0.0, "{model}, ν = {nu}");
            assert_eq!(stress, DMat3::ZERO, "{model}, ν = {nu}");
        }
    }
}

#[test]
fn small_strain_stress_is_the_linear_law_for_every_poisson_ratio() {
    // At a strain ε ~ 1e-6 (no rotation) every model's first Piola–Kirchhoff stress must be the
    // linear σ = λ tr(ε) I + 2μ ε of the same λ and μ to O(ε) relative: the models differ from it
    // by terms quadratic in the strain (and the compression term of auxetic stable Neo-Hookean is
    // cubic). The deviation is measured on the stress scale of the strain, (3|λ| + 2μ) max|ε_ij|
    // (not the linear stress itself, whose volumetric part cancels when tr ε happens to be small):
    // tolerance 1e-5, ten times the expected O(ε).
    let mut rng = Lcg(41);
    let mut worst: f64 = 0.0;
    for nu in POISSON {
        let lame = lame(nu);
        for _ in 0..10 {
            let h = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector()) * 1e-6;
            let strain = (h + h.transpose()) * 0.5;
            let f = DMat3::IDENTITY + strain;
            let linear = DMat3::IDENTITY
                * (lame.lambda * (strain.x_axis.x + strain.y_axis.y + strain.z_axis.z))
                + strain * (2.0 * lame.mu);
            let scale = (3.0 * lame.lambda.abs() + 2.0 * lame.mu) * largest(strain);
            for (model, _, stress) in every_model(lame, &f) {
                let error = largest(stress - linear) / scale;
                worst = worst.max(error);
                assert!(error < 1e-5, "{model}, ν = {nu}: {error:e}");
            }
        }
    }
    println!("worst relative deviation from the linear law at 1e-6 strain: {worst:.2e}");
}

/// The largest absolute entry of `m`.
fn largest(m: DMat3) -> f64 {
    m.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

#[test]
fn a_squeezed_auxetic_cube_in_free_fall_springs_back() {
    // A 10 cm stable Neo-Hookean cube (E = 100 kPa, 1000 kg/m³, 4 x 4 x 4 cells) falls freely (no
    // ground) for 2 s, released with every node moving toward the centre, v = -2 m/s (p - c)/a (a
    // = 5 cm): its faces at 2 m/s, kinetic energy ρ (2 m/s)²/2 = 2000 J per m³. Compressed
    // uniformly, the cube would stop at the J where Ψ(J^(1/3) I) = 2000 J/m³ (found here by
    // bisection on the model's energy); the free cube, whose faces carry no traction, is not
    // strained uniformly, so its volume may dip below that by up to 0.1 of the rest volume (it
    // dips 0.02 to 0.04) and must rebound. Without the compression term of auxetic materials
    // both cubes collapse to a point: the uniform compression's energy turns negative below
    // J = 0.985 at ν = -0.99, and beyond a barrier of 760 J/m³ at ν = -0.5.
    let (half, speed, density) = (0.05, 2.0, 1000.0);
    for nu in [-0.99, -0.5] {
        let material = Material::new(MaterialModel::StableNeoHookean, 1e5, nu, density).unwrap();
        let mesh = mesh::cuboid(DVec3::splat(half), [4, 4, 4]).unwrap();
        let centre = DVec3::new(0.0, 1.0, 0.0);
        let mut cube = DeformableBodyBuilder::new(mesh, material)
            .translation(centre)
            .build()
            .unwrap();
        let positions = cube.positions().to_vec();
        for (v, x) in cube.velocities_mut().iter_mut().zip(&positions) {
            *v = -(*x - centre) * (speed / half);
        }
        let rest = cube.mesh().volume();
        let mut world = FvmWorld::default();
        let handle = world.soft_bodies.insert(cube);
        let (mut smallest, mut largest_volume) = (f64::INFINITY, 0.0f64);
        for _ in 0..120 {
            for (_, outcome) in world.step() {
                outcome.unwrap();
            }
            let volume = world.soft_bodies[handle].deformed_volume() / rest;
            smallest = smallest.min(volume);
            largest_volume = largest_volume.max(volume);
        }
        let uniform = uniform_compression_reached(
            StableNeoHookean::new(material.lame()),
            0.5 * density * speed * speed,
        );
        let cube = &world.soft_bodies[handle];
        println!(
            "ν = {nu}: volume between {smallest:.4} and {largest_volume:.4} of rest (uniform compression would reach {uniform:.4}); {} inverted elements at the end",
            cube.inverted_tet_count()
        );
        assert!(
            smallest >= uniform - 0.1,
            "ν = {nu}: volume down to {smallest}"
        );
        assert!(
            smallest < 1.0 && largest_volume > 1.0,
            "ν = {nu}: the cube must breathe"
        );
        assert_eq!(cube.inverted_tet_count(), 0, "ν = {nu}");
    }
}

/// The volume ratio `J < 1` (dimensionless) at which the energy density of the uniform
/// compression `J^(1/3) I` of `model` reaches `energy` (J/m³), by bisection between rest and the
/// stretch where the energy first reaches it.
fn uniform_compression_reached(model: StableNeoHookean, energy: f64) -> f64 {
    let at = |s: f64| model.energy_density(&DMat3::from_diagonal(DVec3::splat(s)));
    // The first stretch below 1 (in steps of 1e-3) where the energy exceeds `energy`.
    let mut low = 1.0;
    while at(low) < energy {
        low -= 1e-3;
        assert!(low > 0.0, "the energy never reaches {energy} J/m³");
    }
    let mut high = low + 1e-3;
    for _ in 0..60 {
        let mid = 0.5 * (low + high);
        if at(mid) < energy {
            high = mid;
        } else {
            low = mid;
        }
    }
    (0.5 * (low + high)).powi(3)
}
