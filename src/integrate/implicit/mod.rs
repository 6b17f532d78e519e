//! Implicit integration on the incremental potential. Each step finds `x_{n+1} = argmin E(x)` with
//! `E(x) = Σ m |x - x̂|² / (2ĥ²) + Ψ(x) + Φ(x) - Σ m g·x`, where `Ψ` is the elastic energy and `Φ`
//! the damping's dissipation potential over the step, then sets `v_{n+1} = (x_{n+1} - a)/ĥ`:
//!
//! - backward Euler: `ĥ = h`, `a = x_n`, `x̂ = x_n + h v_n`. First order; a mode of angular
//!   frequency `ω` is damped numerically at about `ωh/2`.
//! - BDF2: `ĥ = 2h/3`, `a = (4 x_n - x_{n-1})/3`, `x̂ = a + ĥ (4 v_n - v_{n-1})/3`. Second order,
//!   numerical damping of order `(ωh)³`; the first step after a change of state or step length is
//!   a backward Euler step.
//!
//! The minimization is Newton's method from the inertial prediction `x̂` (for backward Euler
//! `x_n + h v_n`: the previous step's velocity extrapolated, the warm start across steps), or
//! from the current positions when those have the lower potential: each
//! iteration solves the Newton system with the exact tangent (or, where that is not positive
//! definite, with element stress tangents projected to be positive semi-definite) by the chosen
//! [`LinearSolver`] (a sparse Cholesky factorization or a preconditioned conjugate gradient),
//! then a backtracking line search makes `E` decrease. While an earlier factorization keeps
//! cutting the out-of-balance force tenfold per iteration, iterations solve with it instead of
//! assembling and factoring anew ([`crate::chord`]). Both schemes are stable at any step length.

mod group;
mod potential;
mod report;
mod rigid_response;

pub use report::ImplicitReport;

use super::{PreviousStep, SolverWorkspace};
use crate::Error;
use crate::assembly::Stiffness;
use crate::body::DeformableBody;
use crate::chord::{self, Chord};
use crate::constraint::{self, BodyConstraints};
use crate::linear_solver::{LinearSolver, Method, solve_newton_system};
use crate::newton::{Search, check_tolerance, descend, norm};
use potential::{Potential, StepStart};
use rapier3d::glamx::DVec3;
use report::{Outcome, Stop};
use rigid_response::RigidResponse;
use std::cell::RefCell;

/// Newton stops early on a stalled residual only below this relative value; above it, a slow
/// descent is still progress.
const STALL_CEILING: f64 = 1e-4;

/// A frame is redone in up to this many times [`ImplicitIntegrator::substeps`] while a surface
/// point ends it past the middle of the collider it touches (see
/// [`ImplicitIntegrator::substeps`]).
const MAX_CONTACT_REFINEMENT: u32 = 64;

/// Which implicit scheme [`ImplicitIntegrator`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum ImplicitScheme {
    /// Backward Euler: first order, strongly damps high frequencies. The most robust.
    #[default]
    BackwardEuler,
    /// Second-order backward differentiation: far less numerical damping at the same cost.
    Bdf2,
}

