//! Assembly of sparse symmetric tangent matrices (N/m) over a body's mesh: the lower triangle in
//! compressed columns, pinned nodes' rows and columns replaced by the identity.
//!
//! An element contributes `K_e = V Gᵀ A G`, where `A = ∂P/∂F` is the 9 x 9 tangent of the stress
//! with respect to the deformation gradient and `G` maps the four node displacements to `dF`.
//! On request `A` is first projected onto its positive semi-definite part, so that `K_e` has no
//! negative eigenvalue and Newton steps always descend (the stress tangents of St.
//! Venant–Kirchhoff and Neo-Hookean are indefinite under compression); the projection stiffens
//! the rotational directions of a stressed element, so exact tangents are used where they exist.

use crate::Error;
use crate::body::SoftBody;
use crate::fvm::{NodalAveraging, TetRest, gather};
use crate::material::{HyperelasticModel, with_hyperelastic_model};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Col, Side};
use rapier3d::glamx::{DMat3, DVec3};
use rapier3d::na;

/// A 9 x 9 stress tangent `A[(r, c), (s, d)] = ∂P_rc / ∂F_sd` (Pa), indices column-major
/// (`3 c + r`).
pub(crate) type StressTangent = na::SMatrix<f64, 9, 9>;

/// The sparsity pattern of the lower triangle of the 3n x 3n tangent of a mesh, and its values.
#[derive(Debug, Clone)]
pub(crate) struct Stiffness {
    dofs: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// For node `b`: its neighbours `a >= b` (itself first), ascending.
    lower_neighbours: Vec<Vec<u32>>,
    /// Matrix entries in compressed-column order (N/m).
    pub(crate) values: Vec<f64>,
    /// The symbolic Cholesky factorization (fill-reducing ordering and elimination tree) of the
    /// pattern, computed at the first factorization and reused by every later one.
    symbolic: Option<SymbolicLlt<usize>>,
}

