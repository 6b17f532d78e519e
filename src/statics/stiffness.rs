//! Assembly of the tangent stiffness `K = -∂f_int/∂x` (N/m) as a sparse symmetric matrix (lower
//! triangle, compressed columns), with pinned nodes' rows and columns replaced by the identity.

use crate::body::SoftBody;
use crate::fvm::{TetRest, gather};
use crate::material::{HyperelasticModel, with_hyperelastic_model};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use rapier3d::glamx::{DMat3, DVec3};

/// The sparsity pattern of the lower triangle of the 3n x 3n stiffness of a mesh, and its values.
pub(crate) struct Stiffness {
    dofs: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// For node `b`: its neighbours `a >= b` (itself first), ascending.
    lower_neighbours: Vec<Vec<u32>>,
    /// Matrix entries in compressed-column order (N/m).
    pub(crate) values: Vec<f64>,
}

impl Stiffness {
    /// The pattern of `body`'s mesh, values zero.
    pub(crate) fn new(body: &SoftBody) -> Self {
        let n = body.node_count();
        let mut lower_neighbours: Vec<Vec<u32>> = (0..n as u32).map(|b| vec![b]).collect();
        for tet in body.mesh().tets() {
            for &a in tet {
                for &b in tet {
                    if a > b {
                        lower_neighbours[b as usize].push(a);
                    }
                }
            }
        }
        for list in &mut lower_neighbours {
            list.sort_unstable();
            list.dedup();
        }
        let mut col_ptr = Vec::with_capacity(3 * n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (b, list) in lower_neighbours.iter().enumerate() {
            for j in 0..3 {
                row_idx.extend((j..3).map(|i| 3 * b + i));
                for &a in &list[1..] {
                    row_idx.extend((0..3).map(|i| 3 * a as usize + i));
                }
                col_ptr.push(row_idx.len());
            }
        }
        Self {
            dofs: 3 * n,
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
            lower_neighbours,
        }
    }

    /// Index into `values` of the entry (row `3a + i`, column `3b + j`), for `a > b`, or `a == b`
    /// and `i >= j`.
    fn entry(&self, a: usize, i: usize, b: usize, j: usize) -> usize {
        let start = self.col_ptr[3 * b + j];
        if a == b {
            return start + i - j;
        }
        let k = self.lower_neighbours[b]
            .binary_search(&(a as u32))
            .expect("the pattern contains every pair of nodes sharing a tetrahedron");
        start + (3 - j) + 3 * (k - 1) + i
    }

    /// Fills the values with the tangent stiffness of `body` at its current positions.
    pub(crate) fn assemble(&mut self, body: &SoftBody) {
        self.values.fill(0.0);
        let fvm = &body.fvm;
        with_hyperelastic_model!(body.material, |model| {
            for (t, tet) in fvm.tets().iter().enumerate() {
                let k = element_stiffness(&model, &fvm.tet_rest(t), &gather(tet, body.positions()));
                self.add_element(tet, &k, &body.pinned);
            }
        });
        for (node, &pinned) in body.pinned.iter().enumerate() {
            if pinned {
                for i in 0..3 {
                    let e = self.entry(node, i, node, i);
                    self.values[e] = 1.0;
                }
            }
        }
    }

    fn add_element(&mut self, tet: &[u32; 4], k: &[[f64; 12]; 12], pinned: &[bool]) {
        for (cb, &b) in tet.iter().enumerate() {
            for (ca, &a) in tet.iter().enumerate() {
                let (a, b) = (a as usize, b as usize);
                if a < b || pinned[a] || pinned[b] {
                    continue;
                }
                for j in 0..3 {
                    for i in 0..3 {
                        if a == b && i < j {
                            continue;
                        }
                        let e = self.entry(a, i, b, j);
                        self.values[e] += k[3 * ca + i][3 * cb + j];
                    }
                }
            }
        }
    }

    /// A view of the assembled matrix for faer.
    pub(crate) fn as_faer(&self) -> SparseColMatRef<'_, usize, f64> {
        let symbolic = SymbolicSparseColMatRef::new_checked(
            self.dofs,
            self.dofs,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        SparseColMatRef::new(symbolic, &self.values)
    }
}

/// The 12 x 12 tangent stiffness `K[3a+i][3b+j] = -∂f_(a,i)/∂x_(b,j)` (N/m) of one tetrahedron at
/// node positions `x`.
pub(crate) fn element_stiffness<M: HyperelasticModel>(
    model: &M,
    rest: &TetRest,
    x: &[DVec3; 4],
) -> [[f64; 12]; 12] {
    let f = rest.gradient(x);
    // Gradients of the shape functions of nodes 1..3 are the rows of Dm⁻¹.
    let shape_gradients = rest.inverse_rest_edges.transpose();
    let control_normals = rest.control_normals();
    let mut k = [[0.0; 12]; 12];
    for j in 0..3 {
        let mut node0_column = [DVec3::ZERO; 4];
        for b in 1..4 {
            let mut df = DMat3::ZERO;
            let g = shape_gradients.col(b - 1);
            // dF = e_j ⊗ g_b: row j of dF is g_b.
            for c in 0..3 {
                df.col_mut(c)[j] = g[c];
            }
            let dp = model.first_piola_differential(&f, &df);
            let d_forces = dp * control_normals;
            let column = [
                -(d_forces.x_axis + d_forces.y_axis + d_forces.z_axis),
                d_forces.x_axis,
                d_forces.y_axis,
                d_forces.z_axis,
            ];
            for (a, df_a) in column.iter().enumerate() {
                node0_column[a] -= *df_a;
                for i in 0..3 {
                    k[3 * a + i][3 * b + j] = -df_a[i];
                }
            }
        }
        // x_0 enters F with the gradient -(g_1 + g_2 + g_3).
        for (a, df_a) in node0_column.iter().enumerate() {
            for i in 0..3 {
                k[3 * a + i][j] = -df_a[i];
            }
        }
    }
    k
}
