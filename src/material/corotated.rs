//! Corotated linear elasticity: with the polar decomposition `F = R S` (`R` a proper rotation),
//! `Ψ = μ ‖F - R‖² + λ/2 (tr(S) - 3)²` and `P = 2μ (F - R) + λ (tr(S) - 3) R`.
//!
//! The rotation comes from Higham's Newton iteration `X ← (γX + X⁻ᵀ/γ)/2`, which converges
//! quadratically to the polar factor of a well-conditioned `F` in a handful of 3x3 inverses; the
//! scaling `γ = (‖X⁻¹‖/‖X‖)^½` is applied only while `X` is far from a rotation (`γ ≈ 1` near one),
//! and the iteration stops once an update is below 1e-8, its quadratic convergence putting the
//! iterate returned within about 1e-16 of the limit (`‖E'‖ ≈ ‖E‖²/2`). Nearly
//! flat or inverted elements fall back to the singular value decomposition with the sign fix of
//! Irving, Teran and Fedkiw (2004): when `det F < 0` the smallest singular value is negated so that
//! `R` stays a rotation and the energy pushes the element back to positive volume.

use super::diagonal::signed_svd;
use super::neo_hookean::cofactor;
use super::{HyperelasticModel, LameParameters, trace};
use rapier3d::glamx::{DMat3, DVec3};

/// Corotated linear elastic material with the given Lamé parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct Corotated(pub LameParameters);

/// Below this `det F / (‖F‖²/3)^(3/2)` (1 for a rotation, 0 for a flat element) the polar
/// rotation is taken from the SVD rather than Newton's iteration.
const NEWTON_MIN_CONDITION: f64 = 0.05;
/// Newton's iteration stops after an update that changed `X` by at most this (Frobenius norm):
/// the error of the iterate it returns is then about the update's square over two, below 1e-16.
const NEWTON_LAST_UPDATE: f64 = 1e-8;
const NEWTON_MAX_ITERATIONS: usize = 20;
/// Higham's scaling is applied on the first iteration if `|‖F‖²/3 - 1|` exceeds this (near a
/// rotation `γ ≈ 1`, and the unscaled step converges quadratically at less cost)...
const NEWTON_SCALED_WHILE: f64 = 0.05;
/// ... and on the next ones while the last update's Frobenius norm exceeds this.
const NEWTON_SCALED_UPDATE: f64 = 1e-2;

/// The rotation `R` of the polar decomposition `F = R S`, with `det R = +1` even for inverted `F`.
pub(crate) fn polar_rotation(f: &DMat3) -> DMat3 {
    let size = super::double_dot(f, f) / 3.0;
    if f.determinant() > NEWTON_MIN_CONDITION * size * size.sqrt()
        && let Some(rotation) = polar_rotation_newton(f, (size - 1.0).abs() > NEWTON_SCALED_WHILE)
    {
        return rotation;
    }
    polar_rotation_svd(f)
}

/// Higham's Newton iteration for the polar factor, scaled at first if `scaled`; `None` if it has
/// not converged.
fn polar_rotation_newton(f: &DMat3, mut scaled: bool) -> Option<DMat3> {
    let mut x = *f;
    for _ in 0..NEWTON_MAX_ITERATIONS {
        let inverse_transpose = inverse_transpose(&x);
        let next = if scaled {
            let gamma = (super::double_dot(&inverse_transpose, &inverse_transpose)
                / super::double_dot(&x, &x))
            .sqrt()
            .sqrt();
            (x * gamma + inverse_transpose * (1.0 / gamma)) * 0.5
        } else {
            (x + inverse_transpose) * 0.5
        };
        let change = next - x;
        x = next;
        let change_squared = super::double_dot(&change, &change);
        if change_squared <= NEWTON_LAST_UPDATE * NEWTON_LAST_UPDATE {
            return Some(x);
        }
        scaled = change_squared > NEWTON_SCALED_UPDATE * NEWTON_SCALED_UPDATE;
    }
    None
}

/// `X⁻ᵀ`: the cofactor matrix over `det X`.
fn inverse_transpose(x: &DMat3) -> DMat3 {
    let cofactor = cofactor(x);
    cofactor * (1.0 / x.x_axis.dot(cofactor.x_axis))
}

/// The polar rotation from the SVD with the inversion sign fix.
fn polar_rotation_svd(f: &DMat3) -> DMat3 {
    // `U` and `V` are always present: the decomposition was asked for both.
    let Some(svd) = signed_svd(f) else {
        return DMat3::IDENTITY;
    };
    DMat3::from_cols_slice((svd.u * svd.v_t).as_slice())
}

/// Axial vector `a` of a skew matrix `[a]x`.
fn axial(skew: &DMat3) -> DVec3 {
    DVec3::new(skew.y_axis.z, skew.z_axis.x, skew.x_axis.y)
}

/// Cross-product matrix `[w]x`, so that `[w]x v = w x v`.
fn cross_matrix(w: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, w.z, -w.y),
        DVec3::new(-w.z, 0.0, w.x),
        DVec3::new(w.y, -w.x, 0.0),
    )
}

