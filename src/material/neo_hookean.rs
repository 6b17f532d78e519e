//! Stable Neo-Hookean (Smith, de Goes and Kim, "Stable Neo-Hookean Flesh Simulation", 2018), in
//! the log-free form of Kim and Eberle's "Dynamic Deformables" notes:
//! `Ψ = μ/2 (I_C - 3) + V(J)`, `V(J) = -μ (J - 1) + λ'/2 (J - 1)² + c(J)`, with `I_C = tr(FᵀF)`,
//! `J = det F` and `λ' = λ + μ` so that the small-strain limit is exactly linear elasticity with
//! `(λ, μ)`. `P = μ F + V'(J) cof(F)`, defined for inverted elements (`J <= 0`) too.
//!
//! The compression term `c` is zero for `ν >= 0`. For auxetic materials (`ν < 0`, so `λ < 0`) it is
//! `c(J) = λ x³ (1 - 8x)/9` where `x = J - 1 < 0`, zero for `J >= 1`; it keeps `Ψ >= 0`:
//!
//! 1. At a given `J` the smallest `I_C` is `3 |J|^(2/3)` (the mean of the squared singular values
//!    is at least their geometric mean), so `Ψ >= 0` for every `F` exactly when
//!    `W(J) = V(J) - B(J) >= 0` for every `J`, with `B(J) = 3μ/2 (1 - |J|^(2/3))`.
//! 2. Without `c`, `W = W₀ + λ/2 x²` with `W₀ = μ/2 t² (t - 1)² (t² + 2t + 3)` for `J = t³ > 0` and
//!    `W₀ = μ (3/2 |J|^(2/3) + J²/2 - 2J)` for `J <= 0`: `W₀ >= 0`, zero at rest and at `J = 0`.
//!    The plain energy is non-negative for `λ >= 0`; for `λ < 0` it is `λ/2 < 0` at `F = 0`,
//!    although its curvature at rest, `W''(1) = K = λ + 2μ/3`, is positive for every `ν > -1`.
//! 3. For `J >= 1`, `B <= -μ x + μ/6 x²` (`J^(2/3)` has a positive third derivative), so
//!    `W >= K/2 x² >= 0` whatever `λ`: only compression needs a term.
//! 4. For `ν < 0`, `θ = 3K/(2μ)` lies in `(0, 1)` and `V = θ V₀ + (1 - θ) V₁`, with `V₀` the plain `V`
//!    at `λ = 0` and `V₁ = -μ x + μ/6 x² + μ (16/27 x⁴ - 2/27 x³)` (the last term for `x < 0`
//!    only). `V₁` matches `B` to third order at rest and exceeds it elsewhere: by 3 for `x > 0`,
//!    and `W₁ >= μ/3 x⁴` for `x < 0` (an inequality in one variable, tightest at `J = 0`). So
//!    `W = θ W₀ + (1 - θ) W₁ > 0` away from rest.
//!    The `16/27` gives `Ψ(0) = -λ/2`, the mirror of `λ/2` for `λ > 0`.
//!
//! `c` is of order `x³`: the tangent at rest stays that of linear elasticity, and `Ψ` is `C²` at
//! `J = 1` (its third derivative in `J` jumps there by `2λ/3`).

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
    /// `min(λ, 0)` (Pa), the coefficient of the compression term `c` of auxetic materials.
    pub(super) auxetic_lambda: f64,
}

impl StableNeoHookean {
    /// The model whose small-strain limit has Lamé parameters `lame`.
    pub fn new(lame: LameParameters) -> Self {
        Self {
            mu: lame.mu,
            lambda_prime: lame.lambda + lame.mu,
            auxetic_lambda: lame.lambda.min(0.0),
        }
    }

