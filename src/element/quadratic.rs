//! The rest data of a mesh of isoparametric quadratic elements, tetrahedra ([`super::tet10`]) or
//! hexahedra ([`super::hex27`]): per quadrature point the rest shape-function gradients and the
//! volume it stands for, and per node its lumped volume.

use super::{hex27, tet10};
use crate::Error;
use rapier3d::glamx::{DMat3, DVec3};

/// The reference shape of a body's quadratic elements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum ElementShape {
    /// Tetrahedra (10 nodes: corners and mid-edge nodes).
    Tetrahedron,
    /// Hexahedra (27 nodes: the 3 x 3 x 3 lattice), the element of a coarse cage.
    Hexahedron,
}

impl ElementShape {
    /// Nodes per element.
    pub const fn node_count(self) -> usize {
        match self {
            Self::Tetrahedron => tet10::NODES,
            Self::Hexahedron => hex27::NODES,
        }
    }

    /// The quadrature rule: natural coordinates and weights (their sum is the reference
    /// element's volume).
    pub(crate) fn quadrature(self) -> &'static [(DVec3, f64)] {
        match self {
            Self::Tetrahedron => &TETRAHEDRON_QUADRATURE,
            Self::Hexahedron => &hex27::QUADRATURE,
        }
    }

    /// The natural coordinates of the element's corners, where a curved element folds first.
    pub(crate) fn corners(self) -> Vec<DVec3> {
        match self {
            Self::Tetrahedron => vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            Self::Hexahedron => (0..8)
                .map(|c| {
                    DVec3::new(
                        if c & 1 == 0 { -1.0 } else { 1.0 },
                        if c & 2 == 0 { -1.0 } else { 1.0 },
                        if c & 4 == 0 { -1.0 } else { 1.0 },
                    )
                })
                .collect(),
        }
    }

    /// The natural coordinates of the nodes.
    pub(crate) fn reference_nodes(self) -> Vec<DVec3> {
        match self {
            Self::Tetrahedron => tet10::reference_nodes().to_vec(),
            Self::Hexahedron => hex27::reference_nodes().to_vec(),
        }
    }

    /// HRZ lumped-mass fractions per node (positive, summing to one).
    pub(crate) fn lumped_mass_fractions(self) -> &'static [f64] {
        match self {
            Self::Tetrahedron => &tet10::LUMPED_MASS_FRACTIONS,
            Self::Hexahedron => &hex27::LUMPED_MASS_FRACTIONS,
        }
    }

    /// The shape functions at natural coordinates `xi`.
    pub(crate) fn shape_values(self, xi: DVec3) -> Vec<f64> {
        match self {
            Self::Tetrahedron => tet10::shape_values(barycentric(xi)).to_vec(),
            Self::Hexahedron => hex27::shape_values(xi).to_vec(),
        }
    }

    /// The shape functions' gradients with respect to the natural coordinates at `xi`.
    pub(crate) fn natural_gradients(self, xi: DVec3) -> Vec<DVec3> {
        match self {
            Self::Tetrahedron => tet10::natural_gradients(barycentric(xi)).to_vec(),
            Self::Hexahedron => hex27::natural_gradients(xi).to_vec(),
        }
    }
}

/// [`tet10::QUADRATURE`] in natural coordinates `ξ = (L1, L2, L3)`, each point standing for a
/// quarter of the reference tetrahedron's volume 1/6.
const TETRAHEDRON_QUADRATURE: [(DVec3, f64); 4] = {
    let mut rule = [(DVec3::ZERO, 0.0); 4];
    let mut q = 0;
    while q < 4 {
        let l = tet10::QUADRATURE[q];
        rule[q] = (DVec3::new(l[1], l[2], l[3]), 1.0 / 24.0);
        q += 1;
    }
    rule
};

/// The barycentric coordinates `(1 − ξ1 − ξ2 − ξ3, ξ1, ξ2, ξ3)` of a tetrahedron's natural
/// coordinates.
fn barycentric(xi: DVec3) -> [f64; 4] {
    [1.0 - xi.x - xi.y - xi.z, xi.x, xi.y, xi.z]
}

/// The rest map of one element at one point: `J = ∂p/∂ξ` (m) from the rest positions `p` of its
/// nodes and the natural gradients there.
fn rest_jacobian(p: &[DVec3], natural: &[DVec3]) -> DMat3 {
    let mut columns = [DVec3::ZERO; 3];
    for (position, gradient) in p.iter().zip(natural) {
        for (k, column) in columns.iter_mut().enumerate() {
            *column += *position * gradient[k];
        }
    }
    DMat3::from_cols(columns[0], columns[1], columns[2])
}

