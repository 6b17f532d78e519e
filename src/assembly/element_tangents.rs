//! The elements' dense tangents `K_e = Σ_points w ∇N_aᵀ A ∇N_b` (N/m; `w` a point's rest volume,
//! m³; `∇N` its shape-function gradients, 1/m; `A = ∂P/∂F` its stress tangent, Pa), computed on
//! rayon's threads (with the `parallel` feature) and added into the sparse matrix on the calling
//! thread.
//!
//! The elements are taken in batches: each batch is cut into chunks of consecutive elements,
//! each chunk's dense tangents are computed on one thread into its own scratch, then the batch's
//! tangents are added into the matrix by one thread per range of node columns (each range a
//! disjoint part of the values, the ranges sharing out the band of nodes the batch touches),
//! element by element in order. Each element's tangent is the same arithmetic whatever the
//! thread, and each entry receives its terms in element order, so the matrix is the same to the
//! bit whatever the number of threads. A batch bounds the scratch's memory (a few MB).

use super::{Stiffness, StressTangent};
use crate::element::Elements;
use crate::parallel;
use rapier3d::glamx::DVec3;
use rapier3d::na;

/// Dense tangent entries a chunk holds at most (its elements' `(3n)²` each, `n` nodes per
/// element): 512 linear tetrahedra, 11 quadratic hexahedra.
const CHUNK_ENTRIES: usize = 512 * 144;

/// Chunks per batch.
const CHUNKS_PER_BATCH: usize = 16;

/// One chunk's elements: their nodes and their dense tangents.
#[derive(Debug, Clone, Default)]
pub(super) struct ElementTangents {
    /// The nodes of each element, one after the other.
    nodes: Vec<u32>,
    /// Each element's dense `3n x 3n` tangent (N/m), column-major in its local node order.
    blocks: Vec<f64>,
    /// Nodes per element of the chunk (zero while empty).
    per_element: usize,
    /// Scratch of [`ElementTangents::add_point`]: per node of the point, `A ∇N_b`.
    stress_maps: Vec<na::SMatrix<f64, 9, 3>>,
}

impl ElementTangents {
    /// Forgets the chunk's elements.
    fn clear(&mut self) {
        self.nodes.clear();
        self.blocks.clear();
        self.per_element = 0;
    }

    /// Adds one integration point's `w ∇N_aᵀ A ∇N_b` to its element's dense tangent, for the
    /// pairs `a >= b` (the lower triangle of the global matrix); a point whose nodes differ from
    /// the last point's starts the next element.
    pub(super) fn add_point(
        &mut self,
        nodes: &[u32],
        gradients: &[DVec3],
        weight: f64,
        tangent: &StressTangent,
    ) {
        let n = nodes.len();
        let rows = 3 * n;
        if self.per_element != n || self.nodes[self.nodes.len() - n..] != *nodes {
            self.per_element = n;
            self.nodes.extend_from_slice(nodes);
            self.blocks.resize(self.blocks.len() + rows * rows, 0.0);
        }
        let block_start = self.blocks.len() - rows * rows;
        let block = &mut self.blocks[block_start..];
        // A g_b: per node, the 9 x 3 map from its displacement to dP.
        self.stress_maps.clear();
        self.stress_maps.extend(gradients.iter().map(|g| {
            na::SMatrix::<f64, 9, 3>::from_fn(|row, j| {
                (0..3).map(|d| tangent[(row, 3 * d + j)] * g[d]).sum()
            })
        }));
        for (cb, &b) in nodes.iter().enumerate() {
            let map = &self.stress_maps[cb];
            for (ca, &a) in nodes.iter().enumerate() {
                if a < b {
                    continue;
                }
                let ga = gradients[ca] * weight;
                for j in 0..3 {
                    let column = &mut block[rows * (3 * cb + j) + 3 * ca..][..3];
                    for (i, entry) in column.iter_mut().enumerate() {
                        *entry += (0..3).map(|c| ga[c] * map[(3 * c + i, j)]).sum::<f64>();
                    }
                }
            }
        }
    }

    /// Adds the blocks `(a, b)`, `a >= b`, of every element's tangent whose column node `b` lies
    /// in `columns`, skipping pinned nodes; element by element, in order.
    fn scatter_into(&self, pattern: &Stiffness, columns: &mut ColumnRange<'_>, pinned: &[bool]) {
        let n = self.per_element;
        if n == 0 {
            return;
        }
        let rows = 3 * n;
        for (nodes, block) in self
            .nodes
            .chunks_exact(n)
            .zip(self.blocks.chunks_exact(rows * rows))
        {
            for (cb, &b) in nodes.iter().enumerate() {
                let b = b as usize;
                if !columns.nodes.contains(&b) || pinned[b] {
                    continue;
                }
                for (ca, &a) in nodes.iter().enumerate() {
                    let a = a as usize;
                    if a >= b && !pinned[a] {
                        columns.add_block(pattern, (a, b), |j| {
                            &block[rows * (3 * cb + j) + 3 * ca..][..3]
                        });
                    }
                }
            }
        }
    }
}

/// The lower triangle's values in the columns of a range of nodes: the part of the matrix one
/// thread adds to.
struct ColumnRange<'a> {
    nodes: std::ops::Range<usize>,
    /// Index in the matrix's values of the first entry of `values`.
    offset: usize,
    values: &'a mut [f64],
}

