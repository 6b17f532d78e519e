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

use super::check_step;
use crate::Error;
use crate::assembly::{Stiffness, solve};
use crate::body::{DeformableBody, PreviousStep};
use crate::chord::{self, Chord};
use crate::damping::RayleighDamping;
use crate::element::add_point_forces;
use crate::element::deformation_gradient;
use crate::linear_solver::{LinearSolver, Method, solve_newton_system};
use crate::material::green_strain;
use crate::newton::{Search, check_tolerance, descend, norm};
use crate::{attachment, contact};
use rapier3d::glamx::{DMat3, DVec3};

/// Newton stops early on a stalled residual only below this relative value; above it, a slow
/// descent is still progress.
const STALL_CEILING: f64 = 1e-4;

/// Which implicit scheme [`ImplicitIntegrator`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
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
    /// Equal substeps per frame (at least 1); each costs a Newton solve.
    pub substeps: u32,
    /// How each Newton iteration's linear system is solved.
    pub linear_solver: LinearSolver,
    /// Whether Newton iterations solved by the direct method may reuse the Cholesky
    /// factorization of an earlier iteration or step (the chord method) while it keeps cutting
    /// the out-of-balance force tenfold per iteration: the same tolerance is met, and where the
    /// tangent changes little (the linear model, small strains, a fixed step) most iterations
    /// skip the assembly and the factorization. See [`crate::chord`] for the rule. The body
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

/// What one implicit frame step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitReport {
    /// Substeps taken.
    pub substeps: u32,
    /// Newton iterations over all substeps, those that reused a factorization included.
    pub newton_iterations: usize,
    /// Conjugate gradient iterations over all substeps (zero when every system was solved by
    /// the direct method).
    pub linear_iterations: usize,
    /// Newton iterations that solved with an earlier factorization instead of assembling and
    /// factoring the tangent (see [`ImplicitIntegrator::reuse_factorization`]); included in
    /// `newton_iterations`.
    pub reused_factorizations: usize,
    /// Numeric Cholesky factorizations of the Newton system (two in an iteration whose exact
    /// tangent failed to factor and whose projected tangent was factored; none for systems
    /// solved by the conjugate gradient or with a reused factorization).
    pub factorizations: usize,
    /// Newton iterations whose exact tangent was not positive definite (the Cholesky
    /// factorization failed or the conjugate gradient met negative curvature), so that the
    /// tangent with element stress tangents projected to be positive semi-definite was solved.
    pub projected_tangents: usize,
    /// Largest final relative residual over the substeps.
    pub relative_residual: f64,
    /// Whether every substep met the tolerance.
    pub converged: bool,
    /// Tetrahedra inverted (zero or negative volume) at the end of the frame.
    pub inverted_tets: usize,
}

/// What one substep's Newton solve did.
struct Outcome {
    /// Newton iterations.
    iterations: usize,
    /// Conjugate gradient iterations.
    linear_iterations: usize,
    /// Iterations that reused an earlier factorization.
    reused_factorizations: usize,
    /// Numeric Cholesky factorizations.
    factorizations: usize,
    /// Iterations that solved the projected tangent.
    projected_tangents: usize,
    /// Final relative residual.
    residual: f64,
    /// Whether the tolerance was met.
    converged: bool,
}

