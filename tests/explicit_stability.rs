//! The explicit stability limit: the computed critical step `1.5 ℓ / c_p` (damping-corrected)
//! lies below the true limit `2/ω_max` of every generated mesh and within 25 % of it; a step 1.5x
//! over it makes the energy explode; the automatic substeps keep every case bounded; failures are
//! typed errors that keep the previous state.

mod common;

use common::{Lcg, highest_angular_frequency};
use rapier_fvm::prelude::*;

fn meshes() -> Vec<(&'static str, TetMesh)> {
    vec![
        (
            "cube 4^3",
            mesh::cuboid(DVec3::splat(0.1), [4, 4, 4]).unwrap(),
        ),
        (
            "beam 20x2x2",
            mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [20, 2, 2]).unwrap(),
        ),
        (
            "plate 8x8x1",
            mesh::cuboid(DVec3::new(0.1, 0.1, 0.01), [8, 8, 1]).unwrap(),
        ),
        ("cylinder", mesh::cylinder(0.1, 0.2, 6, 6).unwrap()),
        ("sphere", mesh::sphere(0.1, 8).unwrap()),
    ]
}

#[test]
fn computed_critical_step_is_below_and_close_to_the_true_limit() {
    // Nodal averaging lowers the highest frequency (its volumetric energy is at most the
    // per-element one), so the same estimate stays safe; it is only checked from above there.
    println!(
        "mesh          nu   treatment      true limit / (ℓ/c_p)  true / (h_min/c_p)  computed / true"
    );
    for treatment in [
        VolumetricTreatment::PerElement,
        VolumetricTreatment::NodalAverage,
    ] {
        for nu in [-0.5, 0.0, 0.3, 0.45, 0.49] {
            for (name, mesh) in meshes() {
                let material = Material::new(MaterialModel::Linear, 1e6, nu, 1000.0).unwrap();
                let mut body = DeformableBodyBuilder::new(mesh, material)
                    .volumetric(treatment)
                    .build()
                    .unwrap();
                let true_limit = 2.0 / highest_angular_frequency(&mut body);
                let computed = SymplecticEuler::critical_time_step(&body);
                let altitude = body.mesh().min_altitude() / material.dilatational_wave_speed();
                let wave = body.wave_length_scale() / material.dilatational_wave_speed();
                println!(
                    "{name:12} {nu:5}  {treatment:?}  {:20.3}  {:20.3}  {:15.3}",
                    true_limit / wave,
                    true_limit / altitude,
                    computed / true_limit
                );
                assert!(
                    computed <= true_limit,
                    "{name}, nu = {nu}, {treatment:?}: computed step above the true limit ({})",
                    computed / true_limit
                );
                if treatment == VolumetricTreatment::PerElement {
                    assert!(
                        computed >= 0.75 * true_limit,
                        "{name}, nu = {nu}: estimate too pessimistic"
                    );
                }
            }
        }
    }
}

/// A beam with every mode excited by a random displacement.
fn excited_beam(damping_time: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1e6, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.25, 0.05, 0.05), [10, 2, 2]).unwrap();
    let mut builder = DeformableBodyBuilder::new(mesh, material);
    if damping_time > 0.0 {
        builder = builder.damping(
            RayleighDamping::stiffness_proportional(damping_time, material.lame()).unwrap(),
        );
    }
    let mut body = builder.build().unwrap();
    let mut rng = Lcg(3);
    for x in body.positions_mut() {
        *x += rng.vector() * 1e-5;
    }
    body
}

fn mechanical_energy(body: &DeformableBody) -> f64 {
    body.kinetic_energy() + body.elastic_energy()
}

/// Energy after `steps` single steps of `dt`, over the initial energy; infinite if it blew up.
fn energy_growth(mut body: DeformableBody, dt: f64, steps: usize) -> f64 {
    let initial = mechanical_energy(&body);
    let integrator = SymplecticEuler {
        substeps: Substeps::Fixed(1),
        ..Default::default()
    };
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..steps {
        if integrator
            .step(&mut body, &mut constraints, &mut workspace, dt, DVec3::ZERO)
            .is_err()
        {
            return f64::INFINITY;
        }
    }
    mechanical_energy(&body) / initial
}

#[test]
fn steps_above_the_limit_explode_and_automatic_substeps_do_not() {
    for damping_time in [0.0, 2e-3] {
        let body = excited_beam(damping_time);
        let critical = SymplecticEuler::critical_time_step(&body);
        let above = energy_growth(body.clone(), 1.5 * critical, 400);
        let safe = SymplecticEuler::default().stable_time_step(&body);
        let short = energy_growth(body.clone(), safe, 400);
        let long = energy_growth(body.clone(), safe, 4000);
        println!(
            "damping time {damping_time:e} s: critical step {critical:.3e} s; energy x{above:.3e} \
             after 400 steps at 1.5x; x{short:.3} after 400 and x{long:.3} after 4000 at the automatic step"
        );
        assert!(
            above > 1e3,
            "1.5x the limit must be unstable (growth {above})"
        );
        // Symplectic Euler's measured energy oscillates by O(h ω) around a conserved value, it does
        // not grow: bounded by 1.5 after 400 and after 4000 steps.
        assert!(
            short < 1.5 && long < 1.5,
            "the automatic step must not gain energy"
        );
    }
}

