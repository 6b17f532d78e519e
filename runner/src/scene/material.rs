//! `material` and `damping` of a soft body, in SI units.
//!
//! ```toml
//! material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
//! damping = { stiffness_time = 2e-3 }    # s: phi = t λ and psi = t μ
//! damping = { phi = 50.0, psi = 100.0 }  # Pa·s
//! materials = [{ region = "wall", young = 4e5, density = 1200.0 }]
//!                                        # elements of their own E (Pa) and density (kg/m³)
//! ```
//! A region's material keeps the body's model and Poisson's ratio; `young` and `density` default
//! to the body's. It selects a mesh file's volume group (`region`, its elements) or the elements
//! whose centroid lies in a box `min`..`max` (m, rest coordinates); a later entry wins where two
//! overlap. The damping in a region is the body's times the region's `young` over the body's
//! (stiffness-proportional damping keeps its time there; `phi` and `psi` are scaled alike).

use super::check::Checker;
use super::soft_body::RegionName;
use rapier_fvm::damping::RayleighDamping;
use rapier_fvm::material::{Material, MaterialModel};
use serde::Deserialize;

/// A material: constitutive model and constants.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// The constitutive model.
    pub model: ModelSpec,
    /// Young's modulus (Pa), positive.
    pub young: f64,
    /// Poisson's ratio, in (-1, 0.5).
    pub poisson: f64,
    /// Density (kg/m³), positive.
    pub density: f64,
    /// The label bodies are coloured by in the pictures (same label, same colour); default: the
    /// model and Young's modulus, e.g. `stable_neo_hookean, E = 1e5 Pa`.
    pub label: Option<String>,
}

/// The constitutive models of [`MaterialModel`], by their snake-case names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelSpec {
    /// Small-strain linear elasticity.
    Linear,
    /// St. Venant–Kirchhoff.
    StVenantKirchhoff,
    /// Corotated linear elasticity.
    Corotated,
    /// Stable Neo-Hookean.
    StableNeoHookean,
}

impl ModelSpec {
    /// The library's model.
    pub fn model(self) -> MaterialModel {
        match self {
            Self::Linear => MaterialModel::Linear,
            Self::StVenantKirchhoff => MaterialModel::StVenantKirchhoff,
            Self::Corotated => MaterialModel::Corotated,
            Self::StableNeoHookean => MaterialModel::StableNeoHookean,
        }
    }

    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::StVenantKirchhoff => "st_venant_kirchhoff",
            Self::Corotated => "corotated",
            Self::StableNeoHookean => "stable_neo_hookean",
        }
    }
}

impl MaterialSpec {
    /// Checks the constants; `key` is the material's key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        c.positive(&format!("{key}.young"), self.young, "Pa");
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            c.fail(
                &format!("{key}.poisson"),
                format!("must lie in (-1, 0.5), got {}", self.poisson),
            );
        }
        c.positive(&format!("{key}.density"), self.density, "kg/m³");
    }

    /// The library's material.
    ///
    /// # Errors
    /// The library's message for constants it refuses (none once the scene is checked).
    pub fn material(&self) -> Result<Material, rapier_fvm::Error> {
        Material::new(self.model.model(), self.young, self.poisson, self.density)
    }

    /// The label for the pictures.
    pub fn label(&self) -> String {
        self.label
            .clone()
            .unwrap_or_else(|| format!("{}, E = {:e} Pa", self.model.name(), self.young))
    }
}

/// Rayleigh damping on the strain rate: `phi` and `psi` (Pa·s), or `stiffness_time` (s), the
/// stiffness-proportional form `phi = t λ`, `psi = t μ`, in the library's damping stress
/// `σ = φ tr(ε̇) I + 2ψ ε̇`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// Volumetric coefficient φ (Pa·s), on `tr(ε̇) I`; default 0 when `psi` is given.
    pub phi: Option<f64>,
    /// Shear viscosity ψ (Pa·s), on `2 ε̇`; default 0 when `phi` is given.
    pub psi: Option<f64>,
    /// Stiffness-proportional time β (s), instead of `phi` and `psi`.
    pub stiffness_time: Option<f64>,
}

impl DampingSpec {
    /// Checks that one form is given with non-negative values; `key` is the damping's key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        let direct = self.phi.is_some() || self.psi.is_some();
        match (direct, self.stiffness_time) {
            (true, Some(_)) => c.fail(
                key,
                "give either `phi` and `psi` or `stiffness_time`, not both",
            ),
            (false, None) => c.fail(key, "give `phi` and `psi` (Pa·s) or `stiffness_time` (s)"),
            (false, Some(t)) => c.non_negative(&format!("{key}.stiffness_time"), t, "s"),
            (true, None) => {
                for (name, value) in [("phi", self.phi), ("psi", self.psi)] {
                    if let Some(value) = value {
                        c.non_negative(&format!("{key}.{name}"), value, "Pa·s");
                    }
                }
            }
        }
    }

    /// The library's damping for `material`.
    ///
    /// # Errors
    /// The library's message for values it refuses.
    pub fn damping(&self, material: &Material) -> Result<RayleighDamping, rapier_fvm::Error> {
        match self.stiffness_time {
            Some(t) => RayleighDamping::stiffness_proportional(t, material.lame()),
            None => RayleighDamping::new(self.phi.unwrap_or(0.0), self.psi.unwrap_or(0.0)),
        }
    }
}

/// Elements of a soft body with their own Young's modulus and density.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionMaterialSpec {
    /// Lower corner of the box (m, rest coordinates) the elements' centroids lie in.
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m, rest coordinates).
    pub max: Option<[f64; 3]>,
    /// The mesh file's volume group, in place of a box.
    pub region: Option<RegionName>,
    /// Young's modulus (Pa); default the body's.
    pub young: Option<f64>,
    /// Density (kg/m³); default the body's.
    pub density: Option<f64>,
}

impl RegionMaterialSpec {
    /// Checks the selection and the constants; `key` is its key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        self.selection().check(key, c);
        if self.young.is_none() && self.density.is_none() {
            c.fail(key, "give `young` (Pa), `density` (kg/m³) or both");
        }
        if let Some(young) = self.young {
            c.positive(&format!("{key}.young"), young, "Pa");
        }
        if let Some(density) = self.density {
            c.positive(&format!("{key}.density"), density, "kg/m³");
        }
    }

    /// The region's material: `body`'s with this Young's modulus and density.
    ///
    /// # Errors
    /// The library's message for constants it refuses (none once the scene is checked).
    pub fn material(&self, body: &MaterialSpec) -> Result<Material, rapier_fvm::Error> {
        Material::new(
            body.model.model(),
            self.young.unwrap_or(body.young),
            body.poisson,
            self.density.unwrap_or(body.density),
        )
    }
}
