//! Invariants of the internal forces on random states of a distorted mesh:
//! they sum to zero and carry no net torque (1e-12 relative), they are the negative gradient of
//! the elastic energy (central finite differences, 1e-6 relative), the stress differential used by
//! the Newton solver is the derivative of the stress (1e-6), and damping never adds energy. The
//! derivative checks run at ν = 0.3 or 0.35 and at the auxetic ν = -0.5 and -0.99, near rest,
//! crushed and inverted.

mod common;

use common::{Lcg, MODELS, OBJECTIVE_MODELS};
use proptest::prelude::*;
use rapier_fvm::material::{
    Corotated, HyperelasticModel, LinearElastic, StVenantKirchhoff, StableNeoHookean,
};
use rapier_fvm::prelude::*;

/// A body of `mesh` (E = 1e6 Pa, ν = 0.35, damped) with its nodes moved randomly by up to
/// `amplitude` (m) and random velocities up to 1 m/s per component.
fn randomized(mesh: TetMesh, model: MaterialModel, seed: u64, amplitude: f64) -> DeformableBody {
    randomized_at(mesh, model, 0.35, seed, amplitude)
}

/// [`randomized`] with Poisson's ratio `nu`.
fn randomized_at(
    mesh: TetMesh,
    model: MaterialModel,
    nu: f64,
    seed: u64,
    amplitude: f64,
) -> DeformableBody {
    let material = Material::new(model, 1e6, nu, 1000.0).unwrap();
    let damping = RayleighDamping::new(300.0, 200.0).unwrap();
    let mut body = DeformableBodyBuilder::new(mesh, material)
        .damping(damping)
        .build()
        .unwrap();
    let mut rng = Lcg(seed);
    for x in body.positions_mut() {
        *x += rng.vector() * amplitude;
    }
    for v in body.velocities_mut() {
        *v = rng.vector();
    }
    body
}

/// A 4 x 2 x 2-cell (80-tetrahedron) bar, randomized.
fn random_body(model: MaterialModel, seed: u64, amplitude: f64) -> DeformableBody {
    random_body_at(model, 0.35, seed, amplitude)
}

/// [`random_body`] with Poisson's ratio `nu`.
fn random_body_at(model: MaterialModel, nu: f64, seed: u64, amplitude: f64) -> DeformableBody {
    let mesh = mesh::cuboid(DVec3::new(0.2, 0.1, 0.1), [4, 2, 2]).unwrap();
    randomized_at(mesh, model, nu, seed, amplitude)
}

/// Auxetic Poisson's ratios, where the stable Neo-Hookean energy has its compression term.
const AUXETIC: [f64; 2] = [-0.5, -0.99];

fn sums(body: &mut DeformableBody) -> (DVec3, DVec3, f64, f64) {
    let positions = body.positions().to_vec();
    let forces = body.internal_forces().to_vec();
    let net: DVec3 = forces.iter().sum();
    let torque: DVec3 = positions
        .iter()
        .zip(&forces)
        .map(|(x, f)| x.cross(*f))
        .sum();
    let force_scale: f64 = forces.iter().map(|f| f.length()).sum();
    let torque_scale: f64 = positions
        .iter()
        .zip(&forces)
        .map(|(x, f)| x.length() * f.length())
        .sum();
    (net, torque, force_scale, torque_scale)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn internal_forces_sum_to_zero_with_zero_torque(seed in any::<u64>(), model_index in 0usize..3) {
        // Rotation-invariant models, large random deformation (up to 2 cm on 5 cm cells).
        let mut body = random_body(OBJECTIVE_MODELS[model_index], seed, 0.02);
        let (net, torque, force_scale, torque_scale) = sums(&mut body);
        prop_assert!(net.length() <= 1e-12 * force_scale, "net {net}");
        prop_assert!(torque.length() <= 1e-12 * torque_scale, "torque {torque}");
    }

    #[test]
    fn damping_never_adds_energy(seed in any::<u64>(), model_index in 0usize..4) {
        // Power of the damping forces alone: the difference of the internal forces with and
        // without the velocities.
        let mut body = random_body(MODELS[model_index], seed, 0.01);
        let with_velocity = body.internal_forces().to_vec();
        let velocities = body.velocities().to_vec();
        body.velocities_mut().fill(DVec3::ZERO);
        let elastic = body.internal_forces().to_vec();
        let power: f64 = with_velocity
            .iter()
            .zip(&elastic)
            .zip(&velocities)
            .map(|((a, b), v)| (*a - *b).dot(*v))
            .sum();
        prop_assert!(power <= 0.0, "damping power {power} W");
    }
}

