//! The reference cantilever (L = 1 m, 0.1 x 0.1 m section, ρ = 1000 kg/m³, g = 9.81 m/s², clamped
//! at x = 0) against beam theory, and a slender one (0.05 x 0.05 m) bent through 45° against the
//! elastica.

mod common;

use common::{OBJECTIVE_MODELS, cantilever, gravity, timoshenko_tip_deflection};
use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};

/// Static tip deflection (m, positive down) of `cells` at equilibrium.
fn static_tip_deflection(cells: [usize; 3], material: Material) -> f64 {
    let (body, tip) = cantilever(cells, material);
    equilibrium_tip_deflection(body, tip, &StaticSettings::default())
}

/// Static tip deflection (m, positive down) of `body` at equilibrium.
fn equilibrium_tip_deflection(
    mut body: DeformableBody,
    tip: usize,
    settings: &StaticSettings,
) -> f64 {
    let rest = body.positions()[tip].y;
    statics::solve_equilibrium(&mut body, gravity(), settings).unwrap();
    rest - body.positions()[tip].y
}

#[test]
fn nodal_averaging_removes_volumetric_locking() {
    // Linear model, E = 1e8 Pa. Per element, the 40 x 4 x 4 beam loses 22.2 % of the Timoshenko
    // deflection at ν = 0.499 and 23.6 % at 0.4999; with nodal averaging 18.0 % and 19.1 %, and
    // less than per element at every ν (the rest of the gap grows with ν on every mesh alike: the
    // clamped end stops the Poisson contraction beam theory assumes free). Asserted with about a
    // point of margin on the measured values.
    let cells = [40, 4, 4];
    // The residual of a nearly incompressible beam floors near 1e-6 of its weight.
    let settings = StaticSettings {
        tolerance: 1e-5,
        ..StaticSettings::default()
    };
    let error = |nu: f64, treatment: VolumetricTreatment| {
        let material = Material::new(MaterialModel::Linear, 1e8, nu, common::DENSITY).unwrap();
        let (body, tip) = common::cantilever_with(cells, material, None, treatment);
        equilibrium_tip_deflection(body, tip, &settings) / timoshenko_tip_deflection(1e8, nu) - 1.0
    };
    let mut averaged_errors = Vec::new();
    for nu in [0.0, 0.3, 0.45, 0.49, 0.499, 0.4999] {
        let plain = error(nu, VolumetricTreatment::PerElement);
        let averaged = error(nu, VolumetricTreatment::NodalAverage);
        println!(
            "ν = {nu}: per element {:+.2} %, nodal average {:+.2} %",
            100.0 * plain,
            100.0 * averaged
        );
        assert!(averaged.abs() < plain.abs(), "ν = {nu}");
        averaged_errors.push(averaged);
    }
    let nearly_incompressible = averaged_errors[5];
    assert!(
        nearly_incompressible.abs() < 0.20,
        "{nearly_incompressible}"
    );
    assert!((averaged_errors[5] - averaged_errors[4]).abs() < 0.015);
}

#[test]
fn small_deflection_converges_to_timoshenko() {
    // Linear tetrahedra are stiff in bending (shear locking): the error falls as the mesh is
    // refined, roughly as (cell size)^1.5 here, and the finest mesh is within 3 %.
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let reference = timoshenko_tip_deflection(1e8, 0.3);
    println!("Timoshenko reference {:.3} mm", reference * 1e3);
    println!("cells          tets  tip (mm)  error");
    let mut previous_error = f64::INFINITY;
    for n in [1, 2, 4, 6, 8, 10, 12] {
        let cells = [10 * n, n, n];
        let tip = static_tip_deflection(cells, material);
        let error = tip / reference - 1.0;
        println!(
            "{cells:?} {:7}  {:8.3}  {:+.2} %",
            5 * 10 * n * n * n,
            tip * 1e3,
            100.0 * error
        );
        assert!(
            error < 0.0 && error.abs() < previous_error,
            "must converge from the stiff side"
        );
        previous_error = error.abs();
    }
    assert!(previous_error < 0.03, "finest mesh error {previous_error}");
}

