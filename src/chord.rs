//! The chord method: Newton iterations of the implicit integrator that solve with the Cholesky
//! factorization of an earlier tangent instead of assembling and factoring the current one.
//!
//! Any symmetric positive definite matrix `K̃` turns the out-of-balance force `r` into a descent
//! direction `K̃⁻¹ r` of the step's incremental potential, so the line search and the tolerance
//! on the out-of-balance force are those of exact Newton: a step converges to the same tolerance,
//! only by another route. Where the tangent changes little between iterations and steps (the
//! linear model, small strains, a fixed step length, no new contact) such an iteration costs an
//! out-of-balance force and two triangular solves instead of an assembly and a factorization. It
//! converges linearly, cutting the out-of-balance force by about `‖I - K K̃⁻¹‖` per iteration.
//!
//! The rule, for systems solved by the direct method: an iteration reuses the last factorization
//! when it was made for the same effective step `ĥ` (the inertia `M/ĥ²` dominates the matrix),
//! reuse has not failed in this step, and the iterations Newton has left could still reach the
//! tolerance at the contraction [`MAX_CONTRACTION`] with one exact iteration to spare (so a
//! small `max_newton_iterations` keeps exact Newton). A reused iteration only takes the full
//! step or half of it; it fails when neither lowers the potential or when it does not bring the
//! out-of-balance force to the tolerance or below [`MAX_CONTRACTION`] times its value. The rest
//! of the step then uses exact tangents, and reuse pauses for the body's next 1, 2, 4, … up to
//! [`MAX_PAUSE`] implicit substeps (doubling with each consecutive failing substep), so a
//! strongly nonlinear motion wastes at most one solve every few substeps.
//!
//! A factorization is kept with the low-rank correction its direction took in beside it
//! ([`KeptCorrection`]: the dynamic rigid bodies' response, `(K − U Q Uᵀ)⁻¹` by the Woodbury
//! identity), and a reused iteration takes that same correction in: the matrix it solves with is
//! then the whole Newton matrix of the earlier iteration. Taking in the current `U` instead mixes
//! an earlier `K` with a current `U`: a light rigid body pressed into a soft one by stiff
//! penalties makes `K` and `U Q Uᵀ` two large terms that nearly cancel (the body follows the
//! surface), so the slight change of the penalties' pieces between iterations is not cancelled
//! and the iteration contracts poorly (a 27 g box resting on a 625-tetrahedron block: a median
//! contraction of 0.26 per reused iteration, most failing the rule, so the block assembled and
//! factored its tangent at nearly every substep). Where the coupling's geometry changes instead
//! (a heavy body swinging on a rope turns its arms), the current `U` serves better: a reused
//! iteration that does not contract with the kept correction is taken again from the same start
//! with the current coupling before it counts as failing.

use crate::assembly::Factor;
#[cfg(feature = "serde-serialize")]
use crate::assembly::Stiffness;
use crate::newton::dot;
use rapier3d::glamx::DVec3;
use rapier3d::na::{DMatrix, DVector};

/// A reused factorization must bring the out-of-balance force to at most this fraction of its
/// previous value per iteration (dimensionless). At 0.1, a tolerance of 1e-6 is reached within
/// about six reused iterations, each a small fraction of the cost of an exact one.
pub const MAX_CONTRACTION: f64 = 0.1;

/// The longest pause of reuse after failures, in implicit substeps of the body.
pub const MAX_PAUSE: u32 = 16;

/// Whether `remaining` Newton iterations leave room for reuse when the out-of-balance force must
/// still fall by the factor `reduction` (its value over the tolerance's): enough iterations at
/// [`MAX_CONTRACTION`] to get there, and one more.
pub(crate) fn within_budget(reduction: f64, remaining: usize) -> bool {
    let needed = (reduction.ln() / MAX_CONTRACTION.recip().ln())
        .ceil()
        .max(1.0);
    (remaining as f64) > needed
}

/// A low-rank correction `d ↦ d + Z S (Uᵀ d)` of a direction `d = K⁻¹ r` (m per node) solved
/// with a kept factorization of `K`: with `Z = K⁻¹ U` it gives `(K − U S' Uᵀ)⁻¹ r` for the
/// `S = (I − S' Uᵀ Z)⁻¹ S'` the corrected system was made with (Woodbury). The columns are
/// per-node vectors over the system's nodes.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct KeptCorrection {
    /// The columns of `U` (N/m per node).
    pub(crate) u: Vec<Vec<DVec3>>,
    /// The columns of `Z = K⁻¹ U` (dimensionless per node).
    pub(crate) z: Vec<Vec<DVec3>>,
    /// `S` (m/N), `m x m` for `m` columns, column-major.
    pub(crate) s: Vec<f64>,
}

