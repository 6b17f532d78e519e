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

use super::hex27;
use super::quadratic::{ElementShape, QuadraticElements, deformation_gradient};
use crate::material::VolumetricTerm;
use rapier3d::glamx::{DMat3, DVec3};

/// The most quadrature points of an element (quadratic hexahedra).
const MAX_POINTS: usize = hex27::QUADRATURE.len();
/// The most pressure functions of an element: `1, ξ1, ξ2, ξ3`.
const MAX_FUNCTIONS: usize = 4;

/// The pressure functions of every element, orthonormal for its rest quadrature weights: rest
/// data, built once per body.
#[derive(Debug, Clone)]
pub(crate) struct PressureBasis {
    /// Functions per element: 1 for tetrahedra, 4 for hexahedra.
    functions: usize,
    /// Per element and function, its coefficients on `1, ξ1, ξ2, ξ3`.
    coefficients: Vec<[f64; MAX_FUNCTIONS]>,
    /// Per element, function and quadrature point, the function's value there.
    values: Vec<f64>,
}

impl PressureBasis {
    /// The bases of `quadratic`'s elements (Gram–Schmidt on the monomials, per element).
    pub(crate) fn new(quadratic: &QuadraticElements) -> Self {
        let functions = match quadratic.shape() {
            ElementShape::Tetrahedron => 1,
            ElementShape::Hexahedron => MAX_FUNCTIONS,
        };
        let rule = quadratic.shape().quadrature();
        let monomials: Vec<[f64; MAX_FUNCTIONS]> = rule
            .iter()
            .map(|(xi, _)| monomials_at(functions, *xi))
            .collect();
        let mut coefficients = Vec::with_capacity(functions * quadratic.element_count());
        let mut values = Vec::with_capacity(functions * quadratic.point_count());
        for element in 0..quadratic.element_count() {
            let weights = quadratic
                .element_points(element)
                .map(|q| quadratic.point_weight(q));
            let inner = |a: &[f64; MAX_FUNCTIONS], b: &[f64; MAX_FUNCTIONS]| -> f64 {
                weights
                    .clone()
                    .zip(&monomials)
                    .map(|(w, m)| w * dot(a, m) * dot(b, m))
                    .sum()
            };
            let first = coefficients.len();
            for k in 0..functions {
                let mut c = [0.0; MAX_FUNCTIONS];
                c[k] = 1.0;
                for previous in &coefficients[first..] {
                    let projection = inner(&c, previous);
                    for (ci, pi) in c.iter_mut().zip(previous) {
                        *ci -= projection * pi;
                    }
                }
                let norm = inner(&c, &c).sqrt();
                coefficients.push(c.map(|ci| ci / norm));
            }
            for c in &coefficients[first..] {
                values.extend(monomials.iter().map(|m| dot(c, m)));
            }
        }
        Self {
            functions,
            coefficients,
            values,
        }
    }

    /// Element `element`'s functions' values at its quadrature points, function after function.
    fn values(&self, element: usize, points: usize) -> std::slice::ChunksExact<'_, f64> {
        let per_element = self.functions * points;
        self.values[per_element * element..per_element * (element + 1)].chunks_exact(points)
    }

    /// Element `element`'s functions' values at natural coordinates `xi`.
    fn at(&self, element: usize, xi: DVec3) -> impl Iterator<Item = f64> + '_ {
        let m = monomials_at(self.functions, xi);
        self.coefficients[self.functions * element..self.functions * (element + 1)]
            .iter()
            .map(move |c| dot(c, &m))
    }
}

/// The first `count` of the monomials `1, ξ1, ξ2, ξ3` at `xi`, the rest zero.
fn monomials_at(count: usize, xi: DVec3) -> [f64; MAX_FUNCTIONS] {
    let mut values = [1.0, xi.x, xi.y, xi.z];
    values[count..].fill(0.0);
    values
}

fn dot(a: &[f64; MAX_FUNCTIONS], b: &[f64; MAX_FUNCTIONS]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Per quadrature point, `Π m_q − m_q` at positions `x` (m): its share of the averaging.
pub(crate) fn excesses<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    basis: &PressureBasis,
    x: &[DVec3],
) -> Vec<f64> {
    let mut out = Vec::with_capacity(quadratic.point_count());
    for element in 0..quadratic.element_count() {
        let projection = Projection::of(model, quadratic, basis, element, x);
        out.extend(
            projection
                .projected()
                .iter()
                .zip(projection.measures())
                .map(|(projected, m)| projected - m),
        );
    }
    out
}

/// `Σ_e K/2 Σ_i b_i² − Σ_q w_q K/2 m_q²` (J): what the averaging changes in the energy.
pub(crate) fn energy_change<M: VolumetricTerm>(
    model: &M,
    quadratic: &QuadraticElements,
    basis: &PressureBasis,
    x: &[DVec3],
) -> f64 {
    let bulk = model.volumetric_modulus();
    let mut change = 0.0;
    for element in 0..quadratic.element_count() {
        let projection = Projection::of(model, quadratic, basis, element, x);
        let pointwise: f64 = quadratic
            .element_points(element)
            .zip(projection.measures())
            .map(|(q, m)| quadratic.point_weight(q) * m * m)
            .sum();
        let projected: f64 = projection.coefficients().iter().map(|b| b * b).sum();
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
    basis: &PressureBasis,
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
        for function in basis.values(element, points.len()) {
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
    basis: &PressureBasis,
    element: usize,
    xi: DVec3,
    x: &[DVec3],
) -> f64 {
    let projection = Projection::of(model, quadratic, basis, element, x);
    basis
        .at(element, xi)
        .zip(projection.coefficients())
        .map(|(phi, b)| phi * b)
        .sum()
}

/// One element's volume measures at its quadrature points and their projection, in fixed
/// storage (no allocation per element).
struct Projection {
    points: usize,
    functions: usize,
    /// `m(F_q)` per point.
    measures: [f64; MAX_POINTS],
    /// `Π m` per point.
    projected: [f64; MAX_POINTS],
    /// `b_i = Σ_q w_q φ_i m_q` per pressure function.
    coefficients: [f64; MAX_FUNCTIONS],
}

impl Projection {
    fn of<M: VolumetricTerm>(
        model: &M,
        quadratic: &QuadraticElements,
        basis: &PressureBasis,
        element: usize,
        x: &[DVec3],
    ) -> Self {
        let nodes = quadratic.element(element);
        let points = quadratic.element_points(element);
        let mut projection = Self {
            points: points.len(),
            functions: basis.functions,
            measures: [0.0; MAX_POINTS],
            projected: [0.0; MAX_POINTS],
            coefficients: [0.0; MAX_FUNCTIONS],
        };
        for (m, q) in projection.measures.iter_mut().zip(points.clone()) {
            let f = deformation_gradient(nodes, quadratic.point_gradients(q), x);
            *m = model.volume_measure(&f);
        }
        for (b, phi) in projection
            .coefficients
            .iter_mut()
            .zip(basis.values(element, points.len()))
        {
            *b = points
                .clone()
                .zip(phi)
                .zip(&projection.measures)
                .map(|((q, p), m)| quadratic.point_weight(q) * p * m)
                .sum();
            for (projected, p) in projection.projected.iter_mut().zip(phi) {
                *projected += *b * p;
            }
        }
        projection
    }

    fn measures(&self) -> &[f64] {
        &self.measures[..self.points]
    }

    fn projected(&self) -> &[f64] {
        &self.projected[..self.points]
    }

    fn coefficients(&self) -> &[f64] {
        &self.coefficients[..self.functions]
    }
}
