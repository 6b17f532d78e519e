//! The 10-node quadratic tetrahedron: shape functions, the quadrature rule, and the rest data of
//! a mesh of them.
//!
//! Nodes are numbered as in VTK (`VTK_QUADRATIC_TETRA`): corners 0–3, then the mid-edge nodes of
//! the edges [`EDGES`] `(0,1) (1,2) (0,2) (0,3) (1,3) (2,3)`. In barycentric coordinates
//! `L0…L3` the shape functions are `N_i = L_i (2 L_i − 1)` at the corners and `N_ij = 4 L_i L_j`
//! at the mid-edge nodes, so the displacement is quadratic and the deformation gradient linear
//! in each element: a pure bending state is represented exactly, where linear tetrahedra can
//! only approximate it with many elements.
//!
//! The element is isoparametric (curved rest edges are allowed) and integrated by the four-point
//! rule exact for quadratic polynomials ([`QUADRATURE`]): on straight-sided elements the
//! stiffness integrand of linear elasticity is quadratic, so it is integrated exactly.

use crate::Error;
use rapier3d::glamx::{DMat3, DVec3};

/// Nodes per element.
pub const NODES: usize = 10;

/// The corner pair of each mid-edge node `4 + k`.
pub const EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// The four-point rule for tetrahedra (degree 2, positive weights): barycentric coordinates of
/// the points, each with a quarter of the element volume. `a = (5 + 3√5)/20`, `b = (5 − √5)/20`.
pub const QUADRATURE: [[f64; 4]; 4] = {
    const A: f64 = 0.585_410_196_624_968_5;
    const B: f64 = 0.138_196_601_125_010_5;
    [[A, B, B, B], [B, A, B, B], [B, B, A, B], [B, B, B, A]]
};

/// Mass fractions of HRZ lumping (Hinton, Rock and Zienkiewicz 1976): the diagonal of the
/// consistent mass matrix (`ρV/70` at a corner, `8ρV/105` at a mid-edge node) scaled to the
/// element's mass, `1/36` per corner and `4/27` per mid-edge node. Row-sum lumping would give the
/// corners negative masses.
pub const LUMPED_MASS_FRACTIONS: [f64; NODES] = {
    const CORNER: f64 = 1.0 / 36.0;
    const EDGE: f64 = 4.0 / 27.0;
    [
        CORNER, CORNER, CORNER, CORNER, EDGE, EDGE, EDGE, EDGE, EDGE, EDGE,
    ]
};

/// The nodes of the reference element (m): corners at the origin and the unit points, mid-edge
/// nodes halfway.
pub fn reference_nodes() -> [DVec3; NODES] {
    let corners = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    std::array::from_fn(|a| match a {
        0..4 => corners[a],
        _ => {
            let [i, j] = EDGES[a - 4];
            0.5 * (corners[i] + corners[j])
        }
    })
}

/// The shape functions at barycentric coordinates `l` (summing to one).
pub fn shape_values(l: [f64; 4]) -> [f64; NODES] {
    let mut n = [0.0; NODES];
    for i in 0..4 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
    }
    for (k, [i, j]) in EDGES.iter().enumerate() {
        n[4 + k] = 4.0 * l[*i] * l[*j];
    }
    n
}

/// The gradients of the shape functions with respect to the natural coordinates
/// `ξ = (L1, L2, L3)` (with `L0 = 1 − ξ1 − ξ2 − ξ3`), at barycentric coordinates `l`.
pub fn natural_gradients(l: [f64; 4]) -> [DVec3; NODES] {
    // ∂N/∂L_m for the four barycentric coordinates, then ∂/∂ξ_k = ∂/∂L_k − ∂/∂L_0.
    let mut by_barycentric = [[0.0; 4]; NODES];
    for i in 0..4 {
        by_barycentric[i][i] = 4.0 * l[i] - 1.0;
    }
    for (k, [i, j]) in EDGES.iter().enumerate() {
        by_barycentric[4 + k][*i] = 4.0 * l[*j];
        by_barycentric[4 + k][*j] = 4.0 * l[*i];
    }
    by_barycentric.map(|d| DVec3::new(d[1] - d[0], d[2] - d[0], d[3] - d[0]))
}