impl KeptCorrection {
    /// `d + Z S (Uᵀ d)` for the direction `d` (m per node) solved with the kept factorization, or
    /// `None` when the columns do not fit it or the result is not finite.
    pub(crate) fn apply(&self, direction: &[DVec3]) -> Option<Vec<DVec3>> {
        let fits = |columns: &[Vec<DVec3>]| columns.iter().all(|c| c.len() == direction.len());
        let m = self.u.len();
        if !fits(&self.u) || !fits(&self.z) || self.z.len() != m || self.s.len() != m * m {
            return None;
        }
        let u_d = DVector::from_fn(m, |i, _| dot(&self.u[i], direction));
        let weights = DMatrix::from_column_slice(m, m, &self.s) * u_d;
        let mut corrected = direction.to_vec();
        for (z, weight) in self.z.iter().zip(weights.iter()) {
            for (d, z) in corrected.iter_mut().zip(z) {
                *d += *z * *weight;
            }
        }
        corrected.iter().all(|d| d.is_finite()).then_some(corrected)
    }
}

/// Whether a reused iteration that cut the out-of-balance force from `before` to `after` (N;
/// zero when it met the tolerance) contracted enough: to [`MAX_CONTRACTION`] times `before`.
pub(crate) fn contracts(before: f64, after: f64) -> bool {
    after <= MAX_CONTRACTION * before
}

/// The factorization kept for reuse and the pause after failures; one per body.
///
/// Serialized (feature `serde-serialize`) as the matrix the kept factorization was made of and
/// the pause; read back, the matrix is factored again at the body's next implicit step, which
/// gives the same factor (the same pattern, ordering and arithmetic).
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(into = "ChordRecord", from = "ChordRecord")
)]
pub(crate) struct Chord {
    /// The last factorization of the implicit Newton system and the effective step `ĥ` (s) whose
    /// inertia it holds.
    factor: Option<(Factor, f64)>,
    /// The correction the kept factorization's direction took in, if any.
    correction: Option<KeptCorrection>,
    /// The matrix the kept factorization was made of, kept for serialization and factored
    /// again after reading back.
    #[cfg(feature = "serde-serialize")]
    factored: Option<FactoredMatrix>,
    /// Steps still to take without reuse.
    pause: u32,
    /// The pause the next failing step sets.
    next_pause: u32,
    /// Whether the current step is paused.
    paused: bool,
    /// Whether a reused iteration failed in the current step.
    failed_this_step: bool,
}

impl Chord {
    /// Starts a step: counts down the pause.
    pub(crate) fn start_step(&mut self) {
        self.paused = self.pause > 0;
        self.pause = self.pause.saturating_sub(1);
        self.failed_this_step = false;
    }

    /// The factorization an iteration of a step of effective length `h` (s) may reuse, with the
    /// correction its direction took in, if the rule allows one (`within_budget`: see
    /// [`within_budget`]).
    pub(crate) fn factor_for(
        &self,
        h: f64,
        within_budget: bool,
    ) -> Option<(&Factor, Option<&KeptCorrection>)> {
        if self.paused || self.failed_this_step || !within_budget {
            return None;
        }
        self.factor
            .as_ref()
            .filter(|(_, step)| *step == h)
            .map(|(factor, _)| (factor, self.correction.as_ref()))
    }

    /// Keeps a fresh factorization made for effective step `h` (s), with the `correction` its
    /// direction took in.
    pub(crate) fn keep(&mut self, factor: Factor, h: f64, correction: Option<KeptCorrection>) {
        self.factor = Some((factor, h));
        self.correction = correction;
    }

    /// Remembers the matrix the factorization just kept was made of, `stiffness`, for
    /// serialization.
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn remember(&mut self, stiffness: &Stiffness) {
        if let Some((_, h)) = self.factor {
            self.factored = Some(FactoredMatrix {
                values: stiffness.values.clone(),
                extra_pairs: stiffness.extra_pairs().to_vec(),
                h,
                correction: self.correction.clone(),
            });
        }
    }