#[test]
fn linear_model_forces_balance_for_rotation_free_deformation() {
    // The linear model is not rotation invariant: its forces balance exactly, and its torque
    // vanishes for deformations with a symmetric gradient (no rotation). Under rotation its
    // spurious torque is that of the spurious stress measured in `rigid_motion`.
    let mut body = random_body(MaterialModel::Linear, 3, 0.0);
    let f = DMat3::from_cols(
        DVec3::new(1.01, 0.002, -0.003),
        DVec3::new(0.002, 0.99, 0.004),
        DVec3::new(-0.003, 0.004, 1.02),
    );
    let rest = body.mesh().positions().to_vec();
    for (x, p) in body.positions_mut().iter_mut().zip(&rest) {
        *x = f * *p;
    }
    let (net, torque, force_scale, torque_scale) = sums(&mut body);
    assert!(net.length() <= 1e-12 * force_scale);
    assert!(torque.length() <= 1e-12 * torque_scale);
}

#[test]
fn forces_are_the_negative_gradient_of_the_elastic_energy() {
    let auxetic = AUXETIC.map(|nu| (MaterialModel::StableNeoHookean, nu));
    for (model, nu) in MODELS.map(|model| (model, 0.35)).into_iter().chain(auxetic) {
        let mut body = random_body_at(model, nu, 11, 0.01);
        body.velocities_mut().fill(DVec3::ZERO);
        let forces = body.internal_forces().to_vec();
        let largest = forces.iter().map(|f| f.length()).fold(0.0, f64::max);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for n in (0..body.node_count()).step_by(3) {
            for axis in 0..3 {
                let x0 = body.positions()[n];
                body.positions_mut()[n][axis] = x0[axis] + h;
                let plus = body.elastic_energy();
                body.positions_mut()[n][axis] = x0[axis] - h;
                let minus = body.elastic_energy();
                body.positions_mut()[n] = x0;
                let finite_difference = -(plus - minus) / (2.0 * h);
                worst = worst.max((finite_difference - forces[n][axis]).abs() / largest);
            }
        }
        println!("{model:?}, ν = {nu}: worst |f + dE/dx| / max|f| = {worst:.2e}");
        assert!(worst < 1e-6, "{model:?}, ν = {nu}: {worst:e}");
    }
}

/// Checks `first_piola_differential` against central differences of `first_piola`, near rest and
/// crushed to 0.35 in every direction.
fn check_differential(model: &impl HyperelasticModel, name: &str, rng: &mut Lcg) {
    let mut worst: f64 = 0.0;
    for sample in 0..20 {
        let size = if sample % 2 == 0 { 1.0 } else { 0.35 };
        let f = (DMat3::IDENTITY
            + DMat3::from_cols(rng.vector(), rng.vector(), rng.vector()) * 0.3)
            * size;
        let df = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector());
        let h = 1e-6;
        let numeric =
            (model.first_piola(&(f + df * h)) - model.first_piola(&(f - df * h))) / (2.0 * h);
        let analytic = model.first_piola_differential(&f, &df);
        let scale = numeric
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let error = (numeric - analytic)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        worst = worst.max(error / scale);
    }
    println!("{name}: worst relative error of dP = {worst:.2e}");
    assert!(worst < 1e-6, "{name}: {worst:e}");
}

#[test]
fn stress_differentials_match_finite_differences() {
    let mut rng = Lcg(5);
    for nu in [0.3].into_iter().chain(AUXETIC) {
        let lame = Material::new(MaterialModel::Linear, 1e6, nu, 1.0)
            .unwrap()
            .lame();
        let name = |model: &str| format!("{model}, ν = {nu}");
        check_differential(&LinearElastic(lame), &name("linear"), &mut rng);
        check_differential(&StVenantKirchhoff(lame), &name("StVK"), &mut rng);
        check_differential(&Corotated(lame), &name("corotated"), &mut rng);
        let neo = StableNeoHookean::new(lame);
        check_differential(&neo, &name("stable Neo-Hookean"), &mut rng);
    }
}

