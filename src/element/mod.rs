//! The elements a body is discretized by: linear tetrahedra (the finite-volume kernel of
//! [`crate::fvm`]), 10-node quadratic tetrahedra ([`tet10`]) or 27-node quadratic hexahedra
//! ([`hex27`], the element of a coarse cage).
//!
//! Both are seen by the rest of the crate as integration points: a point has the nodes of its
//! element, the rest gradients `∇N_a` (1/m) of their shape functions there, and its weight `w`:
//! the rest volume it stands for (times its element's `E_e/E` where the body's materials differ
//! by region). The deformation gradient at a point is `F = Σ_a x_a ⊗ ∇N_a`, the force on node
//! `a` is `−w P ∇N_a`, the energy `Σ w Ψ(F)` and the tangent `Σ w ∇N_aᵀ (∂P/∂F) ∇N_b`. A linear
//! tetrahedron is one point with its whole volume, and `−V P ∇N_a` is exactly the finite-volume
//! traction `P b_a` on node `a`'s control-volume boundary; a quadratic tetrahedron has four points
//! and a quadratic hexahedron 27 (Galerkin quadrature, which the finite-volume form reduces to for
//! linear elements).

mod mean_dilatation;
mod quadratic;
mod step;

pub use crate::shape::{hex27, tet10};

use crate::damping::RayleighDamping;
use crate::fvm::{FvmMesh, NodalAveraging, VolumetricTreatment};
use crate::material::VolumetricTerm;
pub(crate) use mean_dilatation::{PressureBasis, projected_measure};
pub(crate) use quadratic::deformation_gradient;
pub use quadratic::{ElementShape, QuadraticElements};
use rapier3d::glamx::{DMat3, DVec3};

/// Elements per chunk of [`Elements::sum_over_points`].
const ELEMENTS_PER_SUM: usize = 2048;

/// The most nodes an element has (quadratic hexahedra).
pub(crate) const MAX_ELEMENT_NODES: usize = hex27::NODES;

/// The polynomial order of a body's elements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum ElementOrder {
    /// 4-node tetrahedra, linear motion and constant strain per element.
    Linear,
    /// Quadratic motion and linear strain per element: 10-node tetrahedra with mid-edge nodes,
    /// or 27-node hexahedra (see [`ElementShape`]).
    Quadratic,
}

/// A body's elements with their rest data.
#[derive(Debug, Clone)]
pub(crate) enum Elements {
    Linear {
        fvm: FvmMesh,
        /// The node patches the volumetric term is averaged over, when it is
        /// ([`crate::fvm::VolumetricTreatment::NodalAverage`]).
        nodal_averaging: Option<NodalAveraging>,
    },
    Quadratic {
        elements: QuadraticElements,
        /// The pressure functions the volumetric term is projected on, when it is
        /// ([`mean_dilatation`]).
        pressure: Option<PressureBasis>,
    },
}

impl Elements {
    /// The order of the elements.
    pub(crate) fn order(&self) -> ElementOrder {
        match self {
            Self::Linear { .. } => ElementOrder::Linear,
            Self::Quadratic { .. } => ElementOrder::Quadratic,
        }
    }

    /// The quadratic elements' shape and nodes; `None` for linear tetrahedra.
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn quadratic_nodes(&self) -> Option<(ElementShape, &[u32])> {
        match self {
            Self::Linear { .. } => None,
            Self::Quadratic { elements, .. } => Some((elements.shape(), elements.nodes())),
        }
    }

    /// The shape of the elements.
    pub(crate) fn shape(&self) -> ElementShape {
        match self {
            Self::Linear { .. } => ElementShape::Tetrahedron,
            Self::Quadratic { elements, .. } => elements.shape(),
        }
    }

