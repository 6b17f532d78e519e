//! Backward (implicit) Euler on the incremental potential. Each step of length `h` finds
//! `x_{n+1} = argmin E(x)` with
//! `E(x) = Σ m |x - x̂|² / (2h²) + Ψ(x) + Φ(x) - Σ m g·x`, `x̂ = x_n + h v_n`,
//! where `Ψ` is the elastic energy and `Φ` the damping's dissipation potential over the step; then
//! `v_{n+1} = (x_{n+1} - x_n)/h`. The minimization is Newton's method: element Hessians projected
//! to be positive semi-definite, a sparse Cholesky solve, and a backtracking line search that
//! guarantees `E` decreases. Stable at any step; it damps high frequencies numerically (a mode of
//! angular frequency `ω` loses about `ωh/2` of critical damping per step when `ωh` is small).

use crate::Error;
use crate::assembly::{Stiffness, factorize, solve, stress_tangent};
use crate::body::SoftBody;
use crate::damping::RayleighDamping;
use crate::fvm::gather;
use crate::material::{HyperelasticModel, green_strain, with_hyperelastic_model};
use crate::newton::{line_search, norm};
use rapier3d::glamx::{DMat3, DVec3};

/// The backward Euler integrator and its settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackwardEuler {
    /// Newton stops when the out-of-balance force is below this fraction of the step's force
    /// scale (inertia, gravity and elastic forces) (dimensionless).
    pub tolerance: f64,
    /// Newton iterations per substep at most; a step that has not met the tolerance by then is
    /// kept (its energy decreased) and reported as unconverged.
    pub max_newton_iterations: usize,
    /// Equal substeps per frame (at least 1).
    pub substeps: u32,
}

impl Default for BackwardEuler {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_newton_iterations: 20,
            substeps: 1,
        }
    }
}

/// What one implicit frame step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitReport {
    /// Substeps taken.
    pub substeps: u32,
    /// Newton iterations over all substeps.
    pub newton_iterations: usize,
    /// Largest final relative residual over the substeps.
    pub relative_residual: f64,
    /// Whether every substep met the tolerance.
    pub converged: bool,
    /// Tetrahedra inverted (zero or negative volume) at the end of the frame.
    pub inverted_tets: usize,
}

/// Per-step data: the start of the step and the inertial target.
struct StepStart {
    h: f64,
    positions: Vec<DVec3>,
    target: Vec<DVec3>,
    /// Green strain of every tetrahedron at the start of the step (when damped).
    green: Vec<DMat3>,
    load: Vec<DVec3>,
}

impl BackwardEuler {
    /// Advances `body` by `frame_dt` (s) under uniform gravity (m/s²).
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `frame_dt` or zero substeps;
    /// [`Error::NonFiniteInput`] for a non-finite gravity;
    /// [`Error::IndefiniteStiffness`] if a linear system cannot be factored;
    /// [`Error::NonFiniteState`] if the step produced a NaN. On error the body is left as it was.
    pub fn step(
        &self,
        body: &mut SoftBody,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<ImplicitReport, Error> {
        if !(frame_dt.is_finite() && frame_dt > 0.0) {
            return Err(Error::InvalidTimeStep {
                dt: frame_dt,
                reason: "must be positive and finite",
            });
        }
        if !gravity.is_finite() {
            return Err(Error::NonFiniteInput {
                parameter: "gravity",
            });
        }
        if self.substeps == 0 {
            return Err(Error::InvalidTimeStep {
                dt: frame_dt,
                reason: "at least one substep is needed",
            });
        }
        body.save_state();
        let h = frame_dt / f64::from(self.substeps);
        let mut report = ImplicitReport {
            substeps: self.substeps,
            newton_iterations: 0,
            relative_residual: 0.0,
            converged: true,
            inverted_tets: 0,
        };
        let mut stiffness = Stiffness::new(body);
        for _ in 0..self.substeps {
            match self.substep(body, &mut stiffness, h, gravity) {
                Ok((iterations, residual, converged)) => {
                    report.newton_iterations += iterations;
                    report.relative_residual = report.relative_residual.max(residual);
                    report.converged &= converged;
                }
                Err(error) => {
                    body.restore_state();
                    return Err(error);
                }
            }
        }
        let non_finite = body
            .positions
            .iter()
            .zip(&body.velocities)
            .position(|(x, v)| !(x.is_finite() && v.is_finite()));
        if let Some(node) = non_finite {
            body.restore_state();
            return Err(Error::NonFiniteState { node });
        }
        report.inverted_tets = body.inverted_tet_count();
        Ok(report)
    }

    /// One substep; returns Newton iterations, final relative residual and convergence.
    fn substep(
        &self,
        body: &mut SoftBody,
        stiffness: &mut Stiffness,
        h: f64,
        gravity: DVec3,
    ) -> Result<(usize, f64, bool), Error> {
        let start = StepStart::new(body, h, gravity);
        body.positions.clone_from(&start.target);
        body.velocities.fill(DVec3::ZERO);
        let inertia: Vec<f64> = body.masses.iter().map(|m| m / (h * h)).collect();
        let mut residual = start.residual(body);
        let reference = start.force_scale(body, &residual);
        let mut previous = f64::INFINITY;
        let mut outcome = (self.max_newton_iterations, f64::INFINITY, false);
        for iteration in 0..=self.max_newton_iterations {
            let relative = norm(&residual) / reference;
            let at_round_off = relative > 0.5 * previous && relative <= 1e-9;
            if relative <= self.tolerance || at_round_off {
                outcome = (iteration, relative, true);
                break;
            }
            if iteration == self.max_newton_iterations {
                outcome = (iteration, relative, false);
                break;
            }
            previous = relative;
            start.assemble(body, stiffness, &inertia);
            let direction = solve(&factorize(stiffness, iteration)?, &residual);
            line_search(body, &residual, &direction, |body| start.energy(body));
            residual = start.residual(body);
        }
        for n in 0..body.positions.len() {
            body.velocities[n] = if body.pinned[n] {
                DVec3::ZERO
            } else {
                (body.positions[n] - start.positions[n]) / h
            };
        }
        Ok(outcome)
    }
}

impl StepStart {
    fn new(body: &SoftBody, h: f64, gravity: DVec3) -> Self {
        let positions = body.positions.clone();
        let target = (0..positions.len())
            .map(|n| {
                if body.pinned[n] {
                    positions[n]
                } else {
                    positions[n] + body.velocities[n] * h
                }
            })
            .collect();
        let green = if body.damping.is_some() {
            (0..body.fvm.tets().len())
                .map(|t| {
                    let f = body
                        .fvm
                        .tet_rest(t)
                        .gradient(&gather(&body.fvm.tets()[t], &positions));
                    green_strain(&f)
                })
                .collect()
        } else {
            Vec::new()
        };
        let load = body.masses.iter().map(|m| gravity * *m).collect();
        Self {
            h,
            positions,
            target,
            green,
            load,
        }
    }