/// The spatial (rest) gradients `∇N_a = J⁻ᵀ ∂N_a/∂ξ` (1/m) at natural coordinates `xi` and the
/// Jacobian determinant there, or the determinant alone when it is not positive.
fn rest_gradients(shape: ElementShape, p: &[DVec3], xi: DVec3) -> Result<(Vec<DVec3>, f64), f64> {
    let mut natural = shape.natural_gradients(xi);
    let jacobian = rest_jacobian(p, &natural);
    let determinant = jacobian.determinant();
    // NaN (from non-finite rest positions) is refused as well.
    if determinant.is_nan() || determinant <= 0.0 {
        return Err(determinant);
    }
    let inverse_transpose = jacobian.inverse().transpose();
    for g in &mut natural {
        *g = inverse_transpose * *g;
    }
    Ok((natural, determinant))
}

/// The rest data of a mesh of quadratic elements of one shape.
#[derive(Debug, Clone)]
pub struct QuadraticElements {
    shape: ElementShape,
    /// The elements' nodes, `shape.node_count()` per element.
    nodes: Vec<u32>,
    /// Per quadrature point, `∇N_a` (1/m) of its element's shape functions in rest coordinates.
    gradients: Vec<DVec3>,
    /// Per quadrature point, its stiffness weight (m³): the rest volume it stands for, times its
    /// element's stiffness factor.
    weights: Vec<f64>,
    /// Per element, its rest volume (m³).
    volumes: Vec<f64>,
    node_count: usize,
    points_per_element: usize,
    lumped_volumes: Vec<f64>,
}

impl QuadraticElements {
    /// The rest data of elements of `shape` (`nodes` lists `shape.node_count()` node indices per
    /// element) at rest positions `positions` (m), one per node.
    ///
    /// # Errors
    /// [`Error::FoldedElement`] naming the first element whose rest map folds (its Jacobian
    /// determinant is not positive at a quadrature point or corner): a badly curved element.
    pub fn new(shape: ElementShape, positions: &[DVec3], nodes: &[u32]) -> Result<Self, Error> {
        let per_element = shape.node_count();
        let rule = shape.quadrature();
        let corners = shape.corners();
        let element_count = nodes.len() / per_element;
        let mut gradients = Vec::with_capacity(nodes.len() * rule.len());
        let mut weights = Vec::with_capacity(element_count * rule.len());
        for (element, element_nodes) in nodes.chunks_exact(per_element).enumerate() {
            let p: Vec<DVec3> = element_nodes
                .iter()
                .map(|&n| positions[n as usize])
                .collect();
            let inverted = |determinant: f64| Error::FoldedElement {
                element,
                determinant,
            };
            for corner in &corners {
                rest_gradients(shape, &p, *corner).map_err(inverted)?;
            }
            for (xi, weight) in rule {
                let (point_gradients, determinant) =
                    rest_gradients(shape, &p, *xi).map_err(inverted)?;
                gradients.extend(point_gradients);
                weights.push(weight * determinant);
            }
        }
        let volumes: Vec<f64> = weights
            .chunks_exact(rule.len())
            .map(|w| w.iter().sum())
            .collect();
        let mut elements = Self {
            shape,
            nodes: nodes.to_vec(),
            gradients,
            weights,
            volumes,
            node_count: positions.len(),
            points_per_element: rule.len(),
            lumped_volumes: Vec::new(),
        };
        elements.lumped_volumes = elements.lumped(|_| 1.0);
        Ok(elements)
    }

    /// Per node, `Σ_e h_a V_e value(e)` over the elements `e` at the node, with `h_a` the node's
    /// HRZ fraction in `e` and `V_e` its rest volume (m³): the lumped volumes for `value = 1`,
    /// the lumped masses (kg) for `value` the elements' densities (kg/m³).
    pub(crate) fn lumped(&self, value: impl Fn(usize) -> f64) -> Vec<f64> {
        let mut lumped = vec![0.0; self.node_count];
        let fractions = self.shape.lumped_mass_fractions();
        for (element, element_nodes) in self.elements().enumerate() {
            let share = self.volumes[element] * value(element);
            for (&n, fraction) in element_nodes.iter().zip(fractions) {
                lumped[n as usize] += fraction * share;
            }
        }
        lumped
    }

