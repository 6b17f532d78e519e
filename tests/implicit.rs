//! Backward Euler: stability at huge steps on stiff material, the static limit, agreement with the
//! explicit integrator at small steps, its numerical damping against the closed form, and exact
//! momentum conservation.

mod common;

use common::{Lcg, cantilever, gravity};
use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};
use std::f64::consts::PI;
use std::time::Instant;

fn total_energy(body: &DeformableBody) -> f64 {
    body.kinetic_energy() + body.elastic_energy() + body.gravity_potential_energy(gravity())
}

#[test]
fn huge_steps_on_a_stiff_beam_stay_stable_and_never_gain_energy() {
    // E = 1 GPa at 1/30 s: the explicit integrator would need about 3000 substeps per frame at its
    // default safety factor.
    for model in [
        MaterialModel::StVenantKirchhoff,
        MaterialModel::StableNeoHookean,
    ] {
        let material = Material::new(model, 1e9, 0.3, common::DENSITY).unwrap();
        let (mut body, tip) = cantilever([20, 2, 2], material);
        let explicit_substeps =
            (1.0 / 30.0 / SymplecticEuler::default().stable_time_step(&body)).ceil();
        let integrator = ImplicitIntegrator::default();
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let mut energy = total_energy(&body);
        let start = Instant::now();
        let mut iterations = 0;
        for _ in 0..30 {
            let report = integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 30.0,
                    gravity(),
                )
                .unwrap();
            assert!(
                report.converged,
                "{model:?}: Newton did not converge: {report:?}"
            );
            iterations += report.newton_iterations;
            let next = total_energy(&body);
            assert!(
                next <= energy + 1e-9 * energy.abs().max(1.0),
                "{model:?}: energy rose"
            );
            energy = next;
        }
        let tip_deflection = body.mesh().positions()[tip].y - body.positions()[tip].y;
        println!(
            "{model:?}: 30 frames of 1/30 s in {:.1} ms/frame, {:.1} Newton iterations/frame (explicit would need {explicit_substeps} substeps/frame); tip {:.4} mm",
            start.elapsed().as_secs_f64() * 1e3 / 30.0,
            iterations as f64 / 30.0,
            tip_deflection * 1e3
        );
        assert!(body.positions().iter().all(|x| x.is_finite()));
    }
}

#[test]
fn large_steps_settle_on_the_static_solution() {
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut statik, tip) = cantilever([20, 2, 2], material);
    statics::solve_equilibrium(&mut statik, gravity(), &StaticSettings::default()).unwrap();
    let (mut body, _) = cantilever([20, 2, 2], material);
    let integrator = ImplicitIntegrator::default();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..200 {
        integrator
            .step(
                &mut body,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                gravity(),
            )
            .unwrap();
    }
    let rest = body.mesh().positions()[tip].y;
    let (dynamic, expected) = (
        rest - body.positions()[tip].y,
        rest - statik.positions()[tip].y,
    );
    println!(
        "after 200 frames: tip {:.6} mm, static solver {:.6} mm",
        dynamic * 1e3,
        expected * 1e3
    );
    assert!((dynamic / expected - 1.0).abs() < 1e-5);
}

