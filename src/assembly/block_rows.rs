//! The assembled symmetric tangent as full rows of 3 x 3 blocks, one row per node, for the
//! conjugate gradient's products `(K x)_a = Σ_b K_ab x_b` (N for x in m).
//!
//! A [`Stiffness`] holds its lower triangle in compressed columns, whose product scatters into
//! rows other columns also write; these rows hold both triangles (each off-diagonal block twice,
//! `K_ab = K_baᵀ`), so that each node's row is summed by one thread, in a fixed order, and the
//! product is the same whatever the number of threads. The pattern (the rows' block columns and
//! where each entry lies in the lower triangle) is made once per pattern; each assembly's values
//! are gathered into it.

use super::Stiffness;
use crate::parallel;
use rapier3d::glamx::DMat3;

/// Nodes per chunk of a product: a chunk's rows are summed on one thread.
pub(crate) const ROWS_PER_CHUNK: usize = 512;

/// Block entries per chunk of [`BlockRows::gather_from`].
const GATHERED_PER_CHUNK: usize = 9 * 4096;

/// Both triangles of a symmetric matrix in rows of 3 x 3 blocks.
#[derive(Debug, Clone)]
pub(crate) struct BlockRows {
    /// Per node, where its blocks start in `columns` (one past the last node: their count).
    row_start: Vec<usize>,
    /// The block column (node) of each block, ascending within a row.
    columns: Vec<u32>,
    /// Per node, the index of its diagonal block.
    diagonal: Vec<usize>,
    /// Per block entry (nine per block, column-major), its index in the lower triangle's values.
    gather: Vec<usize>,
    /// Per block, its nine entries (N/m), column-major.
    values: Vec<f64>,
}

impl BlockRows {
    /// The pattern of `stiffness`'s matrix, values zero.
    pub(crate) fn new(stiffness: &Stiffness) -> Self {
        let lower = &stiffness.lower_neighbours;
        let n = lower.len();
        // The nodes below each node coupled with it (`b < a` with `a` in `b`'s list), ascending.
        let mut upper: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (b, list) in lower.iter().enumerate() {
            for &a in &list[1..] {
                upper[a as usize].push(b as u32);
            }
        }
        let mut rows = Self {
            row_start: Vec::with_capacity(n + 1),
            columns: Vec::new(),
            diagonal: Vec::with_capacity(n),
            gather: Vec::new(),
            values: Vec::new(),
        };
        for a in 0..n {
            rows.row_start.push(rows.columns.len());
            for &b in upper[a].iter().chain(&lower[a]) {
                let b = b as usize;
                if b == a {
                    rows.diagonal.push(rows.columns.len());
                }
                rows.columns.push(b as u32);
                for j in 0..3 {
                    for i in 0..3 {
                        // Entry (3a + i, 3b + j), read from the lower triangle.
                        let at = match a.cmp(&b) {
                            std::cmp::Ordering::Greater => stiffness.entry(a, i, b, j),
                            std::cmp::Ordering::Less => stiffness.entry(b, j, a, i),
                            std::cmp::Ordering::Equal => stiffness.entry(a, i.max(j), a, i.min(j)),
                        };
                        rows.gather.push(at);
                    }
                }
            }
        }
        rows.row_start.push(rows.columns.len());
        rows.values = vec![0.0; rows.gather.len()];
        rows
    }

    /// Takes the values of `lower` (the lower triangle's, in the pattern this was made from).
    pub(crate) fn gather_from(&mut self, lower: &[f64]) {
        let gather = &self.gather;
        parallel::map_chunks(&mut self.values, GATHERED_PER_CHUNK, |index, values| {
            let start = index * GATHERED_PER_CHUNK;
            for (value, &at) in values.iter_mut().zip(&gather[start..]) {
                *value = lower[at];
            }
        });
    }

    /// The diagonal block of `node` (N/m).
    pub(crate) fn diagonal_block(&self, node: usize) -> DMat3 {
        let at = 9 * self.diagonal[node];
        DMat3::from_cols_slice(&self.values[at..at + 9])
    }

    /// `out = K x` (flat, three entries per node), and per chunk of [`ROWS_PER_CHUNK`] nodes the
    /// partial sum of `x · out` over its rows, in order.
    pub(crate) fn multiply_into(&self, x: &[f64], out: &mut [f64]) -> Vec<f64> {
        parallel::map_chunks(out, 3 * ROWS_PER_CHUNK, |index, out| {
            let first = index * ROWS_PER_CHUNK;
            let mut x_dot_out = 0.0;
            for (row, out) in out.chunks_exact_mut(3).enumerate() {
                let a = first + row;
                let mut sum = [0.0; 3];
                for block in self.row_start[a]..self.row_start[a + 1] {
                    let b = 3 * self.columns[block] as usize;
                    let v = &self.values[9 * block..9 * block + 9];
                    let (x0, x1, x2) = (x[b], x[b + 1], x[b + 2]);
                    for (i, s) in sum.iter_mut().enumerate() {
                        *s += v[i] * x0 + v[3 + i] * x1 + v[6 + i] * x2;
                    }
                }
                out.copy_from_slice(&sum);
                x_dot_out += x[3 * a] * sum[0] + x[3 * a + 1] * sum[1] + x[3 * a + 2] * sum[2];
            }
            x_dot_out
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::deformed_block;
    use crate::prelude::*;

    /// A deformed, partly pinned 3 x 2 x 2 cube's tangent.
    fn assembled() -> (DeformableBody, Stiffness) {
        let body = deformed_block([3, 2, 2], [0, 5, 17], (7, 0.01));
        let mut stiffness = Stiffness::new(&body);
        let diagonal = vec![3.0e3; body.node_count()];
        stiffness.assemble(&body, Some(&diagonal), false, |_, _| [DMat3::ZERO; 9]);
        (body, stiffness)
    }

    /// The rows' product equals the lower triangle's (to round-off: the sums are grouped
    /// differently), and the partial sums add up to `x · K x`.
    #[test]
    fn product_matches_the_lower_triangle() {
        let (body, stiffness) = assembled();
        let mut rows = BlockRows::new(&stiffness);
        rows.gather_from(&stiffness.values);
        let x: Vec<f64> = (0..3 * body.node_count())
            .map(|i| (i as f64 * 0.71).sin())
            .collect();
        let (mut expected, mut out) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        stiffness.multiply_into(&x, &mut expected);
        let partial = rows.multiply_into(&x, &mut out);
        let scale = expected.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (e, o) in expected.iter().zip(&out) {
            assert!((e - o).abs() <= 1e-12 * scale, "{e} against {o}");
        }
        let quadratic: f64 = x.iter().zip(&expected).map(|(x, k)| x * k).sum();
        let summed: f64 = partial.iter().sum();
        assert!((quadratic - summed).abs() <= 1e-12 * quadratic.abs());
        for node in 0..body.node_count() {
            assert_eq!(rows.diagonal_block(node), stiffness.diagonal_block(node));
        }
    }
}