    /// Multiplies each element's quadrature weights by its factor in `factors` (one per element,
    /// applied once, when the body is built):
    /// its Young's modulus over the modulus of the model the forces are computed with. Stress,
    /// energy and tangent of the element scale alike; its volume and lumped volumes do not.
    ///
    /// # Panics
    /// If `factors` does not have one entry per element.
    pub(crate) fn scale_stiffness(&mut self, factors: &[f64]) {
        assert_eq!(
            factors.len(),
            self.element_count(),
            "one factor per element"
        );
        let q = self.points_per_element;
        for (weights, factor) in self.weights.chunks_exact_mut(q).zip(factors) {
            for w in weights {
                *w *= factor;
            }
        }
    }

    /// The elements' shape.
    pub fn shape(&self) -> ElementShape {
        self.shape
    }

    /// The elements' nodes, [`ElementShape::node_count`] per element.
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.weights.len() / self.points_per_element
    }

    /// The nodes of element `element`.
    ///
    /// # Panics
    /// If the element does not exist.
    pub fn element(&self, element: usize) -> &[u32] {
        let n = self.shape.node_count();
        &self.nodes[n * element..n * (element + 1)]
    }

    /// The elements' node lists, in order.
    pub fn elements(&self) -> std::slice::ChunksExact<'_, u32> {
        self.nodes.chunks_exact(self.shape.node_count())
    }

    /// The indices of element `element`'s quadrature points.
    pub fn element_points(&self, element: usize) -> std::ops::Range<usize> {
        let q = self.points_per_element;
        q * element..q * (element + 1)
    }

    /// Number of quadrature points, element after element.
    pub fn point_count(&self) -> usize {
        self.weights.len()
    }

    /// `∇N_a` (1/m) of the element's shape functions at quadrature point `point`, in rest
    /// coordinates.
    pub fn point_gradients(&self, point: usize) -> &[DVec3] {
        let n = self.shape.node_count();
        &self.gradients[n * point..n * (point + 1)]
    }

    /// The stiffness weight (m³) of quadrature point `point`: the rest volume it stands for,
    /// times its element's stiffness factor (1 unless the body's materials differ by region).
    pub fn point_weight(&self, point: usize) -> f64 {
        self.weights[point]
    }

    /// Rest volume of element `element` (m³), the sum of its quadrature points' rest volumes.
    ///
    /// # Panics
    /// If the element does not exist.
    pub fn volume(&self, element: usize) -> f64 {
        self.volumes[element]
    }

    /// The rest volume (m³) lumped on each node: HRZ fractions of each element's volume; times
    /// the density, the nodal masses.
    pub fn lumped_volumes(&self) -> &[f64] {
        &self.lumped_volumes
    }

    /// The deformation gradient of element `element` (dimensionless) at natural coordinates `xi`
    /// for node positions `x` (m): `F = Σ_a x_a ⊗ ∇N_a`, with the gradients at that point.
    ///
    /// # Panics
    /// If the element does not exist.
    pub fn gradient_at(&self, element: usize, rest: &[DVec3], x: &[DVec3], xi: DVec3) -> DMat3 {
        let nodes = self.element(element);
        let p: Vec<DVec3> = nodes.iter().map(|&n| rest[n as usize]).collect();
        match rest_gradients(self.shape, &p, xi) {
            Ok((gradients, _)) => deformation_gradient(nodes, &gradients, x),
            // The constructor checked the corners and quadrature points; a point between them
            // cannot fold for an element that passed, but stay finite if it does.
            Err(_) => DMat3::IDENTITY,
        }
    }

    /// The natural coordinates of rest point `point` (m) in element `element`, found by Newton's
    /// method on the isoparametric map from `guess`.
    pub(crate) fn natural_coordinates(
        &self,
        element: usize,
        rest: &[DVec3],
        point: DVec3,
        guess: DVec3,
    ) -> DVec3 {
        let p: Vec<DVec3> = self
            .element(element)
            .iter()
            .map(|&n| rest[n as usize])
            .collect();
        let map = |xi: DVec3| -> DVec3 {
            self.shape
                .shape_values(xi)
                .iter()
                .zip(&p)
                .map(|(n, q)| *q * *n)
                .sum()
        };
        let mut xi = guess;
        for _ in 0..NEWTON_ITERATIONS {
            let residual = point - map(xi);
            let jacobian = rest_jacobian(&p, &self.shape.natural_gradients(xi));
            if jacobian.determinant().abs() <= f64::MIN_POSITIVE {
                break;
            }
            xi += jacobian.inverse() * residual;
        }
        xi
    }
}