#[test]
fn small_steps_agree_with_the_explicit_integrator() {
    let material =
        Material::new(MaterialModel::StVenantKirchhoff, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut implicit, tip) = cantilever([10, 2, 2], material);
    let (mut explicit, _) = cantilever([10, 2, 2], material);
    let (frame, frames) = (2e-4, 250);
    let mut largest_gap: f64 = 0.0;
    let mut largest_deflection: f64 = 0.0;
    let (mut implicit_constraints, mut implicit_workspace) =
        (BodyConstraints::new(), SolverWorkspace::new());
    let (mut explicit_constraints, mut explicit_workspace) =
        (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..frames {
        ImplicitIntegrator::default()
            .step(
                &mut implicit,
                &mut implicit_constraints,
                &mut implicit_workspace,
                frame,
                gravity(),
            )
            .unwrap();
        SymplecticEuler::default()
            .step(
                &mut explicit,
                &mut explicit_constraints,
                &mut explicit_workspace,
                frame,
                gravity(),
            )
            .unwrap();
        let (a, b) = (implicit.positions()[tip].y, explicit.positions()[tip].y);
        largest_gap = largest_gap.max((a - b).abs());
        largest_deflection = largest_deflection.max((b - implicit.mesh().positions()[tip].y).abs());
    }
    println!(
        "0.05 s at 0.2 ms: largest tip gap {:.4} mm of {:.4} mm",
        largest_gap * 1e3,
        largest_deflection * 1e3
    );
    // First-order agreement: the gap is a few ωh of the motion (ωh = 0.01 here).
    assert!(largest_gap < 0.02 * largest_deflection);
}

/// Per-step amplification `z` of the mode `ẋ = iω x` (as a complex `(re, im)`), and the
/// equivalent damping ratio `-Re(s)/|s|` of `s = ln(z)/h`.
fn equivalent_damping(z: (f64, f64)) -> f64 {
    let (re, im) = (0.5 * (z.0 * z.0 + z.1 * z.1).ln(), z.1.atan2(z.0));
    -re / (re * re + im * im).sqrt()
}

fn complex_div(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

fn complex_sqrt(a: (f64, f64)) -> (f64, f64) {
    let r = (a.0 * a.0 + a.1 * a.1).sqrt();
    (
        ((r + a.0) / 2.0).sqrt(),
        a.1.signum() * ((r - a.0) / 2.0).sqrt(),
    )
}

/// The closed-form numerical damping ratio of a scheme at `ωh`: backward Euler
/// `z = 1/(1 - iωh)`; BDF2's principal root `z = (2 + sqrt(1 + 2iωh)) / (3 - 2iωh)`.
fn closed_form_damping(scheme: ImplicitScheme, omega_h: f64) -> f64 {
    let z = match scheme {
        ImplicitScheme::BackwardEuler => complex_div((1.0, 0.0), (1.0, -omega_h)),
        ImplicitScheme::Bdf2 => {
            let root = complex_sqrt((1.0, 2.0 * omega_h));
            complex_div((2.0 + root.0, root.1), (3.0, -2.0 * omega_h))
        }
    };
    equivalent_damping(z)
}

#[test]
fn numerical_damping_matches_the_closed_form_of_each_scheme() {
    // Measured on the undamped first bending mode by the logarithmic decrement of the tip over
    // several periods, within 5 % of the closed form.
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut released, tip) = cantilever([10, 2, 2], material);
    statics::solve_equilibrium(&mut released, gravity(), &StaticSettings::default()).unwrap();
    let omega = 2.0 * PI * statics::fundamental_frequency(&released).unwrap();
    println!("scheme          omega h   measured zeta   closed form");
    for (scheme, omega_h, tolerance) in [
        (ImplicitScheme::BackwardEuler, 0.05, 0.05),
        (ImplicitScheme::BackwardEuler, 0.2, 0.05),
        (ImplicitScheme::Bdf2, 0.2, 0.05),
        (ImplicitScheme::Bdf2, 0.5, 0.05),
    ] {
        let h = omega_h / omega;
        let mut body = released.clone();
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let rest = body.mesh().positions()[tip].y;
        let integrator = ImplicitIntegrator {
            scheme,
            ..Default::default()
        };
        let steps = (6.0 * 2.0 * PI / omega_h).ceil() as usize;
        let deflection: Vec<f64> = (0..steps)
            .map(|_| {
                integrator
                    .step(&mut body, &mut constraints, &mut workspace, h, DVec3::ZERO)
                    .unwrap();
                rest - body.positions()[tip].y
            })
            .collect();
        let peaks: Vec<f64> = (1..deflection.len() - 1)
            .filter(|&i| deflection[i] > deflection[i - 1] && deflection[i] >= deflection[i + 1])
            .map(|i| deflection[i])
            .collect();
        let cycles = (peaks.len() - 1) as f64;
        let decrement = (peaks[0] / peaks[peaks.len() - 1]).ln() / cycles;
        let measured = decrement / (4.0 * PI * PI + decrement * decrement).sqrt();
        let expected = closed_form_damping(scheme, omega_h);
        println!("{scheme:14?} {omega_h:8.2}  {measured:14.5}  {expected:12.5}");
        assert!(
            (measured / expected - 1.0).abs() < tolerance,
            "{scheme:?} at {omega_h}"
        );
    }
}

/// Tip heights every `sample` (s) over `samples` samples of the cantilever released under
/// gravity, integrated with `steps_per_sample` implicit steps per sample.
fn tip_trajectory(
    scheme: ImplicitScheme,
    steps_per_sample: u32,
    sample: f64,
    samples: usize,
) -> Vec<f64> {
    let material =
        Material::new(MaterialModel::StVenantKirchhoff, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut body, tip) = cantilever([10, 2, 2], material);
    let integrator = ImplicitIntegrator {
        scheme,
        tolerance: 1e-11,
        substeps: steps_per_sample,
        ..Default::default()
    };
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    (0..samples)
        .map(|_| {
            integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    sample,
                    gravity(),
                )
                .unwrap();
            body.positions()[tip].y
        })
        .collect()
}