/// Per-step data of the incremental potential.
struct StepStart {
    /// The effective step `ĥ` (s).
    h: f64,
    /// Positions (m) and velocities (m/s) at the start of the step.
    positions: Vec<DVec3>,
    velocities: Vec<DVec3>,
    /// `a` (m): the new velocity is `(x - a)/ĥ`.
    anchor: Vec<DVec3>,
    /// `x̂` (m), the inertial target.
    target: Vec<DVec3>,
    /// Per tetrahedron, the Green strain the damping's rate is measured from (when damped).
    green: Vec<DMat3>,
    load: Vec<DVec3>,
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
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<ImplicitReport, Error> {
        check_step(frame_dt, gravity)?;
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
        self.linear_solver.check()?;
        body.save_state();
        let history = body.previous_step.clone();
        let h = frame_dt / f64::from(self.substeps);
        let mut report = ImplicitReport {
            substeps: self.substeps,
            newton_iterations: 0,
            linear_iterations: 0,
            reused_factorizations: 0,
            factorizations: 0,
            projected_tangents: 0,
            relative_residual: 0.0,
            converged: true,
            inverted_tets: 0,
        };
        let mut solver = Solver {
            stiffness: body.take_tangent(),
            // Without reuse, a factorization kept by earlier steps is dropped.
            chord: if self.reuse_factorization {
                std::mem::take(&mut body.chord)
            } else {
                Chord::default()
            },
            method: self.linear_solver.method(body, h),
        };
        for _ in 0..self.substeps {
            match self.substep(body, &mut solver, h, gravity) {
                Ok(Outcome {
                    iterations,
                    linear_iterations,
                    reused_factorizations,
                    factorizations,
                    projected_tangents,
                    residual,
                    converged,
                }) => {
                    report.newton_iterations += iterations;
                    report.linear_iterations += linear_iterations;
                    report.reused_factorizations += reused_factorizations;
                    report.factorizations += factorizations;
                    report.projected_tangents += projected_tangents;
                    report.relative_residual = report.relative_residual.max(residual);
                    report.converged &= converged;
                }
                Err(error) => {
                    body.restore_state();
                    body.previous_step = history;
                    solver.give_back(body);
                    return Err(error);
                }
            }
        }
        solver.give_back(body);
        if let Some(node) = body.first_non_finite_node() {
            body.restore_state();
            body.previous_step = history;
            return Err(Error::NonFiniteState { node });
        }
        report.inverted_tets = body.inverted_tet_count();
        Ok(report)
    }

    /// One substep.
    fn substep(
        &self,
        body: &mut DeformableBody,
        solver: &mut Solver,
        h: f64,
        gravity: DVec3,
    ) -> Result<Outcome, Error> {
        let start = StepStart::new(body, h, gravity, self.scheme);
        contact::lag_friction(body, start.h);
        // Newton starts from the inertial prediction `x̂` (free flight: the warm start that makes
        // smooth motion cost one iteration), or from where the body is when that is the lower
        // potential (a prediction deep inside an obstacle or crushing elements).
        body.velocities.fill(DVec3::ZERO);
        let here = start.energy(body);
        body.positions.clone_from(&start.target);
        let mut potential = start.energy(body);
        // A NaN prediction is not lower either.
        if potential.is_nan() || potential > here {
            body.positions.clone_from(&start.positions);
            potential = here;
        }
        let outcome = self.minimize(body, solver, &start, potential)?;
        contact::record_penalty_impulses(body, start.h, h);
        attachment::record_spring_impulses(body, start.h, h);
        for n in 0..body.positions.len() {
            body.velocities[n] = if body.pinned[n] {
                DVec3::ZERO
            } else {
                (body.positions[n] - start.anchor[n]) / start.h
            };
        }
        body.previous_step = Some(PreviousStep {
            h,
            positions: start.positions,
            velocities: start.velocities,
        });
        Ok(outcome)
    }

    /// Newton's method on the step's incremental potential, from the body's current positions,
    /// where it is `potential` (J). A conjugate gradient that falls back to the direct solve
    /// switches the solver's method to it.
    fn minimize(
        &self,
        body: &mut DeformableBody,
        solver: &mut Solver,
        start: &StepStart,
        mut potential: f64,
    ) -> Result<Outcome, Error> {
        let inertia: Vec<f64> = body
            .masses
            .iter()
            .map(|m| m / (start.h * start.h))
            .collect();
        let mut residual = start.residual(body);
        let reference = start.force_scale(body, &residual);
        // Relative residuals of the earlier iterations, newest last.
        let mut history: Vec<f64> = Vec::new();
        // Filled in as Newton goes; `residual` and `converged` are set on return.
        let mut outcome = Outcome {
            iterations: 0,
            linear_iterations: 0,
            reused_factorizations: 0,
            factorizations: 0,
            projected_tangents: 0,
            residual: f64::NAN,
            converged: false,
        };
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
            if relative <= self.tolerance {
                outcome.converged = true;
                return finish(solver, outcome);
            }
            // A small residual that three iterations could not cut by 10 % sits on its round-off
            // floor (very stiff or nearly incompressible material against a small load).
            let stalled = relative <= STALL_CEILING
                && history.len() >= 3
                && relative > 0.9 * history[history.len() - 3];
            if outcome.iterations == self.max_newton_iterations || stalled {
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
                Some(factor) => (solve(factor, &residual), Search::Short),
                None => (
                    self.exact_direction(body, solver, start, &inertia, &residual, &mut outcome)?,
                    Search::Thorough,
                ),
            };
            let energy = |body: &DeformableBody| start.energy(body);
            let mut next = descend(
                body,
                &residual,
                potential,
                &direction,
                search,
                energy,
                |body| start.residual(body),
            );
            if search == Search::Short {
                outcome.reused_factorizations += 1;
                // Converged counts as enough contraction; no descent as none.
                let after = next.as_ref().map_or(f64::INFINITY, |(next, _)| {
                    let after = norm(next);
                    if after <= self.tolerance * reference {
                        0.0
                    } else {
                        after
                    }
                });
                solver.chord.record(norm(&residual), after);
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
                None => return finish(solver, outcome),
            }
        }
    }

    /// The Newton direction (m per node) of the exact tangent, which the chord keeps for reuse
    /// when it was factored.
    fn exact_direction(
        &self,
        body: &DeformableBody,
        solver: &mut Solver,
        start: &StepStart,
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
            |stiffness, project| start.assemble(body, stiffness, inertia, project),
        )?;
        outcome.linear_iterations += solution.cg_iterations;
        outcome.factorizations += solution.factorizations;
        outcome.projected_tangents += usize::from(solution.projected);
        if solution.fell_back {
            solver.method = Method::Direct;
        }
        if let Some(factor) = solution.factor
            && self.reuse_factorization
        {
            solver.chord.keep(factor, start.h);
        }
        Ok(solution.direction)
    }
}

