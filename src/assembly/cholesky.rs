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
//! The matrix's lower triangle in the fill-reducing order, which faer's numeric factorization
//! would permute anew each time, is laid out once per pattern and gathered into
//! ([`PermutedPattern`]): the same matrix, so the same factor, to the bit. faer sets every
//! value of `L` itself, so a factor dropped leaves its values' storage to the next
//! factorization of its pattern ([`Analysis::spare`]) instead of a zeroed allocation each time.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::{
    factorize_supernodal_numeric_llt, factorize_supernodal_numeric_llt_scratch,
};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    factorize_symbolic_cholesky,
};
use faer::sparse::utils::permute_self_adjoint_to_unsorted;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use std::sync::{Arc, Mutex};

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
pub(crate) struct SymbolicFactor(Arc<Analysis>);

/// faer's analysis of a pattern and, when supernodal, the lower triangle of a matrix of that
/// pattern in the fill-reducing order, as the numeric factorization reads it.
#[derive(Debug)]
struct Analysis {
    cholesky: SymbolicCholesky<usize>,
    permuted: Option<PermutedPattern>,
    /// The values' storage of a dropped supernodal factor of this pattern, for the next one
    /// (faer's numeric factorization zeroes and fills it): a Newton iteration's factor replaces
    /// the last one, and the storage passes from one to the next. At most one is kept, so a
    /// pattern holds at most one factor's values beyond the factors alive.
    spare: Mutex<Option<Vec<f64>>>,
}

impl Analysis {
    /// Storage for a factor's `len` values: the spare one if there is one of that length,
    /// else a new one.
    fn values(&self, len: usize) -> Vec<f64> {
        let spare = self.spare.lock().ok().and_then(|mut spare| spare.take());
        spare
            .filter(|values| values.len() == len)
            .unwrap_or_else(|| vec![0.0; len])
    }
}

/// The lower triangle of the permuted matrix `P A Pᵀ` (column pointers and row indices, rows
/// unsorted within a column) and, for each of its entries, the index of the value of `A` it
/// holds. faer's own numeric factorization permutes `A` anew at every factorization (a count,
/// a prefix sum and a scatter over its entries: a tenth of the factorizations' instructions in
/// the game scene); the permutation depends on the pattern alone, so it is found once, by
/// permuting the values' own indices, and each factorization gathers its values through it:
/// the same matrix, entry for entry, so the same factor.
#[derive(Debug)]
struct PermutedPattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    source: Vec<usize>,
}

impl PermutedPattern {
    /// The permutation `perm` of the lower triangle of `pattern`; `None` if the scratch space
    /// cannot be allocated.
    fn new(pattern: SymbolicSparseColMatRef<'_, usize>, perm: PermRef<'_, usize>) -> Option<Self> {
        let (n, entries) = (pattern.nrows(), pattern.row_idx().len());
        // Indices below 2⁵³ are exact in f64.
        let indices: Vec<f64> = (0..entries).map(|k| k as f64).collect();
        let (mut values, mut col_ptr, mut row_idx) =
            (vec![0.0; entries], vec![0; n + 1], vec![0; entries]);
        let mut buffer = MemBuffer::try_new(StackReq::new::<usize>(n)).ok()?;
        permute_self_adjoint_to_unsorted(
            &mut values,
            &mut col_ptr,
            &mut row_idx,
            SparseColMatRef::new(pattern, &indices),
            perm,
            Side::Lower,
            Side::Lower,
            MemStack::new(&mut buffer),
        );
        let kept = col_ptr[n];
        row_idx.truncate(kept);
        let source = values[..kept].iter().map(|&k| k as usize).collect();
        Some(Self {
            col_ptr,
            row_idx,
            source,
        })
    }

    /// `P A Pᵀ`'s lower triangle for the values of `matrix` (of the analysed pattern).
    fn gather(&self, matrix: SparseColMatRef<'_, usize, f64>) -> Vec<f64> {
        let values = matrix.val();
        self.source.iter().map(|&k| values[k]).collect()
    }
}