#[test]
fn bdf2_converges_at_second_order() {
    // Largest tip error over 0.01 s (sampled every millisecond) against the same scheme at a step
    // 8x finer than the finest tested: halving the step divides the error by about 2 for backward
    // Euler and about 4 for BDF2 (observed order within 0.3).
    let (sample, samples) = (1e-3, 10);
    for (scheme, order) in [
        (ImplicitScheme::BackwardEuler, 1.0),
        (ImplicitScheme::Bdf2, 2.0),
    ] {
        let reference = tip_trajectory(scheme, 128, sample, samples);
        let errors: Vec<f64> = [4, 8, 16]
            .iter()
            .map(|&steps| {
                tip_trajectory(scheme, steps, sample, samples)
                    .iter()
                    .zip(&reference)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        let rates: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
        println!("{scheme:?}: largest tip errors {errors:?} m, observed orders {rates:?}");
        for rate in rates {
            assert!((rate - order).abs() < 0.3, "{scheme:?}: order {rate}");
        }
    }
}

#[test]
fn momentum_is_conserved_by_implicit_steps() {
    // Internal and damping forces sum to zero, so Σ m x̂ = Σ m x at the minimum: the momentum is
    // exact up to the Newton tolerance (1e-10 of the force scale; 1e-8 of m · 1 m/s allowed).
    for scheme in [ImplicitScheme::BackwardEuler, ImplicitScheme::Bdf2] {
        let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.4, 1000.0).unwrap();
        let mesh = mesh::sphere(0.1, 5).unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, material)
            .damping(RayleighDamping::stiffness_proportional(1e-3, material.lame()).unwrap())
            .build()
            .unwrap();
        let mut rng = Lcg(4);
        for v in body.velocities_mut() {
            *v = rng.vector();
        }
        let before = body.linear_momentum();
        let integrator = ImplicitIntegrator {
            scheme,
            tolerance: 1e-10,
            ..Default::default()
        };
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for _ in 0..10 {
            integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    DVec3::ZERO,
                )
                .unwrap();
        }
        let after = body.linear_momentum();
        println!("{scheme:?}: momentum before {before}, after {after}");
        assert!((after - before).length() < 1e-8 * body.total_mass());
    }
}