/// The implicit integrator and its settings.
///
/// Warm start across steps: each step's Newton iteration starts from the inertial prediction
/// `x̂` (backward Euler: `x_n + h v_n`, the last velocity carried over the step; BDF2 its
/// two-step counterpart), so a body at rest in equilibrium or in rigid uniform motion takes no
/// iteration, and a smoothly moving one starts `O(h²)` from the solution; when the prediction has
/// a higher potential than the current positions (a body predicted deep inside an obstacle, or
/// crushing its elements), Newton starts from the current positions instead. The linear solves
/// start from zero (they solve for the Newton correction).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct ImplicitIntegrator {
    /// The time discretization.
    pub scheme: ImplicitScheme,
    /// Newton stops when the out-of-balance force is below this fraction of the step's force
    /// scale (inertia, gravity and elastic forces) (dimensionless).
    pub tolerance: f64,
    /// Newton iterations per substep at most (at least 1); a step that has not met the tolerance
    /// by then, whose residual stops falling (its round-off floor), or along which no descent is
    /// left, keeps its last iterate (each accepted iterate lowered the incremental potential) and
    /// is reported as unconverged.
    pub max_newton_iterations: usize,
    /// Equal substeps per frame (at least 1); each costs a Newton solve. A frame that leaves a
    /// surface point behind its contact plane by more than half the thickness of the collider
    /// it touches (a fast body pressed past the middle of a thin wall, where the penalty of a
    /// long step is too soft to hold it) is redone in twice as many, and so on up to 64 times
    /// as many: the report's `substeps` says how many were taken.
    pub substeps: u32,
    /// How each Newton iteration's linear system is solved.
    pub linear_solver: LinearSolver,
    /// Whether Newton iterations solved by the direct method may reuse the Cholesky
    /// factorization of an earlier iteration or step (the chord method) while it keeps cutting
    /// the out-of-balance force tenfold per iteration: the same tolerance is met, and where the
    /// tangent changes little (the linear model, small strains, a fixed step) most iterations
    /// skip the assembly and the factorization. An iteration reuses the last factorization when
    /// it was made for the same effective step, reuse has not failed in this step, and the
    /// iterations left could still reach the tolerance at a contraction of 0.1 per iteration
    /// with one exact iteration to spare; a reused iteration that does not lower the potential,
    /// or does not cut the out-of-balance force tenfold, ends reuse for the step, and reuse pauses for
    /// the next 1, 2, 4 … 16 implicit substeps after consecutive failures. The body
    /// then keeps its last factorization between steps (8 bytes per nonzero of the Cholesky
    /// factor); `false` frees it after each solve.
    pub reuse_factorization: bool,
}

impl Default for ImplicitIntegrator {
    fn default() -> Self {
        Self {
            scheme: ImplicitScheme::BackwardEuler,
            tolerance: 1e-6,
            max_newton_iterations: 20,
            substeps: 1,
            linear_solver: LinearSolver::Automatic,
            reuse_factorization: true,
        }
    }
}