    /// How the volumetric part of the energy is evaluated.
    pub(crate) fn volumetric_treatment(&self) -> VolumetricTreatment {
        match self {
            Self::Linear {
                nodal_averaging: Some(_),
                ..
            } => VolumetricTreatment::NodalAverage,
            Self::Quadratic {
                pressure: Some(_), ..
            } => VolumetricTreatment::ElementAverage,
            _ => VolumetricTreatment::PerElement,
        }
    }

    /// The nodal averaging and the linear elements it averages over, when the body uses it.
    pub(crate) fn nodal_averaging(&self) -> Option<(&NodalAveraging, &FvmMesh)> {
        match self {
            Self::Linear {
                fvm,
                nodal_averaging: Some(averaging),
            } => Some((averaging, fvm)),
            _ => None,
        }
    }

    /// Number of integration points.
    pub(crate) fn point_count(&self) -> usize {
        match self {
            Self::Linear { fvm, .. } => fvm.tets().len(),
            Self::Quadratic { elements, .. } => elements.point_count(),
        }
    }

    /// The node lists of the elements (the nodes each couples in the tangent).
    pub(crate) fn element_nodes(&self) -> Box<dyn Iterator<Item = &[u32]> + '_> {
        match self {
            Self::Linear { fvm, .. } => Box::new(fvm.tets().iter().map(|t| &t[..])),
            Self::Quadratic { elements, .. } => Box::new(elements.elements()),
        }
    }

    /// Number of elements.
    pub(crate) fn element_count(&self) -> usize {
        match self {
            Self::Linear { fvm, .. } => fvm.tets().len(),
            Self::Quadratic { elements, .. } => elements.element_count(),
        }
    }

    /// Nodes per element.
    pub(crate) fn nodes_per_element(&self) -> usize {
        match self {
            Self::Linear { .. } => 4,
            Self::Quadratic { elements, .. } => elements.shape().node_count(),
        }
    }

    /// Calls `visit(point, nodes, gradients, weight)` for every integration point in order: its
    /// index, its element's nodes, their rest shape-function gradients there (1/m) and its
    /// stiffness weight (m³): the rest volume it stands for, times its element's stiffness factor
    /// (1 unless materials differ by region).
    pub(crate) fn for_each_point(&self, visit: impl FnMut(usize, &[u32], &[DVec3], f64)) {
        self.for_each_point_in(0..self.element_count(), visit);
    }

    /// [`Elements::for_each_point`] over the points of the elements `elements` only.
    pub(crate) fn for_each_point_in(
        &self,
        elements: std::ops::Range<usize>,
        mut visit: impl FnMut(usize, &[u32], &[DVec3], f64),
    ) {
        match self {
            Self::Linear { fvm, .. } => {
                for t in elements {
                    let rest = fvm.tet_rest(t);
                    visit(
                        t,
                        &fvm.tets()[t],
                        &rest.shape_gradients(),
                        fvm.tet_weight(t),
                    );
                }
            }
            Self::Quadratic {
                elements: quadratic,
                ..
            } => {
                for element in elements {
                    let nodes = quadratic.element(element);
                    for point in quadratic.element_points(element) {
                        visit(
                            point,
                            nodes,
                            quadratic.point_gradients(point),
                            quadratic.point_weight(point),
                        );
                    }
                }
            }
        }
    }

    /// The deformation gradient at every integration point for positions `x` (m).
    pub(crate) fn gradients(&self, x: &[DVec3]) -> Vec<DMat3> {
        let mut out = Vec::with_capacity(self.point_count());
        self.for_each_point(|_, nodes, gradients, _| {
            out.push(deformation_gradient(nodes, gradients, x));
        });
        out
    }

    /// Per integration point, its share `Π m_q − m_q` of the element-projected volumetric term
    /// at positions `x` (m), when the elements average it ([`mean_dilatation`]).
    pub(crate) fn volumetric_excesses<M: VolumetricTerm>(
        &self,
        model: &M,
        x: &[DVec3],
    ) -> Option<Vec<f64>> {
        match self {
            Self::Quadratic {
                elements,
                pressure: Some(basis),
            } => Some(mean_dilatation::excesses(model, elements, basis, x)),
            _ => None,
        }
    }

    /// Writes into `out` the internal force (N) on every node for positions `x` (m) and
    /// velocities `v` (m/s).
    pub(crate) fn internal_forces<M: VolumetricTerm>(
        &mut self,
        model: &M,
        damping: Option<&RayleighDamping>,
        x: &[DVec3],
        v: &[DVec3],
        out: &mut [DVec3],
    ) {
        if let Self::Linear {
            fvm,
            nodal_averaging,
        } = self
        {
            fvm.internal_forces(model, damping, x, v, out);
            if let Some(averaging) = nodal_averaging {
                averaging.add_forces(model, fvm, x, out);
            }
            return;
        }
        self.point_forces(model, x, out, |_, nodes, gradients, f| {
            damping.map_or(DMat3::ZERO, |damping| {
                damping.first_piola(f, &deformation_gradient(nodes, gradients, v))
            })
        });
    }

    /// Writes into `out` the forces (N) of the integration points' stresses at positions `x`
    /// (m): the model's first Piola–Kirchhoff stress (with the averaged volumetric term's share
    /// when the elements average it) plus `damping(point, nodes, gradients, F)` (Pa).
    pub(super) fn point_forces<M: VolumetricTerm>(
        &self,
        model: &M,
        x: &[DVec3],
        out: &mut [DVec3],
        damping: impl Fn(usize, &[u32], &[DVec3], &DMat3) -> DMat3 + Sync + Send,
    ) {
        out.fill(DVec3::ZERO);
        let excesses = self.volumetric_excesses(model, x);
        let bulk = model.volumetric_modulus();
        self.add_stress_forces(out, |point, nodes, gradients| {
            let f = deformation_gradient(nodes, gradients, x);
            let mut stress = model.first_piola(&f);
            if let Some(excesses) = &excesses {
                stress += model.volume_measure_gradient(&f) * (bulk * excesses[point]);
            }
            stress + damping(point, nodes, gradients, &f)
        });
    }

    /// Adds `−w P ∇N_a` (N) to `out[a]` for every node `a` of every integration point, `P =
    /// stress(point, nodes, gradients)` (Pa) and `w` the point's weight (m³). Above
    /// [`ELEMENTS_PER_SUM`] elements, each chunk of that many elements sums its forces on one
    /// thread (rayon's with the `parallel` feature) over the span of nodes it touches, and the
    /// chunks' forces are added in order: the same whatever the number of threads.
    pub(crate) fn add_stress_forces(
        &self,
        out: &mut [DVec3],
        stress: impl Fn(usize, &[u32], &[DVec3]) -> DMat3 + Sync + Send,
    ) {
        let count = self.element_count();
        if count <= ELEMENTS_PER_SUM {
            self.for_each_point(|point, nodes, gradients, weight| {
                add_point_forces(
                    nodes,
                    gradients,
                    &(stress(point, nodes, gradients) * weight),
                    out,
                );
            });
            return;
        }
        let windows = crate::parallel::map_ranges(count, ELEMENTS_PER_SUM, |elements| {
            let (first, last) = elements
                .clone()
                .flat_map(|e| self.element(e))
                .fold((u32::MAX, 0), |(first, last), &n| {
                    (first.min(n), last.max(n))
                });
            let mut window = vec![DVec3::ZERO; (last + 1 - first) as usize];
            self.for_each_point_in(elements, |point, nodes, gradients, weight| {
                let weighted = stress(point, nodes, gradients) * weight;
                for (&n, g) in nodes.iter().zip(gradients) {
                    window[(n - first) as usize] -= weighted * *g;
                }
            });
            (first as usize, window)
        });
        for (first, window) in windows {
            for (total, force) in out[first..].iter_mut().zip(window) {
                *total += force;
            }
        }
    }

    /// The nodes of element `element`.
    fn element(&self, element: usize) -> &[u32] {
        match self {
            Self::Linear { fvm, .. } => &fvm.tets()[element],
            Self::Quadratic { elements, .. } => elements.element(element),
        }
    }

    /// Elastic strain energy (J) at positions `x` (m).
    pub(crate) fn elastic_energy<M: VolumetricTerm>(&self, model: &M, x: &[DVec3]) -> f64 {
        let mut energy = match self {
            Self::Linear {
                fvm,
                nodal_averaging: Some(averaging),
            } => return averaging.elastic_energy(model, fvm, x),
            Self::Linear { fvm, .. } => return fvm.elastic_energy(model, x),
            Self::Quadratic {
                elements,
                pressure: Some(basis),
            } => mean_dilatation::energy_change(model, elements, basis, x),
            Self::Quadratic { .. } => 0.0,
        };
        energy += self.sum_over_points(|_, nodes, gradients, weight| {
            weight * model.energy_density(&deformation_gradient(nodes, gradients, x))
        });
        energy
    }

    /// `Σ term(point, nodes, gradients, weight)` over the integration points (see
    /// [`Elements::for_each_point`]), summed in chunks of [`ELEMENTS_PER_SUM`] elements (on
    /// rayon's threads with the `parallel` feature), the chunks' sums in order: the same
    /// whatever the number of threads.
    pub(crate) fn sum_over_points(
        &self,
        term: impl Fn(usize, &[u32], &[DVec3], f64) -> f64 + Sync + Send,
    ) -> f64 {
        crate::parallel::sum_ranges(self.element_count(), ELEMENTS_PER_SUM, |elements| {
            let mut sum = 0.0;
            self.for_each_point_in(elements, |point, nodes, gradients, weight| {
                sum += term(point, nodes, gradients, weight);
            });
            sum
        })
    }

    /// Calls `add(gradient, weight)` for every rank-one term `weight g gᵀ` (N/m) the averaged
    /// volumetric term adds to the tangent, `g` given per node; nothing without averaging.
    pub(crate) fn for_each_volumetric_coupling<M: VolumetricTerm>(
        &self,
        model: &M,
        x: &[DVec3],
        add: impl FnMut(&[(u32, DVec3)], f64),
    ) {
        if let Self::Quadratic {
            elements,
            pressure: Some(basis),
        } = self
        {
            mean_dilatation::for_each_coupling(model, elements, basis, x, add);
        }
    }

    /// The wave length scale (m) at positions `x`, see [`FvmMesh::wave_length_scale`] (and for
    /// `mass_volumes`); for quadratic elements the same Gershgorin bound with the sums over
    /// quadrature points and each node's lumped volume in place of a quarter of each tetrahedron.
    pub(crate) fn wave_length_scale(&self, x: &[DVec3], mass_volumes: Option<&[f64]>) -> f64 {
        let control_volumes = match self {
            Self::Linear { fvm, .. } => return fvm.mixed_wave_length_scale(x, mass_volumes),
            Self::Quadratic { elements, .. } => {
                mass_volumes.unwrap_or_else(|| elements.lumped_volumes())
            }
        };
        let mut row_sum = vec![0.0; control_volumes.len()];
        let mut flattened = false;
        self.for_each_point(|_, nodes, gradients, weight| {
            let f = deformation_gradient(nodes, gradients, x);
            let determinant = f.determinant();
            if determinant.abs() <= f64::EPSILON {
                flattened = true;
                return;
            }
            let spatial = f.inverse().transpose();
            let mut lengths = [0.0; MAX_ELEMENT_NODES];
            for (length, g) in lengths.iter_mut().zip(gradients) {
                *length = (spatial * *g).length();
            }
            let total: f64 = lengths.iter().sum();
            for (&n, length) in nodes.iter().zip(lengths) {
                row_sum[n as usize] += weight * length * total;
            }
        });
        if flattened {
            return 0.0;
        }
        control_volumes
            .iter()
            .zip(&row_sum)
            .filter(|(_, row)| **row > 0.0)
            .map(|(volume, row)| 2.0 * (volume / row).sqrt())
            .fold(f64::INFINITY, f64::min)
    }
}

