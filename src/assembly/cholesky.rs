//! Sparse Cholesky factors `K = L Lᵀ` of assembled tangents (faer's supernodal factorization
//! after its fill-reducing ordering), with the parallelism chosen by size.
//!
//! The factorization is supernodal at every size. faer would pick its simplicial one for the
//! tangent of a small body, whose factor has fewer entries but is computed entry by entry: a
//! cuboid of 4³ and 5³ cells of five tetrahedra (375 and 648 unknowns) took 0.285 and 0.866 ms
//! per numeric factorization simplicial against 0.132 and 0.310 ms supernodal (one thread, the
//! same pattern); from 6³ cells faer picks the supernodal one itself (1 029 unknowns: 0.61 ms
//! against 2.05 ms simplicial; 24 000 unknowns: 0.22 s against 4.6 s).
//! faer's own high-level solvers split every factorization and solve across rayon's threads;
//! for a body of about a thousand unknowns that coordination cost more than the arithmetic (the
//! showcase's gel ball alone, 993 unknowns: 19–20 ms per frame on two threads against 14 ms on
//! one). Below [`PARALLEL_UNKNOWNS`] unknowns a factor is computed and applied on the calling
//! thread, where its arithmetic is the same whatever the number of threads.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use std::sync::Arc;

/// The unknowns from which a factor's numeric factorization and solves run on rayon's threads
/// (with the `parallel` feature).
#[cfg(feature = "parallel")]
pub(crate) const PARALLEL_UNKNOWNS: usize = 30_000;

/// The parallelism for a factor of `unknowns` unknowns.
fn parallelism(unknowns: usize) -> Par {
    #[cfg(feature = "parallel")]
    if unknowns >= PARALLEL_UNKNOWNS {
        return Par::rayon(0);
    }
    let _ = unknowns;
    Par::Seq
}

/// The symbolic analysis of a pattern: its fill-reducing ordering and the factor's structure,
/// shared by every factor of a matrix with that pattern.
#[derive(Debug, Clone)]
pub(crate) struct SymbolicFactor(Arc<SymbolicCholesky<usize>>);

impl SymbolicFactor {
    /// The analysis of the symmetric `pattern`, of which the lower triangle is read; `None` if
    /// faer cannot make it (out of memory, index overflow).
    pub(crate) fn try_new(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Self> {
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            Default::default(),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .ok()?;
        Some(Self(Arc::new(symbolic)))
    }
}

/// The numeric factor `L` of a symmetric positive definite matrix.
#[derive(Debug, Clone)]
pub(crate) struct Factor {
    symbolic: SymbolicFactor,
    values: Vec<f64>,
}

impl Factor {
    /// The factor of `matrix` (lower triangle read), whose pattern `symbolic` analysed; `None`
    /// if the matrix is not numerically positive definite.
    pub(crate) fn try_new(
        symbolic: SymbolicFactor,
        matrix: SparseColMatRef<'_, usize, f64>,
    ) -> Option<Self> {
        let inner = &symbolic.0;
        let par = parallelism(inner.nrows());
        let mut values = vec![0.0; inner.len_val()];
        let scratch = inner.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buffer = MemBuffer::try_new(scratch).ok()?;
        inner
            .factorize_numeric_llt(
                &mut values,
                matrix,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .ok()?;
        Some(Self { symbolic, values })
    }

    /// Solves `K X = B` in place for the columns of `rhs` (`B` in, `X` out).
    pub(crate) fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let inner = &self.symbolic.0;
        let par = parallelism(inner.nrows());
        let mut buffer = MemBuffer::new(inner.solve_in_place_scratch::<f64>(rhs.ncols(), par));
        LltRef::new(inner, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut buffer),
        );
    }
}