/// Newton iterations of [`QuadraticElements::natural_coordinates`]: the map is quadratic, so a
/// guess from the element's straight-sided subdivision converges to round-off in a few.
const NEWTON_ITERATIONS: usize = 8;

/// `F = Σ_a x_a ⊗ ∇N_a` (dimensionless) over the nodes `nodes` with shape-function gradients
/// `gradients` (1/m), for positions `x` (m); with velocities it is the rate `Ḟ` (1/s).
#[inline]
pub(crate) fn deformation_gradient(nodes: &[u32], gradients: &[DVec3], x: &[DVec3]) -> DMat3 {
    let mut columns = [DVec3::ZERO; 3];
    for (&n, g) in nodes.iter().zip(gradients) {
        let xn = x[n as usize];
        columns[0] += xn * g.x;
        columns[1] += xn * g.y;
        columns[2] += xn * g.z;
    }
    DMat3::from_cols(columns[0], columns[1], columns[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quadratic displacement `u(p)` of the reference element and its gradient.
    fn quadratic_displacement(p: DVec3) -> (DVec3, DMat3) {
        (
            DVec3::new(0.3 * p.y * p.y, 0.2 * p.x * p.z, -0.1 * p.x * p.x),
            DMat3::from_cols(
                DVec3::new(0.0, 0.2 * p.z, -0.2 * p.x),
                DVec3::new(0.6 * p.y, 0.0, 0.0),
                DVec3::new(0.0, 0.2 * p.x, 0.0),
            ),
        )
    }

    #[test]
    fn quadratic_displacement_gives_its_exact_gradient_in_both_shapes() {
        for (shape, volume, xi) in [
            (
                ElementShape::Tetrahedron,
                1.0 / 6.0,
                DVec3::new(0.2, 0.3, 0.4),
            ),
            (ElementShape::Hexahedron, 8.0, DVec3::new(0.3, -0.7, 0.45)),
        ] {
            let rest = shape.reference_nodes();
            let x: Vec<DVec3> = rest
                .iter()
                .map(|p| *p + quadratic_displacement(*p).0)
                .collect();
            let nodes: Vec<u32> = (0..shape.node_count() as u32).collect();
            let elements = QuadraticElements::new(shape, &rest, &nodes).unwrap();
            let f = elements.gradient_at(0, &rest, &x, xi);
            let error = f - (DMat3::IDENTITY + quadratic_displacement(xi).1);
            assert!(error.to_cols_array().iter().all(|e| e.abs() < 1e-14));
            assert!((elements.volume(0) - volume).abs() < 1e-14);
            let lumped: f64 = elements.lumped_volumes().iter().sum();
            assert!((lumped - volume).abs() < 1e-14);
        }
    }

    #[test]
    fn natural_coordinates_invert_a_curved_element() {
        // A hexahedron with a bulged face: the map is not affine.
        let shape = ElementShape::Hexahedron;
        let mut rest = shape.reference_nodes();
        rest[4 + 9 * 2] += DVec3::new(0.0, 0.0, 0.3);
        let nodes: Vec<u32> = (0..27).collect();
        let elements = QuadraticElements::new(shape, &rest, &nodes).unwrap();
        let xi = DVec3::new(0.25, -0.4, 0.8);
        let point: DVec3 = shape
            .shape_values(xi)
            .iter()
            .zip(&rest)
            .map(|(n, p)| *p * *n)
            .sum();
        let found = elements.natural_coordinates(0, &rest, point, DVec3::ZERO);
        assert!(found.distance(xi) < 1e-12);
    }

    #[test]
    fn a_folded_element_is_refused_by_index() {
        let shape = ElementShape::Tetrahedron;
        let mut rest = shape.reference_nodes();
        // Pull the (0,1) mid-edge node past corner 1: the rest map folds near that corner.
        rest[4] = DVec3::new(1.2, 0.0, 0.0);
        let nodes: Vec<u32> = (0..10).collect();
        let error = QuadraticElements::new(shape, &rest, &nodes);
        assert!(matches!(
            error,
            Err(Error::FoldedElement { element: 0, .. })
        ));
    }
}
