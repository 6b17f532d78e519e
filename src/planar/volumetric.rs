//! Averaging the volumetric term, which frees elements from volumetric locking as `ν → 0.5`,
//! over groups of integration points (as [`crate::fvm::VolumetricTreatment`] in 3D):
//!
//! `E = Σ_q t w_q Ψ_rest(F_q) + Σ_g t W_g K/2 θ_g²`, `θ_g = Σ_{q∈g} w_q m_q / P_g`,
//!
//! with `w_q` a point's rest area, `P_g = Σ_{q∈g} w_q` the group's, `W_g` its energy weight, and
//! `m` the model's volume measure ([`crate::material::VolumetricTerm`]). The forces are those of
//! the point stress `P(F_q) + K (θ̄_q − m_q) ∂m/∂F` with `θ̄_q = Σ_{g∋q} W_g θ_g / P_g`, and the
//! tangent gains `Σ_g t W_g K g_g g_gᵀ`, `g_g = ∂θ_g/∂x`, which couples the nodes of a group.
//!
//! - **Nodal averaging** (Bonet and Burton 1998; linear triangles in plane strain): a group per
//!   node, of the triangles around it, `W_a` its control area: one constraint per node against
//!   two unknowns, so the mesh is free to bend.
//! - **Element averaging** (mean dilatation; quadratic triangles): a group per element, of its
//!   three points, `W_e = P_e = A_e`: one constraint per element against about four unknowns
//!   (the stable P2/P0 pair).

use super::points::IntegrationPoints;
use rapier3d::glamx::DVec2;

/// The groups the volumetric term is averaged over.
#[derive(Debug, Clone)]
pub(super) struct VolumeAveraging {
    /// The groups of each point, `per_point` each.
    groups_of: Vec<u32>,
    per_point: usize,
    /// `W_g / P_g` per group (dimensionless).
    share: Vec<f64>,
    /// `W_g` per group (m²).
    weight: Vec<f64>,
    /// `P_g` per group (m²).
    patch_area: Vec<f64>,
}

/// The averaged volume measures at some positions.
#[derive(Debug, Clone)]
pub(super) struct Averages {
    /// `m_q` per point.
    pub(super) measure: Vec<f64>,
    /// `θ_g` per group.
    pub(super) group: Vec<f64>,
    /// `θ̄_q` per point.
    pub(super) point: Vec<f64>,
}

impl VolumeAveraging {
    /// A group per node of the linear triangles of `points` (one point each), weighed by the
    /// nodes' `control_areas` (m²).
    pub(super) fn nodal(points: &IntegrationPoints, control_areas: &[f64]) -> Self {
        let groups_of = (0..points.len())
            .flat_map(|q| points.nodes(q).to_vec())
            .collect();
        Self::new(points, groups_of, 3, control_areas.to_vec())
    }

    /// A group per element of `points`.
    pub(super) fn per_element(points: &IntegrationPoints) -> Self {
        let per_element = points.per_element();
        let groups_of: Vec<u32> = (0..points.len())
            .map(|q| (q / per_element) as u32)
            .collect();
        let mut areas = vec![0.0; points.len() / per_element];
        for q in 0..points.len() {
            areas[q / per_element] += points.weight(q);
        }
        Self::new(points, groups_of, 1, areas)
    }

    fn new(
        points: &IntegrationPoints,
        groups_of: Vec<u32>,
        per_point: usize,
        weight: Vec<f64>,
    ) -> Self {
        let mut patch_area = vec![0.0; weight.len()];
        for (q, groups) in groups_of.chunks(per_point).enumerate() {
            for &g in groups {
                patch_area[g as usize] += points.weight(q);
            }
        }
        let share = weight.iter().zip(&patch_area).map(|(w, p)| w / p).collect();
        Self {
            groups_of,
            per_point,
            share,
            weight,
            patch_area,
        }
    }

    /// The groups of point `q`.
    fn groups(&self, q: usize) -> &[u32] {
        &self.groups_of[q * self.per_point..(q + 1) * self.per_point]
    }

    /// The averages of the points' volume `measure`s.
    pub(super) fn averages(&self, points: &IntegrationPoints, measure: Vec<f64>) -> Averages {
        let mut group = vec![0.0; self.patch_area.len()];
        for (q, m) in measure.iter().enumerate() {
            for &g in self.groups(q) {
                group[g as usize] += points.weight(q) * m;
            }
        }
        for (theta, p) in group.iter_mut().zip(&self.patch_area) {
            *theta /= p;
        }
        let point = (0..measure.len())
            .map(|q| {
                (self.groups(q).iter())
                    .map(|&g| self.share[g as usize] * group[g as usize])
                    .sum()
            })
            .collect();
        Averages {
            measure,
            group,
            point,
        }
    }

    /// `Σ_g W_g K/2 θ_g²` (J per m of thickness) for the bulk modulus `k` (Pa).
    pub(super) fn energy(&self, averages: &Averages, k: f64) -> f64 {
        (self.weight.iter().zip(&averages.group))
            .map(|(w, theta)| 0.5 * k * w * theta * theta)
            .sum()
    }

    /// The gradients `g_g = ∂θ_g/∂x` (1/m) of every group's average, as (node, gradient)
    /// entries summed over the group, given each point's `∂m/∂x` per node
    /// (`measure_gradients`, in the order of the point's nodes).
    pub(super) fn average_gradients(
        &self,
        points: &IntegrationPoints,
        measure_gradients: &[Vec<DVec2>],
    ) -> Vec<Vec<(u32, DVec2)>> {
        let mut gradients: Vec<Vec<(u32, DVec2)>> = vec![Vec::new(); self.patch_area.len()];
        for (q, node_gradients) in measure_gradients.iter().enumerate() {
            for &g in self.groups(q) {
                let weight = points.weight(q) / self.patch_area[g as usize];
                for (&b, gradient) in points.nodes(q).iter().zip(node_gradients) {
                    let entries = &mut gradients[g as usize];
                    match entries.iter_mut().find(|(n, _)| *n == b) {
                        Some((_, sum)) => *sum += *gradient * weight,
                        None => entries.push((b, *gradient * weight)),
                    }
                }
            }
        }
        gradients
    }

    /// `W_g` (m²) of group `g`.
    pub(super) fn weight(&self, g: usize) -> f64 {
        self.weight[g]
    }
}
