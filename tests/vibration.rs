//! Free vibration of the reference cantilever: the first bending frequency against
//! Euler–Bernoulli, the explicit integrator against the modal analysis, energy conservation
//! without damping, and the damping ratio of Rayleigh damping.

mod common;

use common::{cantilever, euler_bernoulli_first_frequency};
use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};
use std::f64::consts::PI;

const YOUNG: f64 = 1e8;

fn material(model: MaterialModel) -> Material {
    Material::new(model, YOUNG, 0.3, common::DENSITY).unwrap()
}

#[test]
fn first_bending_frequency_converges_to_euler_bernoulli() {
    // Modal analysis of the discrete model (inverse iteration on K φ = ω² M φ). Linear tets are
    // stiff in bending, so the frequency falls toward the reference as the mesh is refined;
    // within 3 % at the finest mesh (Timoshenko's shear and rotary inertia would lower the
    // reference itself by about 1 % at L/h = 10).
    let reference = euler_bernoulli_first_frequency(YOUNG);
    println!("Euler-Bernoulli reference {reference:.4} Hz");
    let mut previous_error = f64::INFINITY;
    for n in [1, 2, 4, 6, 8, 10] {
        let (body, _) = cantilever([10 * n, n, n], material(MaterialModel::Linear));
        let frequency = statics::fundamental_frequency(&body).unwrap();
        let error = frequency / reference - 1.0;
        println!(
            "[{}, {n}, {n}]: {frequency:.4} Hz, error {:+.2} %",
            10 * n,
            100.0 * error
        );
        assert!(error.abs() < previous_error);
        previous_error = error.abs();
    }
    assert!(previous_error < 0.03, "finest mesh error {previous_error}");
}

/// Deflects the beam to its static shape under gravity, then releases it without gravity.
fn released_from_static_deflection(
    cells: [usize; 3],
    model: MaterialModel,
    damping: Option<RayleighDamping>,
) -> (DeformableBody, usize) {
    let (mut body, tip) = cantilever(cells, material(model));
    statics::solve_equilibrium(&mut body, common::gravity(), &StaticSettings::default()).unwrap();
    let (mut released, _) = common::damped_cantilever(cells, material(model), damping);
    released.positions_mut().copy_from_slice(body.positions());
    (released, tip)
}

/// Tip height (m) sampled every `dt` (s) for `duration` (s), with automatic substeps.
fn tip_history(body: &mut DeformableBody, tip: usize, dt: f64, duration: f64) -> Vec<f64> {
    let integrator = SymplecticEuler::default();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    (0..(duration / dt).round() as usize)
        .map(|_| {
            integrator
                .step(body, &mut constraints, &mut workspace, dt, DVec3::ZERO)
                .unwrap();
            body.positions()[tip].y
        })
        .collect()
}

/// Times (s) and values of the local maxima of `signal` sampled every `dt`, refined by a parabola
/// through the three samples around each.
fn peaks(signal: &[f64], dt: f64) -> Vec<(f64, f64)> {
    (1..signal.len() - 1)
        .filter(|&i| signal[i] > signal[i - 1] && signal[i] >= signal[i + 1])
        .map(|i| {
            let (a, b, c) = (signal[i - 1], signal[i], signal[i + 1]);
            let offset = 0.5 * (a - c) / (a - 2.0 * b + c);
            let time = (i as f64 + 1.0 + offset) * dt;
            (time, b - 0.25 * (a - c) * offset)
        })
        .collect()
}

#[test]
fn explicit_dynamics_vibrates_at_the_modal_frequency() {
    // The time integration reproduces the discrete model's own frequency: period from the peaks
    // of the released tip over 10 periods, within 0.5 % of the modal analysis. (An even number of
    // cells across keeps the mesh symmetric under a quarter turn about the beam axis, so the
    // vertical and horizontal bending modes share one frequency and gravity excites only one.)
    for cells in [[10, 2, 2], [20, 2, 2]] {
        let (mut body, tip) =
            released_from_static_deflection(cells, MaterialModel::StVenantKirchhoff, None);
        let modal = statics::fundamental_frequency(&body).unwrap();
        let dt = 1.0 / (modal * 200.0);
        let history = tip_history(&mut body, tip, dt, 10.5 / modal);
        let peaks = peaks(&history, dt);
        let measured = (peaks.len() - 1) as f64 / (peaks.last().unwrap().0 - peaks[0].0);
        println!("{cells:?}: dynamics {measured:.4} Hz, modal analysis {modal:.4} Hz");
        assert!((measured / modal - 1.0).abs() < 5e-3);
    }
}