#[test]
fn nonlinear_models_agree_with_linear_at_small_deflection() {
    // At 1.5 % of the length, geometric nonlinearity changes the deflection by far less than 0.5 %.
    let cells = [40, 4, 4];
    let linear = static_tip_deflection(
        cells,
        Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap(),
    );
    for model in OBJECTIVE_MODELS {
        let tip = static_tip_deflection(
            cells,
            Material::new(model, 1e8, 0.3, common::DENSITY).unwrap(),
        );
        println!(
            "{model:?}: {:.4} mm vs linear {:.4} mm",
            tip * 1e3,
            linear * 1e3
        );
        assert!((tip / linear - 1.0).abs() < 5e-3, "{model:?}");
    }
}

/// Stiffness-proportional damping time (s) giving the first mode of `body` the damping ratio
/// `zeta`.
fn damping_for(body: &DeformableBody, zeta: f64) -> RayleighDamping {
    let omega = 2.0 * std::f64::consts::PI * statics::fundamental_frequency(body).unwrap();
    RayleighDamping::stiffness_proportional(2.0 * zeta / omega, body.material().lame()).unwrap()
}

/// The cantilever with its first mode damped at the ratio `zeta`.
fn cantilever_damped_at(
    cells: [usize; 3],
    material: Material,
    zeta: f64,
) -> (DeformableBody, usize) {
    let (undamped, _) = cantilever(cells, material);
    common::damped_cantilever(cells, material, Some(damping_for(&undamped, zeta)))
}

/// Runs `seconds` of frames of 1/60 s, each advanced by `step` (body, constraints, workspace,
/// frame step in s); returns the largest node speed (m/s) at the end.
fn settle(
    body: &mut DeformableBody,
    seconds: f64,
    mut step: impl FnMut(&mut DeformableBody, &mut BodyConstraints, &mut SolverWorkspace, f64),
) -> f64 {
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..(seconds * 60.0).round() as usize {
        step(body, &mut constraints, &mut workspace, 1.0 / 60.0);
    }
    body.velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max)
}

#[test]
fn damped_explicit_dynamics_settles_on_the_static_solution() {
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let cells = [10, 1, 1];
    let (mut body, tip) = cantilever_damped_at(cells, material, 0.3);
    let rest = body.positions()[tip].y;
    let speed = settle(&mut body, 1.5, |body, constraints, workspace, dt| {
        let integrator = SymplecticEuler::default();
        integrator
            .step(body, constraints, workspace, dt, gravity())
            .unwrap();
    });
    let dynamic = rest - body.positions()[tip].y;
    let statics = static_tip_deflection(cells, material);
    println!(
        "settled tip {:.5} mm, static solver {:.5} mm, largest speed {speed:.1e} m/s",
        dynamic * 1e3,
        statics * 1e3
    );
    assert!((dynamic / statics - 1.0).abs() < 1e-4);
}

/// Side (m) of the square section of the slender cantilever of the large-deflection tests, of
/// length [`common::LENGTH`]: `L/h = 20`.
const SLENDER_SIDE: f64 = 0.05;
/// Its load parameter `q L³ / (E I)` (dimensionless), with `q` its weight per length: the elastica's
/// tip drops 0.554 L at a slope of 45° (linear theory: `q L⁴ / (8 E I)` = 0.75 L) and the peak
/// bending strain is 6 %.
const LOAD_PARAMETER: f64 = 6.0;

/// The slender cantilever of quadratic tetrahedra on `cells` (ν = 0, ρ = 1000 kg/m³, Young's
/// modulus from [`LOAD_PARAMETER`], 7.85e6 Pa), clamped at x = 0 along +x, with `damping`; and the
/// nodes of its free end.
fn slender_cantilever(
    model: MaterialModel,
    cells: [usize; 3],
    damping: Option<RayleighDamping>,
) -> (DeformableBody, Vec<u32>) {
    let weight = common::DENSITY * common::GRAVITY * SLENDER_SIDE * SLENDER_SIDE;
    let young = weight * common::LENGTH.powi(3) / (LOAD_PARAMETER * SLENDER_SIDE.powi(4) / 12.0);
    let material = Material::new(model, young, 0.0, common::DENSITY).unwrap();
    let half = DVec3::new(common::LENGTH, SLENDER_SIDE, SLENDER_SIDE) * 0.5;
    let linear = mesh::cuboid(half, cells).unwrap();
    let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
    let clamped = quadratic.nodes_where(|p| p.x <= -half.x + 1e-9);
    let free_end = quadratic.nodes_where(|p| p.x >= half.x - 1e-9);
    let mut builder = DeformableBodyBuilder::quadratic(quadratic, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped);
    if let Some(damping) = damping {
        builder = builder.damping(damping);
    }
    (builder.build().unwrap(), free_end)
}

