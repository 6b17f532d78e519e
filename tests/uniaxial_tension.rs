//! Uniaxial tension of a bar with free lateral faces (linear elasticity): the axial stress is
//! `E ε` and the lateral strain `-ν ε`, both to 1e-6 relative.
//!
//! The bar is stretched homogeneously by `ε` along x; its lateral strain `s` is the unknown. For
//! each trial `s` the finite-volume forces are computed; the free lateral faces and the interior
//! must carry no force. Those forces are linear in `s`, so two trials give the `s` at which they
//! vanish: the discrete model's own lateral strain. The axial stress is the resultant of the nodal
//! forces on the end face divided by its area.

mod common;

use rapier_fvm::prelude::*;

const HALF: DVec3 = DVec3::new(0.3, 0.05, 0.05);
const STRAIN: f64 = 1e-4;

/// Nodal forces of the bar stretched by `STRAIN` along x and `lateral` along y and z.
fn forces(body: &mut DeformableBody, lateral: f64) -> Vec<DVec3> {
    let rest: Vec<DVec3> = body.mesh().positions().to_vec();
    let stretch = DVec3::new(1.0 + STRAIN, 1.0 + lateral, 1.0 + lateral);
    for (x, p) in body.positions_mut().iter_mut().zip(&rest) {
        *x = *p * stretch;
    }
    body.internal_forces().to_vec()
}

fn on_end_face(p: DVec3) -> bool {
    (p.x.abs() - HALF.x).abs() < 1e-9
}

/// Net y force on the nodes of the +y lateral face (away from the end faces).
fn lateral_face_force(rest: &[DVec3], forces: &[DVec3]) -> f64 {
    rest.iter()
        .zip(forces)
        .filter(|(p, _)| (p.y - HALF.y).abs() < 1e-9 && !on_end_face(**p))
        .map(|(_, f)| f.y)
        .sum()
}

#[test]
fn uniaxial_tension_gives_e_epsilon_and_minus_nu_epsilon() {
    for nu in [0.0, 0.3, 0.45, -0.3] {
        let e = 2e9;
        let material = Material::new(MaterialModel::Linear, e, nu, 1000.0).unwrap();
        let mesh = mesh::cuboid(HALF, [6, 3, 2]).unwrap();
        let rest = mesh.positions().to_vec();
        let mut body = DeformableBodyBuilder::new(mesh, material).build().unwrap();

        let r0 = lateral_face_force(&rest, &forces(&mut body, 0.0));
        let r1 = lateral_face_force(&rest, &forces(&mut body, -STRAIN));
        // r(s) = r0 + (s / -STRAIN)(r1 - r0) = 0.
        let lateral = STRAIN * r0 / (r1 - r0);
        let equilibrium = forces(&mut body, lateral);

        // Everything but the end faces is free of force at that lateral strain.
        let largest = equilibrium.iter().map(|f| f.length()).fold(0.0, f64::max);
        for (p, f) in rest.iter().zip(&equilibrium) {
            if !on_end_face(*p) {
                assert!(f.length() < 1e-9 * largest, "node at {p} carries {f}");
            }
        }
        let end_force: f64 = rest
            .iter()
            .zip(&equilibrium)
            .filter(|(p, _)| p.x > HALF.x - 1e-9)
            .map(|(_, f)| f.x)
            .sum();
        // The internal force on the end face is the reaction: the applied traction is -end_force.
        let axial_stress = -end_force / (4.0 * HALF.y * HALF.z);
        let stress_error = (axial_stress - e * STRAIN).abs() / (e * STRAIN);
        let lateral_error = (lateral + nu * STRAIN).abs() / STRAIN;
        println!(
            "nu = {nu}: axial stress {axial_stress:.6e} Pa (E eps = {:.6e}, error {stress_error:.1e}), \
             lateral strain {lateral:.6e} (-nu eps = {:.6e}, error {lateral_error:.1e} of eps)",
            e * STRAIN,
            -nu * STRAIN
        );
        assert!(stress_error < 1e-6, "axial stress error {stress_error:e}");
        assert!(
            lateral_error < 1e-6,
            "lateral strain error {lateral_error:e}"
        );
    }
}