#[test]
fn a_refused_implicit_step_leaves_the_body_and_its_history_untouched() {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let (mut body, tip) = cantilever([6, 1, 1], material);
    let bdf2 = ImplicitIntegrator {
        scheme: ImplicitScheme::Bdf2,
        ..Default::default()
    };
    let (mut twin, _) = cantilever([6, 1, 1], material);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let (mut twin_constraints, mut twin_workspace) =
        (BodyConstraints::new(), SolverWorkspace::new());
    let (c, w) = (&mut constraints, &mut workspace);
    let (twin_c, twin_w) = (&mut twin_constraints, &mut twin_workspace);
    for _ in 0..3 {
        bdf2.step(&mut body, c, w, 0.01, gravity()).unwrap();
        bdf2.step(&mut twin, twin_c, twin_w, 0.01, gravity())
            .unwrap();
    }
    let before = (body.positions().to_vec(), body.velocities().to_vec());
    for bad in [
        bdf2.step(&mut body, c, w, 0.01, DVec3::new(f64::NAN, 0.0, 0.0)),
        ImplicitIntegrator {
            max_newton_iterations: 0,
            ..bdf2
        }
        .step(&mut body, c, w, 0.01, gravity()),
        ImplicitIntegrator {
            tolerance: -1.0,
            ..bdf2
        }
        .step(&mut body, c, w, 0.01, gravity()),
    ] {
        assert!(bad.is_err());
    }
    assert_eq!(
        (body.positions().to_vec(), body.velocities().to_vec()),
        before
    );
    // The BDF2 history survived: the next step matches the twin's to the last bit.
    bdf2.step(&mut body, c, w, 0.01, gravity()).unwrap();
    bdf2.step(&mut twin, twin_c, twin_w, 0.01, gravity())
        .unwrap();
    assert_eq!(body.positions()[tip], twin.positions()[tip]);
}

#[test]
fn invalid_implicit_steps_are_typed_errors() {
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    let (mut body, _) = cantilever([4, 1, 1], material);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let (c, w) = (&mut constraints, &mut workspace);
    assert!(matches!(
        ImplicitIntegrator::default().step(&mut body, c, w, -1.0, gravity()),
        Err(Error::InvalidTimeStep { .. })
    ));
    let zero = ImplicitIntegrator {
        substeps: 0,
        ..Default::default()
    };
    assert!(matches!(
        zero.step(&mut body, c, w, 0.01, gravity()),
        Err(Error::InvalidSetting {
            parameter: "substeps",
            ..
        })
    ));
}

fn conjugate_gradient(tolerance: f64, max_iterations: usize) -> LinearSolver {
    LinearSolver::ConjugateGradient {
        tolerance,
        max_iterations,
    }
}

/// The largest distance (m) between the nodes of two bodies.
fn largest_gap(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max)
}

#[test]
fn conjugate_gradient_and_direct_steps_agree() {
    // Ten frames of 1/60 s of a beam (E = 1 MPa) swinging far, so that Newton is nonlinear.
    // - Newton tolerance 1e-10, CG tolerance 1e-10: both minimize the same incremental potential
    //   to the same tolerance; a solve's error only enters through Newton's last (tiny) step, so
    //   the positions agree to about 1e-10 of the motion at worst. 1e-8 is allowed.
    // - Newton tolerance 1e-6 (the default) with CG at 1e-3: each run stops within 1e-6 of the
    //   force scale of the minimum, about 1e-6 of the motion; 1e-5 is allowed.
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, common::DENSITY).unwrap();
    let (beam, _) = cantilever([20, 2, 2], material);
    let run = |tolerance, linear_solver| {
        let integrator = ImplicitIntegrator {
            tolerance,
            linear_solver,
            ..Default::default()
        };
        let mut body = beam.clone();
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let mut linear_iterations = 0;
        for _ in 0..10 {
            let report = integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    gravity(),
                )
                .unwrap();
            assert!(report.converged);
            linear_iterations += report.linear_iterations;
        }
        (body, linear_iterations)
    };
    for (newton, cg, allowed) in [(1e-10, 1e-10, 1e-8), (1e-6, 1e-3, 1e-5)] {
        let (direct, direct_iterations) = run(newton, LinearSolver::Direct);
        let (iterative, cg_iterations) = run(newton, conjugate_gradient(cg, 10_000));
        let gap = largest_gap(direct.positions(), iterative.positions());
        let motion = largest_gap(direct.positions(), beam.positions());
        println!(
            "Newton {newton:e}, CG {cg:e}: largest gap {gap:.3e} m of {motion:.4} m of motion; {cg_iterations} CG iterations"
        );
        assert_eq!(direct_iterations, 0);
        assert!(cg_iterations > 0);
        assert!(gap < allowed * motion, "gap {gap} m");
    }
}