#[test]
fn undamped_vibration_has_no_secular_energy_drift() {
    // Symplectic Euler conserves a modified energy: the measured total energy oscillates by
    // O(h ω) around a constant but does not drift. Over 50 periods the mean energy of the last
    // period is within 1e-4 of the first period's, and no sample strays by more than 1 %.
    let (mut body, tip) =
        released_from_static_deflection([10, 2, 2], MaterialModel::StVenantKirchhoff, None);
    let frequency = statics::fundamental_frequency(&body).unwrap();
    let per_period = 100;
    let dt = 1.0 / (frequency * per_period as f64);
    let integrator = SymplecticEuler::default();
    let initial = body.elastic_energy();
    let mut energies = Vec::new();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..50 * per_period {
        integrator
            .step(&mut body, &mut constraints, &mut workspace, dt, DVec3::ZERO)
            .unwrap();
        energies.push(body.kinetic_energy() + body.elastic_energy());
    }
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64;
    let drift =
        (mean(&energies[energies.len() - per_period..]) - mean(&energies[..per_period])) / initial;
    let spread = energies
        .iter()
        .map(|e| (e / initial - 1.0).abs())
        .fold(0.0, f64::max);
    let amplitude = (body.positions()[tip].y - body.mesh().positions()[tip].y).abs();
    println!(
        "50 periods: drift of the period-mean energy {drift:.2e}, largest deviation {spread:.2e}, tip displacement now {:.3} mm",
        amplitude * 1e3
    );
    assert!(drift.abs() < 1e-4);
    assert!(spread < 1e-2);
}

#[test]
fn rayleigh_damping_gives_damping_ratio_beta_omega_over_two() {
    // φ = βλ, ψ = βμ makes the damping matrix βK, so the first mode decays with ζ = βω/2. The
    // measured ζ (logarithmic decrement over 6 periods of the tip) is within 5 % of βω/2, with ω
    // the measured undamped natural frequency ω_d / sqrt(1 - ζ²).
    let (undamped, _) = cantilever([10, 2, 2], material(MaterialModel::Linear));
    let omega_modal = 2.0 * PI * statics::fundamental_frequency(&undamped).unwrap();
    for target in [0.01, 0.05] {
        let beta = 2.0 * target / omega_modal;
        let damping =
            RayleighDamping::stiffness_proportional(beta, material(MaterialModel::Linear).lame())
                .unwrap();
        let (mut body, tip) =
            released_from_static_deflection([10, 2, 2], MaterialModel::Linear, Some(damping));
        let rest = body.mesh().positions()[tip].y;
        let dt = 2.0 * PI / omega_modal / 200.0;
        let history: Vec<f64> = tip_history(&mut body, tip, dt, 6.5 * 2.0 * PI / omega_modal)
            .iter()
            .map(|y| rest - y)
            .collect();
        // Peaks of the downward deflection (the release point is the first maximum).
        let peaks = peaks(&history, dt);
        let cycles = (peaks.len() - 1) as f64;
        let (first, last) = (peaks[0], *peaks.last().unwrap());
        let decrement = (first.1 / last.1).ln() / cycles;
        let zeta = decrement / (4.0 * PI * PI + decrement * decrement).sqrt();
        let omega_damped = 2.0 * PI * cycles / (last.0 - first.0);
        let omega = omega_damped / (1.0 - zeta * zeta).sqrt();
        let expected = beta * omega / 2.0;
        println!(
            "target {target}: measured zeta {zeta:.5}, beta omega / 2 = {expected:.5} (omega {omega:.3} rad/s, modal {omega_modal:.3})"
        );
        assert!((zeta / expected - 1.0).abs() < 0.05);
    }
}
