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
//! solved again where it would carry contact points onto stiffer pieces of their penalty or
//! friction (`direction`), then a backtracking line search makes `E` decrease. While an earlier factorization keeps
//! cutting the out-of-balance force tenfold per iteration, iterations solve with it instead of
//! assembling and factoring anew ([`crate::chord`]). Both schemes are stable at any step length.

mod angular;
mod direction;
mod group;
mod potential;
mod report;
mod rigid_response;

pub use report::ImplicitReport;

use super::{CrushWatch, PreviousStep, SolverWorkspace};
use crate::Error;
use crate::assembly::Stiffness;
use crate::attachment;
use crate::body::DeformableBody;
use crate::chord::{self, Chord};
use crate::constraint::{self, BodyConstraints};
use crate::contact;
use crate::linear_solver::{LinearSolver, Method};
use crate::newton::{Search, check_tolerance, descend, norm, round_off_floor};
use potential::{Potential, StepStart};
use rapier3d::glamx::DVec3;
use report::{Outcome, Stop};
use rigid_response::RigidResponse;

/// Newton stops early on a stalled residual below this relative value, or within
/// [`ROUND_OFF_MARGIN`] of its measured round-off floor; above both, a slow descent is still
/// progress.
const STALL_CEILING: f64 = 1e-4;

/// A residual Newton cannot lower is on its round-off floor when it is within this factor of the
/// floor measured at the iterate ([`round_off_floor`]): the iterates themselves carry rounding
/// errors of a few units in the last place, which the one-unit perturbation measures once.
const ROUND_OFF_MARGIN: f64 = 2.0;

/// Whether a relative residual `relative` that Newton cannot lower sits on its round-off floor:
/// below [`STALL_CEILING`], or within [`ROUND_OFF_MARGIN`] of the relative floor `floor()`
/// (evaluated only when needed: it costs a residual).
fn on_round_off_floor(relative: f64, floor: impl FnOnce() -> f64) -> bool {
    relative <= STALL_CEILING || relative <= ROUND_OFF_MARGIN * floor()
}

/// A substep is solved again, its deep contacts stiffened, at most this many times (see
/// [`ContactSettings::resting_depth`](crate::contact::ContactSettings::resting_depth)): a load
/// that moves to the neighbours of the stiffened contacts may press them deep in turn.
const STIFFENING_ROUNDS: usize = 3;

/// A frame is redone in up to this many times [`ImplicitIntegrator::substeps`] while its Newton
/// solve fails or a surface point ends it past the middle of the collider it touches (see
/// [`ImplicitIntegrator::step`]).
pub const MAX_REFINEMENT: u32 = 64;

/// The most (rad) a body turns in one backward Euler substep: the step's velocities are chords
/// of the turn, and a spinning body's kinetic energy settles `(ω h)²/4` above its spin's
/// (`angular`), 1e-4 at this turn. A frame of a faster turn is cut into more substeps: a block
/// spinning at 5 rad/s, stepped once per 1/60 s frame, settled 1.7e-3 above in one substep. A
/// swing hardly depends on it since its kick follows the substeps' length (`angular`): a 20 cm
/// bar hinged at one end and released horizontal (up to 12 rad/s) comes back at most 5.0 mm
/// short of its start in 5 s at this turn, 6.3 mm at 0.05 rad, 6.0 mm at 0.01.
const MAX_TURN_PER_SUBSTEP: f64 = 0.02;