/// Mean height (m) of `nodes` of `body`: the height of the section's centre for a section that
/// moves rigidly (its nodes are placed symmetrically about the centre).
fn mean_height(body: &DeformableBody, nodes: &[u32]) -> f64 {
    nodes
        .iter()
        .map(|&n| body.positions()[n as usize].y)
        .sum::<f64>()
        / nodes.len() as f64
}

/// Static tip deflection (m, positive down) of the undamped slender cantilever on `cells`, its
/// weight applied in four equal load steps from rest.
fn slender_static_deflection(model: MaterialModel, cells: [usize; 3]) -> f64 {
    let (mut body, free_end) = slender_cantilever(model, cells, None);
    let rest = mean_height(&body, &free_end);
    for step in 1..=4 {
        let gravity = gravity() * (f64::from(step) / 4.0);
        statics::solve_equilibrium(&mut body, gravity, &StaticSettings::default()).unwrap();
    }
    rest - mean_height(&body, &free_end)
}

/// The slender cantilever bent through 45° by its weight, against the elastica of the same load:
/// inextensible and shear-free, solved by shooting ([`common::elastica_tip_deflection`], converged
/// to 1e-10). A distributed load makes the elastica's equation depend on the arc length, so it
/// lacks the first integral that gives a tip load's elastica in elliptic integrals (Bisshopp and
/// Drucker 1945); and the crate loads bodies by gravity. At ν = 0 the clamped face holds back no
/// Poisson contraction.
///
/// 1. Released from rest with its first mode critically damped, 1.5 s of backward Euler frames
///    of 1/60 s bring the 40 x 1 x 1-cell beam to rest (largest node speed below 1 cm/s) in a
///    finite state, which the static solver refines by less than 1 %.
/// 2. The discretization error: the 80 x 2 x 2-cell beam (solved statically) deflects within
///    0.1 % of it (measured 0.03 to 0.04 %).
/// 3. The model error: the 3D beam also shears, adding `4 E I / (κ G A L²)` = 0.20 % at small
///    load (Timoshenko, Cowper's `κ` = 10/12 at ν = 0; at a load parameter of 0.1 the two meshes
///    give +0.17 % and +0.20 %), and its 6 % peak strain lets the models' moment–curvature laws
///    and the axial stretch add about 0.1 % more. So the tip should exceed the elastica's by about
///    0.3 % (measured +0.25 % corotated, +0.31 % St. Venant–Kirchhoff, +0.35 % stable
///    Neo-Hookean): asserted between 0 and 0.75 %, twice that.
fn large_deflection_matches_the_elastica(model: MaterialModel) {
    let (undamped, _) = slender_cantilever(model, [40, 1, 1], None);
    let damping = damping_for(&undamped, 1.0);
    let (mut body, free_end) = slender_cantilever(model, [40, 1, 1], Some(damping));
    let rest = mean_height(&body, &free_end);
    let speed = settle(&mut body, 1.5, |body, constraints, workspace, dt| {
        let integrator = ImplicitIntegrator::default();
        integrator
            .step(body, constraints, workspace, dt, gravity())
            .unwrap();
    });
    let settled = rest - mean_height(&body, &free_end);
    assert!(body.positions().iter().all(|x| x.is_finite()));
    let report = statics::solve_equilibrium(&mut body, gravity(), &StaticSettings::default())
        .expect("the settled state is near an equilibrium the static solver can refine");
    let refined = rest - mean_height(&body, &free_end);
    let fine = slender_static_deflection(model, [80, 2, 2]);
    let load = LOAD_PARAMETER / common::LENGTH.powi(3);
    let elastica = common::elastica_tip_deflection(load, common::LENGTH);
    let error = refined / elastica - 1.0;
    println!(
        "{model:?}: elastica {elastica:.5} m; 40 x 1 x 1 settled {settled:.5} m (largest speed \
         {speed:.1e} m/s), refined {refined:.5} m in {} iterations ({:+.3} %); 80 x 2 x 2 \
         {fine:.5} m ({:+.3} %)",
        report.iterations,
        100.0 * error,
        100.0 * (fine / elastica - 1.0)
    );
    assert!(speed < 1e-2, "{model:?} still moving at {speed} m/s");
    assert!((refined / settled - 1.0).abs() < 1e-2, "{model:?}");
    assert!(
        (fine / refined - 1.0).abs() < 1e-3,
        "{model:?}: {fine} vs {refined}"
    );
    assert!(error > 0.0 && error < 7.5e-3, "{model:?}: {error:+e}");
}

