//! Elastic materials: the constants a user sets (Young's modulus in Pa, Poisson's ratio, density in
//! kg/m^3), the Lamé parameters derived from them, and the constitutive models.
//!
//! Contract of every model: a strain energy density `Ψ(F)` (J/m^3) of the deformation gradient
//! `F = dX/dp`, its first Piola–Kirchhoff stress `P = ∂Ψ/∂F` (Pa) and the differential
//! `dP = ∂P/∂F : dF` (Pa) used by Newton solvers. All models agree with linear elasticity
//! `σ = λ tr(ε) I + 2 μ ε` for small strains, and every model's energy is non-negative for every
//! `F` (inverted ones included) and every admissible `ν`, zero with zero stress at rest.

mod corotated;
mod diagonal;
mod linear;
mod neo_hookean;
mod per_element;
mod stvk;
mod volumetric;

pub use corotated::Corotated;
pub(crate) use corotated::polar_rotation;
pub use linear::LinearElastic;
pub use neo_hookean::StableNeoHookean;
pub(crate) use per_element::ElementMaterials;
pub use stvk::StVenantKirchhoff;
pub(crate) use stvk::green_strain;
pub use volumetric::VolumetricTerm;

use crate::Error;
use crate::lanes::{Mat3x4, f64x4};
use rapier3d::glamx::DMat3;

/// A hyperelastic constitutive model: energy density, stress and stress differential of the
/// deformation gradient `F` (dimensionless).
pub trait HyperelasticModel: Copy + Send + Sync {
    /// Strain energy density `Ψ(F)` (J/m^3), zero at rest.
    fn energy_density(&self, f: &DMat3) -> f64;
    /// First Piola–Kirchhoff stress `P = ∂Ψ/∂F` (Pa): force per unit rest area.
    fn first_piola(&self, f: &DMat3) -> DMat3;
    /// Differential of the stress, `dP = (∂P/∂F) : dF` (Pa), for a change `df` of `F`.
    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3;

    /// [`HyperelasticModel::first_piola_differential`] for several changes `dfs` at one `F` (the
    /// columns of the stress tangent). The default evaluates them one by one; models whose
    /// differential needs an expensive factorization of `F` override it to do that once.
    fn first_piola_differentials<const N: usize>(&self, f: &DMat3, dfs: &[DMat3; N]) -> [DMat3; N] {
        dfs.each_ref()
            .map(|df| self.first_piola_differential(f, df))
    }

    /// `P(F) + F S_extra` (Pa) in four lanes at once: the stress plus the first Piola–Kirchhoff
    /// form of an extra second Piola–Kirchhoff stress (the damping stress). The default evaluates
    /// the lanes one by one with the scalar methods; models with short branch-free formulas
    /// override it with SIMD arithmetic.
    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let stress = Mat3x4::from_lanes(f.to_lanes().map(|f| self.first_piola(&f)));
        stress + *f * *s_extra
    }
}

/// `λ tr(E) I + 2μ E` in four lanes: the linear law on a symmetric strain `E`.
#[inline(always)]
pub(crate) fn linear_law_lanes(lame: LameParameters, strain: &Mat3x4) -> Mat3x4 {
    (*strain * f64x4::splat(2.0 * lame.mu)).add_diagonal(strain.trace() * f64x4::splat(lame.lambda))
}

/// Which constitutive law a body uses. All four share the Lamé parameters of the material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum MaterialModel {
    /// Linear elasticity on the small (Cauchy) strain `ε = sym(F) - I`. Exact for small
    /// displacements and rotations; a rigid rotation produces spurious stress, so only for bodies
    /// that stay close to their rest orientation.
    Linear,
    /// St. Venant–Kirchhoff: the linear law on the Green strain `G = (FᵀF - I)/2`. Exact under any
    /// rigid motion; fine for large rotations with moderate strain; softens under strong
    /// compression, where below a stretch of 0.6 its principal strains are continued (Irving, Teran
    /// and Fedkiw 2004) so that crushed and inverted elements are pushed back to positive volume.
    StVenantKirchhoff,
    /// Corotated linear elasticity: linear elasticity in the element's rotated frame (polar
    /// decomposition `F = R S`). Rotation-exact, robust, a good default for games.
    Corotated,
    /// Stable Neo-Hookean (Smith, de Goes and Kim 2018, in the form of Kim and Eberle's course
    /// notes): rotation-exact, resists volume change at large strain and stays defined for inverted
    /// elements. The most robust choice for large deformation. For `ν < 0` a compression term
    /// keeps its energy non-negative (see [`StableNeoHookean`]).
    #[default]
    StableNeoHookean,
}

/// Young's modulus and Poisson's ratio, the engineering constants of an isotropic material.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct YoungPoisson {
    /// Young's modulus `E` (Pa), positive.
    pub young_modulus: f64,
    /// Poisson's ratio `ν` (dimensionless), in `(-1, 0.5)`.
    pub poisson_ratio: f64,
}

/// The Lamé parameters of an isotropic material.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct LameParameters {
    /// First Lamé parameter `λ = E ν / ((1 + ν)(1 - 2ν))` (Pa); negative for `ν < 0`.
    pub lambda: f64,
    /// Shear modulus `μ = E / (2 (1 + ν))` (Pa).
    pub mu: f64,
}