/// Adds the forces `−w P ∇N_a` (N) of one integration point to its nodes, `weighted_stress` being
/// `w P` (N·m⁻²·m³ = N·m).
#[inline]
pub(crate) fn add_point_forces(
    nodes: &[u32],
    gradients: &[DVec3],
    weighted_stress: &DMat3,
    out: &mut [DVec3],
) {
    for (&n, g) in nodes.iter().zip(gradients) {
        out[n as usize] -= *weighted_stress * *g;
    }
}

#[cfg(test)]
mod tests {
    use crate::assembly::{assert_forces_and_tangent_match_energy, perturb_positions};
    use crate::prelude::*;

    /// A quadratic 2 x 2 x 2-cell cube whose nodes are moved randomly by up to 7.5 % of its size.
    fn perturbed_quadratic_cube(
        model: MaterialModel,
        nu: f64,
        treatment: VolumetricTreatment,
    ) -> DeformableBody {
        let material = Material::new(model, 1e6, nu, 1000.0).unwrap();
        let linear = mesh::cuboid(DVec3::splat(0.5), [2, 2, 2]).unwrap();
        let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
        let mut body = DeformableBodyBuilder::quadratic(quadratic, material)
            .volumetric(treatment)
            .build()
            .unwrap();
        assert_eq!(body.volumetric_treatment(), treatment);
        perturb_positions(&mut body, 11, 0.075);
        body
    }

