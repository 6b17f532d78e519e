//! Mean dilatation for quadratic tetrahedra (Nagtegaal, Parks and Rice 1974): the volumetric term
//! `K/2 m²` of the energy ([`VolumetricTerm`]) is taken on each element's mean volume measure
//! instead of at each quadrature point,
//!
//! `E = Σ_q w_q Ψ_rest(F_q) + Σ_e V_e K/2 m̄_e²`, `m̄_e = Σ_{q∈e} w_q m(F_q) / V_e`,
//!
//! one volume constraint per element instead of four: quadratic tetrahedra then keep bending at
//! `ν → 0.5`, where with four constraints per element they lock (by 10–20 % on the reference
//! cantilever at `ν = 0.49`). As for nodal averaging, each point's stress becomes
//! `P(F_q) + K (m̄_e − m_q) ∂m/∂F`, and the tangent gains `V_e K g_e g_eᵀ`, `g_e = ∂m̄_e/∂x`,
//! which stays inside the element's own stencil.

use super::tet10::{QuadraticElements, deformation_gradient};
use crate::material::VolumetricTerm;
use rapier3d::glamx::{DMat3, DVec3};

/// Per quadrature point, `m̄_e − m_q` at positions `x` (m): its share of the averaging.
pub(crate) fn excesses<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
) -> Vec<f64> {
    let mut out = Vec::with_capacity(quadratic.points().len());
    for (element, nodes) in quadratic.elements().iter().enumerate() {
        let (measures, mean) = measures(model, quadratic, element, nodes, x);
        out.extend(measures.map(|m| mean - m));
    }
    out
}

/// `Σ_e V_e K/2 m̄_e² − Σ_q w_q K/2 m_q²` (J): what the averaging changes in the energy.
pub(crate) fn energy_change<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
) -> f64 {
    let bulk = model.volumetric_modulus();
    let mut change = 0.0;
    for (element, nodes) in quadratic.elements().iter().enumerate() {
        let (measures, mean) = measures(model, quadratic, element, nodes, x);
        let points = &quadratic.points()[4 * element..4 * element + 4];
        let pointwise: f64 = points
            .iter()
            .zip(measures)
            .map(|(q, m)| q.weight * m * m)
            .sum();
        change += 0.5 * bulk * (quadratic.volume(element) * mean * mean - pointwise);
    }
    change
}

/// Calls `add(gradient, weight)` for every element, with `gradient` its `g_e = ∂m̄_e/∂x` as
/// (node, vector) pairs and `weight = V_e K` (Pa·m³): the tangent's coupling term is the sum of
/// `weight g_e g_eᵀ`.
pub(crate) fn for_each_coupling<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
    mut add: impl FnMut(&[(u32, DVec3)], f64),
) {
    let bulk = model.volumetric_modulus();
    let mut gradient: Vec<(u32, DVec3)> = Vec::new();
    for (element, nodes) in quadratic.elements().iter().enumerate() {
        let volume = quadratic.volume(element);
        gradient.clear();
        gradient.extend(nodes.iter().map(|&n| (n, DVec3::ZERO)));
        for point in &quadratic.points()[4 * element..4 * element + 4] {
            let f = deformation_gradient(nodes, &point.gradients, x);
            let dm = model.volume_measure_gradient(&f) * (point.weight / volume);
            for ((_, g), shape) in gradient.iter_mut().zip(&point.gradients) {
                *g += dm * *shape;
            }
        }
        add(&gradient, volume * bulk);
    }
}

/// The element's mean volume measure `m̄_e` at positions `x` (m).
pub(crate) fn mean_measure<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    element: usize,
    x: &[DVec3],
) -> f64 {
    measures(model, quadratic, element, &quadratic.elements()[element], x).1
}

/// `m(F_q)` at the element's four points and their weighted mean `m̄_e`.
fn measures<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    element: usize,
    nodes: &[u32],
    x: &[DVec3],
) -> ([f64; 4], f64) {
    let points = &quadratic.points()[4 * element..4 * element + 4];
    let measures: [f64; 4] = std::array::from_fn(|q| {
        let f: DMat3 = deformation_gradient(nodes, &points[q].gradients, x);
        model.volume_measure(&f)
    });
    let weighted: f64 = points.iter().zip(measures).map(|(q, m)| q.weight * m).sum();
    (measures, weighted / quadratic.volume(element))
}
