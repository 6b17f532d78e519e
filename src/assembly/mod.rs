//! Assembly of sparse symmetric tangent matrices (N/m) over a body's mesh: the lower triangle in
//! compressed columns, pinned nodes' rows and columns replaced by the identity.
//!
//! An integration point of weight `w` contributes `w Gᵀ A G`, where `A = ∂P/∂F` is the 9 x 9
//! tangent of the stress with respect to the deformation gradient and `G` maps its element's node
//! displacements to `dF` (4 nodes for linear tetrahedra, 10 or 27 for quadratic elements).
//! On request `A` is first projected onto its positive semi-definite part, so that `K_e` has no
//! negative eigenvalue and Newton steps always descend (the stress tangents of St.
//! Venant–Kirchhoff and Neo-Hookean are indefinite under compression); the projection stiffens
//! the rotational directions of a stressed element, so exact tangents are used where they exist.

mod block_rows;
mod cholesky;
mod element_tangents;
mod joint;

pub(crate) use block_rows::{BlockRows, ROWS_PER_CHUNK};
pub(crate) use cholesky::{Factor, SymbolicFactor};

use crate::Error;
use crate::body::DeformableBody;
use crate::element::deformation_gradient;
use crate::fvm::NodalAveraging;
use crate::material::{HyperelasticModel, with_hyperelastic_model};
use crate::stencil::Stencil;
use element_tangents::ElementTangents;
use faer::Col;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
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
    /// The node pairs `[a, b]` (`a > b`) the pattern couples beyond the mesh's, sorted.
    extra_pairs: Vec<[u32; 2]>,
    /// The symbolic Cholesky factorization (fill-reducing ordering and elimination tree) of the
    /// pattern, computed at the first factorization and reused by every later one.
    symbolic: Option<SymbolicFactor>,
    /// The matrix in full block rows for the conjugate gradient's products, its pattern made at
    /// the first [`Stiffness::block_rows`] and its values gathered at each.
    block_rows: Option<BlockRows>,
    /// Scratch of [`Stiffness::add_element_tangents`]: per chunk of elements, their dense
    /// tangents.
    element_tangents: Vec<ElementTangents>,
}

impl Stiffness {
    /// The pattern of `body`'s mesh, values zero: nodes sharing a tetrahedron, nodes a load
    /// couples (a cable's neighbours on its path), and with nodal averaging also nodes sharing a
    /// neighbour (the patches' coupling).
    pub(crate) fn new(body: &DeformableBody) -> Self {
        let n = body.node_count();
        let mut lower_neighbours: Vec<Vec<u32>> = (0..n as u32).map(|b| vec![b]).collect();
        let load_pairs = body.load_pairs();
        let pairs = load_pairs.iter().map(|pair| &pair[..]);
        couple_all_pairs(
            &mut lower_neighbours,
            body.elements.element_nodes().chain(pairs),
        );
        if body.elements.nodal_averaging().is_some() {
            // A node's patch: itself and every node sharing a tetrahedron with it.
            let mut patches: Vec<Vec<u32>> = lower_neighbours.clone();
            for (b, list) in lower_neighbours.iter().enumerate() {
                for &a in &list[1..] {
                    patches[a as usize].push(b as u32);
                }
            }
            couple_all_pairs(&mut lower_neighbours, patches.iter().map(|p| &p[..]));
        }
        Self::with_neighbours(lower_neighbours)
    }

