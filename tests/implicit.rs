//! Backward Euler: stability at huge steps on stiff material, the static limit, agreement with the
//! explicit integrator at small steps, its numerical damping against the closed form, and exact
//! momentum conservation.

mod common;

use common::{Lcg, cantilever, gravity};
use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};
use std::f64::consts::PI;
use std::time::Instant;

fn total_energy(body: &SoftBody) -> f64 {
    body.kinetic_energy() + body.elastic_energy() + body.gravity_potential_energy(gravity())
}

#[test]
fn huge_steps_on_a_stiff_beam_stay_stable_and_never_gain_energy() {
    // E = 1 GPa at 1/30 s: the explicit limit is about 2e-5 s, 1500 substeps per frame.
    for model in [
        MaterialModel::StVenantKirchhoff,
        MaterialModel::StableNeoHookean,
    ] {
        let material = Material::new(model, 1e9, 0.3, common::DENSITY).unwrap();
        let (mut body, tip) = cantilever([20, 2, 2], material);
        let explicit_substeps =
            (1.0 / 30.0 / SymplecticEuler::default().stable_time_step(&body)).ceil();
        let integrator = BackwardEuler::default();
        let mut energy = total_energy(&body);
        let start = Instant::now();
        let mut iterations = 0;
        for _ in 0..30 {
            let report = integrator.step(&mut body, 1.0 / 30.0, gravity()).unwrap();
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
    let integrator = BackwardEuler::default();
    for _ in 0..200 {
        integrator.step(&mut body, 1.0 / 60.0, gravity()).unwrap();
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
    for _ in 0..frames {
        BackwardEuler::default()
            .step(&mut implicit, frame, gravity())
            .unwrap();
        SymplecticEuler::default()
            .step(&mut explicit, frame, gravity())
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

#[test]
fn numerical_damping_matches_the_backward_euler_closed_form() {
    // For ẍ = -ω² x backward Euler multiplies the mode by z = 1/(1 - iωh) per step, an
    // equivalent damping ratio ζ = -Re(s)/|s| with s = ln(z)/h. Measured on the undamped first
    // bending mode by the logarithmic decrement of the tip, within 5 %.
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let (mut released, tip) = cantilever([10, 2, 2], material);
    statics::solve_equilibrium(&mut released, gravity(), &StaticSettings::default()).unwrap();
    let omega = 2.0 * PI * statics::fundamental_frequency(&released).unwrap();
    println!(" omega h   measured zeta   closed form");
    for omega_h in [0.05, 0.2] {
        let h = omega_h / omega;
        let mut body = released.clone();
        let rest = body.mesh().positions()[tip].y;
        let steps = (3.0 * 2.0 * PI / omega_h).ceil() as usize;
        let deflection: Vec<f64> = (0..steps)
            .map(|_| {
                BackwardEuler::default()
                    .step(&mut body, h, DVec3::ZERO)
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
        let (re, im) = (-0.5 * (1.0 + omega_h * omega_h).ln(), omega_h.atan());
        let expected = -re / (re * re + im * im).sqrt();
        println!("{omega_h:8.2}  {measured:14.5}  {expected:12.5}");
        assert!((measured / expected - 1.0).abs() < 0.05);
    }
}

#[test]
fn momentum_is_conserved_by_implicit_steps() {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.4, 1000.0).unwrap();
    let mesh = mesh::sphere(0.1, 5).unwrap();
    let mut body = SoftBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(1e-3, material.lame()).unwrap())
        .build()
        .unwrap();
    let mut rng = Lcg(4);
    for v in body.velocities_mut() {
        *v = rng.vector();
    }
    let before = body.linear_momentum();
    let integrator = BackwardEuler {
        tolerance: 1e-10,
        ..Default::default()
    };
    for _ in 0..10 {
        integrator.step(&mut body, 1.0 / 60.0, DVec3::ZERO).unwrap();
    }
    let after = body.linear_momentum();
    let scale = body.total_mass() * 1.0;
    println!("momentum before {before}, after {after}");
    assert!((after - before).length() < 1e-8 * scale);
}

#[test]
fn invalid_implicit_steps_are_typed_errors() {
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    let (mut body, _) = cantilever([4, 1, 1], material);
    assert!(matches!(
        BackwardEuler::default().step(&mut body, -1.0, gravity()),
        Err(Error::InvalidTimeStep { .. })
    ));
    let zero = BackwardEuler {
        substeps: 0,
        ..Default::default()
    };
    assert!(matches!(
        zero.step(&mut body, 0.01, gravity()),
        Err(Error::InvalidTimeStep { .. })
    ));
}
