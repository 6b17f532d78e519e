//! What an implicit frame did: per frame the [`ImplicitReport`] a user reads, per substep the
//! Newton solve's [`Outcome`] it sums and how it [`Stop`]ped.

use crate::Error;

/// What one implicit frame step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitReport {
    /// Substeps taken.
    pub substeps: u32,
    /// Length of each substep (s): the frame step over the substeps.
    pub substep_dt: f64,
    /// The step (s) whose `m/h²` the contacts' penalties and the glue's springs took in the
    /// last substep: its effective step (`substep_dt`, or two thirds of it for a BDF2 step)
    /// times the substeps, whatever their number. The energy those terms hold after the frame
    /// is counted with it.
    pub penalty_step: f64,
    /// Newton iterations over all substeps, those that reused a factorization included.
    pub newton_iterations: usize,
    /// Conjugate gradient iterations over all substeps (zero when every system was solved by
    /// the direct method).
    pub linear_iterations: usize,
    /// Newton iterations that solved with an earlier factorization instead of assembling and
    /// factoring the tangent (see [`ImplicitIntegrator::reuse_factorization`](super::ImplicitIntegrator::reuse_factorization)); included in
    /// `newton_iterations`.
    pub reused_factorizations: usize,
    /// Numeric Cholesky factorizations of the Newton system (two in an iteration whose exact
    /// tangent failed to factor and whose projected tangent was factored; none for systems
    /// solved by the conjugate gradient or with a reused factorization).
    pub factorizations: usize,
    /// Evaluations of the incremental potential's energy over all substeps (the line searches'
    /// and each Newton solve's start), each an integration over the body's elements and a solve
    /// of its dynamic rigid partners' response; of a body stepped with others as one system, the
    /// system's.
    pub energy_evaluations: usize,
    /// Newton iterations whose exact tangent was not positive definite (the Cholesky
    /// factorization failed or the conjugate gradient met negative curvature), so that the
    /// tangent with element stress tangents projected to be positive semi-definite was solved.
    pub projected_tangents: usize,
    /// Largest final relative residual over the substeps.
    pub relative_residual: f64,
    /// Whether every substep met the tolerance.
    pub converged: bool,
    /// Substeps whose Newton solve stopped short of the tolerance on its round-off floor: a
    /// residual that three iterations could not cut by 10 %, or out of iterations, at most 1e-4
    /// relative or within twice what moving every coordinate by one unit in the last place
    /// changes it by (very stiff or nearly incompressible material against a small load, a very
    /// stiff coupling). Not converged, not failed: the frame is taken.
    pub stalled_substeps: u32,
    /// Elements inverted at the end of the frame (volume ratio `J ≤ 0`, see
    /// [`DeformableBody::element_volume_ratios`](crate::body::DeformableBody::element_volume_ratios)).
    pub inverted_elements: usize,
}

/// How a substep's Newton solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stop {
    /// The tolerance was met.
    Converged,
    /// The residual sat on its round-off floor (see [`ImplicitReport::stalled_substeps`]).
    Stalled,
    /// Out of iterations, or no descent left, above the tolerance.
    Failed,
}

/// What one substep's Newton solve did.
pub(super) struct Outcome {
    /// Newton iterations.
    pub(super) iterations: usize,
    /// Conjugate gradient iterations.
    pub(super) linear_iterations: usize,
    /// Iterations that reused an earlier factorization.
    pub(super) reused_factorizations: usize,
    /// Numeric Cholesky factorizations.
    pub(super) factorizations: usize,
    /// Iterations that solved the projected tangent.
    pub(super) projected_tangents: usize,
    /// Evaluations of the energy (set by the caller, which holds the potential).
    pub(super) energy_evaluations: usize,
    /// Final relative residual.
    pub(super) residual: f64,
    /// How the solve ended.
    pub(super) stop: Stop,
    /// The penalty step (s, see [`ImplicitReport::penalty_step`]) of the substep.
    pub(super) penalty_step: f64,
}

impl ImplicitReport {
    /// The report of a frame of `substeps` of `substep_dt` (s) each before any: nothing done,
    /// converged.
    pub(super) fn empty(substeps: u32, substep_dt: f64) -> Self {
        Self {
            substeps,
            substep_dt,
            penalty_step: substep_dt * f64::from(substeps.max(1)),
            newton_iterations: 0,
            linear_iterations: 0,
            reused_factorizations: 0,
            factorizations: 0,
            energy_evaluations: 0,
            projected_tangents: 0,
            relative_residual: 0.0,
            converged: true,
            stalled_substeps: 0,
            inverted_elements: 0,
        }
    }

    /// Counts a substep's Newton solve in the report.
    pub(super) fn add(&mut self, outcome: &Outcome) {
        self.newton_iterations += outcome.iterations;
        self.linear_iterations += outcome.linear_iterations;
        self.reused_factorizations += outcome.reused_factorizations;
        self.factorizations += outcome.factorizations;
        self.projected_tangents += outcome.projected_tangents;
        self.energy_evaluations += outcome.energy_evaluations;
        self.relative_residual = self.relative_residual.max(outcome.residual);
        self.converged &= outcome.stop == Stop::Converged;
        self.stalled_substeps += u32::from(outcome.stop == Stop::Stalled);
        self.penalty_step = outcome.penalty_step;
    }
}

impl Outcome {
    /// The refusal of a substep, of a frame in `substeps`, whose Newton solve failed: it ran out
    /// of iterations, or no descent was left, above the tolerance and off its round-off floor.
    pub(super) fn failure(&self, substeps: u32) -> Option<Error> {
        (self.stop == Stop::Failed).then_some(Error::NewtonDidNotConverge {
            residual: self.residual,
            substeps,
        })
    }

    /// This solve followed by `next`, a solve of the same substep again from where this one
    /// ended: their iterations added, the last one's residual and stop.
    pub(super) fn then(self, next: Self) -> Self {
        Self {
            iterations: self.iterations + next.iterations,
            linear_iterations: self.linear_iterations + next.linear_iterations,
            reused_factorizations: self.reused_factorizations + next.reused_factorizations,
            factorizations: self.factorizations + next.factorizations,
            projected_tangents: self.projected_tangents + next.projected_tangents,
            energy_evaluations: self.energy_evaluations + next.energy_evaluations,
            residual: next.residual,
            stop: next.stop,
            penalty_step: next.penalty_step,
        }
    }

    /// No iteration yet, of a substep of penalty step `penalty_step` (s); the residual and
    /// convergence are set on return.
    pub(super) fn start(penalty_step: f64) -> Self {
        Self {
            iterations: 0,
            linear_iterations: 0,
            reused_factorizations: 0,
            factorizations: 0,
            projected_tangents: 0,
            energy_evaluations: 0,
            residual: f64::NAN,
            stop: Stop::Failed,
            penalty_step,
        }
    }
}
