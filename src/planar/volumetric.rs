//! Nodal averaging of the volumetric term for plane strain (Bonet and Burton 1998, as
//! [`crate::fvm::VolumetricTreatment::NodalAverage`] in 3D): linear triangles held to a single
//! volume strain each lock as `ν → 0.5`; averaged over each node's patch,
//!
//! `E = Σ_e t A_e Ψ_rest(F_e) + Σ_a t W_a K/2 θ_a²`, `θ_a = Σ_{e∋a} A_e m_e / P_a`,
//!
//! with `W_a` the node's control area, `P_a = Σ_{e∋a} A_e` its patch area and `m` the model's
//! volume measure ([`crate::material::VolumetricTerm`]): one constraint per node against two
//! unknowns, so the mesh is free to bend. The forces are those of the element stress
//! `P(F_e) + K (θ̄_e − m_e) ∂m/∂F` with `θ̄_e = Σ_{a∈e} W_a θ_a / P_a`, and the tangent gains
//! `Σ_a t W_a K g_a g_aᵀ`, `g_a = ∂θ_a/∂x`, which couples the nodes of a patch.

use super::points::IntegrationPoints;
use rapier3d::glamx::DVec2;

/// The patches of a mesh: each node's control and patch areas and its triangles.
#[derive(Debug, Clone)]
pub(super) struct NodalPatches {
    /// `W_a / P_a` per node (dimensionless): the node's share of its patch.
    share: Vec<f64>,
    /// `W_a` per node (m²).
    control_area: Vec<f64>,
    /// `P_a` per node (m²).
    patch_area: Vec<f64>,
}

/// The averaged volume measures at some positions.
#[derive(Debug, Clone)]
pub(super) struct Averages {
    /// `m_e` per triangle.
    pub(super) measure: Vec<f64>,
    /// `θ_a` per node.
    pub(super) node: Vec<f64>,
    /// `θ̄_e` per triangle.
    pub(super) element: Vec<f64>,
}

impl NodalPatches {
    /// The patches of the linear triangles of `points` (one point each) and the nodes'
    /// `control_areas` (m²).
    pub(super) fn new(points: &IntegrationPoints, control_areas: &[f64]) -> Self {
        let mut patch_area = vec![0.0; control_areas.len()];
        for q in 0..points.len() {
            for &n in points.nodes(q) {
                patch_area[n as usize] += points.weight(q);
            }
        }
        let share = control_areas
            .iter()
            .zip(&patch_area)
            .map(|(w, p)| w / p)
            .collect();
        Self {
            share,
            control_area: control_areas.to_vec(),
            patch_area,
        }
    }

    /// The averages of the triangles' volume `measure`s.
    pub(super) fn averages(&self, points: &IntegrationPoints, measure: Vec<f64>) -> Averages {
        let mut node = vec![0.0; self.patch_area.len()];
        for (q, m) in measure.iter().enumerate() {
            for &n in points.nodes(q) {
                node[n as usize] += points.weight(q) * m;
            }
        }
        for (theta, p) in node.iter_mut().zip(&self.patch_area) {
            *theta /= p;
        }
        let element = (0..points.len())
            .map(|q| {
                (points.nodes(q).iter())
                    .map(|&n| self.share[n as usize] * node[n as usize])
                    .sum()
            })
            .collect();
        Averages {
            measure,
            node,
            element,
        }
    }

    /// `Σ_a W_a K/2 θ_a²` (J per m of thickness) for the bulk modulus `k` (Pa).
    pub(super) fn energy(&self, averages: &Averages, k: f64) -> f64 {
        (self.control_area.iter().zip(&averages.node))
            .map(|(w, theta)| 0.5 * k * w * theta * theta)
            .sum()
    }

    /// The gradients `g_a = ∂θ_a/∂x` (1/m) of every node's average, as (node, entries) with
    /// the entries (neighbour node, gradient) summed over the patch, given each point's
    /// `∂m/∂x` per node (`measure_gradients`, in the order of the point's nodes).
    pub(super) fn average_gradients(
        &self,
        points: &IntegrationPoints,
        measure_gradients: &[Vec<DVec2>],
    ) -> Vec<Vec<(u32, DVec2)>> {
        let mut gradients: Vec<Vec<(u32, DVec2)>> = vec![Vec::new(); self.patch_area.len()];
        for (q, node_gradients) in measure_gradients.iter().enumerate() {
            let nodes = points.nodes(q);
            for &a in nodes {
                let weight = points.weight(q) / self.patch_area[a as usize];
                for (&b, g) in nodes.iter().zip(node_gradients) {
                    let entries = &mut gradients[a as usize];
                    match entries.iter_mut().find(|(n, _)| *n == b) {
                        Some((_, sum)) => *sum += *g * weight,
                        None => entries.push((b, *g * weight)),
                    }
                }
            }
        }
        gradients
    }

    /// `W_a` (m²) of node `a`.
    pub(super) fn control_area(&self, a: usize) -> f64 {
        self.control_area[a]
    }
}