#[test]
fn stress_is_the_derivative_of_the_energy_density() {
    let mut rng = Lcg(9);
    for nu in [0.3].into_iter().chain(AUXETIC) {
        let lame = Material::new(MaterialModel::Linear, 1e6, nu, 1.0)
            .unwrap()
            .lame();
        // Near rest, inverted (negative determinant: the robust models must stay smooth), and
        // crushed to 0.35 in every direction (J about 0.04, the auxetic compression term's range).
        for (flip, size) in [(1.0, 1.0), (-1.0, 1.0), (1.0, 0.35), (-1.0, 0.35)] {
            let f = DMat3::from_diagonal(DVec3::new(1.0, 1.0, flip))
                * (DMat3::IDENTITY
                    + DMat3::from_cols(rng.vector(), rng.vector(), rng.vector()) * 0.2)
                * size;
            check_stress(
                lame,
                &f,
                &format!("ν = {nu}, det F sign {flip}, size {size}"),
            );
        }
    }
}

/// Checks every model's `first_piola` at `f` against central differences of `energy_density`.
fn check_stress(lame: LameParameters, f: &DMat3, case: &str) {
    type EnergyAndStress<'a> = &'a dyn Fn(&DMat3) -> (f64, DMat3);
    fn of(model: &impl HyperelasticModel) -> impl Fn(&DMat3) -> (f64, DMat3) + '_ {
        |f| (model.energy_density(f), model.first_piola(f))
    }
    let (linear, stvk) = (LinearElastic(lame), StVenantKirchhoff(lame));
    let (corotated, neo) = (Corotated(lame), StableNeoHookean::new(lame));
    let models: [(&str, EnergyAndStress); 4] = [
        ("linear", &of(&linear)),
        ("StVK", &of(&stvk)),
        ("corotated", &of(&corotated)),
        ("stable Neo-Hookean", &of(&neo)),
    ];
    for (name, model) in models {
        let (_, stress) = model(f);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for c in 0..3 {
            for r in 0..3 {
                let (mut plus, mut minus) = (*f, *f);
                plus.col_mut(c)[r] += h;
                minus.col_mut(c)[r] -= h;
                let derivative = (model(&plus).0 - model(&minus).0) / (2.0 * h);
                worst = worst.max((derivative - stress.col(c)[r]).abs());
            }
        }
        let scale = largest(stress);
        println!(
            "{name} ({case}): worst |dΨ/dF - P| / max|P| = {:.2e}",
            worst / scale
        );
        assert!(worst < 1e-6 * scale, "{name} ({case})");
    }
}

#[test]
fn simd_mesh_loop_matches_the_scalar_kernel() {
    // The mesh loop evaluates four tetrahedra per SIMD lane group; it must agree with the scalar
    // reference `tet_forces` summed tetrahedron by tetrahedron (1e-13 of the largest force).
    use rapier_fvm::fvm::{FvmMesh, tet_forces};
    // 80 tetrahedra (one chunk), 20 250 (three chunks of the parallel loop, the last block
    // padded) and a 29 184-tetrahedron ball (block-structured, renumbered in spatial order).
    // A St. Venant–Kirchhoff bar crushed and inverted in places (4 cm moves on 5 cm cells)
    // sends blocks below its compression threshold through the lane-by-lane fallback; auxetic
    // stable Neo-Hookean bars, compressed in places, exercise its compression term's lanes.
    let crushed = random_body(MaterialModel::StVenantKirchhoff, 31, 0.04);
    assert!(crushed.inverted_tet_count() > 0);
    let auxetic = AUXETIC.map(|nu| random_body_at(MaterialModel::StableNeoHookean, nu, 22, 0.02));
    let bodies = MODELS
        .map(|model| random_body(model, 21, 0.01))
        .into_iter()
        .chain([crushed])
        .chain(auxetic)
        .chain([randomized(
            mesh::cuboid(DVec3::new(0.3, 0.3, 0.05), [27, 30, 5]).unwrap(),
            MaterialModel::StVenantKirchhoff,
            8,
            1e-3,
        )])
        .chain([randomized(
            mesh::sphere(0.1, 20).unwrap(),
            MaterialModel::StableNeoHookean,
            9,
            1e-4,
        )]);
    for body in bodies {
        let model = body.material().model();
        let fvm = FvmMesh::new(body.mesh());
        let lame = body.material().lame();
        let damping = body.damping().copied();
        let x = body.positions();
        let v = body.velocities();
        let mut expected = vec![DVec3::ZERO; body.node_count()];
        for (t, tet) in fvm.tets().iter().enumerate() {
            let xs = tet.map(|n| x[n as usize]);
            let vs = tet.map(|n| v[n as usize]);
            let rest = fvm.tet_rest(t);
            let forces = match model {
                MaterialModel::Linear => {
                    tet_forces(&LinearElastic(lame), damping.as_ref(), &rest, &xs, &vs)
                }
                MaterialModel::StVenantKirchhoff => {
                    tet_forces(&StVenantKirchhoff(lame), damping.as_ref(), &rest, &xs, &vs)
                }
                MaterialModel::Corotated => {
                    tet_forces(&Corotated(lame), damping.as_ref(), &rest, &xs, &vs)
                }
                _ => tet_forces(
                    &StableNeoHookean::new(lame),
                    damping.as_ref(),
                    &rest,
                    &xs,
                    &vs,
                ),
            };
            for (c, &n) in tet.iter().enumerate() {
                expected[n as usize] += forces[c];
            }
        }
        let mut body = body;
        let actual = body.internal_forces().to_vec();
        let largest = expected.iter().map(|f| f.length()).fold(0.0, f64::max);
        let worst = expected
            .iter()
            .zip(&actual)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-13 * largest,
            "{model:?}: {worst:e} of {largest:e}"
        );
    }
}

