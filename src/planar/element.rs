//! Per-triangle rest data and the finite-volume force: `F = D_x D_p⁻¹` (constant in a linear
//! triangle, `D` the edge matrices from the first corner, rest `p` and world `x`) and
//! `f_i = t P b_i`, the traction of the constant stress `P` integrated over the part of node
//! `i`'s control-volume boundary inside the triangle (`b_i` half the outward length-weighted
//! normal of the edge opposite `i`, whatever the control volumes, see
//! [`super::ControlVolumes`]), times the rest thickness `t`. The forces sum to zero and their
//! torque vanishes when `P Fᵀ` is symmetric, as every model's is.

use super::mesh::signed_area;
use rapier3d::glamx::{DMat2, DVec2};

/// Rest data of one linear triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleRest {
    /// `D_p⁻¹` (1/m), the inverse of the rest edge matrix.
    inverse_edges: DMat2,
    /// Rest area (m²).
    area: f64,
    /// `b_i` (m): half the outward length-weighted normal of the edge opposite corner `i`.
    normals: [DVec2; 3],
}

/// The matrix whose columns are `x₁ − x₀` and `x₂ − x₀`.
fn edges(x: &[DVec2; 3]) -> DMat2 {
    DMat2::from_cols(x[1] - x[0], x[2] - x[0])
}

impl TriangleRest {
    /// The rest data of the counterclockwise triangle with rest corners `p` (m), whose area
    /// [`super::TriangleMesh::new`] checked to be positive.
    pub fn new(p: [DVec2; 3]) -> Self {
        let normals = std::array::from_fn(|i| {
            let (from, to) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            let d = to - from;
            DVec2::new(d.y, -d.x) / 2.0
        });
        Self {
            inverse_edges: edges(&p).inverse(),
            area: signed_area(p[0], p[1], p[2]),
            normals,
        }
    }

    /// Rest area (m²).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// `b_i` (m) for the three corners.
    pub fn normals(&self) -> [DVec2; 3] {
        self.normals
    }

    /// The deformation gradient (dimensionless) for world corners `x` (m).
    pub fn gradient(&self, x: &[DVec2; 3]) -> DMat2 {
        edges(x) * self.inverse_edges
    }

    /// The change of the deformation gradient (dimensionless) when corner `i` moves by `dx`
    /// (m): `dx ⊗ ∇Nᵢ`, with `∇Nᵢ = −b_i / A`.
    pub fn gradient_change(&self, i: usize, dx: DVec2) -> DMat2 {
        let grad = -self.normals[i] / self.area;
        DMat2::from_cols(dx * grad.x, dx * grad.y)
    }

    /// The forces (N) on the corners under the first Piola–Kirchhoff stress `p` (Pa) for a rest
    /// `thickness` (m).
    pub fn forces(&self, p: &DMat2, thickness: f64) -> [DVec2; 3] {
        self.normals.map(|b| *p * b * thickness)
    }
}
