//! Per-triangle rest data and the finite-volume force: with the deformation gradient `F`
//! constant in a linear triangle (so the stress `P`), `f_i = t P b_i`, the traction of `P`
//! integrated over the part of node `i`'s control-volume boundary inside the triangle (`b_i`
//! half the outward length-weighted normal of the edge opposite `i`, whatever the control
//! volumes, see
//! [`super::ControlVolumes`]), times the rest thickness `t`. The forces sum to zero and their
//! torque vanishes when `P Fᵀ` is symmetric, as every model's is.

use super::mesh::signed_area;
use rapier3d::glamx::{DMat2, DVec2};

/// Rest data of one linear triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleRest {
    /// Rest area (m²).
    area: f64,
    /// `b_i` (m): half the outward length-weighted normal of the edge opposite corner `i`.
    normals: [DVec2; 3],
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

    /// The forces (N) on the corners under the first Piola–Kirchhoff stress `p` (Pa) for a rest
    /// `thickness` (m).
    pub fn forces(&self, p: &DMat2, thickness: f64) -> [DVec2; 3] {
        self.normals.map(|b| *p * b * thickness)
    }
}
