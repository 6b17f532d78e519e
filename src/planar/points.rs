//! The integration points of a 2D body's elements: where the deformation gradient is
//! evaluated, the nodes it depends on with their rest shape-function gradients `∇N_a`, and the
//! rest area each point stands for. The force on node `a` is `f_a = −Σ_q w_q t P_q ∇N_a(q)`.
//!
//! - Linear triangles: one point per triangle, `w = A`, `∇N_a = −b_a/A`, so that
//!   `f_a = t P b_a`, the finite-volume force of [`super::TriangleRest`].
//! - Quadratic (6-node) triangles, straight-sided, nodes ordered corners then the mid-edge nodes
//!   of edges 01, 12, 20: the three-point rule at barycentric `(2/3, 1/6, 1/6)` and its
//!   permutations, `w = A/3`, exact for the stiffness of the linear law; masses lumped by HRZ
//!   (a corner 1/19 of the area, a mid-edge node 16/57), as the 3D quadratic elements' are.

use super::element::TriangleRest;
use rapier3d::glamx::{DMat2, DVec2};

/// HRZ lumped-mass fractions of a 6-node triangle: corners, then mid-edge nodes.
pub(super) const QUADRATIC_MASS_FRACTIONS: [f64; 6] = [
    1.0 / 19.0,
    1.0 / 19.0,
    1.0 / 19.0,
    16.0 / 57.0,
    16.0 / 57.0,
    16.0 / 57.0,
];

/// The integration points of a body.
#[derive(Debug, Clone)]
pub(super) struct IntegrationPoints {
    /// Nodes per point (3 for linear triangles, 6 for quadratic ones).
    per_point: usize,
    /// The nodes of each point, `per_point` each.
    nodes: Vec<u32>,
    /// The rest gradients `∇N_a` (1/m) of those nodes' shape functions at each point.
    gradients: Vec<DVec2>,
    /// The rest area (m²) each point stands for.
    weights: Vec<f64>,
    /// Points per element.
    per_element: usize,
}

/// The gradients `∇N_a` (1/m) of a straight-sided 6-node triangle's shape functions at
/// barycentric coordinates `l`, from the linear ones `linear` (`∇L_i`).
fn quadratic_gradients(l: [f64; 3], linear: [DVec2; 3]) -> [DVec2; 6] {
    let corner = |i: usize| linear[i] * (4.0 * l[i] - 1.0);
    let mid = |i: usize, j: usize| (linear[i] * l[j] + linear[j] * l[i]) * 4.0;
    [
        corner(0),
        corner(1),
        corner(2),
        mid(0, 1),
        mid(1, 2),
        mid(2, 0),
    ]
}

impl IntegrationPoints {
    /// One point per linear triangle with rest data `rest` and corners `triangles`.
    pub(super) fn linear(triangles: &[[u32; 3]], rest: &[TriangleRest]) -> Self {
        let mut points = Self::empty(3, 1, triangles.len());
        for (nodes, rest) in triangles.iter().zip(rest) {
            let gradients = rest.normals().map(|b| -b / rest.area());
            points.push(nodes, &gradients, rest.area());
        }
        points
    }

    /// Three points per 6-node triangle of `elements`, whose corners have rest data `rest`.
    pub(super) fn quadratic(elements: &[[u32; 6]], rest: &[TriangleRest]) -> Self {
        let mut points = Self::empty(6, 3, elements.len());
        for (nodes, rest) in elements.iter().zip(rest) {
            let linear = rest.normals().map(|b| -b / rest.area());
            for k in 0..3 {
                let mut l = [1.0 / 6.0; 3];
                l[k] = 2.0 / 3.0;
                points.push(nodes, &quadratic_gradients(l, linear), rest.area() / 3.0);
            }
        }
        points
    }

    fn empty(per_point: usize, per_element: usize, elements: usize) -> Self {
        let count = elements * per_element;
        Self {
            per_point,
            nodes: Vec::with_capacity(count * per_point),
            gradients: Vec::with_capacity(count * per_point),
            weights: Vec::with_capacity(count),
            per_element,
        }
    }

    fn push(&mut self, nodes: &[u32], gradients: &[DVec2], weight: f64) {
        self.nodes.extend_from_slice(nodes);
        self.gradients.extend_from_slice(gradients);
        self.weights.push(weight);
    }

    /// The number of points.
    pub(super) fn len(&self) -> usize {
        self.weights.len()
    }

    /// Points per element.
    pub(super) fn per_element(&self) -> usize {
        self.per_element
    }

    /// The nodes of point `q`.
    pub(super) fn nodes(&self, q: usize) -> &[u32] {
        &self.nodes[q * self.per_point..(q + 1) * self.per_point]
    }

    /// The rest gradients `∇N_a` (1/m) at point `q`, in the order of [`Self::nodes`].
    pub(super) fn gradients(&self, q: usize) -> &[DVec2] {
        &self.gradients[q * self.per_point..(q + 1) * self.per_point]
    }

    /// The rest area (m²) point `q` stands for.
    pub(super) fn weight(&self, q: usize) -> f64 {
        self.weights[q]
    }

    /// The deformation gradient `Σ_a x_a ⊗ ∇N_a` (dimensionless) at point `q` for nodal
    /// `values`, or its rate for nodal velocities.
    pub(super) fn gradient(&self, q: usize, values: &[DVec2]) -> DMat2 {
        (self.nodes(q).iter().zip(self.gradients(q))).fold(DMat2::ZERO, |f, (n, g)| {
            let x = values[*n as usize];
            f + DMat2::from_cols(x * g.x, x * g.y)
        })
    }

    /// The change of the deformation gradient at point `q` when its `a`-th node moves by `dx`.
    pub(super) fn gradient_change(&self, q: usize, a: usize, dx: DVec2) -> DMat2 {
        let g = self.gradients(q)[a];
        DMat2::from_cols(dx * g.x, dx * g.y)
    }

    /// The force (N) of the stress `p` (Pa) at point `q` on its `a`-th node, for the rest
    /// `thickness` (m): `−w t P ∇N_a`.
    pub(super) fn force(&self, q: usize, a: usize, p: &DMat2, thickness: f64) -> DVec2 {
        -(*p * self.gradients(q)[a]) * (self.weights[q] * thickness)
    }

    /// Adds the forces (N) of the stress `p` (Pa) at point `q` to `forces`.
    pub(super) fn add_forces(&self, q: usize, p: &DMat2, thickness: f64, forces: &mut [DVec2]) {
        for (a, n) in self.nodes(q).iter().enumerate() {
            forces[*n as usize] += self.force(q, a, p, thickness);
        }
    }
}