#[test]
fn automatic_substeps_keep_every_case_bounded() {
    // A cantilever released from rest under gravity: its total energy (kinetic + elastic +
    // gravitational) can only stay at or below zero, its initial value, up to the integrator's
    // bounded energy error.
    let frame = 1.0 / 60.0;
    for young in [1e4, 1e6, 1e8] {
        for nu in [-0.5, 0.0, 0.3, 0.45, 0.49] {
            for model in [
                MaterialModel::StVenantKirchhoff,
                MaterialModel::StableNeoHookean,
            ] {
                for damping_time in [0.0, 1e-3] {
                    let material = Material::new(model, young, nu, 1000.0).unwrap();
                    let damping = (damping_time > 0.0).then(|| {
                        RayleighDamping::stiffness_proportional(damping_time, material.lame())
                            .unwrap()
                    });
                    let (mut body, _) = common::damped_cantilever([6, 1, 1], material, damping);
                    let gravity = common::gravity();
                    let start = body.gravity_potential_energy(gravity);
                    let weight_scale = body.total_mass() * common::GRAVITY * common::LENGTH;
                    let integrator = SymplecticEuler::default();
                    let (mut constraints, mut workspace) =
                        (BodyConstraints::new(), SolverWorkspace::new());
                    for _ in 0..20 {
                        integrator
                            .step(&mut body, &mut constraints, &mut workspace, frame, gravity)
                            .unwrap();
                    }
                    let total = body.kinetic_energy()
                        + body.elastic_energy()
                        + body.gravity_potential_energy(gravity)
                        - start;
                    assert!(
                        total.is_finite() && total <= 0.01 * weight_scale,
                        "E = {young}, nu = {nu}, {model:?}, damping {damping_time}: energy {total}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_non_finite_state_is_rejected_and_the_previous_state_kept() {
    let mut body = excited_beam(0.0);
    body.velocities_mut()[5].y = f64::NAN;
    let before = (body.positions().to_vec(), body.velocities()[..5].to_vec());
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let err = SymplecticEuler::default()
        .step(
            &mut body,
            &mut constraints,
            &mut workspace,
            1.0 / 60.0,
            DVec3::ZERO,
        )
        .unwrap_err();
    assert!(matches!(err, Error::NonFiniteState { .. }));
    assert_eq!(body.positions(), &before.0[..]);
    assert_eq!(&body.velocities()[..5], &before.1[..]);
}

#[test]
fn invalid_steps_are_typed_errors() {
    let mut body = excited_beam(0.0);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let (c, w) = (&mut constraints, &mut workspace);
    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            SymplecticEuler::default().step(&mut body, c, w, dt, DVec3::ZERO),
            Err(Error::InvalidTimeStep { .. })
        ));
    }
    let zero_substeps = SymplecticEuler {
        substeps: Substeps::Fixed(0),
        ..Default::default()
    };
    assert!(matches!(
        zero_substeps.step(&mut body, c, w, 0.01, DVec3::ZERO),
        Err(Error::InvalidSetting {
            parameter: "substeps",
            ..
        })
    ));
    let bad_safety = SymplecticEuler {
        safety_factor: 1.5,
        ..Default::default()
    };
    assert!(matches!(
        bad_safety.step(&mut body, c, w, 0.01, DVec3::ZERO),
        Err(Error::InvalidSetting {
            parameter: "safety_factor",
            ..
        })
    ));
    assert!(matches!(
        SymplecticEuler::default().step(&mut body, c, w, 0.01, DVec3::new(0.0, f64::NAN, 0.0)),
        Err(Error::NonFiniteInput {
            parameter: "gravity"
        })
    ));
    // A frame that would need more substeps than allowed is refused, state untouched.
    let before = body.positions().to_vec();
    let capped = SymplecticEuler {
        max_substeps: 10,
        ..Default::default()
    };
    assert!(matches!(
        capped.step(&mut body, c, w, 1.0, DVec3::ZERO),
        Err(Error::TooManySubsteps { max: 10, .. })
    ));
    assert_eq!(body.positions(), &before[..]);
}

#[test]
fn a_damped_body_with_a_flat_element_is_refused_not_stepped() {
    // A flat element makes the stable step zero; with damping the estimate must stay zero (not
    // NaN, which would let a single huge substep through).
    let mut body = excited_beam(1e-3);
    for x in body.positions_mut() {
        x.z = 0.0;
    }
    assert_eq!(SymplecticEuler::critical_time_step(&body), 0.0);
    let before = body.positions().to_vec();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    assert!(matches!(
        SymplecticEuler::default().step(
            &mut body,
            &mut constraints,
            &mut workspace,
            1.0 / 60.0,
            DVec3::ZERO
        ),
        Err(Error::TooManySubsteps { .. })
    ));
    assert_eq!(body.positions(), &before[..]);
}
