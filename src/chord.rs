//! The chord method: Newton iterations of the implicit integrator that solve with the Cholesky
//! factorization of an earlier tangent instead of assembling and factoring the current one.
//!
//! Any symmetric positive definite matrix `K̃` turns the out-of-balance force `r` into a descent
//! direction `K̃⁻¹ r` of the step's incremental potential, so the line search and the tolerance
//! on the out-of-balance force are those of exact Newton: a step converges to the same tolerance,
//! only by another route. Where the tangent changes little between iterations and steps (the
//! linear model, small strains, a fixed step length, no new contact) such an iteration costs an
//! out-of-balance force and two triangular solves instead of an assembly and a factorization. It
//! converges linearly, cutting the out-of-balance force by about `‖I - K̃⁻¹ K‖` per iteration.
//!
//! The rule, for systems solved by the direct method: an iteration reuses the last factorization
//! when it was made for the same effective step `ĥ` (the inertia `M/ĥ²` dominates the matrix),
//! reuse has not failed in this step, and it is not the last iteration Newton is allowed (which
//! always gets the exact tangent). A reused iteration fails when it does not cut the
//! out-of-balance force below [`MAX_CONTRACTION`] times its value; the rest of the step then uses
//! exact tangents, and reuse pauses for 1, 2, 4, … up to [`MAX_PAUSE`] steps (doubling with each
//! consecutive failing step), so a strongly nonlinear motion wastes at most one solve every few
//! steps.

use faer::sparse::linalg::solvers::Llt;

/// A reused factorization must cut the out-of-balance force at least by this factor per
/// iteration (dimensionless). At 0.1, a tolerance of 1e-6 is reached within about six reused
/// iterations, each a small fraction of the cost of an exact one.
pub const MAX_CONTRACTION: f64 = 0.1;

/// The longest pause, in steps, of reuse after failures.
pub const MAX_PAUSE: u32 = 16;

/// The factorization kept for reuse and the pause after failures; one per body.
#[derive(Debug, Clone, Default)]
pub(crate) struct Chord {
    /// The last factorization of the implicit Newton system and the effective step `ĥ` (s) whose
    /// inertia it holds.
    factor: Option<(Llt<usize, f64>, f64)>,
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

    /// The factorization an iteration of a step of effective length `h` (s) may reuse, if the
    /// rule allows one (`last_iteration`: the last iteration Newton is allowed).
    pub(crate) fn factor_for(&self, h: f64, last_iteration: bool) -> Option<&Llt<usize, f64>> {
        if self.paused || self.failed_this_step || last_iteration {
            return None;
        }
        self.factor
            .as_ref()
            .filter(|(_, step)| *step == h)
            .map(|(factor, _)| factor)
    }

    /// Keeps a fresh factorization made for effective step `h` (s).
    pub(crate) fn keep(&mut self, factor: Llt<usize, f64>, h: f64) {
        self.factor = Some((factor, h));
    }

    /// Records a reused iteration that cut the out-of-balance force from `before` to `after`
    /// (N): a failure if not by [`MAX_CONTRACTION`].
    pub(crate) fn record(&mut self, before: f64, after: f64) {
        if after <= MAX_CONTRACTION * before {
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

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;
    use faer::sparse::SparseColMat;
    use faer::sparse::linalg::solvers::SymbolicLlt;

    /// The factorization of the 1 x 1 matrix `[2]`.
    fn factor() -> Llt<usize, f64> {
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(
            1,
            1,
            &[faer::sparse::Triplet::new(0, 0, 2.0)],
        )
        .unwrap();
        let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).unwrap();
        Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower).unwrap()
    }

    #[test]
    fn a_factorization_is_reused_only_for_its_own_step_and_never_last() {
        let mut chord = Chord::default();
        chord.start_step();
        assert!(chord.factor_for(0.01, false).is_none());
        chord.keep(factor(), 0.01);
        assert!(chord.factor_for(0.01, false).is_some());
        assert!(chord.factor_for(0.02, false).is_none());
        assert!(chord.factor_for(0.01, true).is_none());
    }

    #[test]
    fn failures_pause_reuse_for_doubling_numbers_of_steps() {
        let mut chord = Chord::default();
        chord.keep(factor(), 0.01);
        // Steps on which reuse was offered, over 40 steps that each fail when offered.
        let mut offered = Vec::new();
        for step in 0..40 {
            chord.start_step();
            let reused = chord.factor_for(0.01, false).is_some();
            if reused {
                offered.push(step);
                chord.record(1.0, 0.5);
                assert!(chord.factor_for(0.01, false).is_none());
            }
            chord.end_step(reused);
        }
        // Pauses of 1, 2, 4, 8, then 16 steps.
        assert_eq!(offered, [0, 2, 5, 10, 19, 36]);
        // A step whose reuse contracts enough resets the growth: the next failure pauses 1 step.
        let mut chord = Chord::default();
        chord.keep(factor(), 0.01);
        let mut offered = Vec::new();
        for (step, after) in [0.5, 0.5, 0.01, 0.5, 0.5, 0.5].into_iter().enumerate() {
            chord.start_step();
            let reused = chord.factor_for(0.01, false).is_some();
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