    /// After reading back: factors the kept matrix of `body` again, on the pattern it was made
    /// on; a matrix that does not fit the body is dropped.
    #[cfg(feature = "serde-serialize")]
    pub(crate) fn refactor(&mut self, body: &crate::body::DeformableBody) {
        if self.factor.is_some() {
            return;
        }
        let Some(matrix) = self.factored.take() else {
            return;
        };
        let Some(mut stiffness) = Stiffness::new(body).widened(&matrix.extra_pairs) else {
            return;
        };
        if matrix.values.len() != stiffness.values.len() {
            return;
        }
        stiffness.values.clone_from(&matrix.values);
        if let Ok(factor) = crate::assembly::factorize(&mut stiffness, 0) {
            self.factor = Some((factor, matrix.h));
            self.correction.clone_from(&matrix.correction);
            self.factored = Some(matrix);
        }
    }

    /// Records a reused iteration that cut the out-of-balance force from `before` to `after`
    /// (N; zero when it met the tolerance): a failure unless it [`contracts`].
    pub(crate) fn record(&mut self, before: f64, after: f64) {
        if contracts(before, after) {
            return;
        }
        if !self.failed_this_step {
            self.failed_this_step = true;
            self.pause = self.next_pause.max(1);
            self.next_pause = (2 * self.pause).min(MAX_PAUSE);
        }
    }

    /// Ends a step: a step whose reused iterations all succeeded resets the pause's growth.
    pub(crate) fn end_step(&mut self, reused: bool) {
        if reused && !self.failed_this_step {
            self.next_pause = 0;
        }
    }
}

/// The matrix a kept factorization was made of: its values (compressed-column order, N/m), the
/// node pairs its pattern couples beyond the mesh's, its effective step `ĥ` (s), and the
/// correction kept with it.
#[cfg(feature = "serde-serialize")]
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct FactoredMatrix {
    values: Vec<f64>,
    extra_pairs: Vec<[u32; 2]>,
    h: f64,
    #[serde(default)]
    correction: Option<KeptCorrection>,
}

/// What a [`Chord`] is written as: the matrix of its kept factorization and its pause.
#[cfg(feature = "serde-serialize")]
#[derive(serde::Serialize, serde::Deserialize)]
pub(crate) struct ChordRecord {
    factored: Option<FactoredMatrix>,
    pause: u32,
    next_pause: u32,
}

#[cfg(feature = "serde-serialize")]
impl From<Chord> for ChordRecord {
    fn from(chord: Chord) -> Self {
        Self {
            factored: chord.factored,
            pause: chord.pause,
            next_pause: chord.next_pause,
        }
    }
}

