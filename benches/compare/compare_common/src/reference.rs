//! Scene constants and closed-form references, the same as `benches/compare/common.py`.

use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// Gravity (m/s^2): along -z in the peers' scripts and `rapier_builtin`, along -y (rapier's
/// default) in `compare_cases`.
pub const G: f64 = 9.81;

/// Cantilever length (m); clamped at x = 0.
pub const BEAM_L: f64 = 1.0;
/// Cantilever section width and height (m).
pub const BEAM_B: f64 = 0.1;
/// Cantilever section height (m).
pub const BEAM_H: f64 = 0.1;
/// Cantilever density (kg/m^3).
pub const BEAM_RHO: f64 = 1000.0;
/// Cantilever Young's modulus (Pa).
pub const BEAM_E: f64 = 1e8;
/// Cantilever Poisson's ratio of scenes 1 and 3.
pub const BEAM_NU: f64 = 0.3;
/// Poisson's ratios of scene 2.
pub const POISSON_SWEEP: [f64; 5] = [0.0, 0.3, 0.45, 0.49, 0.499];

/// Young's modulus of the contact scenes' soft bodies (Pa).
pub const SOFT_E: f64 = 1e5;
/// Poisson's ratio of the contact scenes' soft bodies.
pub const SOFT_NU: f64 = 0.3;
/// Density of the contact scenes' soft bodies (kg/m^3).
pub const SOFT_RHO: f64 = 1000.0;
/// Edge of the dropped (and the scaling) cube (m).
pub const DROP_SIZE: f64 = 0.2;
/// Height of the dropped cube's bottom face at release (m).
pub const DROP_HEIGHT: f64 = 0.5;
/// The soft block under the rigid box (m), bottom face pinned at z = 0.
pub const BLOCK_SIZE: [f64; 3] = [0.3, 0.3, 0.1];
/// Edge of the rigid box (m).
pub const BOX_SIZE: f64 = 0.1;
/// Mass of the rigid box (kg).
pub const BOX_MASS: f64 = 1.0;
/// Friction coefficient of every contact scene.
pub const FRICTION: f64 = 0.5;
/// The scaling scene stops before a size predicted to take longer than this (s).
pub const SCALING_CASE_BUDGET_S: f64 = 30.0;
/// Stiffness-proportional damping time of the contact and scaling scenes (s).
pub const SOFT_BETA: f64 = 0.01;

/// Shear correction of a rectangular section (Cowper 1966): 10(1+nu)/(12+11nu).
pub fn cowper_kappa(nu: f64) -> f64 {
    10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)
}

/// Euler-Bernoulli tip deflection of the cantilever under its own weight: q L^4 / (8 E I).
pub fn beam_eb_tip() -> f64 {
    let q = BEAM_RHO * G * BEAM_B * BEAM_H;
    let i = BEAM_B * BEAM_H.powi(3) / 12.0;
    q * BEAM_L.powi(4) / (8.0 * BEAM_E * i)
}

/// Timoshenko tip deflection: q L^4/(8 E I) + q L^2/(2 kappa G A), kappa from Cowper.
pub fn beam_timoshenko_tip(nu: f64) -> f64 {
    let q = BEAM_RHO * G * BEAM_B * BEAM_H;
    let shear = BEAM_E / (2.0 * (1.0 + nu));
    beam_eb_tip() + q * BEAM_L.powi(2) / (2.0 * cowper_kappa(nu) * shear * BEAM_B * BEAM_H)
}

/// First clamped-free bending frequency (Hz): (1.87510)^2 / (2 pi L^2) sqrt(E I / (rho A)).
pub fn beam_eb_frequency() -> f64 {
    let (i, a) = (BEAM_B * BEAM_H.powi(3) / 12.0, BEAM_B * BEAM_H);
    1.875_104_068_7_f64.powi(2) / (2.0 * PI * BEAM_L.powi(2)) * (BEAM_E * i / (BEAM_RHO * a)).sqrt()
}

/// First clamped-free frequency (Hz) of the Timoshenko beam (shear kappa G A, rotary inertia
/// rho I) with `n` two-node elements (one-point shear integration, lumped mass), by inverse
/// iteration; `common.py` solves the same model (converged to ~1e-5 at n = 400).
pub fn beam_timoshenko_frequency(nu: f64, n: usize) -> f64 {
    let (stiffness, mass) = timoshenko_system(nu, n);
    let chol = stiffness
        .clone()
        .cholesky()
        .expect("the clamped Timoshenko stiffness is positive definite");
    let mut x = DVector::from_element(mass.len(), 1.0);
    let mut lambda = f64::NAN;
    for _ in 0..100 {
        x = chol.solve(&x.component_mul(&mass));
        x /= x.norm();
        let next = x.dot(&(&stiffness * &x)) / x.dot(&x.component_mul(&mass));
        let converged = (next - lambda).abs() <= 1e-13 * next;
        lambda = next;
        if converged {
            break;
        }
    }
    lambda.sqrt() / (2.0 * PI)
}

/// Stiffness and lumped mass diagonal of the clamped Timoshenko beam's free dofs
/// (deflection and rotation per node, the clamped node removed).
fn timoshenko_system(nu: f64, n: usize) -> (DMatrix<f64>, DVector<f64>) {
    let (i, a) = (BEAM_B * BEAM_H.powi(3) / 12.0, BEAM_B * BEAM_H);
    let kga = cowper_kappa(nu) * BEAM_E / (2.0 * (1.0 + nu)) * a;
    let le = BEAM_L / n as f64;
    let ndof = 2 * (n + 1);
    let b = [-1.0 / le, -0.5, 1.0 / le, -0.5];
    let bend = BEAM_E * i / le;
    let mut k = DMatrix::zeros(ndof, ndof);
    let mut m = DVector::zeros(ndof);
    for e in 0..n {
        for r in 0..4 {
            for c in 0..4 {
                let kb = match (r, c) {
                    (1, 1) | (3, 3) => bend,
                    (1, 3) | (3, 1) => -bend,
                    _ => 0.0,
                };
                k[(2 * e + r, 2 * e + c)] += kb + kga * le * b[r] * b[c];
            }
        }
        for node in [e, e + 1] {
            m[2 * node] += BEAM_RHO * a * le / 2.0;
            m[2 * node + 1] += BEAM_RHO * i * le / 2.0;
        }
    }
    let free = ndof - 2;
    (
        k.view((2, 2), (free, free)).into_owned(),
        m.rows(2, free).into_owned(),
    )
}

/// Centroid height of a cube resting under its own weight on frictionless ground (uniaxial
/// stress): H/2 - rho g H^2 / (3 E).
pub fn drop_rest_centroid() -> f64 {
    DROP_SIZE / 2.0 - SOFT_RHO * G * DROP_SIZE.powi(2) / (3.0 * SOFT_E)
}

/// Relative error `(value - reference) / reference`; `None` without a finite value.
pub fn rel_error(value: Option<f64>, reference: f64) -> Option<f64> {
    value
        .filter(|v| v.is_finite())
        .map(|v| (v - reference) / reference)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_match_the_readme() {
        assert!((beam_timoshenko_tip(BEAM_NU) * 1e3 - 14.865).abs() < 1e-3);
        assert!((beam_eb_tip() * 1e3 - 14.715).abs() < 1e-3);
        assert!((beam_eb_frequency() - 5.108).abs() < 1e-3);
        assert!((beam_timoshenko_frequency(BEAM_NU, 400) - 5.069).abs() < 1e-3);
        assert!((drop_rest_centroid() * 1e3 - 98.69).abs() < 1e-2);
    }
}