impl ImplicitIntegrator {
    /// Advances `body` by `frame_dt` (s) under uniform gravity (m/s²).
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `frame_dt`;
    /// [`Error::NonFiniteInput`] for a non-finite gravity; [`Error::InvalidSetting`] for zero
    /// substeps, a non-positive tolerance, zero Newton iterations or an invalid
    /// [`LinearSolver::ConjugateGradient`] setting;
    /// [`Error::IndefiniteStiffness`] if a linear system cannot be factored;
    /// [`Error::NonFiniteState`] if the step produced a NaN. On error the body is left as it was.
    pub fn step(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<ImplicitReport, Error> {
        let before = workspace.previous_step.clone();
        let mut refined = *self;
        loop {
            let report =
                refined.step_in_substeps(body, constraints, workspace, frame_dt, gravity)?;
            let limit = self.substeps.saturating_mul(MAX_CONTACT_REFINEMENT);
            if refined.substeps >= limit || !constraints.contacts.past_middle(body) {
                return Ok(report);
            }
            // A point ended past the middle of the collider it touches: the frame is redone in
            // twice the substeps.
            workspace.restore_state(body);
            constraints.restore();
            workspace.previous_step.clone_from(&before);
            refined.substeps = refined.substeps.saturating_mul(2).min(limit);
        }
    }

    /// [`ImplicitIntegrator::step`] in [`ImplicitIntegrator::substeps`], however deep the
    /// contacts end.
    fn step_in_substeps(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<ImplicitReport, Error> {
        Error::check_step(frame_dt, gravity)?;
        self.check()?;
        workspace.save_state(body);
        constraints.save();
        let history = workspace.history(body).cloned();
        let h = frame_dt / f64::from(self.substeps);
        let mut report = ImplicitReport::empty(self.substeps);
        let mut stiffness = workspace.take_tangent(body);
        let uncoupled = constraint::uncoupled_pairs(body, constraints, &stiffness);
        if !uncoupled.is_empty()
            && let Some(widened) = stiffness.widened(&uncoupled)
        {
            stiffness = widened;
        }
        #[cfg(feature = "serde-serialize")]
        workspace.chord.refactor(body);
        let mut solver = Solver {
            stiffness,
            // Without reuse, a factorization kept by earlier steps is dropped.
            chord: if self.reuse_factorization {
                std::mem::take(&mut workspace.chord)
            } else {
                Chord::default()
            },
            method: self.linear_solver.method(body, h),
            last_step: history.clone(),
            forces: std::mem::take(&mut workspace.forces),
        };
        for _ in 0..self.substeps {
            match self.substep(body, constraints, &mut solver, h, gravity) {
                Ok(outcome) => report.add(&outcome),
                Err(error) => {
                    workspace.restore_state(body);
                    constraints.restore();
                    solver.give_back(workspace, history);
                    return Err(error);
                }
            }
        }
        if let Some(node) = body.first_non_finite_node() {
            workspace.restore_state(body);
            constraints.restore();
            solver.give_back(workspace, history);
            return Err(Error::NonFiniteState { node });
        }
        let last = solver.last_step.take();
        solver.give_back(workspace, last);
        report.inverted_tets = body.inverted_tet_count();
        Ok(report)
    }

    /// Checks the settings.
    fn check(&self) -> Result<(), Error> {
        if self.substeps == 0 {
            return Err(Error::InvalidSetting {
                parameter: "substeps",
                value: 0.0,
                reason: "at least one substep is needed",
            });
        }
        check_tolerance(self.tolerance)?;
        if self.max_newton_iterations == 0 {
            return Err(Error::InvalidSetting {
                parameter: "max_newton_iterations",
                value: 0.0,
                reason: "at least one Newton iteration is needed",
            });
        }
        self.linear_solver.check()
    }

    /// One substep.
    fn substep(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        solver: &mut Solver,
        h: f64,
        gravity: DVec3,
    ) -> Result<Outcome, Error> {
        let (start, response) =
            self.begin_substep(body, constraints, solver.last_step.as_ref(), (h, gravity));
        let incremental = Potential {
            start: &start,
            constraints,
            rigid: RefCell::new(response),
        };
        // Newton starts from the inertial prediction `x̂` (free flight: the warm start that makes
        // smooth motion cost one iteration), or from where the body is when that is the lower
        // potential (a prediction deep inside an obstacle or crushing elements).
        let here = incremental.energy(body);
        body.positions.clone_from(&start.target);
        let mut potential = incremental.energy(body);
        // A NaN prediction is not lower either.
        if potential.is_nan() || potential > here {
            body.positions.clone_from(&start.positions);
            potential = here;
        }
        let outcome = self.minimize(body, solver, &incremental, potential)?;
        let response = incremental.rigid.into_inner();
        solver.last_step = Some(end_substep(body, constraints, start, response, h));
        Ok(outcome)
    }

    /// Readies `body` and its `constraints` for an implicit substep of `h` (s) under `gravity`
    /// (m/s²) after `previous`: the step's start, and the touched rigid bodies' response, at
    /// rest. The rigid bodies fall, as rapier will make them (unless held); the constraints
    /// begin the step; the body's velocities are zeroed (the potential holds them).
    fn begin_substep(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        previous: Option<&PreviousStep>,
        (h, gravity): (f64, DVec3),
    ) -> (StepStart, RigidResponse) {
        let start = StepStart::new(body, previous, h, gravity, self.scheme);
        for proxy in &mut constraints.rigid_proxies {
            proxy.fall(gravity, h);
        }
        let response = RigidResponse::new(constraints.rigid_proxies.clone(), start.h, h);
        for kind in constraint::IMPLICIT {
            kind.begin(body, constraints, response.start());
        }
        body.velocities.fill(DVec3::ZERO);
        (start, response)
    }

    /// Newton's method on the step's incremental potential, from the body's current positions,
    /// where it is `potential` (J). A conjugate gradient that falls back to the direct solve
    /// switches the solver's method to it.
    fn minimize(
        &self,
        body: &mut DeformableBody,
        solver: &mut Solver,
        incremental: &Potential,
        mut potential: f64,
    ) -> Result<Outcome, Error> {
        let inertia: Vec<f64> = body
            .masses
            .iter()
            .map(|m| m / (incremental.start.h * incremental.start.h))
            .collect();
        let start = incremental.start;
        let mut residual = incremental.residual(body, &mut solver.forces);
        let reference = incremental.force_scale(body, &residual);
        // Relative residuals of the earlier iterations, newest last.
        let mut history: Vec<f64> = Vec::new();
        let mut outcome = Outcome::start();
        solver.chord.start_step();
        let finish = |solver: &mut Solver, outcome: Outcome| -> Result<Outcome, Error> {
            solver.chord.end_step(outcome.reused_factorizations > 0);
            Ok(outcome)
        };
        loop {
            let relative = norm(&residual) / reference;
            outcome.residual = relative;
            if !relative.is_finite() {
                let node = residual.iter().position(|r| !r.is_finite()).unwrap_or(0);
                return Err(Error::NonFiniteState { node });
            }
            if let Some(stop) = self.stop(relative, &history, outcome.iterations) {
                outcome.stop = stop;
                return finish(solver, outcome);
            }
            history.push(relative);
            let remaining = self.max_newton_iterations - outcome.iterations;
            let reusable = (self.reuse_factorization && solver.method == Method::Direct)
                .then(|| {
                    let budget = chord::within_budget(relative / self.tolerance, remaining);
                    solver.chord.factor_for(start.h, budget)
                })
                .flatten();
            let (direction, search) = match reusable {
                Some(factor) => (
                    incremental.reused_direction(body, factor, &residual),
                    Search::Short,
                ),
                None => (
                    self.exact_direction(
                        body,
                        solver,
                        incremental,
                        &inertia,
                        &residual,
                        &mut outcome,
                    )?,
                    Search::Thorough,
                ),
            };
            let energy = |body: &DeformableBody| incremental.energy(body);
            let mut next = descend(
                body,
                &residual,
                potential,
                &direction,
                search,
                energy,
                |body| incremental.residual(body, &mut solver.forces),
            );
            if search == Search::Short {
                outcome.reused_factorizations += 1;
                self.record_reuse(&mut solver.chord, &residual, next.as_ref(), reference);
                if next.is_none() {
                    // The exact tangent may still descend where an earlier one does not; this
                    // iteration did not move, so it leaves the stall history.
                    history.pop();
                    next = Some((residual.clone(), potential));
                }
            }
            outcome.iterations += 1;
            match next {
                Some((next, energy)) => (residual, potential) = (next, energy),
                None => {
                    // No descent left: round-off below the stall ceiling, a failure above it.
                    if outcome.residual <= STALL_CEILING {
                        outcome.stop = Stop::Stalled;
                    }
                    return finish(solver, outcome);
                }
            }
        }
    }

    /// Tells the chord how a reused iteration from `residual` went: to `next` (its residual), or
    /// nowhere; a residual within the tolerance of the force scale `reference` (N) counts as
    /// enough contraction.
    fn record_reuse(
        &self,
        chord: &mut Chord,
        residual: &[DVec3],
        next: Option<&(Vec<DVec3>, f64)>,
        reference: f64,
    ) {
        let after = next.map_or(f64::INFINITY, |(next, _)| {
            let after = norm(next);
            if after <= self.tolerance * reference {
                0.0
            } else {
                after
            }
        });
        chord.record(norm(residual), after);
    }

    /// Whether Newton stops at the relative residual `relative` after `iterations`, the earlier
    /// relative residuals being `history` (newest last): how it stops when it meets the
    /// tolerance, is out of iterations or stalled, `None` to go on. A small
    /// residual that three iterations could not cut by 10 % sits on its round-off floor (very
    /// stiff or nearly incompressible material against a small load).
    fn stop(&self, relative: f64, history: &[f64], iterations: usize) -> Option<Stop> {
        if relative <= self.tolerance {
            return Some(Stop::Converged);
        }
        let stalled = relative <= STALL_CEILING
            && history.len() >= 3
            && relative > 0.9 * history[history.len() - 3];
        if stalled {
            Some(Stop::Stalled)
        } else {
            (iterations == self.max_newton_iterations).then_some(Stop::Failed)
        }
    }

    /// The Newton direction (m per node) of the exact tangent, which the chord keeps for reuse
    /// when it was factored.
    fn exact_direction(
        &self,
        body: &DeformableBody,
        solver: &mut Solver,
        incremental: &Potential,
        inertia: &[f64],
        residual: &[DVec3],
        outcome: &mut Outcome,
    ) -> Result<Vec<DVec3>, Error> {
        // The exact Hessian converges fastest; where it is indefinite (compressed elements)
        // the per-element projection restores a descent direction.
        let solution = solve_newton_system(
            solver.method,
            self.tolerance / outcome.residual,
            &mut solver.stiffness,
            residual,
            outcome.iterations,
            |stiffness, project| incremental.assemble(body, stiffness, inertia, project),
        )?;
        outcome.linear_iterations += solution.cg_iterations;
        outcome.factorizations += solution.factorizations;
        outcome.projected_tangents += usize::from(solution.projected);
        if solution.fell_back {
            solver.method = Method::Direct;
        }
        let mut direction = solution.direction;
        if let Some(factor) = &solution.factor {
            direction =
                incremental.take_in_rigid_response(body, (factor, false), residual, direction);
        }
        if let Some(factor) = solution.factor
            && self.reuse_factorization
        {
            solver.chord.keep(factor, incremental.start.h);
            #[cfg(feature = "serde-serialize")]
            solver.chord.remember(&solver.stiffness);
        }
        Ok(direction)
    }
}

/// Ends an implicit substep of `h` (s) from `start` at the body's positions: the rigid bodies'
/// `response` is solved there, every constraint records its impulses, and the velocities become
/// `(x − a)/ĥ`. Returns the substep's start, for the next one.
fn end_substep(
    body: &mut DeformableBody,
    constraints: &mut BodyConstraints,
    start: StepStart,
    mut response: RigidResponse,
    h: f64,
) -> PreviousStep {
    response.solve(body, constraints);
    for kind in constraint::IMPLICIT {
        kind.record_impulses(body, constraints, response.step());
    }
    for n in 0..body.positions.len() {
        body.velocities[n] = if body.pinned[n] {
            DVec3::ZERO
        } else {
            (body.positions[n] - start.anchor[n]) / start.h
        };
    }
    PreviousStep {
        h,
        positions: start.positions,
        velocities: start.velocities,
        edits: body.state_edits(),
    }
}

/// The implicit step's linear algebra and history, carried across substeps: the tangent
/// workspace, the factorization kept for reuse, the solve method, and the start of the last
/// substep (for BDF2).
struct Solver {
    stiffness: Stiffness,
    chord: Chord,
    method: Method,
    last_step: Option<PreviousStep>,
    /// Scratch for the internal forces (N per node).
    forces: Vec<DVec3>,
}

impl Solver {
    /// Returns the tangent and the kept factorization to the workspace for the body's next
    /// step, with `history` as the state two-step schemes start from.
    fn give_back(self, workspace: &mut SolverWorkspace, history: Option<PreviousStep>) {
        workspace.tangent = Some(self.stiffness);
        workspace.chord = self.chord;
        workspace.forces = self.forces;
        workspace.previous_step = history;
    }
}