/// The rest map of one element at one point: `J = ∂p/∂ξ` (m) from the rest positions `p` of its
/// nodes and the natural gradients there.
fn rest_jacobian(p: &[DVec3; NODES], natural: &[DVec3; NODES]) -> DMat3 {
    let mut columns = [DVec3::ZERO; 3];
    for (position, gradient) in p.iter().zip(natural) {
        for (k, column) in columns.iter_mut().enumerate() {
            *column += *position * gradient[k];
        }
    }
    DMat3::from_cols(columns[0], columns[1], columns[2])
}

/// The spatial (rest) gradients `∇N_a = J⁻ᵀ ∂N_a/∂ξ` (1/m) at barycentric coordinates `l` and
/// the Jacobian determinant there, or the determinant alone when it is not positive.
fn rest_gradients(p: &[DVec3; NODES], l: [f64; 4]) -> Result<([DVec3; NODES], f64), f64> {
    let natural = natural_gradients(l);
    let jacobian = rest_jacobian(p, &natural);
    let determinant = jacobian.determinant();
    // NaN (from non-finite rest positions) is refused as well.
    if determinant.is_nan() || determinant <= 0.0 {
        return Err(determinant);
    }
    let inverse_transpose = jacobian.inverse().transpose();
    Ok((natural.map(|g| inverse_transpose * g), determinant))
}

/// One quadrature point of an element in its rest configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraturePoint {
    /// `∇N_a` (1/m) of the ten shape functions at the point, in rest coordinates.
    pub gradients: [DVec3; NODES],
    /// The rest volume the point stands for (m³): its weight times the Jacobian determinant.
    pub weight: f64,
}

/// The rest data of a mesh of quadratic tetrahedra: four quadrature points per element.
#[derive(Debug, Clone)]
pub struct QuadraticElements {
    elements: Vec<[u32; NODES]>,
    points: Vec<QuadraturePoint>,
    lumped_volumes: Vec<f64>,
}

impl QuadraticElements {
    /// The rest data of `elements` (10 node indices each) at rest positions `positions` (m), one
    /// per node.
    ///
    /// # Errors
    /// [`Error::InvertedTet`] naming the first element whose rest map folds (its Jacobian
    /// determinant is not positive at a quadrature point or corner): a badly curved element.
    pub fn new(positions: &[DVec3], elements: &[[u32; NODES]]) -> Result<Self, Error> {
        let mut points = Vec::with_capacity(4 * elements.len());
        for (element, nodes) in elements.iter().enumerate() {
            let p = nodes.map(|n| positions[n as usize]);
            let inverted = |determinant: f64| Error::InvertedTet {
                tet: element,
                volume: determinant / 6.0,
            };
            for corner in 0..4 {
                let mut l = [0.0; 4];
                l[corner] = 1.0;
                rest_gradients(&p, l).map_err(inverted)?;
            }
            for l in QUADRATURE {
                let (gradients, determinant) = rest_gradients(&p, l).map_err(inverted)?;
                points.push(QuadraturePoint {
                    gradients,
                    weight: determinant / 24.0,
                });
            }
        }
        let mut lumped_volumes = vec![0.0; positions.len()];
        for (element, nodes) in elements.iter().enumerate() {
            let volume: f64 = points[4 * element..4 * element + 4]
                .iter()
                .map(|q| q.weight)
                .sum();
            for (&n, fraction) in nodes.iter().zip(LUMPED_MASS_FRACTIONS) {
                lumped_volumes[n as usize] += fraction * volume;
            }
        }
        Ok(Self {
            elements: elements.to_vec(),
            points,
            lumped_volumes,
        })
    }

    /// The elements (10 node indices each).
    pub fn elements(&self) -> &[[u32; NODES]] {
        &self.elements
    }

    /// The quadrature points, four per element in element order.
    pub fn points(&self) -> &[QuadraturePoint] {
        &self.points
    }

    /// Rest volume of element `element` (m³), the sum of its quadrature weights.
    ///
    /// # Panics
    /// If the element does not exist.
    pub fn volume(&self, element: usize) -> f64 {
        self.points[4 * element..4 * element + 4]
            .iter()
            .map(|q| q.weight)
            .sum()
    }

    /// The rest volume (m³) lumped on each node: HRZ fractions ([`LUMPED_MASS_FRACTIONS`]) of
    /// each element's volume; times the density, the nodal masses.
    pub fn lumped_volumes(&self) -> &[f64] {
        &self.lumped_volumes
    }

