//! The 27-node quadratic (triquadratic) hexahedron: the element of a coarse quadratic cage.
//!
//! Nodes are numbered lexicographically on the 3 x 3 x 3 lattice of the reference cube
//! `[−1, 1]³`: node `i + 3j + 9k` (`i, j, k ∈ {0, 1, 2}`) sits at natural coordinates
//! `ξ = (i − 1, j − 1, k − 1)`. The shape functions are products of the one-dimensional quadratic
//! Lagrange polynomials `s(s − 1)/2`, `1 − s²`, `s(s + 1)/2`, so the motion is quadratic along
//! every axis: one element across a beam's section bends it as a continuum does, where
//! tetrahedra need several.
//!
//! The element is integrated by the 3 x 3 x 3 Gauss rule ([`QUADRATURE`]), exact for the
//! stiffness of linear elasticity on parallelepipeds (degree 4 per axis) and free of the
//! zero-energy (hourglass) modes of reduced rules.

use rapier3d::glamx::DVec3;

/// Nodes per element.
pub const NODES: usize = 27;

/// The Gauss–Legendre rule of three points on `[−1, 1]`: abscissae and weights.
const GAUSS: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// The 27-point tensor Gauss rule on the reference cube: natural coordinates and weights
/// (summing to its volume, 8).
pub const QUADRATURE: [(DVec3, f64); 27] = {
    let mut rule = [(DVec3::ZERO, 0.0); 27];
    let mut q = 0;
    while q < 27 {
        let (x, wx) = GAUSS[q % 3];
        let (y, wy) = GAUSS[(q / 3) % 3];
        let (z, wz) = GAUSS[q / 9];
        rule[q] = (DVec3::new(x, y, z), wx * wy * wz);
        q += 1;
    }
    rule
};

/// The one-dimensional HRZ mass fractions of a quadratic Lagrange element: the consistent
/// diagonal `4/15, 16/15, 4/15` scaled to sum to one.
const LUMPED_1D: [f64; 3] = [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0];

/// Mass fractions of HRZ lumping (the consistent diagonal scaled to the element's mass): products
/// of the one-dimensional `1/6, 2/3, 1/6`, from `1/216` at a corner to `64/216` at the centre;
/// all positive.
pub const LUMPED_MASS_FRACTIONS: [f64; NODES] = {
    let mut fractions = [0.0; NODES];
    let mut a = 0;
    while a < NODES {
        fractions[a] = LUMPED_1D[a % 3] * LUMPED_1D[(a / 3) % 3] * LUMPED_1D[a / 9];
        a += 1;
    }
    fractions
};

/// The lattice position `(i, j, k)` of local node `a`.
pub const fn lattice(a: usize) -> [usize; 3] {
    [a % 3, (a / 3) % 3, a / 9]
}

/// The natural coordinates of the nodes (corners at `±1`).
pub fn reference_nodes() -> [DVec3; NODES] {
    std::array::from_fn(|a| {
        let [i, j, k] = lattice(a);
        DVec3::new(i as f64 - 1.0, j as f64 - 1.0, k as f64 - 1.0)
    })
}

/// The one-dimensional quadratic Lagrange polynomials at `s` and their derivatives.
fn lagrange(s: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * s * (s - 1.0), 1.0 - s * s, 0.5 * s * (s + 1.0)],
        [s - 0.5, -2.0 * s, s + 0.5],
    )
}

/// The shape functions at natural coordinates `xi`.
pub fn shape_values(xi: DVec3) -> [f64; NODES] {
    let (x, y, z) = (lagrange(xi.x).0, lagrange(xi.y).0, lagrange(xi.z).0);
    std::array::from_fn(|a| {
        let [i, j, k] = lattice(a);
        x[i] * y[j] * z[k]
    })
}

/// The gradients of the shape functions with respect to the natural coordinates at `xi`.
pub fn natural_gradients(xi: DVec3) -> [DVec3; NODES] {
    let ((x, dx), (y, dy), (z, dz)) = (lagrange(xi.x), lagrange(xi.y), lagrange(xi.z));
    std::array::from_fn(|a| {
        let [i, j, k] = lattice(a);
        DVec3::new(
            dx[i] * y[j] * z[k],
            x[i] * dy[j] * z[k],
            x[i] * y[j] * dz[k],
        )
    })
}

