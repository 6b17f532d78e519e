//! Stable Neo-Hookean (Smith, de Goes and Kim, "Stable Neo-Hookean Flesh Simulation", 2018), in
//! the log-free form of Kim and Eberle's "Dynamic Deformables" notes:
//! `Ψ = μ/2 (I_C - 3) - μ (J - 1) + λ'/2 (J - 1)²`, with `I_C = tr(FᵀF)`, `J = det F` and
//! `λ' = λ + μ` so that the small-strain limit is exactly linear elasticity with `(λ, μ)`.
//! `P = μ F + (λ' (J - 1) - μ) cof(F)`, defined for inverted elements (`J <= 0`) too.

use super::{HyperelasticModel, LameParameters, double_dot, green_strain, trace};
use crate::lanes::{Mat3x4, f64x4};
use rapier3d::glamx::DMat3;

/// Green strain above which the energy is evaluated in its direct form.
const LARGE_STRAIN: f64 = 0.1;

/// Stable Neo-Hookean material.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct StableNeoHookean {
    pub(super) mu: f64,
    /// `λ' = λ + μ` (Pa), the volumetric coefficient of this energy.
    pub(super) lambda_prime: f64,
}

impl StableNeoHookean {
    /// The model whose small-strain limit has Lamé parameters `lame`.
    pub fn new(lame: LameParameters) -> Self {
        Self {
            mu: lame.mu,
            lambda_prime: lame.lambda + lame.mu,
        }
    }
}

/// Cofactor matrix `cof(F) = det(F) F⁻ᵀ = ∂ det F / ∂F`, column `i` being `f_(i+1) x f_(i+2)`.
#[inline(always)]
pub(crate) fn cofactor(f: &DMat3) -> DMat3 {
    DMat3::from_cols(
        f.y_axis.cross(f.z_axis),
        f.z_axis.cross(f.x_axis),
        f.x_axis.cross(f.y_axis),
    )
}

/// Differential of the cofactor matrix for a change `df` of `f`.
pub(crate) fn cofactor_differential(f: &DMat3, df: &DMat3) -> DMat3 {
    DMat3::from_cols(
        df.y_axis.cross(f.z_axis) + f.y_axis.cross(df.z_axis),
        df.z_axis.cross(f.x_axis) + f.z_axis.cross(df.x_axis),
        df.x_axis.cross(f.y_axis) + f.x_axis.cross(df.y_axis),
    )
}

/// The Green-strain quantities the energy is evaluated from at small strain: `J - 1` and
/// `tr G - (J - 1) = (I_C - 3)/2 - (J - 1)`, with the order-ε terms cancelled analytically; `None`
/// at large strain or inversion, where the direct forms are accurate.
///
/// At a strain `ε`, `(I_C - 3)/2` and `J - 1` are both of order `ε` while the energy is of order
/// `ε²`, so subtracting them would lose `1/ε` of the digits (the energy of a 1e-6 strain only to
/// 1e-4 relative), which blinds line searches near equilibrium.
fn small_strain_terms(f: &DMat3) -> Option<(f64, f64)> {
    let g = green_strain(f);
    let largest_strain = g.to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if f.determinant() <= 0.0 || largest_strain > LARGE_STRAIN {
        return None;
    }
    let tr = trace(&g);
    // det(I + 2G) - 1 = J² - 1, expanded in G.
    let quadratic = tr * tr - trace(&(g * g));
    let d = 2.0 * tr + 2.0 * quadratic + 8.0 * g.determinant();
    let s = (1.0 + d).sqrt();
    let j_minus_one = d / (s + 1.0);
    let deviatoric = (tr * (s - 1.0) - 2.0 * quadratic - 8.0 * g.determinant()) / (s + 1.0);
    Some((j_minus_one, deviatoric))
}

impl StableNeoHookean {
    /// `J - 1` (dimensionless), accurate at small strain.
    pub(super) fn volume_change(&self, f: &DMat3) -> f64 {
        small_strain_terms(f).map_or_else(|| f.determinant() - 1.0, |(j_minus_one, _)| j_minus_one)
    }

    /// `μ/2 (I_C - 3) - μ (J - 1)` (J/m³): the energy without its volumetric term.
    pub(super) fn shear_energy_density(&self, f: &DMat3) -> f64 {
        let deviatoric = small_strain_terms(f).map_or_else(
            || 0.5 * (double_dot(f, f) - 3.0) - (f.determinant() - 1.0),
            |(_, deviatoric)| deviatoric,
        );
        self.mu * deviatoric
    }
}

impl HyperelasticModel for StableNeoHookean {
    /// Evaluated from the Green strain at small strain, without the cancellation of the textbook
    /// form (see [`StableNeoHookean`]'s shear and volume terms).
    fn energy_density(&self, f: &DMat3) -> f64 {
        let j_minus_one = self.volume_change(f);
        self.shear_energy_density(f) + 0.5 * self.lambda_prime * j_minus_one * j_minus_one
    }

    #[inline(always)]
    fn first_piola(&self, f: &DMat3) -> DMat3 {
        let j = f.determinant();
        *f * self.mu + cofactor(f) * (self.lambda_prime * (j - 1.0) - self.mu)
    }

    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        let cof = cofactor(f);
        let j = f.determinant();
        *df * self.mu
            + cof * (self.lambda_prime * double_dot(&cof, df))
            + cofactor_differential(f, df) * (self.lambda_prime * (j - 1.0) - self.mu)
    }

    /// `F (μ I + S_extra) + (λ' (J - 1) - μ) cof(F)`.
    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let cofactor = f.cofactor();
        let j = f.cols[0].dot(cofactor.cols[0]);
        let volumetric = (j - f64x4::ONE) * f64x4::splat(self.lambda_prime) - f64x4::splat(self.mu);
        *f * s_extra.add_diagonal(f64x4::splat(self.mu)) + cofactor * volumetric
    }
}
