//! Materials that change from element to element inside one body (a stiff wall in a soft
//! finger, a hard core in a gel).
//!
//! Every element keeps the body's constitutive model and Poisson's ratio; its Young's modulus
//! `E_e` and density `ρ_e` are its own. Every model's energy, stress and tangent are proportional
//! to `E` at fixed `ν` (both Lamé parameters are), so an element of modulus `E_e` is the body's
//! model times its stiffness factor `s_e = E_e / E`: the factor multiplies the element's
//! integration weights, and nothing else in the force, energy or tangent loops changes. The
//! element's Rayleigh damping stress is scaled alike: stiffness-proportional damping keeps its
//! time constant `β` in every element. Masses are lumped from each element's own density.

use super::Material;
use crate::Error;

/// The materials of a body whose elements do not all share one: the assignments as given and,
/// per element, its stiffness factor and density.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ElementMaterials {
    /// The assignments in the order given: element indices and their material. An element
    /// named by several takes the last one's.
    assignments: Vec<(Vec<u32>, Material)>,
    /// Per element, the index of its assignment plus one; 0 for the body's material.
    sources: Vec<u32>,
    /// Per element, `s_e = E_e / E` (dimensionless).
    stiffness_factors: Vec<f64>,
    /// Per element, its density (kg/m³).
    densities: Vec<f64>,
    /// Per node, its rest control volume (m³): the masses over one density no longer give it.
    control_volumes: Vec<f64>,
    /// `Σ s_e V_e` (m³) over the elements: the body's volume as its stiffness sees it.
    stiffness_volume: f64,
}

impl ElementMaterials {
    /// The materials of a body of `element_count` elements whose material is `body` and whose
    /// elements listed in `assignments` take the material given with them; `None` when there
    /// are no assignments or they change no element's modulus or density. Its
    /// [geometry](ElementMaterials::set_geometry) is to be set once the elements are built.
    ///
    /// # Errors
    /// [`Error::ElementOutOfRange`] for an element index not below `element_count`;
    /// [`Error::RegionMaterialMismatch`] for a material of another model or Poisson's ratio
    /// than `body`'s.
    pub(crate) fn new(
        body: &Material,
        assignments: Vec<(Vec<u32>, Material)>,
        element_count: usize,
    ) -> Result<Option<Self>, Error> {
        if assignments.is_empty() {
            return Ok(None);
        }
        let mut sources = vec![0; element_count];
        let mut stiffness_factors = vec![1.0; element_count];
        let mut densities = vec![body.density(); element_count];
        for (source, (elements, material)) in (1..).zip(&assignments) {
            if material.model() != body.model() {
                return Err(Error::RegionMaterialMismatch { what: "model" });
            }
            if material.elasticity().poisson_ratio != body.elasticity().poisson_ratio {
                return Err(Error::RegionMaterialMismatch {
                    what: "Poisson's ratio",
                });
            }
            let factor = young(material) / young(body);
            for &element in elements {
                let e = element as usize;
                if e >= element_count {
                    return Err(Error::ElementOutOfRange {
                        element: e,
                        element_count,
                    });
                }
                sources[e] = source;
                stiffness_factors[e] = factor;
                densities[e] = material.density();
            }
        }
        let uniform = stiffness_factors.iter().all(|&s| s == 1.0)
            && densities.iter().all(|&d| d == body.density());
        Ok((!uniform).then_some(Self {
            assignments,
            sources,
            stiffness_factors,
            densities,
            control_volumes: Vec::new(),
            stiffness_volume: 0.0,
        }))
    }

    /// Sets what the elements' rest geometry gives: each node's rest `control_volumes` (m³)
    /// and `Σ s_e V_e` (m³), the `stiffness_volume`.
    pub(crate) fn set_geometry(&mut self, control_volumes: Vec<f64>, stiffness_volume: f64) {
        self.control_volumes = control_volumes;
        self.stiffness_volume = stiffness_volume;
    }

    /// Per node, its rest control volume (m³).
    pub(crate) fn control_volumes(&self) -> &[f64] {
        &self.control_volumes
    }

    /// `Σ s_e V_e` (m³) over the elements.
    pub(crate) fn stiffness_volume(&self) -> f64 {
        self.stiffness_volume
    }

    /// The assignments as given.
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn assignments(&self) -> &[(Vec<u32>, Material)] {
        &self.assignments
    }

    /// Per element, `s_e = E_e / E` (dimensionless).
    pub(crate) fn stiffness_factors(&self) -> &[f64] {
        &self.stiffness_factors
    }

    /// Per element, its density (kg/m³).
    pub(crate) fn densities(&self) -> &[f64] {
        &self.densities
    }

    /// The material of element `element` in a body of material `body`.
    ///
    /// # Panics
    /// If the element does not exist.
    pub(crate) fn material_of(&self, body: &Material, element: usize) -> Material {
        match self.sources[element] {
            0 => *body,
            source => self.assignments[source as usize - 1].1,
        }
    }
}

/// Young's modulus (Pa) of `material`.
fn young(material: &Material) -> f64 {
    material.elasticity().young_modulus
}