#[test]
fn large_deflection_stvk_matches_the_elastica() {
    large_deflection_matches_the_elastica(MaterialModel::StVenantKirchhoff);
}

#[test]
fn large_deflection_corotated_matches_the_elastica() {
    large_deflection_matches_the_elastica(MaterialModel::Corotated);
}

#[test]
fn large_deflection_stable_neo_hookean_matches_the_elastica() {
    large_deflection_matches_the_elastica(MaterialModel::StableNeoHookean);
}

#[test]
fn the_elastica_is_converged_and_tends_to_euler_bernoulli() {
    // The oracle of the large-deflection tests: doubling its Runge–Kutta steps changes its tip
    // deflection by less than 1e-10 relative (fourth order: about 1e-13 expected), and at a load
    // parameter of 1e-3 it is Euler–Bernoulli's q L⁴ / (8 E I) to 1e-6 (its first nonlinear term
    // is relative O(parameter²)).
    let load = LOAD_PARAMETER / common::LENGTH.powi(3);
    let tip = common::elastica_tip_deflection(load, common::LENGTH);
    let doubled = common::elastica_tip_deflection_in(load, common::LENGTH, 4000);
    println!("elastica at a load parameter of {LOAD_PARAMETER}: {tip:.12} m, {doubled:.12} m");
    assert!((doubled / tip - 1.0).abs() < 1e-10);
    let small = 1e-3 / common::LENGTH.powi(3);
    let linear = small * common::LENGTH.powi(4) / 8.0;
    let tip = common::elastica_tip_deflection(small, common::LENGTH);
    assert!((tip / linear - 1.0).abs() < 1e-6, "{tip} vs {linear}");
}

#[test]
fn static_solver_errors_leave_the_body_untouched() {
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut body, _) = cantilever([4, 1, 1], material);
    let before = body.positions().to_vec();
    assert!(matches!(
        statics::solve_equilibrium(
            &mut body,
            DVec3::new(f64::NAN, 0.0, 0.0),
            &StaticSettings::default()
        ),
        Err(Error::NonFiniteInput {
            parameter: "gravity"
        })
    ));
    let mesh = body.mesh().clone();
    let all = 0..mesh.node_count() as u32;
    let mut frozen = DeformableBodyBuilder::new(mesh, material)
        .pinned_nodes(all)
        .build()
        .unwrap();
    assert_eq!(
        statics::solve_equilibrium(&mut frozen, gravity(), &StaticSettings::default()),
        Err(Error::NoFreeNode)
    );
    assert_eq!(
        statics::fundamental_frequency(&frozen),
        Err(Error::NoFreeNode)
    );
    // A body with no pinned node has rigid motions: its stiffness is singular.
    let free = DeformableBodyBuilder::new(body.mesh().clone(), material)
        .build()
        .unwrap();
    let mut free_body = free.clone();
    let outcome = statics::solve_equilibrium(&mut free_body, gravity(), &StaticSettings::default());
    assert!(
        outcome.is_err(),
        "an unsupported body has no static equilibrium: {outcome:?}"
    );
    assert_eq!(free_body.positions(), free.positions());
    assert_eq!(body.positions(), &before[..]);
}
