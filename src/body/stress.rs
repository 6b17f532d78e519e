//! Per-tetrahedron stress at the current positions, for output and post-processing: the Cauchy
//! (true) stress `σ = P Fᵀ / det F` (Pa), force per unit deformed area in world axes, from the
//! first Piola–Kirchhoff stress `P` of the element's material, and its von Mises equivalent
//! `σ_vm = sqrt(3/2 s:s)`, `s = σ - tr(σ)/3 I`.

use super::DeformableBody;
use crate::element::{Elements, projected_measure};
use crate::fvm::{TetRest, gather};
use crate::material::{HyperelasticModel, VolumetricTerm, with_hyperelastic_model};
use rapier3d::glamx::{DMat3, DVec3};

/// The Cauchy stress `P Fᵀ / det F` (Pa) for a deformation gradient `f` and first
/// Piola–Kirchhoff stress `piola` (Pa); the Kirchhoff stress `P Fᵀ` where `det F <= 0`.
fn cauchy_from_piola(f: &DMat3, piola: DMat3) -> DMat3 {
    let kirchhoff = piola * f.transpose();
    let volume_ratio = f.determinant();
    if volume_ratio > 0.0 {
        kirchhoff * volume_ratio.recip()
    } else {
        kirchhoff
    }
}

impl DeformableBody {
    /// The Cauchy stress `σ = P Fᵀ / det F` (Pa) of every tetrahedron of [`DeformableBody::mesh`] at
    /// the current positions, in mesh order and world axes; symmetric for every model. For
    /// quadratic elements, whose stress varies inside the element, each tetrahedron of the
    /// subdivision gets the stress at its centroid.
    ///
    /// It is the elastic stress the internal forces come from: with
    /// [`VolumetricTreatment::NodalAverage`](crate::fvm::VolumetricTreatment::NodalAverage) it
    /// includes the element's share of the averaged volumetric term. The viscous stress of the
    /// Rayleigh damping is not included.
    ///
    /// An inverted or flattened tetrahedron (`det F <= 0`) has no Cauchy stress; for it the
    /// Kirchhoff stress `τ = P Fᵀ` (Pa) is returned instead, the Cauchy stress it would have at
    /// its rest volume: finite and of the right sign, never NaN for finite positions. Count those
    /// elements with [`DeformableBody::inverted_tet_count`].
    pub fn cauchy_stresses(&self) -> Vec<DMat3> {
        with_hyperelastic_model!(self.material, |model| {
            match &self.elements {
                Elements::Linear {
                    fvm,
                    nodal_averaging,
                } => {
                    let measures = nodal_averaging
                        .as_ref()
                        .map(|averaging| averaging.measures(&model, fvm, &self.positions));
                    let bulk = model.volumetric_modulus();
                    fvm.tets()
                        .iter()
                        .enumerate()
                        .map(|(t, tet)| {
                            let f = fvm.tet_rest(t).gradient(&gather(tet, &self.positions));
                            let mut piola = model.first_piola(&f);
                            if let Some(measures) = &measures {
                                piola += model.volume_measure_gradient(&f)
                                    * (bulk * measures.excess(tet, t));
                            }
                            cauchy_from_piola(&f, piola * self.stiffness_factor(t))
                        })
                        .collect()
                }
                Elements::Quadratic {
                    elements: quadratic,
                    pressure,
                } => {
                    let rest = self.mesh.positions();
                    let bulk = model.volumetric_modulus();
                    let reference = quadratic.shape().reference_nodes();
                    self.mesh
                        .tets()
                        .iter()
                        .enumerate()
                        .map(|(t, sub_tet)| {
                            let element = self.subdivision_parents[t] as usize;
                            // The centroid's natural coordinates: the tetrahedron's nodes are
                            // the element's own.
                            let nodes = quadratic.element(element);
                            let xi = sub_tet
                                .iter()
                                .map(|n| {
                                    let local = nodes.iter().position(|m| m == n).unwrap_or(0);
                                    reference[local]
                                })
                                .sum::<DVec3>()
                                * 0.25;
                            let f = quadratic.gradient_at(element, rest, &self.positions, xi);
                            let mut piola = model.first_piola(&f);
                            if let Some(basis) = pressure {
                                let projected = projected_measure(
                                    &model,
                                    quadratic,
                                    basis,
                                    element,
                                    xi,
                                    &self.positions,
                                );
                                piola += model.volume_measure_gradient(&f)
                                    * (bulk * (projected - model.volume_measure(&f)));
                            }
                            cauchy_from_piola(&f, piola * self.stiffness_factor(element))
                        })
                        .collect()
                }
            }
        })
    }

    /// The Cauchy stress (Pa) of every tetrahedron of the embedded mesh
    /// ([`DeformableBody::embedding`]) at the current positions, in its mesh order and world axes;
    /// `None` without one. Each is the material's stress at the fine tetrahedron's own
    /// deformation gradient, from its interpolated vertices: the simulated field's mean over
    /// the tetrahedron (exact for a fine tetrahedron inside one linear element). The
    /// volumetric projection of [`VolumetricTreatment::ElementAverage`](crate::fvm::VolumetricTreatment::ElementAverage)
    /// and the viscous stress are not included; inverted tetrahedra get the Kirchhoff stress,
    /// as in [`DeformableBody::cauchy_stresses`].
    pub fn embedded_cauchy_stresses(&self) -> Option<Vec<DMat3>> {
        let embedding = self.embedding.as_ref()?;
        let x = embedding.positions(&self.positions);
        let rest = embedding.mesh().positions();
        Some(with_hyperelastic_model!(self.material, |model| {
            embedding
                .mesh()
                .tets()
                .iter()
                .map(|tet| {
                    let f = TetRest::new(gather(tet, rest)).gradient(&gather(tet, &x));
                    cauchy_from_piola(&f, model.first_piola(&f))
                })
                .collect()
        }))
    }

    /// Element `element`'s Young's modulus over the body's material's (1 unless materials differ
    /// by region): the factor of its stress.
    fn stiffness_factor(&self, element: usize) -> f64 {
        (self.element_materials.as_ref()).map_or(1.0, |m| m.stiffness_factors()[element])
    }

    /// The von Mises equivalent stress `sqrt(3/2 s:s)` (Pa) of a stress tensor `stress` (Pa),
    /// with `s` its deviatoric part: the uniaxial stress of the same distortion energy.
    pub fn von_mises(stress: &DMat3) -> f64 {
        let mean = (stress.x_axis.x + stress.y_axis.y + stress.z_axis.z) / 3.0;
        let deviator = *stress - DMat3::IDENTITY * mean;
        let squared = deviator.x_axis.length_squared()
            + deviator.y_axis.length_squared()
            + deviator.z_axis.length_squared();
        (1.5 * squared).sqrt()
    }
}