    /// The deformation gradient of element `element` (dimensionless) at barycentric coordinates
    /// `l` for node positions `x` (m): `F = Σ_a x_a ⊗ ∇N_a`, with the gradients at that point.
    ///
    /// # Panics
    /// If the element does not exist.
    pub fn gradient_at(&self, element: usize, rest: &[DVec3], x: &[DVec3], l: [f64; 4]) -> DMat3 {
        let nodes = &self.elements[element];
        let p = nodes.map(|n| rest[n as usize]);
        match rest_gradients(&p, l) {
            Ok((gradients, _)) => deformation_gradient(nodes, &gradients, x),
            // The constructor checked the corners and quadrature points; a point between them
            // cannot fold for an element that passed, but stay finite if it does.
            Err(_) => DMat3::IDENTITY,
        }
    }
}

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

    fn barycentric(p: DVec3) -> [f64; 4] {
        [1.0 - p.x - p.y - p.z, p.x, p.y, p.z]
    }

    #[test]
    fn shape_functions_are_nodal_and_a_partition_of_unity() {
        let nodes = reference_nodes();
        for (a, p) in nodes.iter().enumerate() {
            let n = shape_values(barycentric(*p));
            for (b, value) in n.iter().enumerate() {
                let expected = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (value - expected).abs() < 1e-15,
                    "N_{b} at node {a} = {value}"
                );
            }
        }
        let l = [0.1, 0.2, 0.3, 0.4];
        assert!((shape_values(l).iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let gradient_sum: DVec3 = natural_gradients(l).iter().sum();
        assert!(gradient_sum.length() < 1e-14);
    }

    #[test]
    fn natural_gradients_match_finite_differences() {
        let l = [0.15, 0.25, 0.35, 0.25];
        let h = 1e-6;
        let gradients = natural_gradients(l);
        for k in 0..3 {
            // Moving ξ_k moves L_{k+1} and L_0 oppositely.
            let mut plus = l;
            plus[k + 1] += h;
            plus[0] -= h;
            let mut minus = l;
            minus[k + 1] -= h;
            minus[0] += h;
            let (np, nm) = (shape_values(plus), shape_values(minus));
            for a in 0..NODES {
                let fd = (np[a] - nm[a]) / (2.0 * h);
                assert!((gradients[a][k] - fd).abs() < 1e-8, "node {a}, ξ{k}");
            }
        }
    }

    #[test]
    fn lumped_masses_are_the_scaled_consistent_diagonal() {
        // The consistent diagonal integrated with the exact monomial formula
        // ∫ L_i^a L_j^b dV = a! b! 3! / (a + b + 3)! V.
        let corner = 1.0 / 70.0;
        let edge = 8.0 / 105.0;
        let total = 4.0 * corner + 6.0 * edge;
        assert!((LUMPED_MASS_FRACTIONS[0] - corner / total).abs() < 1e-15);
        assert!((LUMPED_MASS_FRACTIONS[4] - edge / total).abs() < 1e-15);
        assert!((LUMPED_MASS_FRACTIONS.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn quadratic_displacement_gives_its_exact_linear_gradient() {
        // x = p + u(p) with u quadratic: F = I + ∇u exactly at every point.
        let u = |p: DVec3| DVec3::new(0.3 * p.y * p.y, 0.2 * p.x * p.z, -0.1 * p.x * p.x);
        let grad_u = |p: DVec3| {
            DMat3::from_cols(
                DVec3::new(0.0, 0.2 * p.z, -0.2 * p.x),
                DVec3::new(0.6 * p.y, 0.0, 0.0),
                DVec3::new(0.0, 0.2 * p.x, 0.0),
            )
        };
        let rest = reference_nodes();
        let x: Vec<DVec3> = rest.iter().map(|p| *p + u(*p)).collect();
        let elements = QuadraticElements::new(&rest, &[std::array::from_fn(|a| a as u32)]).unwrap();
        let l = [0.1, 0.2, 0.3, 0.4];
        let p = DVec3::new(l[1], l[2], l[3]);
        let f = elements.gradient_at(0, &rest, &x, l);
        let error = f - (DMat3::IDENTITY + grad_u(p));
        assert!(error.to_cols_array().iter().all(|e| e.abs() < 1e-14));
        assert!((elements.volume(0) - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn a_folded_element_is_refused_by_index() {
        let mut rest = reference_nodes();
        // Pull the (0,1) mid-edge node past corner 1: the rest map folds near that corner.
        rest[4] = DVec3::new(1.2, 0.0, 0.0);
        let error = QuadraticElements::new(&rest, &[std::array::from_fn(|a| a as u32)]);
        assert!(matches!(error, Err(Error::InvertedTet { tet: 0, .. })));
    }
}
