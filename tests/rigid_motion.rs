//! Rigid motion: a rotated and translated body, spinning and drifting, carries no elastic and no
//! damping force for the rotation-invariant models (to 1e-10 of the force a 1 % strain would
//! produce, i.e. round-off); the linear model's spurious stress under rotation is measured against
//! its closed form.

mod common;

use common::{Lcg, OBJECTIVE_MODELS};
use rapier_fvm::prelude::*;

const YOUNG: f64 = 1e7;

fn body(model: MaterialModel) -> DeformableBody {
    let material = Material::new(model, YOUNG, 0.3, 1000.0).unwrap();
    let damping = RayleighDamping::stiffness_proportional(0.05, material.lame()).unwrap();
    let mesh = mesh::sphere(0.1, 5).unwrap();
    DeformableBodyBuilder::new(mesh, material)
        .damping(damping)
        .build()
        .unwrap()
}

/// Places the body at `x = R p + t` with velocity `v = ω x (x - t) + v0`.
fn move_rigidly(body: &mut DeformableBody, rotation: DQuat, spin: DVec3, drift: DVec3) {
    let translation = DVec3::new(1.0, -2.0, 0.5);
    let rest = body.mesh().positions().to_vec();
    for (n, p) in rest.iter().enumerate() {
        let x = rotation * *p + translation;
        body.positions_mut()[n] = x;
        body.velocities_mut()[n] = spin.cross(x - translation) + drift;
    }
}

/// The force scale of a 1 % strain on this mesh: E * 0.01 * (area of a typical face).
fn force_scale(body: &DeformableBody) -> f64 {
    YOUNG * 0.01 * body.mesh().min_altitude().powi(2)
}

#[test]
fn rigid_motion_produces_no_force_for_rotation_invariant_models() {
    let mut rng = Lcg(42);
    for model in OBJECTIVE_MODELS {
        let mut body = body(model);
        let scale = force_scale(&body);
        for degrees in [0.0, 30.0, 90.0, 135.0, 179.0, 180.0] {
            let axis = rng.vector().normalize();
            let rotation = DQuat::from_axis_angle(axis, f64::to_radians(degrees));
            move_rigidly(&mut body, rotation, rng.vector() * 5.0, rng.vector() * 3.0);
            let largest = body
                .internal_forces()
                .iter()
                .map(|f| f.length())
                .fold(0.0, f64::max);
            assert!(
                largest < 1e-10 * scale,
                "{model:?} at {degrees} degrees: force {largest:e} N vs scale {scale:e} N"
            );
            // Energy of a 1 % strain: E (0.01)² V / 2.
            let energy_scale = 0.5 * YOUNG * 1e-4 * body.mesh().volume();
            assert!(body.elastic_energy().abs() < 1e-10 * energy_scale);
        }
    }
}

#[test]
fn damping_ignores_rigid_spin_even_for_the_linear_model() {
    // Damping acts on the Green strain rate, whatever the elastic model: at rest shape, a pure
    // spin gives no damping force. The linear model's elastic force vanishes at zero rotation.
    let mut body = body(MaterialModel::Linear);
    let scale = force_scale(&body);
    move_rigidly(
        &mut body,
        DQuat::IDENTITY,
        DVec3::new(3.0, -7.0, 2.0),
        DVec3::ONE,
    );
    let largest = body
        .internal_forces()
        .iter()
        .map(|f| f.length())
        .fold(0.0, f64::max);
    assert!(largest < 1e-10 * scale, "{largest:e}");
}

#[test]
fn linear_model_spurious_energy_under_rotation_matches_its_closed_form() {
    // Rotating by θ about a unit axis a gives the linear model the strain
    // ε = sym(R) - I = (cos θ - 1)(I - a aᵀ), hence the energy density
    // μ ε:ε + λ/2 tr(ε)² = (1 - cos θ)² (2 μ + 2 λ): no force for the right reason is possible.
    let mut body = body(MaterialModel::Linear);
    let lame = body.material().lame();
    let volume = body.mesh().volume();
    println!(
        "rotation  spurious energy (J)  closed form (J)  largest spurious force / 1% strain force"
    );
    for degrees in [1.0, 10.0, 30.0, 90.0, 180.0] {
        let theta = f64::to_radians(degrees);
        let axis = DVec3::new(1.0, 1.0, 0.0).normalize();
        move_rigidly(
            &mut body,
            DQuat::from_axis_angle(axis, theta),
            DVec3::ZERO,
            DVec3::ZERO,
        );
        let energy = body.elastic_energy();
        let expected = volume * (1.0 - theta.cos()).powi(2) * 2.0 * (lame.mu + lame.lambda);
        let scale = force_scale(&body);
        let largest = body
            .internal_forces()
            .iter()
            .map(|f| f.length())
            .fold(0.0, f64::max);
        println!(
            "{degrees:7.1}  {energy:18.6e}  {expected:15.6e}  {:.3e}",
            largest / scale
        );
        assert!((energy - expected).abs() <= 1e-9 * expected);
    }
}
