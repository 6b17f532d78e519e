//! The volumetric term of each model's energy, `Ψ(F) = Ψ_rest(F) + K/2 m(F)²`, with `K = λ + 2μ/3`
//! the bulk modulus: the part that locks linear tetrahedra as `ν → 0.5`. Nodal averaging
//! ([`crate::fvm::VolumetricTreatment::NodalAverage`]) evaluates it on node patches instead of
//! single elements.
//!
//! | model | `m(F)` | `Ψ_rest` |
//! |---|---|---|
//! | linear | `tr(ε) = tr(F) - 3` | `μ dev(ε) : dev(ε)` |
//! | St. Venant–Kirchhoff | `tr(G) = (‖F‖² - 3)/2` | `μ dev(G) : dev(G)` |
//! | corotated | `tr(S) - 3`, `F = R S` | `μ dev(S - I) : dev(S - I)` |
//! | stable Neo-Hookean | `J - 1` | `μ/2 (I_C - 3) - μ (J - 1) + μ/6 (J - 1)² + c(J)` |
//!
//! In every case `m` is the volume strain to first order and `Ψ_rest` is, at small strain, the
//! deviatoric energy `μ dev(ε) : dev(ε)` of linear elasticity, which does not resist volume
//! change (the stable Neo-Hookean compression term `c(J)` of `ν < 0`, see [`StableNeoHookean`], is
//! of third order); for the linear and corotated models it is non-negative at any strain. St.
//! Venant–Kirchhoff's `Ψ_rest` is `Ψ - K/2 tr(G)²`, with `Ψ` its inversion-safe energy: beyond its
//! compression threshold (see [`StVenantKirchhoff`]) that continued energy and the raw `tr(G)`
//! part differ, so with nodal averaging its resistance to inversion comes from `Ψ_rest` alone and
//! is weaker; prefer stable Neo-Hookean for crushed, nearly incompressible bodies.
//!
//! Damping is not averaged: its volumetric viscosity `φ` still acts per element, so nearly
//! incompressible bodies with nodal averaging should be damped in shear only (`φ = 0`), or their
//! bending modes are over-damped.

use super::corotated::{RotationDifferential, polar_rotation};
use super::neo_hookean::{cofactor, cofactor_differential};
use super::{
    Corotated, HyperelasticModel, LameParameters, LinearElastic, StVenantKirchhoff,
    StableNeoHookean, double_dot, trace,
};
use rapier3d::glamx::DMat3;

/// A model's volumetric term `K/2 m(F)²` and the rest of its energy.
pub trait VolumetricTerm: HyperelasticModel {
    /// The bulk modulus `K = λ + 2μ/3` (Pa), the coefficient of the term; positive for every
    /// admissible Poisson's ratio.
    fn volumetric_modulus(&self) -> f64;
    /// The volume measure `m(F)` (dimensionless), zero at rest.
    fn volume_measure(&self, f: &DMat3) -> f64;
    /// Its gradient `∂m/∂F` (dimensionless).
    fn volume_measure_gradient(&self, f: &DMat3) -> DMat3;
    /// The differential of the gradient, `(∂²m/∂F²) : df`.
    fn volume_measure_differential(&self, f: &DMat3, df: &DMat3) -> DMat3;
    /// `Ψ_rest(F) = Ψ(F) - K/2 m(F)²` (J/m³). The default subtracts; models override it where a
    /// direct form avoids cancelling the large volumetric term of nearly incompressible materials.
    fn energy_density_without_volumetric(&self, f: &DMat3) -> f64 {
        self.energy_density(f) - 0.5 * self.volumetric_modulus() * self.volume_measure(f).powi(2)
    }
}

impl VolumetricTerm for LinearElastic {
    fn volumetric_modulus(&self) -> f64 {
        bulk_modulus(self.0)
    }

    fn volume_measure(&self, f: &DMat3) -> f64 {
        trace(f) - 3.0
    }

    fn volume_measure_gradient(&self, _f: &DMat3) -> DMat3 {
        DMat3::IDENTITY
    }

    fn volume_measure_differential(&self, _f: &DMat3, _df: &DMat3) -> DMat3 {
        DMat3::ZERO
    }

    fn energy_density_without_volumetric(&self, f: &DMat3) -> f64 {
        let strain = super::symmetric_part(f) - DMat3::IDENTITY;
        self.0.mu * deviatoric_square(&strain)
    }
}

impl VolumetricTerm for StVenantKirchhoff {
    fn volumetric_modulus(&self) -> f64 {
        bulk_modulus(self.0)
    }

    fn volume_measure(&self, f: &DMat3) -> f64 {
        0.5 * (double_dot(f, f) - 3.0)
    }

    fn volume_measure_gradient(&self, f: &DMat3) -> DMat3 {
        *f
    }

    fn volume_measure_differential(&self, _f: &DMat3, df: &DMat3) -> DMat3 {
        *df
    }
}

impl VolumetricTerm for Corotated {
    fn volumetric_modulus(&self) -> f64 {
        bulk_modulus(self.0)
    }

    fn volume_measure(&self, f: &DMat3) -> f64 {
        trace(&(polar_rotation(f).transpose() * *f)) - 3.0
    }

    fn volume_measure_gradient(&self, f: &DMat3) -> DMat3 {
        polar_rotation(f)
    }

    fn volume_measure_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        RotationDifferential::new(f, &polar_rotation(f)).apply(df)
    }

    fn energy_density_without_volumetric(&self, f: &DMat3) -> f64 {
        let stretch = polar_rotation(f).transpose() * *f;
        self.0.mu * deviatoric_square(&(super::symmetric_part(&stretch) - DMat3::IDENTITY))
    }
}

impl VolumetricTerm for StableNeoHookean {
    fn volumetric_modulus(&self) -> f64 {
        // λ' = λ + μ, so λ' - μ/3 = K.
        self.lambda_prime - self.mu / 3.0
    }

    fn volume_measure(&self, f: &DMat3) -> f64 {
        self.volume_change(f)
    }

    fn volume_measure_gradient(&self, f: &DMat3) -> DMat3 {
        cofactor(f)
    }

    fn volume_measure_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        cofactor_differential(f, df)
    }

    fn energy_density_without_volumetric(&self, f: &DMat3) -> f64 {
        let (x, deviatoric) = self.strain_terms(f);
        let energy = self.mu * deviatoric + self.mu / 6.0 * x.powi(2);
        self.compression(x).map_or(energy, |c| energy + c[0])
    }
}

/// `K = λ + 2μ/3` (Pa).
fn bulk_modulus(lame: LameParameters) -> f64 {
    lame.lambda + 2.0 * lame.mu / 3.0
}

/// `dev(E) : dev(E) = E : E - tr(E)²/3` of a symmetric `E`.
fn deviatoric_square(e: &DMat3) -> f64 {
    double_dot(e, e) - trace(e).powi(2) / 3.0
}