#[test]
fn forces_are_bit_identical_whatever_the_thread_count() {
    let mesh = mesh::cuboid(DVec3::splat(0.2), [16, 16, 16]).unwrap();
    let mut body = randomized(mesh, MaterialModel::StableNeoHookean, 12, 1e-3);
    let forces_with = |threads: usize, body: &mut DeformableBody| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| body.internal_forces().to_vec())
    };
    let one = forces_with(1, &mut body);
    let two = forces_with(2, &mut body);
    let three = forces_with(3, &mut body);
    assert!(one == two && two == three);
}

#[test]
fn every_model_has_the_linear_elastic_tangent_at_rest() {
    // dP at F = I must be λ tr(dF) I + μ (dF + dFᵀ) for every model (this checks, among others,
    // the stable Neo-Hookean's λ' = λ + μ, and that its compression term for ν < 0 leaves the
    // tangent at rest alone), to round-off.
    let mut rng = Lcg(17);
    for nu in [0.3].into_iter().chain(AUXETIC).cycle().take(12) {
        let lame = Material::new(MaterialModel::Linear, 1e6, nu, 1.0)
            .unwrap()
            .lame();
        let df = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector());
        let expected = LinearElastic(lame).first_piola_differential(&DMat3::IDENTITY, &df);
        let scale = expected
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let models: [(&str, DMat3); 3] = [
            (
                "StVK",
                StVenantKirchhoff(lame).first_piola_differential(&DMat3::IDENTITY, &df),
            ),
            (
                "corotated",
                Corotated(lame).first_piola_differential(&DMat3::IDENTITY, &df),
            ),
            (
                "stable Neo-Hookean",
                StableNeoHookean::new(lame).first_piola_differential(&DMat3::IDENTITY, &df),
            ),
        ];
        for (name, actual) in models {
            let error = (actual - expected)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(error < 1e-12 * scale, "{name}, ν = {nu}: {error:e}");
        }
    }
}

#[test]
fn small_strain_energies_keep_their_digits() {
    // At a 1e-6 strain every model's energy must match linear elasticity's μ ε:ε + λ/2 tr(ε)²
    // to its own order, O(ε) = 1e-6 relative (tolerance 1e-5): an energy computed by subtracting
    // order-ε invariants would be wrong in the fourth digit and blind the Newton line searches.
    let lame = Material::new(MaterialModel::Linear, 1e9, 0.45, 1.0)
        .unwrap()
        .lame();
    let mut rng = Lcg(23);
    for _ in 0..10 {
        let h = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector()) * 1e-6;
        let f = DMat3::IDENTITY + (h + h.transpose()) * 0.5;
        let linear = LinearElastic(lame).energy_density(&f);
        for (name, energy) in [
            ("StVK", StVenantKirchhoff(lame).energy_density(&f)),
            ("corotated", Corotated(lame).energy_density(&f)),
            (
                "stable Neo-Hookean",
                StableNeoHookean::new(lame).energy_density(&f),
            ),
        ] {
            assert!(
                (energy / linear - 1.0).abs() < 1e-5,
                "{name}: {energy:e} vs {linear:e}"
            );
        }
    }
}

