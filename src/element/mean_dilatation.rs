//! Mean dilatation for quadratic elements (Nagtegaal, Parks and Rice 1974): the volumetric term
//! `K/2 m²` of the energy ([`VolumetricTerm`]) is taken on the projection `Π m` of the volume
//! measure onto a small space of pressure functions per element instead of at each quadrature
//! point,
//!
//! `E = Σ_q w_q Ψ_rest(F_q) + Σ_e ∫_e K/2 (Π m)²`,
//!
//! so each element carries a few volume constraints instead of one per quadrature point, and
//! quadratic elements keep bending at `ν → 0.5`, where with one per point they lock (by 10–25 %
//! on the reference cantilever at `ν = 0.49`). The pressure space is the constants for
//! tetrahedra (one constraint; `Π m` is the element's mean `m̄_e`) and the linear functions of
//! the natural coordinates for hexahedra (four, the stable Q2/P1 pairing: with constants alone a
//! 27-node element bends with a free, zero-mean dilatation across its section).
//!
//! With an orthonormal basis `φ_i` of the pressure space (`Σ_q w_q φ_i φ_j = δ_ij`), the
//! coefficients are `b_i = Σ_q w_q φ_i m_q`, the averaged term is `K/2 Σ_i b_i²`, each point's
//! stress becomes `P(F_q) + K (Π m_q − m_q) ∂m/∂F`, and the tangent gains `K g_i g_iᵀ`,
//! `g_i = ∂b_i/∂x`, which stays inside the element's own stencil. Both sets of constraints
//! need at least two elements across a bent section.

use super::quadratic::{ElementShape, QuadraticElements, deformation_gradient};
use crate::material::VolumetricTerm;
use rapier3d::glamx::{DMat3, DVec3};

/// Per quadrature point, `Π m_q − m_q` at positions `x` (m): its share of the averaging.
pub(crate) fn excesses<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
) -> Vec<f64> {
    let mut out = Vec::with_capacity(quadratic.point_count());
    for element in 0..quadratic.element_count() {
        let projection = Projection::of(model, quadratic, element, x);
        out.extend(
            projection
                .measures
                .iter()
                .enumerate()
                .map(|(q, m)| projection.projected_at_point(q) - m),
        );
    }
    out
}

/// `Σ_e K/2 Σ_i b_i² − Σ_q w_q K/2 m_q²` (J): what the averaging changes in the energy.
pub(crate) fn energy_change<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
) -> f64 {
    let bulk = model.volumetric_modulus();
    let mut change = 0.0;
    for element in 0..quadratic.element_count() {
        let projection = Projection::of(model, quadratic, element, x);
        let pointwise: f64 = quadratic
            .element_points(element)
            .zip(&projection.measures)
            .map(|(q, m)| quadratic.point_weight(q) * m * m)
            .sum();
        let projected: f64 = projection.coefficients.iter().map(|b| b * b).sum();
        change += 0.5 * bulk * (projected - pointwise);
    }
    change
}

/// Calls `add(gradient, weight)` for every element and pressure function, with `gradient` its
/// `g_i = ∂b_i/∂x` as (node, vector) pairs and `weight = K` (Pa): the tangent's coupling term is
/// the sum of `weight g_i g_iᵀ`.
pub(crate) fn for_each_coupling<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    x: &[DVec3],
    mut add: impl FnMut(&[(u32, DVec3)], f64),
) {
    let bulk = model.volumetric_modulus();
    let mut gradient: Vec<(u32, DVec3)> = Vec::new();
    let mut measure_gradients: Vec<DMat3> = Vec::new();
    for (element, nodes) in quadratic.elements().enumerate() {
        let points = quadratic.element_points(element);
        // `w_q ∂m/∂F` per point, shared by the element's pressure functions.
        measure_gradients.clear();
        measure_gradients.extend(points.clone().map(|point| {
            let f = deformation_gradient(nodes, quadratic.point_gradients(point), x);
            model.volume_measure_gradient(&f) * quadratic.point_weight(point)
        }));
        for function in &PressureBasis::values_at_points(quadratic, element) {
            gradient.clear();
            gradient.extend(nodes.iter().map(|&n| (n, DVec3::ZERO)));
            for ((point, phi), dm) in points.clone().zip(function).zip(&measure_gradients) {
                let dm = *dm * *phi;
                for ((_, g), shape) in gradient.iter_mut().zip(quadratic.point_gradients(point)) {
                    *g += dm * *shape;
                }
            }
            add(&gradient, bulk);
        }
    }
}

/// The projected volume measure `Π m` of element `element` at natural coordinates `xi`, at
/// positions `x` (m).
pub(crate) fn projected_measure<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    element: usize,
    xi: DVec3,
    x: &[DVec3],
) -> f64 {
    let projection = Projection::of(model, quadratic, element, x);
    projection
        .basis
        .at(xi)
        .iter()
        .zip(&projection.coefficients)
        .map(|(phi, b)| phi * b)
        .sum()
}

