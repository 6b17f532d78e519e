//! Linear elasticity: `ε = sym(F) - I`, `P = σ = λ tr(ε) I + 2 μ ε`,
//! `Ψ = μ ε:ε + λ/2 tr(ε)²`.

use super::{
    HyperelasticModel, LameParameters, double_dot, linear_law_lanes, symmetric_part, trace,
};
use crate::lanes::{Mat3x4, f64x4};
use rapier3d::glamx::DMat3;

/// Linear (small-strain) elasticity with the given Lamé parameters. Not invariant under rotation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct LinearElastic(pub LameParameters);

impl LinearElastic {
    #[inline(always)]
    fn stress_of_strain(&self, strain: &DMat3) -> DMat3 {
        let LameParameters { lambda, mu } = self.0;
        DMat3::IDENTITY * (lambda * trace(strain)) + *strain * (2.0 * mu)
    }
}

impl HyperelasticModel for LinearElastic {
    fn energy_density(&self, f: &DMat3) -> f64 {
        let strain = symmetric_part(f) - DMat3::IDENTITY;
        let LameParameters { lambda, mu } = self.0;
        mu * double_dot(&strain, &strain) + 0.5 * lambda * trace(&strain).powi(2)
    }

    #[inline(always)]
    fn first_piola(&self, f: &DMat3) -> DMat3 {
        self.stress_of_strain(&(symmetric_part(f) - DMat3::IDENTITY))
    }

    fn first_piola_differential(&self, _f: &DMat3, df: &DMat3) -> DMat3 {
        self.stress_of_strain(&symmetric_part(df))
    }

    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let strain = f.symmetric_part().add_diagonal(f64x4::splat(-1.0));
        linear_law_lanes(self.0, &strain) + *f * *s_extra
    }
}