#[test]
fn conjugate_gradient_falls_back_to_the_projected_tangent_on_negative_curvature() {
    // A stable Neo-Hookean cube crushed flat (heights within ±1 mm), partly inverted: the exact
    // tangent is indefinite there, the conjugate gradient meets negative curvature and the
    // projected tangent is solved instead. Backward Euler only dissipates, so the energy
    // (kinetic + elastic, no gravity) must not rise beyond round-off (1e-9 relative).
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::splat(0.1), [4, 4, 4]).unwrap();
    let mut body = DeformableBodyBuilder::new(mesh, material).build().unwrap();
    let mut rng = Lcg(7);
    for x in body.positions_mut() {
        x.y = 1e-3 * rng.next();
    }
    let integrator = ImplicitIntegrator {
        linear_solver: conjugate_gradient(1e-6, 2000),
        ..Default::default()
    };
    let energy = |body: &DeformableBody| body.kinetic_energy() + body.elastic_energy();
    let (inverted, mut last) = (body.inverted_tet_count(), energy(&body));
    let (mut projected, mut cg_iterations) = (0, 0);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..30 {
        let report = integrator
            .step(
                &mut body,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                DVec3::ZERO,
            )
            .unwrap();
        projected += report.projected_tangents;
        cg_iterations += report.linear_iterations;
        assert!(body.positions().iter().all(|x| x.is_finite()));
        let next = energy(&body);
        assert!(
            next <= last * (1.0 + 1e-9),
            "energy rose: {last} -> {next} J"
        );
        last = next;
    }
    println!(
        "{inverted} tets inverted at the start; {projected} projected tangents, {cg_iterations} CG iterations over 30 frames; {} inverted, energy {last:.3e} J at the end",
        body.inverted_tet_count()
    );
    assert!(inverted > 0);
    assert!(projected > 0);
}

#[test]
fn invalid_conjugate_gradient_settings_are_typed_errors() {
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    let (mut body, _) = cantilever([4, 1, 1], material);
    let before = body.positions().to_vec();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for (solver, parameter) in [
        (conjugate_gradient(0.0, 100), "linear_solver.tolerance"),
        (conjugate_gradient(-1e-3, 100), "linear_solver.tolerance"),
        (conjugate_gradient(f64::NAN, 100), "linear_solver.tolerance"),
        (
            conjugate_gradient(f64::INFINITY, 100),
            "linear_solver.tolerance",
        ),
        (conjugate_gradient(1e-3, 0), "linear_solver.max_iterations"),
    ] {
        let integrator = ImplicitIntegrator {
            linear_solver: solver,
            ..Default::default()
        };
        match integrator.step(&mut body, &mut constraints, &mut workspace, 0.01, gravity()) {
            Err(Error::InvalidSetting { parameter: p, .. }) => assert_eq!(p, parameter),
            other => panic!("{solver:?}: {other:?}"),
        }
    }
    assert_eq!(body.positions(), &before[..]);
}

/// A body with the constraints and solver caches kept beside it.
type BodyState = (DeformableBody, BodyConstraints, SolverWorkspace);

/// A body that has not been stepped, with empty constraints and caches.
fn unstepped(body: &DeformableBody) -> BodyState {
    (body.clone(), BodyConstraints::new(), SolverWorkspace::new())
}

/// `frames` steps of `dt` (s) from `state` (a body with its constraints and solver caches),
/// asserting that each converged; the final state, the Newton iterations that reused a
/// factorization and the factorizations.
fn run_frames(
    integrator: &ImplicitIntegrator,
    state: &BodyState,
    frames: usize,
    dt: f64,
) -> (BodyState, usize, usize) {
    let (mut body, mut constraints, mut workspace) = state.clone();
    let (mut reused, mut factorizations) = (0, 0);
    for _ in 0..frames {
        let report = integrator
            .step(&mut body, &mut constraints, &mut workspace, dt, gravity())
            .unwrap();
        assert!(report.converged, "{report:?}");
        reused += report.reused_factorizations;
        factorizations += report.factorizations;
    }
    ((body, constraints, workspace), reused, factorizations)
}