impl ColumnRange<'_> {
    /// Adds the block of node rows `a` and column `b` (`a >= b`, `b` in the range), whose column
    /// `j` holds its rows `i` in `column(j)[i]`; of a diagonal block, the lower triangle.
    fn add_block<'b>(
        &mut self,
        pattern: &Stiffness,
        (a, b): (usize, usize),
        column: impl Fn(usize) -> &'b [f64],
    ) {
        if a == b {
            for j in 0..3 {
                let start = pattern.col_ptr[3 * b + j] - self.offset;
                for i in j..3 {
                    self.values[start + i - j] += column(j)[i];
                }
            }
            return;
        }
        let k = pattern.lower_neighbours[b]
            .binary_search(&(a as u32))
            .expect("the pattern contains every pair of coupled nodes");
        for j in 0..3 {
            let first = pattern.col_ptr[3 * b + j] + (3 - j) + 3 * (k - 1) - self.offset;
            for (value, added) in self.values[first..first + 3].iter_mut().zip(column(j)) {
                *value += added;
            }
        }
    }
}

/// The columns of the nodes `span` cut into `parts` ranges of about as many nodes, each with its
/// values (`values` all the matrix's).
fn column_ranges<'a>(
    pattern: &Stiffness,
    values: &'a mut [f64],
    span: std::ops::Range<usize>,
    parts: usize,
) -> Vec<ColumnRange<'a>> {
    let per_part = span.len().div_ceil(parts.max(1)).max(1);
    let mut ranges = Vec::with_capacity(parts);
    let start = pattern.col_ptr[3 * span.start];
    let mut rest = &mut values[start..];
    let mut first = span.start;
    while first < span.end {
        let end = (first + per_part).min(span.end);
        let (offset, stop) = (pattern.col_ptr[3 * first], pattern.col_ptr[3 * end]);
        let (part, after) = std::mem::take(&mut rest).split_at_mut(stop - offset);
        ranges.push(ColumnRange {
            nodes: first..end,
            offset,
            values: part,
        });
        rest = after;
        first = end;
    }
    ranges
}

/// The nodes from the lowest to the highest of the elements of `chunks` (empty if none): a
/// batch of consecutive elements touches a narrow band of the nodes, which its column ranges
/// then share out among the threads.
fn node_span(chunks: &[ElementTangents]) -> std::ops::Range<usize> {
    let mut nodes = chunks.iter().flat_map(|chunk| chunk.nodes.iter().copied());
    let Some(first) = nodes.next() else {
        return 0..0;
    };
    let (low, high) = nodes.fold((first, first), |(lo, hi), n| (lo.min(n), hi.max(n)));
    low as usize..high as usize + 1
}

impl Stiffness {
    /// Adds the dense tangent of every element of `elements` (nodes `pinned` skipped), each point's
    /// stress tangent given by `point_tangent(point, nodes, gradients)` (Pa); the points of a
    /// chunk of elements are visited on one thread, in order.
    pub(super) fn add_element_tangents(
        &mut self,
        elements: &Elements,
        pinned: &[bool],
        point_tangent: impl Fn(usize, &[u32], &[DVec3]) -> StressTangent + Sync,
    ) {
        let count = elements.element_count();
        let nodes = elements.nodes_per_element();
        let per_chunk = (CHUNK_ENTRIES / (9 * nodes * nodes)).max(1);
        let per_batch = per_chunk * CHUNKS_PER_BATCH;
        let mut scratch = std::mem::take(&mut self.element_tangents);
        let mut first = 0;
        while first < count {
            let batch_end = (first + per_batch).min(count);
            let chunks = (batch_end - first).div_ceil(per_chunk);
            if scratch.len() < chunks {
                scratch.resize_with(chunks, ElementTangents::default);
            }
            parallel::map_chunks(&mut scratch[..chunks], 1, |chunk, tangents| {
                let tangents = &mut tangents[0];
                tangents.clear();
                let start = first + chunk * per_chunk;
                let end = (start + per_chunk).min(batch_end);
                elements.for_each_point_in(start..end, |point, nodes, gradients, weight| {
                    let a = point_tangent(point, nodes, gradients);
                    tangents.add_point(nodes, gradients, weight, &a);
                });
            });
            let mut values = std::mem::take(&mut self.values);
            let pattern = &*self;
            let span = node_span(&scratch[..chunks]);
            let mut ranges = column_ranges(pattern, &mut values, span, parallel::threads());
            parallel::for_each(&mut ranges, |columns| {
                for tangents in &scratch[..chunks] {
                    tangents.scatter_into(pattern, columns, pinned);
                }
            });
            self.values = values;
            first = batch_end;
        }
        self.element_tangents = scratch;
    }
}

#[cfg(all(test, feature = "parallel"))]
mod tests {
    use super::*;
    use crate::assembly::deformed_block;
    use rapier3d::glamx::DMat3;

    /// The tangent of a deformed, partly pinned cube of 12 cells a side (8 640 tetrahedra: two
    /// batches, the second partly filled) assembled on a pool of `threads` threads.
    fn assembled_on(threads: usize) -> Vec<f64> {
        let body = deformed_block([12; 3], [0, 100, 1000], (11, 0.005));
        let mut stiffness = Stiffness::new(&body);
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| stiffness.assemble(&body, None, false, |_, _| [DMat3::ZERO; 9]));
        stiffness.values
    }

    #[test]
    fn the_tangent_is_bit_identical_whatever_the_thread_count() {
        // Each batch's column ranges share out the band of nodes it touches; every entry still
        // receives its elements' terms in element order, so the sums are the same to the bit.
        let one = assembled_on(1);
        assert!(one.iter().any(|v| *v != 0.0));
        for threads in [2, 3, 5] {
            assert!(assembled_on(threads) == one, "{threads} threads");
        }
    }
}