    /// The compression term at `x = J - 1`: `[c, c', c'']` (J/m³, Pa, Pa; derivatives in `J`),
    /// zero for `x >= 0`; `None` for `ν >= 0`, where it is absent.
    #[inline(always)]
    pub(super) fn compression(&self, x: f64) -> Option<[f64; 3]> {
        (self.auxetic_lambda < 0.0).then(|| {
            let (x, k) = (x.min(0.0), self.auxetic_lambda / 9.0);
            [
                x * x * x * (1.0 - 8.0 * x) * k,
                x * x * (3.0 - 32.0 * x) * k,
                x * (6.0 - 96.0 * x) * k,
            ]
        })
    }

    /// `V'(J) = λ' (J - 1) - μ + c'(J)` (Pa), the coefficient of `cof(F)` in the stress.
    #[inline(always)]
    fn volume_slope(&self, j: f64) -> f64 {
        let slope = self.lambda_prime * (j - 1.0) - self.mu;
        self.compression(j - 1.0).map_or(slope, |c| slope + c[1])
    }

    /// `V''(J) = λ' + c''(J)` (Pa).
    #[inline(always)]
    fn volume_curvature(&self, j: f64) -> f64 {
        self.compression(j - 1.0)
            .map_or(self.lambda_prime, |c| self.lambda_prime + c[2])
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
    /// `J - 1` and `(I_C - 3)/2 - (J - 1)` (dimensionless), accurate at small strain: both from
    /// one evaluation of [`small_strain_terms`].
    pub(super) fn strain_terms(&self, f: &DMat3) -> (f64, f64) {
        small_strain_terms(f).unwrap_or_else(|| {
            let j_minus_one = f.determinant() - 1.0;
            (j_minus_one, 0.5 * (double_dot(f, f) - 3.0) - j_minus_one)
        })
    }

    /// `J - 1` (dimensionless), accurate at small strain.
    pub(super) fn volume_change(&self, f: &DMat3) -> f64 {
        self.strain_terms(f).0
    }
}

impl HyperelasticModel for StableNeoHookean {
    /// Evaluated from the Green strain at small strain, without the cancellation of the textbook
    /// form (see [`StableNeoHookean`]'s shear and volume terms).
    fn energy_density(&self, f: &DMat3) -> f64 {
        let (j_minus_one, deviatoric) = self.strain_terms(f);
        let energy = self.mu * deviatoric + 0.5 * self.lambda_prime * j_minus_one * j_minus_one;
        self.compression(j_minus_one)
            .map_or(energy, |c| energy + c[0])
    }

    #[inline(always)]
    fn first_piola(&self, f: &DMat3) -> DMat3 {
        let j = f.determinant();
        *f * self.mu + cofactor(f) * self.volume_slope(j)
    }

    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        self.first_piola_differentials(f, &[*df])[0]
    }

    /// `μ dF + V''(J) (cof(F) : dF) cof(F) + V'(J) d cof(F)[dF]`, with `cof(F)`, `J` and the
    /// volume terms' slope and curvature evaluated once for all the changes.
    fn first_piola_differentials<const N: usize>(&self, f: &DMat3, dfs: &[DMat3; N]) -> [DMat3; N] {
        let cof = cofactor(f);
        let j = f.determinant();
        let (curvature, slope) = (self.volume_curvature(j), self.volume_slope(j));
        dfs.each_ref().map(|df| {
            *df * self.mu
                + cof * (curvature * double_dot(&cof, df))
                + cofactor_differential(f, df) * slope
        })
    }

    /// `F (μ I + S_extra) + V'(J) cof(F)`.
    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let cofactor = f.cofactor();
        let j = f.cols[0].dot(cofactor.cols[0]);
        let mut volumetric =
            (j - f64x4::ONE) * f64x4::splat(self.lambda_prime) - f64x4::splat(self.mu);
        if self.auxetic_lambda < 0.0 {
            // c'(J) of `compression`, lane by lane.
            let x = (j - f64x4::ONE).min(f64x4::ZERO);
            volumetric += x
                * x
                * (f64x4::splat(3.0) - f64x4::splat(32.0) * x)
                * f64x4::splat(self.auxetic_lambda / 9.0);
        }
        *f * s_extra.add_diagonal(f64x4::splat(self.mu)) + cofactor * volumetric
    }
}