impl HyperelasticModel for Corotated {
    fn energy_density(&self, f: &DMat3) -> f64 {
        let r = polar_rotation(f);
        let LameParameters { lambda, mu } = self.0;
        let diff = *f - r;
        let stretch_trace = trace(&(r.transpose() * *f));
        mu * super::double_dot(&diff, &diff) + 0.5 * lambda * (stretch_trace - 3.0).powi(2)
    }

    fn first_piola(&self, f: &DMat3) -> DMat3 {
        let r = polar_rotation(f);
        let LameParameters { lambda, mu } = self.0;
        let stretch_trace = trace(&(r.transpose() * *f));
        (*f - r) * (2.0 * mu) + r * (lambda * (stretch_trace - 3.0))
    }

    /// Uses the differential of the polar rotation (`McAdams` et al. 2011).
    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        self.first_piola_differentials(f, &[*df])[0]
    }

    /// Decomposes `F` once for all the changes.
    fn first_piola_differentials<const N: usize>(&self, f: &DMat3, dfs: &[DMat3; N]) -> [DMat3; N] {
        let r = polar_rotation(f);
        let LameParameters { lambda, mu } = self.0;
        let rotation = RotationDifferential::new(f, &r);
        dfs.each_ref().map(|df| {
            let dr = rotation.apply(df);
            (*df - dr) * (2.0 * mu)
                + r * (lambda * trace(&(r.transpose() * *df)))
                + dr * (lambda * (rotation.stretch_trace - 3.0))
        })
    }
}

/// The differential `dR` of the polar rotation `R` of `F` for a change `dF`:
/// `dR = R [w]x` with `w = (tr(S) I - S)⁻¹ axial(Rᵀ dF - dFᵀ R)` (`McAdams` et al. 2011); zero
/// where that system is singular (two stretches summing to zero: a flattened or inverted element).
pub(crate) struct RotationDifferential {
    rotation: DMat3,
    /// `tr(S)`, `S = Rᵀ F` the stretch.
    stretch_trace: f64,
    /// `(tr(S) I - S)⁻¹`, or `None` where it is singular.
    system_inverse: Option<DMat3>,
}

impl RotationDifferential {
    /// The differential at `f`, whose polar rotation is `r`.
    pub(crate) fn new(f: &DMat3, r: &DMat3) -> Self {
        let s = r.transpose() * *f;
        let stretch_trace = trace(&s);
        let system = DMat3::IDENTITY * stretch_trace - s;
        let system_inverse = (system.determinant().abs() > 1e-12 * stretch_trace.abs().powi(3))
            .then(|| system.inverse());
        Self {
            rotation: *r,
            stretch_trace,
            system_inverse,
        }
    }

    /// `dR` for the change `df`.
    pub(crate) fn apply(&self, df: &DMat3) -> DMat3 {
        let Some(inverse) = self.system_inverse else {
            return DMat3::ZERO;
        };
        let rt_df = self.rotation.transpose() * *df;
        self.rotation * cross_matrix(inverse * axial(&(rt_df - rt_df.transpose())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stretches from 1e-4 to 40 % (and a uniform scale of 3, where the scaled iteration starts)
    /// under rotations about several axes: Newton's rotation is the SVD's `U Vᵀ` to 1e-13 (both
    /// are accurate to a few ulps times the stretch's condition number, at most 2.4 here) and a
    /// rotation to 1e-14.
    #[test]
    fn newtons_rotation_is_the_singular_value_decompositions() {
        for (case, strain) in [1e-4, 1e-2, 0.1, 0.4].into_iter().enumerate() {
            for axis in [
                DVec3::X,
                DVec3::new(1.0, 2.0, -0.5),
                DVec3::new(-3.0, 0.2, 1.0),
            ] {
                let rotation = DMat3::from_axis_angle(axis.normalize(), 0.7 + case as f64);
                let symmetric = DMat3::from_cols(
                    DVec3::new(1.0, 0.3, -0.5),
                    DVec3::new(0.3, -0.8, 0.2),
                    DVec3::new(-0.5, 0.2, 0.6),
                );
                for scale in [1.0, 3.0] {
                    let f = rotation * (DMat3::IDENTITY + symmetric * strain) * scale;
                    let newton = polar_rotation(&f);
                    let from_svd = polar_rotation_svd(&f);
                    let difference = newton - from_svd;
                    let orthogonality = newton.transpose() * newton - DMat3::IDENTITY;
                    assert!(
                        super::super::double_dot(&difference, &difference).sqrt() < 1e-13,
                        "strain {strain}, scale {scale}: {newton} against {from_svd}"
                    );
                    assert!(
                        super::super::double_dot(&orthogonality, &orthogonality).sqrt() < 1e-14
                    );
                    assert!((newton.determinant() - 1.0).abs() < 1e-14);
                }
            }
        }
    }
}