/// Whether a frame refused with `error` may succeed in more substeps: a failed Newton solve, a
/// Newton system whose factorization broke down (the tangent is positive definite in exact
/// arithmetic, its inertia `m/ĥ²` growing as the substep shrinks), a contact the penalty of a
/// long step could not hold, an element crushed by a step too long to follow an impact.
fn refinable(error: &Error) -> bool {
    matches!(
        error,
        Error::NewtonDidNotConverge { .. }
            | Error::IndefiniteStiffness { .. }
            | Error::ContactNotResolved { .. }
            | Error::ElementCrushed { .. }
    )
}

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
    derive(serde::Serialize, serde::Deserialize),
    serde(default)
)]
pub struct ImplicitIntegrator {
    /// The time discretization.
    pub scheme: ImplicitScheme,
    /// Newton stops when the out-of-balance force is below this fraction of the step's force
    /// scale (inertia, gravity and elastic forces) (dimensionless).
    pub tolerance: f64,
    /// Newton iterations per substep at most (at least 1); default 100. A substep that has not
    /// met the tolerance by then, or along which no descent is left, has failed (the frame is
    /// redone in more substeps, see [`ImplicitIntegrator::substeps`]), unless its residual sits
    /// on its round-off floor: then it keeps its last iterate (each accepted iterate lowered the
    /// incremental potential) and is reported as stalled. Smooth motion and rest take one to a
    /// few iterations; a change between sticking and sliding friction at many contacts takes
    /// tens (55 measured when two kinematic fingers squeezing a soft cube start to lift it).
    pub max_newton_iterations: usize,
    /// Equal substeps per frame (at least 1); each costs a Newton solve. A frame whose Newton
    /// solve fails, that leaves a surface point behind its contact plane by more than half the
    /// thickness of the collider it touches (a fast body pressed past the middle of a thin wall,
    /// where the penalty of a long step is too soft to hold it), or that crushes an element, is
    /// redone in twice as many, and so on up to [`ImplicitIntegrator::max_refinement`] times as
    /// many, then refused: the report's `substeps` says how many were taken.
    pub substeps: u32,
    /// How many times [`ImplicitIntegrator::substeps`] a failing frame may be redone in, at
    /// most (at least 1: 1 refuses it at once); default [`MAX_REFINEMENT`].
    pub max_refinement: u32,
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
            max_newton_iterations: 100,
            substeps: 1,
            max_refinement: MAX_REFINEMENT,
            linear_solver: LinearSolver::Automatic,
            reuse_factorization: true,
        }
    }
}

