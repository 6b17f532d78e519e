//! St. Venant–Kirchhoff: the linear law on the Green strain `G = (FᵀF - I)/2`,
//! `S = λ tr(G) I + 2 μ G`, `P = F S`, `Ψ = μ G:G + λ/2 tr(G)²`.

use super::{
    HyperelasticModel, LameParameters, double_dot, linear_law_lanes, symmetric_part, trace,
};
use crate::lanes::{Mat3x4, f64x4};
use rapier3d::glamx::DMat3;

/// St. Venant–Kirchhoff material with the given Lamé parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StVenantKirchhoff(pub LameParameters);

impl StVenantKirchhoff {
    /// Second Piola–Kirchhoff stress `S` (Pa) of a symmetric Green strain.
    #[inline(always)]
    fn second_piola(&self, green: &DMat3) -> DMat3 {
        let LameParameters { lambda, mu } = self.0;
        DMat3::IDENTITY * (lambda * trace(green)) + *green * (2.0 * mu)
    }
}

/// Green strain `G = (FᵀF - I)/2`.
#[inline(always)]
pub(crate) fn green_strain(f: &DMat3) -> DMat3 {
    (f.transpose() * *f - DMat3::IDENTITY) * 0.5
}

impl HyperelasticModel for StVenantKirchhoff {
    fn energy_density(&self, f: &DMat3) -> f64 {
        let g = green_strain(f);
        let LameParameters { lambda, mu } = self.0;
        mu * double_dot(&g, &g) + 0.5 * lambda * trace(&g).powi(2)
    }

    #[inline(always)]
    fn first_piola(&self, f: &DMat3) -> DMat3 {
        *f * self.second_piola(&green_strain(f))
    }

    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        let s = self.second_piola(&green_strain(f));
        let ds = self.second_piola(&symmetric_part(&(f.transpose() * *df)));
        *df * s + *f * ds
    }

    /// `F (S + S_extra)`: one product for the elastic and the extra stress.
    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let green = (f.transpose_mul(f).add_diagonal(f64x4::splat(-1.0))) * f64x4::splat(0.5);
        *f * (linear_law_lanes(self.0, &green) + *s_extra)
    }
}