    /// The pattern of `lower_neighbours` (per node `b`, itself first, then its neighbours
    /// `a > b`, ascending), values zero.
    fn with_neighbours(lower_neighbours: Vec<Vec<u32>>) -> Self {
        let n = lower_neighbours.len();
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
            extra_pairs: Vec::new(),
            symbolic: None,
            block_rows: None,
            element_tangents: Vec::new(),
        }
    }

    /// Whether the pattern holds the blocks coupling nodes `a` and `b`.
    pub(crate) fn couples(&self, a: u32, b: u32) -> bool {
        let (high, low) = if a > b { (a, b) } else { (b, a) };
        self.lower_neighbours[low as usize]
            .binary_search(&high)
            .is_ok()
    }

    /// The pattern widened by the node pairs `extra` (`[a, b]`, `a > b`: nodes a constraint
    /// couples beyond the mesh's, such as a self-contact's node and triangle), values zero; its
    /// symbolic factorization is made anew at the first factorization. `None` for a pair naming
    /// a node the pattern does not have, or not ordered.
    pub(crate) fn widened(&self, extra: &[[u32; 2]]) -> Option<Self> {
        let n = self.lower_neighbours.len();
        if extra.iter().any(|&[a, b]| a <= b || a as usize >= n) {
            return None;
        }
        let mut lower_neighbours = self.lower_neighbours.clone();
        for &[a, b] in extra {
            lower_neighbours[b as usize].push(a);
        }
        for list in &mut lower_neighbours {
            // Each node stays first in its own list (its neighbours are all greater).
            list.sort_unstable();
            list.dedup();
        }
        let mut extra_pairs = self.extra_pairs.clone();
        extra_pairs.extend_from_slice(extra);
        extra_pairs.sort_unstable();
        extra_pairs.dedup();
        Some(Self {
            extra_pairs,
            ..Self::with_neighbours(lower_neighbours)
        })
    }

    /// The node pairs the pattern couples beyond the mesh's (see [`Stiffness::widened`]).
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn extra_pairs(&self) -> &[[u32; 2]] {
        &self.extra_pairs
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
    /// integration point (see [`crate::element`]) `w ∇N_aᵀ A ∇N_b` with `A` the stress tangent of
    /// the elastic stress differential plus `extra(point, F)` (further stress differentials, Pa,
    /// for the nine unit changes of `F` in column-major order: a further tangent's columns),
    /// projected to be positive semi-definite if `project`; the coupling of nodal averaging
    /// if the body uses it; the Hessians of its follower loads' potentials ([`crate::load`]; a
    /// chamber's pressure not if `project`); and `diagonal[n] I` on each free node.
    pub(crate) fn assemble(
        &mut self,
        body: &DeformableBody,
        diagonal: Option<&[f64]>,
        project: bool,
        extra: impl Fn(usize, &DMat3) -> [DMat3; 9] + Sync,
    ) {
        self.values.fill(0.0);
        let x = body.positions();
        with_hyperelastic_model!(body.material, |model| {
            let averaging = body.elements.nodal_averaging();
            let measures = averaging.map(|(a, fvm)| a.measures(&model, fvm, x));
            let excesses = body.elements.volumetric_excesses(&model, x);
            let changes = unit_changes();
            let point_tangent = |point: usize, nodes: &[u32], gradients: &[DVec3]| {
                let f = deformation_gradient(nodes, gradients, x);
                let excess = match (&measures, &excesses) {
                    (Some(m), _) => Some(m.excess(nodes, point)),
                    (_, Some(excesses)) => Some(excesses[point]),
                    _ => None,
                };
                let elastic = match excess {
                    Some(excess) => changes
                        .map(|df| NodalAveraging::element_differential(&model, &f, excess, &df)),
                    None => model.first_piola_differentials(&f, &changes),
                };
                let extra = extra(point, &f);
                let a = tangent_from_columns(std::array::from_fn(|c| elastic[c] + extra[c]));
                if project { project_positive(a) } else { a }
            };
            self.add_element_tangents(&body.elements, &body.pinned, point_tangent);
            // The coupling is positive semi-definite (K > 0), so it needs no projection.
            if let Some((averaging, fvm)) = averaging {
                averaging.for_each_coupling(&model, fvm, x, |gradient, weight| {
                    self.add_outer(gradient, weight, &body.pinned)
                });
            }
            body.elements
                .for_each_volumetric_coupling(&model, x, |gradient, weight| {
                    self.add_outer(gradient, weight, &body.pinned)
                });
        });
        crate::load::add_follower_tangents(body, self, project);
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

    /// Adds the tangent `w_a w_b block` (N/m) of a term acting on a point that moves with the
    /// nodes of `at` (a node, or an embedded vertex with its element's nodes), skipping pinned
    /// nodes.
    pub(crate) fn add_stencil_block(&mut self, at: Stencil, block: &DMat3, pinned: &[bool]) {
        for (&b, wb) in at.nodes.iter().zip(at.weights) {
            for (&a, wa) in at.nodes.iter().zip(at.weights) {
                let weight = wa * wb;
                self.add_pair_block(a as usize, b as usize, pinned, |i, j| {
                    weight * block.col(j)[i]
                });
            }
        }
    }

    /// Adds the block `K_ab = block` (N/m) and its transpose `K_ba` (for `a == b`, the
    /// symmetric `block` once), skipping pinned nodes.
    pub(crate) fn add_pair(&mut self, a: usize, b: usize, block: &DMat3, pinned: &[bool]) {
        if a >= b {
            self.add_pair_block(a, b, pinned, |i, j| block.col(j)[i]);
        } else {
            self.add_pair_block(b, a, pinned, |i, j| block.col(i)[j]);
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
        if a == b {
            for j in 0..3 {
                let start = self.col_ptr[3 * b + j];
                for i in j..3 {
                    self.values[start + i - j] += value(i, j);
                }
            }
            return;
        }
        // One search for the block; its nine entries follow arithmetically (see `entry`).
        let k = self.lower_neighbours[b]
            .binary_search(&(a as u32))
            .expect("the pattern contains every pair of coupled nodes");
        for j in 0..3 {
            let first = self.col_ptr[3 * b + j] + (3 - j) + 3 * (k - 1);
            for i in 0..3 {
                self.values[first + i] += value(i, j);
            }
        }
    }

    /// The 3 x 3 diagonal block of node `node` (N/m).
    #[cfg(test)]
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
    #[cfg(test)]
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

    /// The assembled matrix in full block rows (see [`BlockRows`]).
    pub(crate) fn block_rows(&mut self) -> &BlockRows {
        let mut rows = self
            .block_rows
            .take()
            .unwrap_or_else(|| BlockRows::new(self));
        rows.gather_from(&self.values);
        self.block_rows.insert(rows)
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
pub(crate) fn factorize(stiffness: &mut Stiffness, iteration: usize) -> Result<Factor, Error> {
    let indefinite = Error::IndefiniteStiffness { iteration };
    let symbolic = match &stiffness.symbolic {
        Some(symbolic) => symbolic.clone(),
        None => {
            let pattern = stiffness.as_faer().symbolic();
            let symbolic = SymbolicFactor::try_new(pattern).ok_or_else(|| indefinite.clone())?;
            stiffness.symbolic = Some(symbolic.clone());
            symbolic
        }
    };
    Factor::try_new(symbolic, stiffness.as_faer()).ok_or(indefinite)
}

/// Solves `K u_k = rhs_k` for every column `rhs_k` (per-node vectors) in one pass over the
/// factor.
pub(crate) fn solve_columns(factor: &Factor, columns: &[Vec<DVec3>]) -> Vec<Vec<DVec3>> {
    let Some(n) = columns.first().map(Vec::len) else {
        return Vec::new();
    };
    let mut x = faer::Mat::<f64>::from_fn(3 * n, columns.len(), |i, k| columns[k][i / 3][i % 3]);
    factor.solve_in_place(x.as_mut());
    (0..columns.len())
        .map(|k| {
            (0..n)
                .map(|a| DVec3::new(x[(3 * a, k)], x[(3 * a + 1, k)], x[(3 * a + 2, k)]))
                .collect()
        })
        .collect()
}

/// Solves `K u = rhs` for per-node vectors.
pub(crate) fn solve(factor: &Factor, rhs: &[DVec3]) -> Vec<DVec3> {
    let mut x = Col::<f64>::from_fn(3 * rhs.len(), |i| rhs[i / 3][i % 3]);
    factor.solve_in_place(x.as_mat_mut());
    (0..rhs.len())
        .map(|n| DVec3::new(x[3 * n], x[3 * n + 1], x[3 * n + 2]))
        .collect()
}

/// The nine unit changes of `F`, in the column-major order of a [`StressTangent`]'s columns.
pub(crate) fn unit_changes() -> [DMat3; 9] {
    std::array::from_fn(|column| {
        let mut df = [0.0; 9];
        df[column] = 1.0;
        DMat3::from_cols_array(&df)
    })
}

/// The stress tangent `∂P/∂F` whose columns are the stress differentials `dps` (Pa) of the nine
/// [`unit_changes`].
fn tangent_from_columns(dps: [DMat3; 9]) -> StressTangent {
    let mut tangent = StressTangent::zeros();
    for (column, dp) in dps.iter().enumerate() {
        for (row, value) in dp.to_cols_array().iter().enumerate() {
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

/// Checks, by central differences along a fixed direction, that a body's forces are minus the
/// gradient of its elastic energy (to 1e-6 relative) and its assembled tangent minus the
/// gradient of the forces (to 1e-5 of the largest `K d`); `label` names the case in failures.
/// A step of 1e-6 m on metre-sized bodies keeps truncation (~1e-12) and round-off (~1e-10)
/// well inside these bounds while any missing term fails them.
#[cfg(test)]
pub(crate) fn assert_forces_and_tangent_match_energy(body: &mut DeformableBody, label: &str) {
    let shift = |body: &mut DeformableBody, direction: &[DVec3], step: f64| {
        for (x, d) in body.positions_mut().iter_mut().zip(direction) {
            *x += *d * step;
        }
    };
    let n = body.node_count();
    let direction: Vec<DVec3> = (0..n)
        .map(|i| DVec3::new((i % 3) as f64 - 1.0, (i % 5) as f64 * 0.5 - 1.0, 0.7))
        .collect();
    let h = 1e-6;
    let f0 = body.internal_forces().to_vec();
    shift(body, &direction, h);
    let (e_plus, f_plus) = (body.elastic_energy(), body.internal_forces().to_vec());
    shift(body, &direction, -2.0 * h);
    let (e_minus, f_minus) = (body.elastic_energy(), body.internal_forces().to_vec());
    shift(body, &direction, h);
    let slope = (e_plus - e_minus) / (2.0 * h);
    let work: f64 = f0.iter().zip(&direction).map(|(f, d)| f.dot(*d)).sum();
    assert!(
        (slope + work).abs() <= 1e-6 * work.abs().max(1.0),
        "{label}: dE/ds {slope} vs -f·d {}",
        -work
    );
    let mut stiffness = Stiffness::new(body);
    stiffness.assemble(body, None, false, |_, _| [DMat3::ZERO; 9]);
    let k_d = stiffness.multiply(&direction);
    let scale = k_d.iter().map(|v| v.length()).fold(0.0, f64::max);
    for node in 0..n {
        let difference = -(f_plus[node] - f_minus[node]) / (2.0 * h);
        assert!(
            (difference - k_d[node]).length() <= 1e-5 * scale,
            "{label}, node {node}: K d {} vs -df/ds {difference}",
            k_d[node]
        );
    }
}

/// Moves every node of `body` by a pseudo-random offset of up to `amplitude` (m) per axis, the
/// same for the same `seed`.
#[cfg(test)]
pub(crate) fn perturb_positions(body: &mut DeformableBody, mut seed: u64, amplitude: f64) {
    for x in body.positions_mut() {
        for i in 0..3 {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            x[i] += amplitude * ((seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0);
        }
    }
}

/// A 20 cm rubber block (stable Neo-Hookean, E = 1e5 Pa, ν = 0.3) of `cells`, its nodes `pinned`,
/// every node moved as [`perturb_positions`] moves them with `seed` and `amplitude` (m).
#[cfg(test)]
pub(crate) fn deformed_block(
    cells: [usize; 3],
    pinned: [u32; 3],
    (seed, amplitude): (u64, f64),
) -> DeformableBody {
    use crate::prelude::*;
    let mesh = mesh::cuboid(DVec3::splat(0.1), cells).expect("a mesh");
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).expect("a material");
    let mut body = DeformableBodyBuilder::new(mesh, material)
        .pinned_nodes(pinned)
        .build()
        .expect("a body");
    perturb_positions(&mut body, seed, amplitude);
    body
}
