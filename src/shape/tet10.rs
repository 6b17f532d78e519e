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

use rapier3d::glamx::DVec3;

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

/// The smallest Jacobian determinant `det ∂x/∂ξ` of the element with nodes at `p` (m³ per unit
/// natural volume) over its corners and quadrature points, where a curved element folds first:
/// not positive (or NaN) for an element whose rest map folds.
pub fn smallest_jacobian_determinant(p: &[DVec3; NODES]) -> f64 {
    let corners = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let mut smallest = f64::INFINITY;
    for l in corners.iter().chain(&QUADRATURE) {
        let determinant = jacobian_determinant(p, *l);
        if determinant.is_nan() {
            return f64::NAN;
        }
        smallest = smallest.min(determinant);
    }
    smallest
}

/// Whether `determinant`, an element's [`smallest_jacobian_determinant`], says its rest map does
/// not fold (positive, not NaN).
pub fn unfolded(determinant: f64) -> bool {
    determinant > 0.0
}

/// The rest volume (m³) of the element with nodes at `p`, curved edges included: its Jacobian
/// determinant is cubic in the natural coordinates, so the five-point rule of degree 3 (the
/// centroid with weight −4/5, the points `(1/2, 1/6, 1/6, 1/6)` with 9/20 each) integrates it
/// exactly.
pub fn volume(p: &[DVec3; NODES]) -> f64 {
    const A: f64 = 0.5;
    const B: f64 = 1.0 / 6.0;
    let rule = [
        ([0.25; 4], -0.8),
        ([A, B, B, B], 0.45),
        ([B, A, B, B], 0.45),
        ([B, B, A, B], 0.45),
        ([B, B, B, A], 0.45),
    ];
    rule.iter()
        .map(|(l, weight)| weight * jacobian_determinant(p, *l))
        .sum::<f64>()
        / 6.0
}

/// `det ∂x/∂ξ` of the element with nodes at `p` at barycentric coordinates `l`.
fn jacobian_determinant(p: &[DVec3; NODES], l: [f64; 4]) -> f64 {
    let mut columns = [DVec3::ZERO; 3];
    for (position, gradient) in p.iter().zip(natural_gradients(l)) {
        for (k, column) in columns.iter_mut().enumerate() {
            *column += *position * gradient[k];
        }
    }
    columns[0].dot(columns[1].cross(columns[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn barycentric(p: DVec3) -> [f64; 4] {
        [1.0 - p.x - p.y - p.z, p.x, p.y, p.z]
    }

    #[test]
    fn the_volume_of_a_straight_and_a_curved_element_is_exact() {
        // Round-off only (1e-15 on volumes of order 1/6: sums of a few products of order 1).
        // Straight: the reference element scaled by 2 holds 8/6 m³.
        let straight = reference_nodes().map(|p| p * 2.0);
        assert!((volume(&straight) - 8.0 / 6.0).abs() < 1e-15);
        // The mid-edge node of edge (0,1) moved by d along y: x = ξ + d N_4(ξ) e_y, so
        // det J = 1 + d ∂N_4/∂ξ_2 = 1 - 4 d L1, and the volume is 1/6 - d/6 (∫ L1 = 1/24).
        let mut bent = reference_nodes();
        bent[4].y += 0.1;
        assert!((volume(&bent) - (1.0 / 6.0 - 0.1 / 6.0)).abs() < 1e-15);
        // Every mid-edge node moved: det J is a cubic. Against Gauss-Legendre products on the
        // unit cube mapped onto the element (ξ = (u, (1-u) v, (1-u)(1-v) w), Jacobian
        // (1-u)² (1-v)): four points per direction integrate the degree-6 integrand exactly.
        let mut curved = reference_nodes();
        for (k, node) in curved[4..].iter_mut().enumerate() {
            let k = k as f64;
            *node += DVec3::new(0.07 * (k - 2.5), 0.05 * (1.5 - k).abs(), 0.09 - 0.03 * k);
        }
        let gauss = [
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
        ]
        .map(|(x, w)| ((x + 1.0) / 2.0, w / 2.0));
        let mut integral = 0.0;
        for (u, wu) in gauss {
            for (v, wv) in gauss {
                for (w, ww) in gauss {
                    let xi = DVec3::new(u, (1.0 - u) * v, (1.0 - u) * (1.0 - v) * w);
                    let l = [1.0 - xi.x - xi.y - xi.z, xi.x, xi.y, xi.z];
                    let duffy = (1.0 - u).powi(2) * (1.0 - v);
                    integral += wu * wv * ww * duffy * jacobian_determinant(&curved, l);
                }
            }
        }
        assert!(
            (volume(&curved) - integral).abs() < 1e-15,
            "{} {integral}",
            volume(&curved)
        );
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
}
