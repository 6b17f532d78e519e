//! The block-Jacobi preconditioned conjugate gradient on `K u = b` (`K` symmetric, N/m; `b` N;
//! `u` m), started from `u = 0`:
//!
//! `r₀ = b, z₀ = P r₀, p₀ = z₀`; then `α = rᵀz / pᵀK p`, `u += α p`, `r -= α K p`,
//! `z = P r`, `β = r'ᵀz' / rᵀz`, `p = z + β p`, until `‖r‖ <= tolerance ‖b‖`,
//! with `P` the inverses of the nodes' 3 x 3 diagonal blocks.
//!
//! Every pass over the vectors (the product, the updates, the sums) is cut into fixed chunks of
//! nodes worked on rayon's threads with the `parallel` feature and summed in chunk order
//! (see [`crate::parallel`]): the iterates do not depend on the number of threads.

use crate::assembly::{BlockRows, ROWS_PER_CHUNK};
use crate::material::is_positive_definite;
use crate::parallel::{self, map_chunk_pairs, map_chunks};
use rapier3d::glamx::{DMat3, DVec3};

/// Entries per chunk of the vector passes: the product's chunk of nodes, three per node.
const CHUNK: usize = 3 * ROWS_PER_CHUNK;

/// The end of a conjugate gradient solve.
pub(super) enum CgOutcome {
    /// An iterate (flat, 3 entries per node), the iterations taken and whether the tolerance was
    /// met.
    Solved {
        x: Vec<f64>,
        iterations: usize,
        converged: bool,
    },
    /// A search direction (or a diagonal block) of zero or negative curvature after this many
    /// iterations: the matrix is not positive definite.
    NegativeCurvature { iterations: usize },
}

/// The preconditioned conjugate gradient on `matrix u = b` from `u = 0`, until
/// `‖b - K u‖ <= tolerance ‖b‖` or `max_iterations`.
pub(super) fn conjugate_gradient(
    matrix: &BlockRows,
    b: &[f64],
    tolerance: f64,
    max_iterations: usize,
) -> CgOutcome {
    let dofs = b.len();
    let mut x = vec![0.0; dofs];
    let Some(preconditioner) = block_jacobi(matrix, dofs / 3) else {
        return CgOutcome::NegativeCurvature { iterations: 0 };
    };
    let target = tolerance * parallel::dot(b, b, CHUNK).sqrt();
    if target == 0.0 {
        return CgOutcome::Solved {
            x,
            iterations: 0,
            converged: true,
        };
    }
    let mut r = b.to_vec();
    let mut z = vec![0.0; dofs];
    let mut rz = precondition(&preconditioner, &r, &mut z);
    let mut p = z.clone();
    let mut q = vec![0.0; dofs];
    for iteration in 1..=max_iterations {
        let curvature: f64 = matrix.multiply_into(&p, &mut q).iter().sum();
        if curvature.is_nan() || curvature <= 0.0 {
            return CgOutcome::NegativeCurvature {
                iterations: iteration,
            };
        }
        let alpha = rz / curvature;
        let r_norm = advance((&mut x, &mut r), alpha, (&p, &q)).sqrt();
        if r_norm <= target {
            return CgOutcome::Solved {
                x,
                iterations: iteration,
                converged: true,
            };
        }
        let next = precondition(&preconditioner, &r, &mut z);
        let beta = next / rz;
        rz = next;
        map_chunks(&mut p, CHUNK, |index, p| {
            for (p, z) in p.iter_mut().zip(&z[index * CHUNK..]) {
                *p = z + beta * *p;
            }
        });
    }
    CgOutcome::Solved {
        x,
        iterations: max_iterations,
        converged: false,
    }
}

/// `x += α p`, `r -= α q`; returns `rᵀr`.
fn advance((x, r): (&mut [f64], &mut [f64]), alpha: f64, (p, q): (&[f64], &[f64])) -> f64 {
    let partial = map_chunk_pairs((x, r), CHUNK, |index, x, r| {
        let start = index * CHUNK;
        let (p, q) = (&p[start..], &q[start..]);
        let mut r_r = 0.0;
        for (k, (x, r)) in x.iter_mut().zip(r.iter_mut()).enumerate() {
            *x += alpha * p[k];
            *r -= alpha * q[k];
            r_r += *r * *r;
        }
        r_r
    });
    partial.iter().sum()
}

/// The inverses of the nodes' 3 x 3 diagonal blocks (m/N), or `None` if one is not positive
/// definite (then neither is the matrix).
fn block_jacobi(matrix: &BlockRows, nodes: usize) -> Option<Vec<DMat3>> {
    (0..nodes)
        .map(|node| {
            let a = matrix.diagonal_block(node);
            is_positive_definite(&a).then(|| a.inverse())
        })
        .collect()
}

/// `z = P r` for the block-Jacobi preconditioner `P`; returns `rᵀz`.
fn precondition(preconditioner: &[DMat3], r: &[f64], z: &mut [f64]) -> f64 {
    let partial = map_chunks(z, CHUNK, |index, z| {
        let first = index * ROWS_PER_CHUNK;
        let mut r_z = 0.0;
        for (node, z) in z.chunks_exact_mut(3).enumerate() {
            let r = &r[3 * (first + node)..][..3];
            let r = DVec3::new(r[0], r[1], r[2]);
            let v = preconditioner[first + node] * r;
            z.copy_from_slice(&v.to_array());
            r_z += r.dot(v);
        }
        r_z
    });
    partial.iter().sum()
}