    /// `-∇E` (N): elastic and damping forces, gravity and the inertial pull toward `x̂`; zero on
    /// pinned nodes.
    fn residual(&self, body: &mut SoftBody) -> Vec<DVec3> {
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
        for (r, &pinned) in residual.iter_mut().zip(&body.pinned) {
            if pinned {
                *r = DVec3::ZERO;
            }
        }
        residual
    }

    fn add_damping_forces(&self, body: &SoftBody, damping: &RayleighDamping, out: &mut [DVec3]) {
        for (t, tet) in body.fvm.tets().iter().enumerate() {
            let rest = body.fvm.tet_rest(t);
            let f = rest.gradient(&gather(tet, &body.positions));
            let stress = damping.step_first_piola(&f, &self.green[t], self.h);
            let forces = stress * rest.control_normals();
            let node0 = -(forces.x_axis + forces.y_axis + forces.z_axis);
            for (corner, force) in [node0, forces.x_axis, forces.y_axis, forces.z_axis]
                .iter()
                .enumerate()
            {
                out[tet[corner] as usize] += *force;
            }
        }
    }

    /// The force scale the tolerance is relative to (N): the largest of gravity, the inertial
    /// pull and the initial out-of-balance force.
    fn force_scale(&self, body: &SoftBody, initial_residual: &[DVec3]) -> f64 {
        let inertial: Vec<DVec3> = (0..body.positions.len())
            .map(|n| (self.target[n] - self.positions[n]) * (body.masses[n] / (self.h * self.h)))
            .collect();
        norm(&self.load)
            .max(norm(&inertial))
            .max(norm(initial_residual))
            .max(f64::MIN_POSITIVE)
    }

    /// The incremental potential `E(x)` (J) at the body's positions.
    fn energy(&self, body: &SoftBody) -> f64 {
        let inertia: f64 = (0..body.positions.len())
            .map(|n| 0.5 * body.masses[n] * (body.positions[n] - self.target[n]).length_squared())
            .sum::<f64>()
            / (self.h * self.h);
        let load: f64 = self
            .load
            .iter()
            .zip(&body.positions)
            .map(|(f, x)| f.dot(*x))
            .sum();
        let dissipation = match body.damping {
            Some(damping) => (0..body.fvm.tets().len())
                .map(|t| {
                    let rest = body.fvm.tet_rest(t);
                    let f = rest.gradient(&gather(&body.fvm.tets()[t], &body.positions));
                    rest.volume * damping.step_potential(&f, &self.green[t], self.h)
                })
                .sum(),
            None => 0.0,
        };
        inertia + body.elastic_energy() + dissipation - load
    }

    /// `M/h² + K_elastic + K_damping`, each element's stress tangent projected to be positive
    /// semi-definite.
    fn assemble(&self, body: &SoftBody, stiffness: &mut Stiffness, inertia: &[f64]) {
        let damping = body.damping;
        with_hyperelastic_model!(body.material, |model| stiffness.assemble(
            body,
            Some(inertia),
            true,
            |t, f| stress_tangent(|df| {
                let elastic = model.first_piola_differential(f, df);
                match &damping {
                    Some(d) => {
                        elastic + d.step_first_piola_differential(f, &self.green[t], self.h, df)
                    }
                    None => elastic,
                }
            })
        ));
    }
}