#[cfg(feature = "serde-serialize")]
impl From<ChordRecord> for Chord {
    fn from(record: ChordRecord) -> Self {
        Self {
            factored: record.factored,
            pause: record.pause.min(MAX_PAUSE),
            next_pause: record.next_pause.min(MAX_PAUSE),
            ..Self::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::SymbolicFactor;
    use faer::sparse::SparseColMat;

    /// The factorization of the 1 x 1 matrix `[2]`.
    fn factor() -> Factor {
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(
            1,
            1,
            &[faer::sparse::Triplet::new(0, 0, 2.0)],
        )
        .unwrap();
        let symbolic = SymbolicFactor::try_new(matrix.symbolic()).unwrap();
        Factor::try_new(symbolic, matrix.as_ref()).unwrap()
    }

    /// Within the iteration budget.
    const ALLOWED: bool = true;

    /// Per-node vectors as one vector of their components, and back.
    fn flat(nodes: &[DVec3]) -> DVector<f64> {
        DVector::from_iterator(3 * nodes.len(), nodes.iter().flat_map(|v| v.to_array()))
    }
    fn nodes(flat: &DVector<f64>) -> Vec<DVec3> {
        (flat.as_slice().chunks_exact(3))
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect()
    }

    #[test]
    fn a_kept_correction_solves_the_corrected_system_of_its_factorization() {
        // Woodbury: with `Z = K⁻¹ U` and `S = (I − S' Uᵀ Z)⁻¹ S'`, `d + Z S Uᵀ d` for
        // `d = K⁻¹ r` is `(K − U S' Uᵀ)⁻¹ r`, compared with a dense solve of that system
        // (two nodes, two columns; agreement to 1e-12, round-off of well-conditioned 6 x 6
        // solves).
        let k = DMatrix::from_fn(6, 6, |i, j| {
            if i == j {
                4.0 + i as f64
            } else {
                1.0 / (1.0 + (i + j) as f64)
            }
        });
        let u_columns = [
            vec![DVec3::new(1.0, 0.5, -0.2), DVec3::new(0.3, -1.0, 0.4)],
            vec![DVec3::new(-0.1, 0.2, 0.7), DVec3::new(0.6, 0.1, -0.5)],
        ];
        let u = DMatrix::from_columns(&[flat(&u_columns[0]), flat(&u_columns[1])]);
        let s_prime = DMatrix::from_row_slice(2, 2, &[0.8, 0.1, 0.1, 0.5]);
        let k_lu = k.clone().lu();
        let z = k_lu.solve(&u).unwrap();
        let s = (DMatrix::identity(2, 2) - &s_prime * u.transpose() * &z)
            .lu()
            .solve(&s_prime)
            .unwrap();
        let correction = KeptCorrection {
            u: u_columns.to_vec(),
            z: (0..2).map(|c| nodes(&z.column(c).into_owned())).collect(),
            s: s.as_slice().to_vec(),
        };
        let r = DVector::from_row_slice(&[1.0, -2.0, 0.5, 0.3, 1.5, -0.7]);
        let corrected = correction.apply(&nodes(&k_lu.solve(&r).unwrap())).unwrap();
        let expected = (&k - &u * &s_prime * u.transpose()).lu().solve(&r).unwrap();
        let error = (flat(&corrected) - &expected).norm();
        assert!(error <= 1e-12 * expected.norm(), "error {error}");
        // A direction over other nodes than the columns' is not corrected.
        assert!(correction.apply(&[DVec3::ONE; 3]).is_none());
    }

    #[test]
    fn a_factorization_is_reused_only_for_its_own_step_and_within_budget() {
        let mut chord = Chord::default();
        chord.start_step();
        assert!(chord.factor_for(0.01, ALLOWED).is_none());
        chord.keep(factor(), 0.01, None);
        assert!(chord.factor_for(0.01, ALLOWED).is_some());
        assert!(chord.factor_for(0.02, ALLOWED).is_none());
        assert!(chord.factor_for(0.01, !ALLOWED).is_none());
    }

    #[test]
    fn the_budget_leaves_room_for_contraction_and_one_exact_iteration() {
        // A reduction of 5e3 takes four iterations at 0.1: five are needed, four are not enough.
        assert!(within_budget(5e3, 5));
        assert!(!within_budget(5e3, 4));
        // The last iteration (or a single one) is always exact.
        assert!(!within_budget(2.0, 1));
        assert!(within_budget(2.0, 2));
    }

    #[test]
    fn failures_pause_reuse_for_doubling_numbers_of_steps() {
        let mut chord = Chord::default();
        chord.keep(factor(), 0.01, None);
        // Steps on which reuse was offered, over 40 steps that each fail when offered.
        let mut offered = Vec::new();
        for step in 0..40 {
            chord.start_step();
            let reused = chord.factor_for(0.01, ALLOWED).is_some();
            if reused {
                offered.push(step);
                chord.record(1.0, 0.5);
                assert!(chord.factor_for(0.01, ALLOWED).is_none());
            }
            chord.end_step(reused);
        }
        // Pauses of 1, 2, 4, 8, then 16 steps.
        assert_eq!(offered, [0, 2, 5, 10, 19, 36]);
        // A step whose reuse contracts enough resets the growth: the next failure pauses 1 step.
        let mut chord = Chord::default();
        chord.keep(factor(), 0.01, None);
        let mut offered = Vec::new();
        for (step, after) in [0.5, 0.5, 0.01, 0.5, 0.5, 0.5].into_iter().enumerate() {
            chord.start_step();
            let reused = chord.factor_for(0.01, ALLOWED).is_some();
            if reused {
                offered.push(step);
                chord.record(1.0, after);
            }
            chord.end_step(reused);
        }
        // Fails at 0 (pause 1), succeeds at 2, fails at 3 (pause 1 again, not 2), offered at 5.
        assert_eq!(offered, [0, 2, 3, 5]);
    }
}