/// The implicit step's linear algebra, carried across substeps: the tangent workspace, the
/// factorization kept for reuse and the solve method.
struct Solver {
    stiffness: Stiffness,
    chord: Chord,
    method: Method,
}

impl Solver {
    /// Returns the workspace and the kept factorization to the body for its next step.
    fn give_back(self, body: &mut DeformableBody) {
        body.tangent = Some(self.stiffness);
        body.chord = self.chord;
    }
}

impl StepStart {
    /// The potential of a step of length `h` from the body's state; BDF2 uses the previous
    /// step when it had the same length, backward Euler otherwise.
    fn new(body: &DeformableBody, h: f64, gravity: DVec3, scheme: ImplicitScheme) -> Self {
        let positions = body.positions.clone();
        let previous = match scheme {
            ImplicitScheme::Bdf2 => body.previous_step.as_ref().filter(|p| p.h == h),
            ImplicitScheme::BackwardEuler => None,
        };
        let green_at = |x: &[DVec3]| -> Vec<DMat3> {
            body.elements
                .gradients(x)
                .iter()
                .map(green_strain)
                .collect()
        };
        let damped = body.damping.is_some();
        let (effective_h, anchor, velocity, green) = match previous {
            Some(previous) => {
                let combine = |now: &[DVec3], before: &[DVec3]| -> Vec<DVec3> {
                    now.iter()
                        .zip(before)
                        .map(|(a, b)| (*a * 4.0 - *b) / 3.0)
                        .collect()
                };
                let green = if damped {
                    let (now, before) = (green_at(&positions), green_at(&previous.positions));
                    now.iter()
                        .zip(&before)
                        .map(|(a, b)| (*a * 4.0 - *b) * (1.0 / 3.0))
                        .collect()
                } else {
                    Vec::new()
                };
                (
                    2.0 * h / 3.0,
                    combine(&positions, &previous.positions),
                    combine(&body.velocities, &previous.velocities),
                    green,
                )
            }
            None => {
                let green = if damped {
                    green_at(&positions)
                } else {
                    Vec::new()
                };
                (h, positions.clone(), body.velocities.clone(), green)
            }
        };
        let target = (0..positions.len())
            .map(|n| {
                if body.pinned[n] {
                    positions[n]
                } else {
                    anchor[n] + velocity[n] * effective_h
                }
            })
            .collect();
        let load = body.gravity_load(gravity);
        Self {
            h: effective_h,
            positions,
            velocities: body.velocities.clone(),
            anchor,
            target,
            green,
            load,
        }
    }