impl ImplicitIntegrator {
    /// Advances `body` by `frame_dt` (s) under uniform gravity (m/s²), in
    /// [`ImplicitIntegrator::substeps`], or more for a body spinning fast enough to turn more
    /// than 0.02 rad in one backward Euler substep (its kinetic energy would settle `(ω h)²/4`
    /// off its spin's).
    ///
    /// A frame whose Newton solve fails (out of iterations, or no descent left, above the
    /// tolerance and off its round-off floor), or that leaves a surface point past the middle of
    /// the collider it touches, is redone in twice the substeps, and so on up to
    /// [`ImplicitIntegrator::max_refinement`] times [`ImplicitIntegrator::substeps`]; past that
    /// it is refused.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `frame_dt`;
    /// [`Error::NonFiniteInput`] for a non-finite gravity; [`Error::InvalidSetting`] for zero
    /// substeps, a non-positive tolerance, zero `max_refinement`, zero Newton iterations or an invalid
    /// [`LinearSolver::ConjugateGradient`] setting;
    /// [`Error::IndefiniteStiffness`] if a linear system cannot be factored;
    /// [`Error::NonFiniteState`] if the step produced a NaN; [`Error::NewtonDidNotConverge`] and
    /// [`Error::ContactNotResolved`] when refinement could not resolve the frame;
    /// [`Error::ElementCrushed`] for a frame that crushes an element (see
    /// [`COLLAPSE_RATIO`](crate::integrate::COLLAPSE_RATIO)). On error the body is left as it
    /// was.
    pub fn step(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<ImplicitReport, Error> {
        let before = workspace.previous_step.clone();
        let watch = CrushWatch::new(body);
        let turning = self.turning_substeps(body, frame_dt);
        let mut refined = ImplicitIntegrator {
            // Zero substeps stay, for `check` to refuse.
            substeps: if self.substeps == 0 {
                0
            } else {
                self.substeps.max(turning)
            },
            ..*self
        };
        let limit = refined.substeps.saturating_mul(self.max_refinement);
        crate::parallel::on_pool(|| {
            loop {
                let attempt = refined.step_in_substeps(
                    body,
                    constraints,
                    workspace,
                    (frame_dt, gravity),
                    &watch,
                );
                match attempt {
                    Err(error) if refinable(&error) && refined.substeps < limit => {
                        workspace.previous_step.clone_from(&before);
                        refined.substeps = refined.substeps.saturating_mul(2).min(limit);
                    }
                    outcome => break outcome,
                }
            }
        })
    }

    /// The substeps a backward Euler frame of `frame_dt` (s) needs for `body` to turn at most
    /// [`MAX_TURN_PER_SUBSTEP`] in each (one for a body at rest; BDF2 needs none).
    fn turning_substeps(&self, body: &DeformableBody, frame_dt: f64) -> u32 {
        if self.scheme != ImplicitScheme::BackwardEuler {
            return 1;
        }
        let turns = (angular::spin(body) * frame_dt / MAX_TURN_PER_SUBSTEP).ceil();
        if turns.is_finite() && turns >= 1.0 {
            turns.min(f64::from(u32::MAX)) as u32
        } else {
            1
        }
    }

    /// [`ImplicitIntegrator::step`] in [`ImplicitIntegrator::substeps`], refused (the body left
    /// as it was) at the first failed Newton solve, or when the frame ends past a collider's
    /// middle or crushes an element `watch` did not see crushed at the start.
    fn step_in_substeps(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        (frame_dt, gravity): (f64, DVec3),
        watch: &CrushWatch,
    ) -> Result<ImplicitReport, Error> {
        Error::check_step(frame_dt, gravity)?;
        self.check()?;
        workspace.save_state(body);
        constraints.save();
        let history = workspace.history(body).cloned();
        let h = frame_dt / f64::from(self.substeps);
        let mut report = ImplicitReport::empty(self.substeps, h);
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
        let mut failure = None;
        for _ in 0..self.substeps {
            match self.substep(body, constraints, &mut solver, h, gravity) {
                Ok(outcome) => {
                    report.add(&outcome);
                    failure = outcome.failure(self.substeps);
                }
                Err(error) => failure = Some(error),
            }
            if failure.is_some() {
                break;
            }
        }
        let checked = match failure {
            Some(error) => Err(error),
            None => self.frame_failure(body, constraints, watch),
        };
        match checked {
            Ok(inverted) => {
                let last = solver.last_step.take();
                solver.give_back(workspace, last);
                report.inverted_elements = inverted;
                Ok(report)
            }
            Err(error) => {
                workspace.restore_state(body);
                constraints.restore();
                solver.give_back(workspace, history);
                Err(error)
            }
        }
    }

    /// What refuses a frame once its substeps are done: a non-finite state, a surface point
    /// past the middle of the collider it touches, an element crushed by the frame. Otherwise
    /// the number of inverted tetrahedra.
    fn frame_failure(
        &self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        watch: &CrushWatch,
    ) -> Result<usize, Error> {
        if let Some(node) = body.first_non_finite_node() {
            return Err(Error::NonFiniteState { node });
        }
        if constraints.contacts.past_middle(body) {
            return Err(Error::ContactNotResolved {
                substeps: self.substeps,
            });
        }
        watch.check(body)
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
        if self.max_refinement == 0 {
            return Err(Error::InvalidSetting {
                parameter: "max_refinement",
                value: 0.0,
                reason: "at least 1 is needed (1 refuses a failing frame at once)",
            });
        }
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
        let incremental = Potential::new(&start, constraints, response);
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
        let mut outcome = self.minimize(body, solver, &incremental, potential)?;
        outcome.energy_evaluations = incremental.evaluations();
        let mut response = incremental.rigid.into_inner();
        for _ in 0..STIFFENING_ROUNDS {
            response.solve(body, constraints);
            if outcome.stop == Stop::Failed
                || !contact::stiffen_deep_contacts(
                    body,
                    &mut constraints.contacts,
                    response.step(),
                    &start.positions,
                )
            {
                break;
            }
            response.forget_solution();
            let stiffened = Potential::new(&start, constraints, response);
            let potential = stiffened.energy(body);
            let mut again = self.minimize(body, solver, &stiffened, potential)?;
            again.energy_evaluations = stiffened.evaluations();
            outcome = outcome.then(again);
            response = stiffened.rigid.into_inner();
        }
        let previous = solver.last_step.as_ref().map(|step| step.h);
        let ended = end_substep(body, constraints, (start, response), (h, previous), true);
        solver.last_step = Some(ended);
        Ok(outcome)
    }

    /// The penalty step (s, see [`ImplicitStep`](crate::contact::ImplicitStep)) of substeps of
    /// effective length `effective` (s): that length times the number of substeps, the
    /// effective step of the whole step the integrator was given.
    fn penalty_step(&self, effective: f64) -> f64 {
        effective * f64::from(self.substeps.max(1))
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
        let steps = (start.h, self.penalty_step(start.h), h);
        let response = RigidResponse::new(constraints.rigid_proxies.clone(), steps);
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
        let mut residual = incremental.residual(body, &mut solver.forces);
        let reference = incremental.force_scale(body, &residual);
        // Relative residuals of the earlier iterations, newest last.
        let mut history: Vec<f64> = Vec::new();
        let mut outcome = Outcome::start(self.penalty_step(incremental.start.h));
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
            let floor = |body: &mut DeformableBody, forces: &mut Vec<DVec3>| {
                round_off_floor(body, &residual, |b| incremental.residual(b, forces)) / reference
            };
            let stop = self.stop(relative, &history, outcome.iterations, || {
                floor(body, &mut solver.forces)
            });
            if let Some(stop) = stop {
                outcome.stop = stop;
                return finish(solver, outcome);
            }
            history.push(relative);
            let (direction, search, kept) = self.direction(
                body,
                (solver, incremental),
                (&inertia, &residual),
                &mut outcome,
            )?;
            let start = kept.then(|| body.positions.clone());
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
                let from = (&residual[..], potential, reference);
                next =
                    self.reuse_served(body, (solver, incremental), from, start, next, &mut outcome);
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
                    // No descent left: round-off on its floor, a failure above it.
                    if on_round_off_floor(outcome.residual, || floor(body, &mut solver.forces)) {
                        outcome.stop = Stop::Stalled;
                    }
                    return finish(solver, outcome);
                }
            }
        }
    }

    /// The Newton direction (m per node) for `residual` (N) at the iteration `outcome` has
    /// reached, and how far to search along it: with an earlier factorization while the chord
    /// may reuse one (see [`ImplicitIntegrator::reuse_factorization`]), else with the exact
    /// tangent (`inertia` its `m/ĥ²` per node).
    fn direction(
        &self,
        body: &DeformableBody,
        (solver, incremental): (&mut Solver, &Potential),
        (inertia, residual): (&[f64], &[DVec3]),
        outcome: &mut Outcome,
    ) -> Result<(Vec<DVec3>, Search, bool), Error> {
        let remaining = self.max_newton_iterations - outcome.iterations;
        let reusable = (self.reuse_factorization && solver.method == Method::Direct)
            .then(|| {
                let budget = chord::within_budget(outcome.residual / self.tolerance, remaining);
                solver.chord.factor_for(incremental.start.h, budget)
            })
            .flatten();
        Ok(match reusable {
            Some(kept) => {
                let (direction, kept) = incremental.reused_direction(body, kept, residual);
                (direction, Search::Short, kept)
            }
            None => (
                self.exact_direction(body, solver, incremental, inertia, residual, outcome)?,
                Search::Thorough,
                false,
            ),
        })
    }

    /// What a reused iteration from `start` (the body's positions, where the out-of-balance
    /// force and minimized energy were `from`'s residual (N) and potential (J), `reference` its
    /// force scale) came to, `next`; if it took in the kept correction (`start` given) and did
    /// not contract, the iteration taken again from `start` with the current coupling (see
    /// [`reuse_with_current_coupling`]), counted in `outcome`.
    fn reuse_served(
        &self,
        body: &mut DeformableBody,
        (solver, incremental): (&mut Solver, &Potential),
        (residual, potential, reference): (&[DVec3], f64, f64),
        start: Option<Vec<DVec3>>,
        next: Option<(Vec<DVec3>, f64)>,
        outcome: &mut Outcome,
    ) -> Option<(Vec<DVec3>, f64)> {
        let after = self.reuse_after(next.as_ref(), reference);
        let Some(start) = start.filter(|_| !chord::contracts(norm(residual), after)) else {
            return next;
        };
        body.positions.clone_from(&start);
        outcome.reused_factorizations += 1;
        reuse_with_current_coupling(body, solver, incremental, (residual, potential))
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
        chord.record(norm(residual), self.reuse_after(next, reference));
    }

    /// The out-of-balance force (N) a reused iteration left, `next`'s, as the chord counts it:
    /// zero within the tolerance of the force scale `reference` (N), infinite if it did not move.
    fn reuse_after(&self, next: Option<&(Vec<DVec3>, f64)>, reference: f64) -> f64 {
        next.map_or(f64::INFINITY, |(next, _)| {
            let after = norm(next);
            if after <= self.tolerance * reference {
                0.0
            } else {
                after
            }
        })
    }

    /// Whether Newton stops at the relative residual `relative` after `iterations`, the earlier
    /// relative residuals being `history` (newest last): how it stops when it meets the
    /// tolerance, is out of iterations or stalled, `None` to go on. A residual that three
    /// iterations could not cut by 10 % on its round-off floor (see [`on_round_off_floor`];
    /// `floor()` the measured floor, relative) is stalled: very stiff or nearly incompressible
    /// material against a small load. Out of iterations, it is stalled if within
    /// [`ROUND_OFF_MARGIN`] of the measured floor, failed otherwise.
    fn stop(
        &self,
        relative: f64,
        history: &[f64],
        iterations: usize,
        mut floor: impl FnMut() -> f64,
    ) -> Option<Stop> {
        if relative <= self.tolerance {
            return Some(Stop::Converged);
        }
        let stuck = history.len() >= 3 && relative > 0.9 * history[history.len() - 3];
        if stuck && on_round_off_floor(relative, &mut floor) {
            return Some(Stop::Stalled);
        }
        (iterations == self.max_newton_iterations).then(|| {
            if relative <= ROUND_OFF_MARGIN * floor() {
                Stop::Stalled
            } else {
                Stop::Failed
            }
        })
    }
}