#[test]
fn continued_stvk_stays_consistent_when_crushed_and_inverted() {
    // Below its compression threshold (stretch 0.6) St. Venant–Kirchhoff continues its principal
    // strains. Its stress must stay the derivative of its energy and dP that of the stress (the
    // 1e-6 tolerances above), for stretches crushed, nearly flat and inverted; an inverted
    // stretch must be pushed back (the energy falls as it grows toward positive); and energy,
    // stress and dP must join continuously at the threshold (the continuation is C²).
    let lame = Material::new(MaterialModel::Linear, 1e6, 0.3, 1.0)
        .unwrap()
        .lame();
    let model = StVenantKirchhoff(lame);
    let mut rng = Lcg(29);
    let stretches: [[f64; 3]; 9] = [
        [1.1, 0.9, 0.3],
        [1.2, 0.5, 0.45],
        [0.55, 0.5, 0.4],
        [1.0, 0.9, 0.02],
        [1.0, 0.9, 0.59],
        [1.0, 0.8, -0.5],
        [1.05, 1.0, -0.95],
        [0.9, 0.3, -0.2],
        [1.3, 0.7, -1e-3],
    ];
    let (mut worst_stress, mut worst_differential): (f64, f64) = (0.0, 0.0);
    for sigma in stretches {
        let mut rotation = || DMat3::from_axis_angle(rng.vector().normalize(), 3.0 * rng.next());
        let (u, v) = (rotation(), rotation());
        let f = u * DMat3::from_diagonal(DVec3::from(sigma)) * v.transpose();
        let stress = model.first_piola(&f);
        let h = 1e-6;
        let mut error: f64 = 0.0;
        for c in 0..3 {
            for r in 0..3 {
                let (mut plus, mut minus) = (f, f);
                plus.col_mut(c)[r] += h;
                minus.col_mut(c)[r] -= h;
                let derivative =
                    (model.energy_density(&plus) - model.energy_density(&minus)) / (2.0 * h);
                error = error.max((derivative - stress.col(c)[r]).abs());
            }
        }
        worst_stress = worst_stress.max(error / largest(stress));
        for _ in 0..3 {
            let df = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector());
            let numeric =
                (model.first_piola(&(f + df * h)) - model.first_piola(&(f - df * h))) / (2.0 * h);
            let analytic = model.first_piola_differential(&f, &df);
            worst_differential =
                worst_differential.max(largest(numeric - analytic) / largest(numeric));
        }
        if sigma[2] < 0.0 {
            // Growing the inverted stretch: dF = u e3 e3ᵀ vᵀ.
            let grow = u * DMat3::from_diagonal(DVec3::Z) * v.transpose();
            let power = double_dot(&stress, &grow);
            assert!(power < 0.0, "{sigma:?}: P : dF = {power:e} Pa");
        }
    }
    // Just above the threshold (closed form) and just below it (continuation), 2e-9 apart.
    let (u, v) = (
        DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
        DMat3::from_axis_angle(DVec3::new(-2.0, 1.0, 0.5).normalize(), 1.9),
    );
    let df = DMat3::from_cols(rng.vector(), rng.vector(), rng.vector());
    let [above, below] = [1e-9, -1e-9].map(|offset| {
        let f = u * DMat3::from_diagonal(DVec3::new(1.1, 0.9, 0.6 + offset)) * v.transpose();
        (
            model.energy_density(&f),
            model.first_piola(&f),
            model.first_piola_differential(&f, &df),
        )
    });
    let join = [
        (above.0 - below.0).abs() / above.0.abs(),
        largest(above.1 - below.1) / largest(above.1),
        largest(above.2 - below.2) / largest(above.2),
    ];
    println!(
        "continued StVK: worst |dΨ/dF - P| / max|P| = {worst_stress:.2e}, worst relative error of dP = {worst_differential:.2e}; relative jumps of Ψ, P, dP across the threshold {:.1e}, {:.1e}, {:.1e}",
        join[0], join[1], join[2]
    );
    assert!(worst_stress < 1e-6, "{worst_stress:e}");
    assert!(worst_differential < 1e-6, "{worst_differential:e}");
    assert!(join.iter().all(|&jump| jump < 1e-6), "{join:?}");
}

/// `A : B`, the Frobenius inner product.
fn double_dot(a: &DMat3, b: &DMat3) -> f64 {
    a.x_axis.dot(b.x_axis) + a.y_axis.dot(b.y_axis) + a.z_axis.dot(b.z_axis)
}

/// The largest absolute entry of `m`.
fn largest(m: DMat3) -> f64 {
    m.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs()))
}