/// The element's nodes mirrored along its first natural axis (lattice node `(i, j, k)` takes
/// `(2 − i, j, k)`'s): the same element numbered with the opposite handedness.
pub fn mirrored<T: Copy>(nodes: &[T; NODES]) -> [T; NODES] {
    std::array::from_fn(|a| nodes[a - a % 3 + 2 - a % 3])
}

/// `det ∂x/∂ξ` of the element with nodes at `p` (m) at natural coordinates `xi` (m³ per unit
/// natural volume).
pub fn jacobian_determinant(p: &[DVec3; NODES], xi: DVec3) -> f64 {
    let gradients = natural_gradients(xi);
    let mut columns = [DVec3::ZERO; 3];
    for (x, g) in p.iter().zip(&gradients) {
        for (k, column) in columns.iter_mut().enumerate() {
            *column += *x * g[k];
        }
    }
    columns[0].dot(columns[1].cross(columns[2]))
}

/// The smallest Jacobian determinant of the element with nodes at `p` (m) over its corners and
/// quadrature points (m³ per unit natural volume): not positive (or NaN) for an element whose
/// rest map folds.
pub fn smallest_jacobian_determinant(p: &[DVec3; NODES]) -> f64 {
    let corners = reference_nodes()
        .into_iter()
        .filter(|xi| xi.abs() == DVec3::ONE);
    let mut smallest = f64::INFINITY;
    for xi in corners.chain(QUADRATURE.iter().map(|(xi, _)| *xi)) {
        let determinant = jacobian_determinant(p, xi);
        if determinant.is_nan() {
            return f64::NAN;
        }
        smallest = smallest.min(determinant);
    }
    smallest
}

/// The rest volume (m³) of the element with nodes at `p`, curved faces included: its Jacobian
/// determinant has degree at most 5 along each natural axis, which [`QUADRATURE`] integrates
/// exactly.
pub fn volume(p: &[DVec3; NODES]) -> f64 {
    QUADRATURE
        .iter()
        .map(|(xi, weight)| weight * jacobian_determinant(p, *xi))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_functions_are_nodal_and_a_partition_of_unity() {
        let nodes = reference_nodes();
        for (a, xi) in nodes.iter().enumerate() {
            for (b, value) in shape_values(*xi).iter().enumerate() {
                let expected = if a == b { 1.0 } else { 0.0 };
                assert!((value - expected).abs() < 1e-15, "N_{b} at node {a}");
            }
        }
        let xi = DVec3::new(0.3, -0.7, 0.45);
        assert!((shape_values(xi).iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(natural_gradients(xi).iter().sum::<DVec3>().length() < 1e-14);
    }

    #[test]
    fn natural_gradients_match_finite_differences() {
        let xi = DVec3::new(0.3, -0.7, 0.45);
        let h = 1e-6;
        let gradients = natural_gradients(xi);
        for (k, axis) in DVec3::AXES.into_iter().enumerate() {
            let step = axis * h;
            let (plus, minus) = (shape_values(xi + step), shape_values(xi - step));
            for a in 0..NODES {
                let fd = (plus[a] - minus[a]) / (2.0 * h);
                assert!((gradients[a][k] - fd).abs() < 1e-8, "node {a}, ξ{k}");
            }
        }
    }

    #[test]
    fn quadrature_integrates_degree_five_per_axis_exactly() {
        // ∫ x⁴ y² z⁰ over [−1, 1]³ = (2/5)(2/3)(2).
        let integral: f64 = QUADRATURE
            .iter()
            .map(|(p, w)| w * p.x.powi(4) * p.y * p.y)
            .sum();
        assert!((integral - 2.0 / 5.0 * 2.0 / 3.0 * 2.0).abs() < 1e-14);
        assert!((QUADRATURE.iter().map(|q| q.1).sum::<f64>() - 8.0).abs() < 1e-14);
    }

    #[test]
    fn lumped_masses_are_the_scaled_consistent_diagonal() {
        // The consistent diagonal ∫ N_a² over the cube, by the (exact, degree 4) Gauss rule.
        let diagonal: Vec<f64> = (0..NODES)
            .map(|a| {
                QUADRATURE
                    .iter()
                    .map(|(xi, w)| w * shape_values(*xi)[a].powi(2))
                    .sum()
            })
            .collect();
        let total: f64 = diagonal.iter().sum();
        for (d, fraction) in diagonal.iter().zip(LUMPED_MASS_FRACTIONS) {
            assert!((d / total - fraction).abs() < 1e-15);
            assert!(fraction > 0.0);
        }
    }
}
