//! Rayleigh damping on the strain rate: `σ_damp = φ tr(ε̇) I + 2ψ ε̇`.
//!
//! The strain rate is the rate of the Green strain, `ε̇ = Ġ = sym(Fᵀ Ḟ)`, which equals the small
//! strain rate `sym(Ḟ)` to first order and is exactly zero for any rigid motion (translation or
//! spin), so rigid motion is never damped. The stress enters as a second Piola–Kirchhoff stress,
//! `P_damp = F σ_damp`. Its power on the body, `-V σ_damp : ε̇`, is never positive when `ψ >= 0`
//! and `φ + 2ψ/3 >= 0`.

use crate::Error;
use crate::lanes::{Mat3x4, f64x4};
use crate::material::{LameParameters, double_dot, green_strain, symmetric_part, trace};
use rapier3d::glamx::DMat3;

/// Rayleigh damping coefficients, the viscous counterparts of the Lamé parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "DampingParts")
)]
pub struct RayleighDamping {
    /// Volumetric damping coefficient `φ` (Pa·s), multiplying `tr(ε̇)`.
    phi: f64,
    /// Shear damping coefficient `ψ` (Pa·s), multiplying `2 ε̇`.
    psi: f64,
}

/// The damping of an implicit step (see [`RayleighDamping::step_potential`]): its strain rate
/// is the Green strain's change over the step of `h` (s) from `green`, one per integration point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepDamping<'a> {
    /// The body's damping.
    pub(crate) damping: &'a RayleighDamping,
    /// Per integration point, the Green strain the rate is measured from.
    pub(crate) green: &'a [DMat3],
    /// The step (s).
    pub(crate) h: f64,
}

/// A [`RayleighDamping`] as written (feature `serde-serialize`); read back through
/// [`RayleighDamping::new`].
#[cfg(feature = "serde-serialize")]
#[derive(serde::Deserialize)]
struct DampingParts {
    phi: f64,
    psi: f64,
}

#[cfg(feature = "serde-serialize")]
impl TryFrom<DampingParts> for RayleighDamping {
    type Error = Error;

    fn try_from(parts: DampingParts) -> Result<Self, Error> {
        Self::new(parts.phi, parts.psi)
    }
}

impl RayleighDamping {
    /// Damping with coefficients `φ` and `ψ` (Pa·s).
    ///
    /// # Errors
    /// [`Error::InvalidMaterial`] if either is not finite, `ψ < 0`, or `φ + 2ψ/3 < 0` (the bulk
    /// viscosity would be negative and the damping would inject energy).
    pub fn new(phi: f64, psi: f64) -> Result<Self, Error> {
        if !(psi.is_finite() && psi >= 0.0) {
            return Err(Error::InvalidMaterial {
                parameter: "psi",
                value: psi,
                reason: "shear damping must be finite and non-negative (Pa s)",
            });
        }
        if !(phi.is_finite() && phi + 2.0 * psi / 3.0 >= 0.0) {
            return Err(Error::InvalidMaterial {
                parameter: "phi",
                value: phi,
                reason: "volumetric damping must be finite with phi + 2 psi / 3 >= 0 (Pa s)",
            });
        }
        Ok(Self { phi, psi })
    }