#[test]
fn reusing_factorizations_meets_the_same_tolerance() {
    // Newton with the exact tangent at every iteration against Newton reusing earlier
    // factorizations (the chord method), both to the default tolerance 1e-6: each run stops
    // within 1e-6 of the force scale of the same minimum, so the positions agree to about 1e-6
    // of the motion per step; 1e-5 of the motion is allowed after the run.
    // - Linear model with stiffness-proportional damping (first mode critically damped), 120
    //   steps of 1/240 s: the tangent barely changes, so most iterations reuse.
    // - Stable Neo-Hookean beam (E = 1 MPa) swinging far, 10 steps of 1/60 s, then 10 of
    //   1/120 s: strongly nonlinear, and the step length changes.
    let linear = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let omega = 2.0 * PI * 5.07;
    let damping = RayleighDamping::stiffness_proportional(2.0 / omega, linear.lame()).unwrap();
    let (stiff, _) = common::damped_cantilever([10, 1, 1], linear, Some(damping));
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, common::DENSITY).unwrap();
    let (soft, _) = cantilever([20, 2, 2], rubber);
    let exact = ImplicitIntegrator {
        reuse_factorization: false,
        linear_solver: LinearSolver::Direct,
        ..Default::default()
    };
    let chord = ImplicitIntegrator {
        reuse_factorization: true,
        ..exact
    };
    let cases = [
        ("linear, damped", &stiff, &[(120, 1.0 / 240.0)][..]),
        (
            "Neo-Hookean",
            &soft,
            &[(10, 1.0 / 60.0), (10, 1.0 / 120.0)][..],
        ),
    ];
    for (label, start, schedule) in cases {
        let (mut with_exact, mut with_chord) = (unstepped(start), unstepped(start));
        let (mut reused, mut chord_factorizations, mut exact_factorizations) = (0, 0, 0);
        for &(frames, dt) in schedule {
            let (body, none, factorizations) = run_frames(&exact, &with_exact, frames, dt);
            assert_eq!(none, 0);
            exact_factorizations += factorizations;
            with_exact = body;
            let (body, some, factorizations) = run_frames(&chord, &with_chord, frames, dt);
            reused += some;
            chord_factorizations += factorizations;
            with_chord = body;
        }
        let gap = largest_gap(with_exact.0.positions(), with_chord.0.positions());
        let motion = largest_gap(with_exact.0.positions(), start.positions());
        println!(
            "{label}: gap {gap:.3e} m of {motion:.4} m of motion; exact Newton {exact_factorizations} factorizations, chord {chord_factorizations} factorizations and {reused} reuses"
        );
        assert!(gap < 1e-5 * motion, "{label}: gap {gap} m");
        assert!(reused > 0, "{label}");
    }
}

#[test]
fn the_report_counts_the_evaluations_of_the_energy() {
    // A Newton solve evaluates the energy where the body is and at the inertial prediction
    // (it starts from the lower), then at least once per iteration in its line search. A cube
    // at rest in zero gravity is at the minimum already: no iteration, exactly two
    // evaluations. Stretched 10 % along x and released, it iterates, and each iteration adds at
    // least one evaluation to those two.
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let cube = || {
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
            .build()
            .unwrap()
    };
    let step = |body: &mut DeformableBody| {
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        common::implicit_frame_without_gravity(body, &mut constraints, &mut workspace)
    };
    let mut resting = cube();
    let report = step(&mut resting);
    assert_eq!(
        (report.newton_iterations, report.energy_evaluations),
        (0, 2)
    );
    let mut stretched = cube();
    for x in stretched.positions_mut() {
        x.x *= 1.1;
    }
    let report = step(&mut stretched);
    assert!(report.newton_iterations > 0, "{report:?}");
    assert!(
        report.energy_evaluations >= 2 + report.newton_iterations,
        "{report:?}"
    );
}