impl Stiffness {
    /// The pattern of `body`'s mesh, values zero: nodes sharing a tetrahedron, and with nodal
    /// averaging also nodes sharing a neighbour (the patches' coupling).
    pub(crate) fn new(body: &SoftBody) -> Self {
        let n = body.node_count();
        let mut lower_neighbours: Vec<Vec<u32>> = (0..n as u32).map(|b| vec![b]).collect();
        couple_all_pairs(
            &mut lower_neighbours,
            body.mesh().tets().iter().map(|t| &t[..]),
        );
        if body.nodal_averaging.is_some() {
            // A node's patch: itself and every node sharing a tetrahedron with it.
            let mut patches: Vec<Vec<u32>> = lower_neighbours.clone();
            for (b, list) in lower_neighbours.iter().enumerate() {
                for &a in &list[1..] {
                    patches[a as usize].push(b as u32);
                }
            }
            couple_all_pairs(&mut lower_neighbours, patches.iter().map(|p| &p[..]));
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
            symbolic: None,
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
            .expect("the pattern contains every pair of coupled nodes");
        start + (3 - j) + 3 * (k - 1) + i
    }

    /// Fills the values with the body's tangent stiffness at its current positions: for every
    /// tetrahedron `V Gᵀ A G` with `A` the stress tangent of the elastic stress differential plus
    /// `extra(t, F, dF)` (a further stress differential, Pa), projected to be positive
    /// semi-definite if `project`; the coupling of nodal averaging if the body uses it; and
    /// `diagonal[n] I` on each free node.
    pub(crate) fn assemble(
        &mut self,
        body: &SoftBody,
        diagonal: Option<&[f64]>,
        project: bool,
        extra: impl Fn(usize, &DMat3, &DMat3) -> DMat3,
    ) {
        self.values.fill(0.0);
        let fvm = &body.fvm;
        with_hyperelastic_model!(body.material, |model| {
            let averaging = body.nodal_averaging.as_ref();
            let measures = averaging.map(|a| a.measures(&model, fvm, body.positions()));
            for (t, tet) in fvm.tets().iter().enumerate() {
                let rest = fvm.tet_rest(t);
                let f = rest.gradient(&gather(tet, body.positions()));
                let a = stress_tangent(|df| {
                    let elastic = match &measures {
                        Some(m) => {
                            NodalAveraging::element_differential(&model, &f, m.excess(tet, t), df)
                        }
                        None => model.first_piola_differential(&f, df),
                    };
                    elastic + extra(t, &f, df)
                });
                let k = element_matrix(&rest, &if project { project_positive(a) } else { a });
                self.add_element(tet, &k, &body.pinned);
            }
            // The coupling is positive semi-definite (K > 0), so it needs no projection.
            if let Some(averaging) = averaging {
                averaging.for_each_coupling(&model, fvm, body.positions(), |gradient, weight| {
                    self.add_outer(gradient, weight, &body.pinned)
                });
            }
        });
        for (node, &pinned) in body.pinned.iter().enumerate() {
            for i in 0..3 {
                let e = self.entry(node, i, node, i);
                if pinned {
                    self.values[e] = 1.0;
                } else if let Some(diagonal) = diagonal {
                    self.values[e] += diagonal[node];
                }
            }
        }
    }

    /// Adds the 3 x 3 block `block` (N/m) to the diagonal block of a free node.
    pub(crate) fn add_node_block(&mut self, node: usize, block: &DMat3) {
        for j in 0..3 {
            for i in j..3 {
                let e = self.entry(node, i, node, j);
                self.values[e] += block.col(j)[i];
            }
        }
    }

    /// Adds `weight g gᵀ` (N/m), `g` given per node, skipping pinned nodes.
    fn add_outer(&mut self, gradient: &[(u32, DVec3)], weight: f64, pinned: &[bool]) {
        for &(b, gb) in gradient {
            for &(a, ga) in gradient {
                self.add_pair_block(a as usize, b as usize, pinned, |i, j| {
                    weight * ga[i] * gb[j]
                });
            }
        }
    }

    fn add_element(&mut self, tet: &[u32; 4], k: &[[f64; 12]; 12], pinned: &[bool]) {
        for (cb, &b) in tet.iter().enumerate() {
            for (ca, &a) in tet.iter().enumerate() {
                self.add_pair_block(a as usize, b as usize, pinned, |i, j| {
                    k[3 * ca + i][3 * cb + j]
                });
            }
        }
    }

    /// Adds `value(i, j)` to the entries (row `3a + i`, column `3b + j`) of the lower triangle,
    /// unless either node is pinned or the block lies above the diagonal.
    fn add_pair_block(
        &mut self,
        a: usize,
        b: usize,
        pinned: &[bool],
        value: impl Fn(usize, usize) -> f64,
    ) {
        if a < b || pinned[a] || pinned[b] {
            return;
        }
        for j in 0..3 {
            for i in 0..3 {
                if a == b && i < j {
                    continue;
                }
                let e = self.entry(a, i, b, j);
                self.values[e] += value(i, j);
            }
        }
    }

    /// Number of rows (and columns): three per node.
    pub(crate) fn dofs(&self) -> usize {
        self.dofs
    }

    /// The 3 x 3 diagonal block of node `node` (N/m).
    pub(crate) fn diagonal_block(&self, node: usize) -> DMat3 {
        let mut block = [0.0; 9];
        for j in 0..3 {
            for i in j..3 {
                let value = self.values[self.entry(node, i, node, j)];
                block[3 * j + i] = value;
                block[3 * i + j] = value;
            }
        }
        DMat3::from_cols_array(&block)
    }

    /// `out = K x` for the assembled symmetric matrix `K` (from its lower triangle), `x` and
    /// `out` flat with three entries per node.
    pub(crate) fn multiply_into(&self, x: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for column in 0..self.dofs {
            let (start, end) = (self.col_ptr[column], self.col_ptr[column + 1]);
            // The first entry of every column is its diagonal.
            let xc = x[column];
            let mut transposed = self.values[start] * xc;
            for k in start + 1..end {
                let row = self.row_idx[k];
                let value = self.values[k];
                out[row] += value * xc;
                transposed += value * x[row];
            }
            out[column] += transposed;
        }
    }

    /// The product of the assembled symmetric matrix with a per-node vector field.
    #[cfg(test)]
    pub(crate) fn multiply(&self, v: &[DVec3]) -> Vec<DVec3> {
        let x: Vec<f64> = v.iter().flat_map(|v| v.to_array()).collect();
        let mut out = vec![0.0; self.dofs];
        self.multiply_into(&x, &mut out);
        out.chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect()
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

/// Adds to `lower_neighbours` (per node `b`, the nodes `a >= b` it is coupled with, ascending)
/// every pair of nodes within each group of `groups`.
fn couple_all_pairs<'a>(
    lower_neighbours: &mut [Vec<u32>],
    groups: impl Iterator<Item = &'a [u32]>,
) {
    for group in groups {
        for &a in group {
            for &b in group {
                if a > b {
                    lower_neighbours[b as usize].push(a);
                }
            }
        }
    }
    for list in lower_neighbours.iter_mut() {
        list.sort_unstable();
        list.dedup();
    }
}

/// The Cholesky factor of an assembled matrix.
pub(crate) fn factorize(
    stiffness: &mut Stiffness,
    iteration: usize,
) -> Result<Llt<usize, f64>, Error> {
    let indefinite = Error::IndefiniteStiffness { iteration };
    let symbolic = match &stiffness.symbolic {
        Some(symbolic) => symbolic.clone(),
        None => {
            let pattern = stiffness.as_faer().symbolic();
            let symbolic =
                SymbolicLlt::try_new(pattern, Side::Lower).map_err(|_| indefinite.clone())?;
            stiffness.symbolic = Some(symbolic.clone());
            symbolic
        }
    };
    Llt::try_new_with_symbolic(symbolic, stiffness.as_faer(), Side::Lower).map_err(|_| indefinite)
}

/// Solves `K u = rhs` for per-node vectors.
pub(crate) fn solve(factor: &Llt<usize, f64>, rhs: &[DVec3]) -> Vec<DVec3> {
    let mut x = Col::<f64>::from_fn(3 * rhs.len(), |i| rhs[i / 3][i % 3]);
    factor.solve_in_place(x.as_mat_mut());
    (0..rhs.len())
        .map(|n| DVec3::new(x[3 * n], x[3 * n + 1], x[3 * n + 2]))
        .collect()
}

/// The stress tangent `∂P/∂F` of `differential` (a stress differential `dF -> dP`) at one `F`,
/// built column by column from the nine unit changes of `F`.
pub(crate) fn stress_tangent(differential: impl Fn(&DMat3) -> DMat3) -> StressTangent {
    let mut tangent = StressTangent::zeros();
    for column in 0..9 {
        let mut df = [0.0; 9];
        df[column] = 1.0;
        let dp = differential(&DMat3::from_cols_array(&df)).to_cols_array();
        for (row, value) in dp.iter().enumerate() {
            tangent[(row, column)] = *value;
        }
    }
    tangent
}

/// The nearest positive semi-definite matrix to the symmetric part of `a` (negative eigenvalues
/// set to zero).
pub(crate) fn project_positive(a: StressTangent) -> StressTangent {
    let symmetric = (a + a.transpose()) * 0.5;
    let eigen = na::SymmetricEigen::new(symmetric);
    if eigen.eigenvalues.iter().all(|&l| l >= 0.0) {
        return symmetric;
    }
    let clamped = eigen.eigenvalues.map(|l| l.max(0.0));
    eigen.eigenvectors * StressTangent::from_diagonal(&clamped) * eigen.eigenvectors.transpose()
}

/// `K_e[3a+i][3b+j] = V Σ A[(i,c),(j,d)] g_a,c g_b,d` (N/m): the element matrix of a stress
/// tangent, `g_a` the gradient of node `a`'s shape function.
fn element_matrix(rest: &TetRest, tangent: &StressTangent) -> [[f64; 12]; 12] {
    let gradients = rest.shape_gradients();
    // G: 9 x 12, vec(dF) = G dx with dF_rc = Σ_b dx_b,r g_b,c at row 3c + r.
    let mut map = na::SMatrix::<f64, 9, 12>::zeros();
    for (b, gradient) in gradients.iter().enumerate() {
        for r in 0..3 {
            for c in 0..3 {
                map[(3 * c + r, 3 * b + r)] = gradient[c];
            }
        }
    }
    let k = map.transpose() * tangent * map * rest.volume;
    std::array::from_fn(|row| std::array::from_fn(|col| k[(row, col)]))
}
