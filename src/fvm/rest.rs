//! Per-tetrahedron data fixed by the rest mesh, computed once when a body is built.

use crate::mesh::TetMesh;
use rapier3d::glamx::{DMat3, DVec3};

/// Rest data of one tetrahedron `[x0, x1, x2, x3]`: 10 numbers, the least the force kernel needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetRest {
    /// `Dm⁻¹` (1/m), the inverse of the rest edge matrix `Dm = [p1 - p0, p2 - p0, p3 - p0]`, so that
    /// `F = Ds Dm⁻¹` with `Ds` the deformed edge matrix. Its rows are the gradients of the linear
    /// shape functions of nodes 1 to 3.
    pub inverse_rest_edges: DMat3,
    /// Rest volume (m³).
    pub volume: f64,
}

impl TetRest {
    /// Rest data of a positively oriented tetrahedron with rest positions `p` (m).
    pub fn new(p: [DVec3; 4]) -> Self {
        let rest_edges = DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
        Self {
            inverse_rest_edges: rest_edges.inverse(),
            volume: rest_edges.determinant() / 6.0,
        }
    }

    /// Rest data of every tetrahedron of `mesh`, in mesh order.
    pub fn of_mesh(mesh: &TetMesh) -> Vec<Self> {
        let positions = mesh.positions();
        mesh.tets()
            .iter()
            .map(|t| Self::new(t.map(|i| positions[i as usize])))
            .collect()
    }

    /// Deformation gradient `F = Ds Dm⁻¹` (dimensionless) for node positions `x`, or its rate
    /// `Ḟ` (1/s) for node velocities.
    #[inline(always)]
    pub fn gradient(&self, x: &[DVec3; 4]) -> DMat3 {
        DMat3::from_cols(x[1] - x[0], x[2] - x[0], x[3] - x[0]) * self.inverse_rest_edges
    }

    /// The gradients `∇N_0 … ∇N_3` (1/m) of the four linear shape functions in the rest
    /// configuration: the rows of `Dm⁻¹` for nodes 1 to 3, and minus their sum for node 0.
    #[inline(always)]
    pub fn shape_gradients(&self) -> [DVec3; 4] {
        let g = self.inverse_rest_edges.transpose();
        [
            -(g.x_axis + g.y_axis + g.z_axis),
            g.x_axis,
            g.y_axis,
            g.z_axis,
        ]
    }

    /// Columns `b1, b2, b3` (m²): the rest area-weighted normals of the control-volume boundary
    /// pieces of nodes 1 to 3 inside this tetrahedron, `b_i = (1/3) A_i n_i` with `A_i n_i` the
    /// area-weighted outward normal of the face opposite node `i`; `b0 = -(b1 + b2 + b3)`.
    /// Equal to `-V Dm⁻ᵀ`, the form the kernel uses.
    #[inline(always)]
    pub fn control_normals(&self) -> DMat3 {
        self.inverse_rest_edges.transpose() * -self.volume
    }
}