    /// Stiffness-proportional damping `φ = β λ`, `ψ = β μ`: the damping matrix is `β K` at rest, so
    /// a mode of angular frequency `ω` (rad/s) gets the damping ratio `β ω / 2`. `beta` is in
    /// seconds.
    ///
    /// # Errors
    /// [`Error::InvalidMaterial`] if `beta` is negative or not finite.
    pub fn stiffness_proportional(beta: f64, lame: LameParameters) -> Result<Self, Error> {
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(Error::InvalidMaterial {
                parameter: "beta",
                value: beta,
                reason: "stiffness-proportional damping time must be finite and non-negative (s)",
            });
        }
        Self::new(beta * lame.lambda, beta * lame.mu)
    }

    /// Volumetric coefficient `φ` (Pa·s).
    pub fn phi(&self) -> f64 {
        self.phi
    }

    /// Shear coefficient `ψ` (Pa·s).
    pub fn psi(&self) -> f64 {
        self.psi
    }

    /// The P-wave viscosity `φ + 2ψ` (Pa·s), the damping counterpart of `λ + 2μ`.
    pub fn p_wave_viscosity(&self) -> f64 {
        self.phi + 2.0 * self.psi
    }

    /// The damping of a sheet free across its thickness (plane stress), acting on in-plane
    /// strain rates: the 3D law with the rate across the sheet that leaves no stress across it,
    /// `Ġ₃₃ = −φ (Ġ₁₁ + Ġ₂₂)/(φ + 2ψ)`, is `φ* tr Ġ I + 2ψ Ġ` in the plane with
    /// `φ* = 2φψ/(φ + 2ψ)` (zero when `φ + 2ψ = 0`), as `λ* = 2λμ/(λ + 2μ)` is for the
    /// stiffness. Its in-plane bulk viscosity `φ* + ψ` is non-negative whenever the 3D one is.
    pub(crate) fn plane_stress(&self) -> Self {
        let viscosity = self.p_wave_viscosity();
        let phi = if viscosity > 0.0 {
            2.0 * self.phi * self.psi / viscosity
        } else {
            0.0
        };
        Self { phi, psi: self.psi }
    }

    /// Damping stress as a first Piola–Kirchhoff stress (Pa), for deformation gradient `f` and its
    /// rate `f_dot` (1/s).
    #[inline(always)]
    pub fn first_piola(&self, f: &DMat3, f_dot: &DMat3) -> DMat3 {
        let strain_rate = symmetric_part(&(f.transpose() * *f_dot));
        let stress =
            DMat3::IDENTITY * (self.phi * trace(&strain_rate)) + strain_rate * (2.0 * self.psi);
        *f * stress
    }

    /// The damping stress as a second Piola–Kirchhoff stress `φ tr(ε̇) I + 2ψ ε̇` (Pa) in four
    /// lanes, for deformation gradients `f` and their rates `f_dot` (1/s).
    #[inline(always)]
    pub fn second_piola_lanes(&self, f: &Mat3x4, f_dot: &Mat3x4) -> Mat3x4 {
        let strain_rate = f.transpose_mul(f_dot).symmetric_part();
        (strain_rate * f64x4::splat(2.0 * self.psi))
            .add_diagonal(strain_rate.trace() * f64x4::splat(self.phi))
    }

    /// [`RayleighDamping::step_first_piola`]'s stress as a second Piola–Kirchhoff stress
    /// `φ tr(Ġ) I + 2ψ Ġ` (Pa) in four lanes, `Ġ = (G(F) − G_prev)/h` for deformation gradients
    /// `f`, the Green strains `green_previous` the rate is measured from and the step `h` (s).
    #[inline(always)]
    pub(crate) fn step_second_piola_lanes(
        &self,
        f: &Mat3x4,
        green_previous: &Mat3x4,
        h: f64,
    ) -> Mat3x4 {
        let green = f.transpose_mul(f).add_diagonal(f64x4::splat(-1.0)) * f64x4::splat(0.5);
        let rate = (green - *green_previous) * f64x4::splat(1.0 / h);
        (rate * f64x4::splat(2.0 * self.psi)).add_diagonal(rate.trace() * f64x4::splat(self.phi))
    }

    /// `φ tr(E) I + 2ψ E` (Pa) for a symmetric strain rate `E` (1/s).
    #[inline(always)]
    fn stress_of_rate(&self, rate: &DMat3) -> DMat3 {
        DMat3::IDENTITY * (self.phi * trace(rate)) + *rate * (2.0 * self.psi)
    }

    /// The dissipation potential of one step of length `h` (s) per unit rest volume (J/m³),
    /// `h (φ/2 tr(Ġ)² + ψ Ġ:Ġ)` with the rate taken over the step, `Ġ = (G(F) - G_prev)/h`: its
    /// derivative in `F` is the damping stress, so implicit integrators can minimize it.
    pub(crate) fn step_potential(&self, f: &DMat3, green_previous: &DMat3, h: f64) -> f64 {
        let rate = (green_strain(f) - *green_previous) * (1.0 / h);
        h * (0.5 * self.phi * trace(&rate).powi(2) + self.psi * double_dot(&rate, &rate))
    }

    /// `∂/∂F` of [`RayleighDamping::step_potential`]: `F σ_damp(Ġ)` (Pa).
    pub(crate) fn step_first_piola(&self, f: &DMat3, green_previous: &DMat3, h: f64) -> DMat3 {
        let rate = (green_strain(f) - *green_previous) * (1.0 / h);
        *f * self.stress_of_rate(&rate)
    }

    /// Differentials of [`RayleighDamping::step_first_piola`] for the changes `dfs` of `F` (Pa),
    /// the rate's stress evaluated once for all of them.
    pub(crate) fn step_first_piola_differentials<const N: usize>(
        &self,
        f: &DMat3,
        green_previous: &DMat3,
        h: f64,
        dfs: &[DMat3; N],
    ) -> [DMat3; N] {
        let rate = (green_strain(f) - *green_previous) * (1.0 / h);
        let stress = self.stress_of_rate(&rate);
        dfs.map(|df| {
            let d_rate = symmetric_part(&(f.transpose() * df)) * (1.0 / h);
            df * stress + *f * self.stress_of_rate(&d_rate)
        })
    }

    /// [`RayleighDamping::step_first_piola_differentials`] for the nine unit changes of `F` in
    /// column-major order (`dF = e_i e_jᵀ` for column `3j + i`), the stress tangent's columns
    /// (Pa): the products with a unit change taken as the row or column it picks (`dF S` is
    /// `S`'s row `j` in row `i`, `Fᵀ dF` is `F`'s row `i` in column `j`) instead of multiplied
    /// through its zeros, the same values.
    pub(crate) fn step_first_piola_unit_differentials(
        &self,
        f: &DMat3,
        green_previous: &DMat3,
        h: f64,
    ) -> [DMat3; 9] {
        let rate = (green_strain(f) - *green_previous) * (1.0 / h);
        let stress = self.stress_of_rate(&rate);
        let f_rows = f.transpose();
        std::array::from_fn(|column| {
            let (i, j) = (column % 3, column / 3);
            let mut picked = DMat3::ZERO;
            *picked.col_mut(j) = f_rows.col(i);
            let d_rate = symmetric_part(&picked) * (1.0 / h);
            let mut df_stress = DMat3::ZERO;
            for k in 0..3 {
                df_stress.col_mut(k)[i] = stress.col(k)[j];
            }
            df_stress + *f * self.stress_of_rate(&d_rate)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::green_strain;

    /// The step's stress in four lanes, `F S`, is the scalar [`RayleighDamping::step_first_piola`]
    /// of each lane to round-off (1e-13 of its largest entry): the force kernel's implicit path
    /// takes it so.
    #[test]
    fn the_step_stress_in_lanes_is_the_scalar_one() {
        let damping = RayleighDamping::new(300.0, 200.0).unwrap();
        let lane = |l: usize, scale: f64| {
            let k = l as f64;
            DMat3::from_cols_array(&[
                1.0 + scale * k,
                0.05 * k,
                -0.02,
                0.03,
                0.95 + 0.5 * scale * k,
                0.04 * k,
                -0.01,
                0.02,
                1.05 - scale,
            ])
        };
        let fs: [DMat3; 4] = std::array::from_fn(|l| lane(l, 0.03));
        let previous: [DMat3; 4] = std::array::from_fn(|l| green_strain(&lane(l, 0.01)));
        let h = 1e-3;
        let lanes = damping.step_second_piola_lanes(
            &Mat3x4::from_lanes(fs),
            &Mat3x4::from_lanes(previous),
            h,
        );
        for l in 0..4 {
            let scalar = damping.step_first_piola(&fs[l], &previous[l], h);
            let ours = fs[l] * lanes.lane(l);
            let scale = scalar
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(scale > 0.0);
            assert!(
                (ours - scalar)
                    .to_cols_array()
                    .iter()
                    .all(|d| d.abs() <= 1e-13 * scale)
            );
        }
    }

    /// The step potential's stress is its derivative and the differential is the stress's
    /// derivative (central differences, 1e-6 relative): the implicit integrator's Newton
    /// direction and line search rely on both.
    #[test]
    fn step_potential_derivatives_match_finite_differences() {
        let damping = RayleighDamping::new(300.0, 200.0).unwrap();
        let f = DMat3::from_cols_array(&[1.1, 0.05, -0.02, 0.03, 0.95, 0.04, -0.01, 0.02, 1.05]);
        let previous = green_strain(&DMat3::from_cols_array(&[
            1.0, 0.01, 0.0, 0.0, 1.02, 0.01, 0.02, 0.0, 0.98,
        ]));
        let (h, eps) = (1e-3, 1e-7);
        let stress = damping.step_first_piola(&f, &previous, h);
        let scale = stress
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        for k in 0..9 {
            let mut unit = [0.0; 9];
            unit[k] = 1.0;
            let df = DMat3::from_cols_array(&unit);
            let plus = damping.step_potential(&(f + df * eps), &previous, h);
            let minus = damping.step_potential(&(f - df * eps), &previous, h);
            let numeric = (plus - minus) / (2.0 * eps);
            assert!((numeric - stress.to_cols_array()[k]).abs() < 1e-6 * scale);
            let numeric_dp = (damping.step_first_piola(&(f + df * eps), &previous, h)
                - damping.step_first_piola(&(f - df * eps), &previous, h))
                * (0.5 / eps);
            let [analytic_dp] = damping.step_first_piola_differentials(&f, &previous, h, &[df]);
            let dp_scale = analytic_dp
                .to_cols_array()
                .iter()
                .fold(1e-30f64, |m, x| m.max(x.abs()));
            let error = (numeric_dp - analytic_dp)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(error < 1e-6 * dp_scale);
        }
    }

    /// The unit changes' differentials are the general ones for the unit changes, value for
    /// value (`==`: a zero's sign may differ), at deformations stretched, sheared, turned and
    /// inverted.
    #[test]
    fn unit_differentials_are_the_general_ones_for_unit_changes() {
        let damping = RayleighDamping::new(300.0, 200.0).unwrap();
        let units = crate::assembly::unit_changes();
        let previous = green_strain(&DMat3::from_cols_array(&[
            1.0, 0.01, 0.0, 0.0, 1.02, 0.01, 0.02, 0.0, 0.98,
        ]));
        let turn =
            DMat3::from_axis_angle(rapier3d::glamx::DVec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
        for f in [
            DMat3::from_cols_array(&[1.1, 0.05, -0.02, 0.03, 0.95, 0.04, -0.01, 0.02, 1.05]),
            turn * DMat3::from_cols_array(&[1.3, 0.2, 0.0, -0.1, 0.7, 0.3, 0.0, 0.1, 0.9]),
            DMat3::from_cols_array(&[-0.9, 0.1, 0.2, 0.0, 1.1, -0.3, 0.4, 0.0, 1.0]),
        ] {
            let h = 1.0 / 240.0;
            let general = damping.step_first_piola_differentials(&f, &previous, h, &units);
            let unit = damping.step_first_piola_unit_differentials(&f, &previous, h);
            assert_eq!(general, unit, "F = {f}");
        }
    }
}