impl SymbolicFactor {
    /// The analysis of the symmetric `pattern`, of which the lower triangle is read; `None` if
    /// faer cannot make it (out of memory, index overflow).
    pub(crate) fn try_new(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Self> {
        let cholesky = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            Default::default(),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .ok()?;
        let permuted = match (cholesky.raw(), cholesky.perm()) {
            (SymbolicCholeskyRaw::Simplicial(_), _) => None,
            (SymbolicCholeskyRaw::Supernodal(_), Some(perm)) => {
                Some(PermutedPattern::new(pattern, perm)?)
            }
            (SymbolicCholeskyRaw::Supernodal(_), None) => {
                let identity: Vec<usize> = (0..pattern.nrows()).collect();
                let perm = PermRef::new_checked(&identity, &identity, pattern.nrows());
                Some(PermutedPattern::new(pattern, perm)?)
            }
        };
        Some(Self(Arc::new(Analysis {
            cholesky,
            permuted,
            spare: Mutex::new(None),
        })))
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
        let Analysis {
            cholesky, permuted, ..
        } = &*symbolic.0;
        let n = cholesky.nrows();
        let par = parallelism(n);
        let (SymbolicCholeskyRaw::Supernodal(supernodal), Some(permuted)) =
            (cholesky.raw(), permuted)
        else {
            let mut values = vec![0.0; cholesky.len_val()];
            // faer keeps its simplicial factorization for the tiniest patterns (a single
            // unknown) even when told to force the supernodal one: its own path for them.
            let scratch = cholesky.factorize_numeric_llt_scratch::<f64>(par, Default::default());
            let mut buffer = MemBuffer::try_new(scratch).ok()?;
            let stack = MemStack::new(&mut buffer);
            let regularization = Default::default();
            let params = Default::default();
            let lower = Side::Lower;
            let factored = cholesky.factorize_numeric_llt(
                &mut values,
                matrix,
                lower,
                regularization,
                par,
                stack,
                params,
            );
            factored.ok()?;
            return Some(Self { symbolic, values });
        };
        let gathered = permuted.gather(matrix);
        let pattern = SymbolicSparseColMatRef::new_unsorted_checked(
            n,
            n,
            &permuted.col_ptr,
            None,
            &permuted.row_idx,
        );
        let scratch = factorize_supernodal_numeric_llt_scratch::<usize, f64>(
            supernodal,
            par,
            Default::default(),
        );
        let mut buffer = MemBuffer::try_new(scratch).ok()?;
        let mut values = symbolic.0.values(cholesky.len_val());
        factorize_supernodal_numeric_llt(
            &mut values,
            SparseColMatRef::new(pattern, &gathered),
            Default::default(),
            supernodal,
            par,
            MemStack::new(&mut buffer),
            Default::default(),
        )
        .ok()?;
        Some(Self { symbolic, values })
    }

    /// Solves `K X = B` in place for the columns of `rhs` (`B` in, `X` out).
    pub(crate) fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let inner = &self.symbolic.0.cholesky;
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

impl Drop for Factor {
    /// Leaves a supernodal factor's values' storage to the next factorization of its pattern.
    fn drop(&mut self) {
        let analysis = &self.symbolic.0;
        if analysis.permuted.is_some()
            && let Ok(mut spare) = analysis.spare.lock()
        {
            *spare = Some(std::mem::take(&mut self.values));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// A symmetric positive definite matrix of `n` unknowns, each coupled with the next three
    /// (both triangles stored), diagonally dominant, every entry distinct.
    fn banded(n: usize) -> SparseColMat<usize, f64> {
        let mut entries = Vec::new();
        for i in 0..n {
            entries.push(Triplet::new(i, i, 10.0 + 0.01 * i as f64));
            for j in i + 1..(i + 4).min(n) {
                let value = -1.0 - 1e-5 * (i * n + j) as f64;
                entries.push(Triplet::new(i, j, value));
                entries.push(Triplet::new(j, i, value));
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &entries).unwrap()
    }

    /// faer's own factor of `matrix` with the analysis `symbolic`, its values.
    fn faers_own(symbolic: &SymbolicFactor, matrix: &SparseColMat<usize, f64>) -> Vec<f64> {
        let inner = &symbolic.0.cholesky;
        let mut theirs = vec![0.0; inner.len_val()];
        let scratch = inner.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let mut buffer = MemBuffer::new(scratch);
        (inner.factorize_numeric_llt(
            &mut theirs,
            matrix.as_ref(),
            Side::Lower,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut buffer),
            Default::default(),
        ))
        .unwrap();
        theirs
    }

    #[test]
    fn a_factor_through_the_kept_permutation_is_faers_own_to_the_bit() {
        let matrix = banded(60);
        let symbolic = SymbolicFactor::try_new(matrix.symbolic()).unwrap();
        let inner = &symbolic.0.cholesky;
        assert!(matches!(inner.raw(), SymbolicCholeskyRaw::Supernodal(_)));
        assert!(inner.perm().is_some());
        let ours = Factor::try_new(symbolic.clone(), matrix.as_ref()).unwrap();
        assert_eq!(ours.values, faers_own(&symbolic, &matrix));
    }

    #[test]
    fn a_factor_made_in_a_dropped_factors_storage_is_faers_own_to_the_bit() {
        // The second matrix has the first's pattern and other values: its factor, made in the
        // storage the first factor left when dropped (holding the first's values), must hold
        // none of them.
        let first = banded(60);
        let symbolic = SymbolicFactor::try_new(first.symbolic()).unwrap();
        let dropped = Factor::try_new(symbolic.clone(), first.as_ref()).unwrap();
        let storage = dropped.values.as_ptr();
        drop(dropped);
        let mut second = first.clone();
        for (k, value) in second.val_mut().iter_mut().enumerate() {
            *value *= 1.0 + 1e-3 * (k % 7) as f64;
        }
        let ours = Factor::try_new(symbolic.clone(), second.as_ref()).unwrap();
        assert_eq!(ours.values.as_ptr(), storage, "the storage was not reused");
        assert_eq!(ours.values, faers_own(&symbolic, &second));
        assert_ne!(ours.values, faers_own(&symbolic, &first));
    }

    #[test]
    fn a_single_unknown_is_factored_by_faers_own_path() {
        // `[2] x = [4]`: x = 2, to the rounding of dividing twice by the factor √2 (a few units in
        // the last place).
        let matrix = SparseColMat::try_new_from_triplets(1, 1, &[Triplet::new(0, 0, 2.0)]).unwrap();
        let symbolic = SymbolicFactor::try_new(matrix.symbolic()).unwrap();
        assert!(matches!(
            symbolic.0.cholesky.raw(),
            SymbolicCholeskyRaw::Simplicial(_)
        ));
        let factor = Factor::try_new(symbolic, matrix.as_ref()).unwrap();
        let mut rhs = faer::Mat::<f64>::from_fn(1, 1, |_, _| 4.0);
        factor.solve_in_place(rhs.as_mut());
        assert!(
            (rhs[(0, 0)] - 2.0).abs() <= 4.0 * f64::EPSILON,
            "{}",
            rhs[(0, 0)]
        );
    }
}