    /// A 2 x 1 x 1-cell cage of quadratic hexahedra (each 0.5 m wide) whose nodes are moved
    /// randomly by up to 3.75 % of its size.
    fn perturbed_hex_cage(
        model: MaterialModel,
        nu: f64,
        treatment: VolumetricTreatment,
    ) -> DeformableBody {
        let material = Material::new(model, 1e6, nu, 1000.0).unwrap();
        let cage = mesh::QuadraticHexMesh::cuboid(DVec3::new(0.5, 0.25, 0.25), [2, 1, 1]).unwrap();
        let mut body = DeformableBodyBuilder::quadratic_hex(cage, material)
            .volumetric(treatment)
            .build()
            .unwrap();
        perturb_positions(&mut body, 13, 0.0375);
        body
    }

    /// For quadratic elements of both shapes as for linear ones, with and without mean dilatation
    /// (the projected volumetric term): the forces
    /// are minus the gradient of the energy, and the assembled tangent minus the gradient of the
    /// forces, by central differences
    /// (see [`assert_forces_and_tangent_match_energy`] for the step and tolerances).
    #[test]
    fn quadratic_forces_and_tangent_match_finite_differences_of_the_energy() {
        for model in [
            MaterialModel::Linear,
            MaterialModel::StVenantKirchhoff,
            MaterialModel::Corotated,
            MaterialModel::StableNeoHookean,
        ] {
            for (nu, treatment) in [
                (0.3, VolumetricTreatment::PerElement),
                (0.49, VolumetricTreatment::PerElement),
                (-0.6, VolumetricTreatment::PerElement),
                (0.3, VolumetricTreatment::ElementAverage),
                (0.499, VolumetricTreatment::ElementAverage),
            ] {
                let mut body = perturbed_quadratic_cube(model, nu, treatment);
                assert_forces_and_tangent_match_energy(
                    &mut body,
                    &format!("{model:?} ν = {nu} {treatment:?}"),
                );
                let mut cage = perturbed_hex_cage(model, nu, treatment);
                assert_forces_and_tangent_match_energy(
                    &mut cage,
                    &format!("hexahedra: {model:?} ν = {nu} {treatment:?}"),
                );
            }
        }
    }
}