    /// `-∇E` (N): elastic and damping forces, gravity, contact penalties and the inertial pull
    /// toward `x̂`; zero on pinned nodes.
    fn residual(&self, body: &mut DeformableBody) -> Vec<DVec3> {
        body.velocities.fill(DVec3::ZERO);
        body.compute_internal_forces();
        let mut residual: Vec<DVec3> = (0..body.positions.len())
            .map(|n| {
                let inertial =
                    (self.target[n] - body.positions[n]) * (body.masses[n] / (self.h * self.h));
                body.forces[n] + self.load[n] + inertial
            })
            .collect();
        if let Some(damping) = body.damping {
            self.add_damping_forces(body, &damping, &mut residual);
        }
        contact::for_each_active_penalty(body, self.h, |at, stiffness, gap, normal| {
            for (&node, w) in at.nodes.iter().zip(at.weights) {
                residual[node as usize] -= normal * (w * stiffness * gap);
            }
        });
        contact::for_each_friction(body, self.h, |at, _, force, _| {
            for (&node, w) in at.nodes.iter().zip(at.weights) {
                residual[node as usize] += force * *w;
            }
        });
        attachment::for_each_spring(body, self.h, |node, stiffness, target| {
            residual[node] += (target - body.positions[node]) * stiffness;
        });
        for (r, &pinned) in residual.iter_mut().zip(&body.pinned) {
            if pinned {
                *r = DVec3::ZERO;
            }
        }
        residual
    }

    fn add_damping_forces(
        &self,
        body: &DeformableBody,
        damping: &RayleighDamping,
        out: &mut [DVec3],
    ) {
        body.elements
            .for_each_point(|point, nodes, gradients, weight| {
                let f = deformation_gradient(nodes, gradients, &body.positions);
                let stress = damping.step_first_piola(&f, &self.green[point], self.h);
                add_point_forces(nodes, gradients, &(stress * weight), out);
            });
    }

    /// The force scale the tolerance is relative to (N): the largest of gravity, the inertial
    /// pull and the initial out-of-balance force.
    fn force_scale(&self, body: &DeformableBody, initial_residual: &[DVec3]) -> f64 {
        let inertial: Vec<DVec3> = (0..body.positions.len())
            .map(|n| (self.target[n] - self.positions[n]) * (body.masses[n] / (self.h * self.h)))
            .collect();
        norm(&self.load)
            .max(norm(&inertial))
            .max(norm(initial_residual))
            .max(f64::MIN_POSITIVE)
    }

    /// The incremental potential `E(x)` (J) at the body's positions.
    fn energy(&self, body: &DeformableBody) -> f64 {
        let inertia: f64 = (0..body.positions.len())
            .map(|n| 0.5 * body.masses[n] * (body.positions[n] - self.target[n]).length_squared())
            .sum::<f64>()
            / (self.h * self.h);
        // The load's work is measured from the start of the step.
        let load: f64 = self
            .load
            .iter()
            .zip(body.positions.iter().zip(&self.positions))
            .map(|(f, (x, x0))| f.dot(*x - *x0))
            .sum();
        let dissipation = match body.damping {
            Some(damping) => {
                let mut dissipation = 0.0;
                body.elements
                    .for_each_point(|point, nodes, gradients, weight| {
                        let f = deformation_gradient(nodes, gradients, &body.positions);
                        dissipation +=
                            weight * damping.step_potential(&f, &self.green[point], self.h);
                    });
                dissipation
            }
            None => 0.0,
        };
        let mut penalty = 0.0;
        contact::for_each_active_penalty(body, self.h, |_, stiffness, gap, _| {
            penalty += 0.5 * stiffness * gap * gap;
        });
        contact::for_each_friction(body, self.h, |_, energy, _, _| {
            penalty += energy;
        });
        attachment::for_each_spring(body, self.h, |node, stiffness, target| {
            penalty += 0.5 * stiffness * (body.positions[node] - target).length_squared();
        });
        inertia + body.elastic_energy() + dissipation + penalty - load
    }

    /// `M/h² + K_elastic + K_damping + K_contact`, each element's stress tangent projected to be positive
    /// semi-definite if `project`.
    fn assemble(
        &self,
        body: &DeformableBody,
        stiffness: &mut Stiffness,
        inertia: &[f64],
        project: bool,
    ) {
        let damping = body.damping;
        stiffness.assemble(body, Some(inertia), project, |t, f, df| match &damping {
            Some(d) => d.step_first_piola_differential(f, &self.green[t], self.h, df),
            None => DMat3::ZERO,
        });
        contact::for_each_active_penalty(body, self.h, |at, k, _, normal| {
            stiffness.add_stencil_block(at, &contact::penalty_tangent(k, normal), &body.pinned);
        });
        contact::for_each_friction(body, self.h, |at, _, _, tangent| {
            stiffness.add_stencil_block(at, &tangent, &body.pinned);
        });
        attachment::for_each_spring(body, self.h, |node, k, _| {
            stiffness.add_node_block(node, &(DMat3::IDENTITY * k));
        });
    }
}