/// The pressure functions of one element, orthonormal for its quadrature weights: per function
/// its coefficients on `1, ξ1, ξ2, ξ3`.
struct PressureBasis {
    /// The monomials used: 1 for tetrahedra, 4 for hexahedra.
    monomials: usize,
    /// Per function, its coefficients (filled by [`PressureBasis::orthonormalize`]).
    coefficients: Vec<[f64; 4]>,
}

impl PressureBasis {
    /// The unnormalized monomials of the shape's pressure space.
    fn of(shape: ElementShape) -> Self {
        let monomials = match shape {
            ElementShape::Tetrahedron => 1,
            ElementShape::Hexahedron => 4,
        };
        Self {
            monomials,
            coefficients: Vec::new(),
        }
    }

    /// The monomials `1, ξ1, ξ2, ξ3` (the first `monomials` of them) at `xi`.
    fn monomials_at(&self, xi: DVec3) -> [f64; 4] {
        let mut values = [1.0, xi.x, xi.y, xi.z];
        values[self.monomials..].fill(0.0);
        values
    }

    /// The basis made orthonormal for element `element`'s quadrature weights (Gram–Schmidt).
    fn orthonormalize(mut self, quadratic: &QuadraticElements, element: usize) -> Self {
        let rule = quadratic.shape().quadrature();
        let weights: Vec<f64> = quadratic
            .element_points(element)
            .map(|q| quadratic.point_weight(q))
            .collect();
        let inner = |a: &[f64; 4], b: &[f64; 4]| -> f64 {
            rule.iter()
                .zip(&weights)
                .map(|((xi, _), w)| {
                    let m = self.monomials_at(*xi);
                    let (fa, fb) = (dot(a, &m), dot(b, &m));
                    w * fa * fb
                })
                .sum()
        };
        let mut functions: Vec<[f64; 4]> = Vec::with_capacity(self.monomials);
        for k in 0..self.monomials {
            let mut c = [0.0; 4];
            c[k] = 1.0;
            for previous in &functions {
                let projection = inner(&c, previous);
                for (ci, pi) in c.iter_mut().zip(previous) {
                    *ci -= projection * pi;
                }
            }
            let norm = inner(&c, &c).sqrt();
            functions.push(c.map(|ci| ci / norm));
        }
        self.coefficients = functions;
        self
    }

    /// The functions' values at `xi`.
    fn at(&self, xi: DVec3) -> Vec<f64> {
        let m = self.monomials_at(xi);
        self.coefficients.iter().map(|c| dot(c, &m)).collect()
    }

    /// Per function of element `element`'s basis, its values at the element's quadrature points.
    fn values_at_points(quadratic: &QuadraticElements, element: usize) -> Vec<Vec<f64>> {
        let basis = Self::of(quadratic.shape()).orthonormalize(quadratic, element);
        let rule = quadratic.shape().quadrature();
        let at_points: Vec<Vec<f64>> = rule.iter().map(|(xi, _)| basis.at(*xi)).collect();
        (0..basis.coefficients.len())
            .map(|i| at_points.iter().map(|values| values[i]).collect())
            .collect()
    }
}

fn dot(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One element's volume measures at its quadrature points and their projection.
struct Projection {
    basis: PressureBasis,
    /// `m(F_q)` per point.
    measures: Vec<f64>,
    /// `Π m` per point.
    projected: Vec<f64>,
    /// `b_i = Σ_q w_q φ_i m_q` per pressure function.
    coefficients: Vec<f64>,
}

impl Projection {
    fn of<M: VolumetricTerm>(
        model: &M,
        quadratic: &QuadraticElements,
        element: usize,
        x: &[DVec3],
    ) -> Self {
        let nodes = quadratic.element(element);
        let basis = PressureBasis::of(quadratic.shape()).orthonormalize(quadratic, element);
        let rule = quadratic.shape().quadrature();
        let measures: Vec<f64> = quadratic
            .element_points(element)
            .map(|q| {
                let f: DMat3 = deformation_gradient(nodes, quadratic.point_gradients(q), x);
                model.volume_measure(&f)
            })
            .collect();
        let values: Vec<Vec<f64>> = rule.iter().map(|(xi, _)| basis.at(*xi)).collect();
        let mut coefficients = vec![0.0; basis.coefficients.len()];
        for ((q, m), phi) in quadratic
            .element_points(element)
            .zip(&measures)
            .zip(&values)
        {
            let w = quadratic.point_weight(q);
            for (b, p) in coefficients.iter_mut().zip(phi) {
                *b += w * p * m;
            }
        }
        let projected = values
            .iter()
            .map(|phi| phi.iter().zip(&coefficients).map(|(p, b)| p * b).sum())
            .collect();
        Self {
            basis,
            measures,
            projected,
            coefficients,
        }
    }

    /// `Π m` at the element's quadrature point `q` (local index).
    fn projected_at_point(&self, q: usize) -> f64 {
        self.projected[q]
    }
}