impl YoungPoisson {
    /// Checks that `E > 0` (Pa) is finite and `-1 < ν < 0.5`.
    ///
    /// # Errors
    /// [`Error::InvalidMaterial`] naming the parameter out of range.
    pub fn new(young_modulus: f64, poisson_ratio: f64) -> Result<Self, Error> {
        if !(young_modulus.is_finite() && young_modulus > 0.0) {
            return Err(Error::InvalidMaterial {
                parameter: "young_modulus",
                value: young_modulus,
                reason: "must be positive and finite (Pa)",
            });
        }
        if !(poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(Error::InvalidMaterial {
                parameter: "poisson_ratio",
                value: poisson_ratio,
                reason: "must lie in (-1, 0.5) for a stable isotropic material",
            });
        }
        Ok(Self {
            young_modulus,
            poisson_ratio,
        })
    }
}

impl From<YoungPoisson> for LameParameters {
    fn from(c: YoungPoisson) -> Self {
        let (e, nu) = (c.young_modulus, c.poisson_ratio);
        Self {
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
        }
    }
}

impl LameParameters {
    /// The P-wave (dilatational) modulus `λ + 2μ` (Pa).
    pub fn p_wave_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu
    }
}

/// A complete material: constitutive model, elastic constants and density.
///
/// # Example
/// ```
/// use rapier_fvm::material::{Material, MaterialModel};
/// // Soft rubber: E = 1 MPa, ν = 0.45, 1100 kg/m^3.
/// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
/// assert!((rubber.lame().mu - 1e6 / 2.9).abs() < 1e-6);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "MaterialParts")
)]
pub struct Material {
    model: MaterialModel,
    elasticity: YoungPoisson,
    density: f64,
}

/// A [`Material`] as written (feature `serde-serialize`); read back through [`Material::new`].
#[cfg(feature = "serde-serialize")]
#[derive(serde::Deserialize)]
struct MaterialParts {
    model: MaterialModel,
    elasticity: YoungPoisson,
    density: f64,
}

#[cfg(feature = "serde-serialize")]
impl TryFrom<MaterialParts> for Material {
    type Error = Error;

    fn try_from(parts: MaterialParts) -> Result<Self, Error> {
        let YoungPoisson {
            young_modulus,
            poisson_ratio,
        } = parts.elasticity;
        Self::new(parts.model, young_modulus, poisson_ratio, parts.density)
    }
}

impl Material {
    /// A material from its model, Young's modulus (Pa), Poisson's ratio and density (kg/m^3).
    ///
    /// # Errors
    /// [`Error::InvalidMaterial`] if `E <= 0`, `ν` is outside `(-1, 0.5)` or the density is not
    /// positive and finite.
    pub fn new(
        model: MaterialModel,
        young_modulus: f64,
        poisson_ratio: f64,
        density: f64,
    ) -> Result<Self, Error> {
        let elasticity = YoungPoisson::new(young_modulus, poisson_ratio)?;
        if !(density.is_finite() && density > 0.0) {
            return Err(Error::InvalidMaterial {
                parameter: "density",
                value: density,
                reason: "must be positive and finite (kg/m^3)",
            });
        }
        Ok(Self {
            model,
            elasticity,
            density,
        })
    }

    /// The constitutive model.
    pub fn model(&self) -> MaterialModel {
        self.model
    }

    /// Young's modulus and Poisson's ratio.
    pub fn elasticity(&self) -> YoungPoisson {
        self.elasticity
    }

    /// Density (kg/m^3).
    pub fn density(&self) -> f64 {
        self.density
    }

    /// The Lamé parameters (Pa).
    pub fn lame(&self) -> LameParameters {
        self.elasticity.into()
    }

    /// Speed of pressure (dilatational) waves `sqrt((λ + 2μ)/ρ)` (m/s), which bounds the explicit
    /// time step.
    pub fn dilatational_wave_speed(&self) -> f64 {
        (self.lame().p_wave_modulus() / self.density).sqrt()
    }
}

/// Runs `$body` with `$m` bound to the concrete [`HyperelasticModel`] of `$material`, so that hot
/// loops are compiled once per model instead of dispatching per element.
macro_rules! with_hyperelastic_model {
    ($material:expr, |$m:ident| $body:expr) => {{
        let material: &$crate::material::Material = &$material;
        let lame = material.lame();
        match material.model() {
            $crate::material::MaterialModel::Linear => {
                let $m = $crate::material::LinearElastic(lame);
                $body
            }
            $crate::material::MaterialModel::StVenantKirchhoff => {
                let $m = $crate::material::StVenantKirchhoff(lame);
                $body
            }
            $crate::material::MaterialModel::Corotated => {
                let $m = $crate::material::Corotated(lame);
                $body
            }
            $crate::material::MaterialModel::StableNeoHookean => {
                let $m = $crate::material::StableNeoHookean::new(lame);
                $body
            }
        }
    }};
}
pub(crate) use with_hyperelastic_model;

/// `(M + Mᵀ)/2`.
#[inline(always)]
pub(crate) fn symmetric_part(m: &DMat3) -> DMat3 {
    (*m + m.transpose()) * 0.5
}

/// `A : B = tr(Aᵀ B)`, the Frobenius inner product.
#[inline(always)]
pub(crate) fn double_dot(a: &DMat3, b: &DMat3) -> f64 {
    a.x_axis.dot(b.x_axis) + a.y_axis.dot(b.y_axis) + a.z_axis.dot(b.z_axis)
}

/// Whether a symmetric 3x3 matrix is positive definite (Sylvester's criterion: its leading
/// principal minors are positive). False for a non-finite matrix.
#[inline(always)]
pub(crate) fn is_positive_definite(m: &DMat3) -> bool {
    m.x_axis.x > 0.0
        && m.x_axis.x * m.y_axis.y - m.y_axis.x * m.x_axis.y > 0.0
        && m.determinant() > 0.0
}

/// Trace of a 3x3 matrix.
#[inline(always)]
pub(crate) fn trace(m: &DMat3) -> f64 {
    m.x_axis.x + m.y_axis.y + m.z_axis.z
}