/// A reused iteration again from where `body` is, its out-of-balance force and minimized
/// energy `(residual, potential)` (N, J), with the kept factorization of `solver`'s chord and
/// the current coupling instead of the kept correction, which did not serve (the coupling's
/// geometry changed: a heavy body swinging on a rope turns its arms). Returns what [`descend`]
/// does; `None`, the body not moved, also without a factorization to reuse.
fn reuse_with_current_coupling(
    body: &mut DeformableBody,
    solver: &mut Solver,
    incremental: &Potential,
    (residual, potential): (&[DVec3], f64),
) -> Option<(Vec<DVec3>, f64)> {
    let (factor, _) = solver.chord.factor_for(incremental.start.h, true)?;
    let (direction, _) = incremental.reused_direction(body, (factor, None), residual);
    let energy = |body: &DeformableBody| incremental.energy(body);
    descend(
        body,
        residual,
        potential,
        &direction,
        Search::Short,
        energy,
        |body| incremental.residual(body, &mut solver.forces),
    )
}

/// Ends an implicit substep of `h` (s) from `start` at the body's positions: the rigid bodies'
/// `response` is solved there, every constraint records its impulses, and the velocities become
/// `(x − a)/ĥ`, with the angular momentum a backward Euler step drains given back
/// ([`angular`]): to a body `alone` (not stepped with others it touches) that nothing pins, holds
/// or pushes at the step's end, all it started with; to a body alone, unpinned and without loads
/// but its weight that only dynamic rigid bodies push, exactly what they and its weight gave it
/// ([`constraint::partner_angular_impulse`]: equal and opposite to what the rigid bodies take);
/// to others the drain, a body pinned or glued to still rigid bodies at a point or along a line
/// swinging with its loads' torque at the step's start over the kick of `previous`, the last
/// substep's length (s), and `h`. Returns the substep's start, for the next one.
fn end_substep(
    body: &mut DeformableBody,
    constraints: &mut BodyConstraints,
    (start, mut response): (StepStart, RigidResponse),
    (h, previous): (f64, Option<f64>),
    alone: bool,
) -> PreviousStep {
    response.solve(body, constraints);
    let free = alone
        && !body.pinned.contains(&true)
        && constraints.attachments.is_empty()
        && !constraint::pushed_from_outside(body, constraints, response.step());
    let exchanged = (alone && !body.pinned.contains(&true) && body.loads.is_empty())
        .then(|| constraint::partner_angular_impulse(body, constraints, response.step()))
        .flatten();
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
    // A backward Euler step (`ĥ = h`) gives back the spin it drained; all of it to a free body.
    if start.h == h {
        if free {
            angular::keep_free_spin(body, &start.positions, &start.velocities);
        } else if let Some(exchanged) = exchanged {
            let weight_moment: DVec3 = (body.positions.iter().zip(&start.load))
                .map(|(x, weight)| x.cross(*weight * h))
                .sum();
            let before = (start.positions.as_slice(), start.velocities.as_slice());
            angular::keep_exchanged(body, before, exchanged + weight_moment);
        } else {
            let begun = (&start.positions[..], &start.velocities[..], &start.load[..]);
            let (attachments, proxies) = (&constraints.attachments, &constraints.rigid_proxies);
            let still = attachment::still_anchors(body, attachments, proxies);
            angular::give_back(body, begun, &still, (h, previous));
        }
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
