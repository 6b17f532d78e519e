//! Symplectic (semi-implicit) Euler with automatic substepping:
//! `v ← v + h (f_int(x, v)/m + g)`, then `x ← x + h v`, for each substep `h`.
//!
//! The substep is limited by the Courant–Friedrichs–Lewy condition: a pressure wave must not cross
//! a cell in one step. The critical step of the undamped scheme is estimated at the start of each
//! frame as `h_crit = C ℓ / c_p`, with `c_p = sqrt((λ+2μ)/ρ)` the pressure wave speed, `ℓ` the
//! mesh's [`wave_length_scale`](crate::fvm::FvmMesh::wave_length_scale) in its current shape (a
//! per-node cell size that counts the elements sharing the node and shrinks as they are crushed)
//! and `C` the [`COURANT_NUMBER`] measured on this crate's meshes.
//! Damping lowers it: with the highest mode at `ω = 2/h_crit` damped at `ζ = β ω/2`
//! (`β = (φ+2ψ)/(λ+2μ)`), the limit becomes `(2/ω)(sqrt(1+ζ²) - ζ)`. The automatic substep is that
//! limit times a safety factor.

use super::{BodyInStep, CrushWatch, SolverWorkspace};
use crate::Error;
use crate::body::DeformableBody;
use crate::constraint::{self, BodyConstraints};
use crate::contact::{self, BetweenContact};
use rapier3d::glamx::DVec3;

/// Ratio of the critical explicit step to `ℓ / c_p`. The true limit `2/ω_max` (power iteration
/// on `M⁻¹K`) measured on generated boxes, beams, plates, cylinders and spheres lies between
/// 1.54 and 1.89 `ℓ / c_p` for `-0.5 <= ν <= 0.49`; 1.5 stays below all of them (see the
/// `explicit_stability` tests), and the default safety factor halves it again. The smallest
/// element altitude `h_min` in place of `ℓ` spreads from 0.93 to 1.75 on the same meshes, which
/// would cost up to twice the substeps.
pub const COURANT_NUMBER: f64 = 1.5;

/// Automatic substeps re-evaluate the stability limit every this many substeps.
const RECHECK_INTERVAL: u32 = 16;

/// How a frame step is split into substeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum Substeps {
    /// As many equal substeps as needed to stay below the stable step.
    #[default]
    Automatic,
    /// Exactly this many equal substeps, whatever the stability limit (at least 1; not capped
    /// by `max_substeps`).
    Fixed(u32),
}

/// The symplectic Euler integrator and its settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct SymplecticEuler {
    /// Fraction of the critical step used by [`Substeps::Automatic`] (dimensionless, in (0, 1]).
    pub safety_factor: f64,
    /// How frames are split into substeps.
    pub substeps: Substeps,
    /// The most substeps [`Substeps::Automatic`] may take in one frame; a frame needing more is
    /// refused with [`Error::TooManySubsteps`] instead of running for minutes.
    pub max_substeps: u32,
}

impl Default for SymplecticEuler {
    /// Automatic substeps at half the critical step: nonlinear stiffening, distorted elements and
    /// contacts all lower the limit below its rest-state estimate.
    fn default() -> Self {
        Self {
            safety_factor: 0.5,
            substeps: Substeps::Automatic,
            max_substeps: 100_000,
        }
    }
}

/// What one frame step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Number of substeps taken.
    pub substeps: u32,
    /// Length of the shortest substep (s): automatic substeps shorten within a frame when the
    /// stability limit drops (elements crushed by an impact).
    pub substep_dt: f64,
    /// Elements inverted at the end of the frame (volume ratio `J ≤ 0`, see
    /// [`DeformableBody::element_volume_ratios`](crate::body::DeformableBody::element_volume_ratios)).
    pub inverted_elements: usize,
}

impl SymplecticEuler {
    /// Estimated critical time step (s) of the explicit scheme for `body` in its current shape:
    /// steps above it make the highest modes grow. Zero if an element is flat. The elements'
    /// highest frequency `ω_e = 2c/ℓ` (`c` the pressure wave speed, `ℓ` the
    /// [wave length scale](DeformableBody::wave_length_scale)) is raised by the follower loads'
    /// stiffness to `sqrt(ω_e² + ω_l²)` (Gershgorin's bound, `ω_l` from the cables' `2T/d`, the
    /// pressures' `|p| s/6` and the chambers' liquids' rank-one stiffness over the nodal
    /// masses), the step scaled alike.
    pub fn critical_time_step(body: &DeformableBody) -> f64 {
        let mut undamped =
            COURANT_NUMBER * body.wave_length_scale() / body.material().dilatational_wave_speed();
        let loads = body.load_frequency_squared();
        if loads > 0.0 {
            let elements = 2.0 * COURANT_NUMBER / undamped;
            undamped = 2.0 * COURANT_NUMBER / (elements * elements + loads).sqrt();
        }
        let Some(damping) = body.damping() else {
            return undamped;
        };
        let omega = 2.0 / undamped;
        let beta = damping.p_wave_viscosity() / body.material().lame().p_wave_modulus();
        let zeta = 0.5 * beta * omega;
        // (2/ω)(sqrt(1+ζ²) - ζ), written so that a flat element (ω = ∞) gives 0, not NaN.
        2.0 / (omega * ((1.0 + zeta * zeta).sqrt() + zeta))
    }

    /// The substep (s) used by [`Substeps::Automatic`]: the critical step times the safety factor.
    pub fn stable_time_step(&self, body: &DeformableBody) -> f64 {
        self.safety_factor * Self::critical_time_step(body)
    }

    /// Advances `body` by `frame_dt` (s) under uniform gravity (m/s²), in substeps, against
    /// its `constraints`, with `workspace` its solver caches.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `frame_dt`;
    /// [`Error::InvalidSetting`] for a zero fixed substep count or a safety factor outside (0, 1];
    /// [`Error::NonFiniteInput`] for a non-finite gravity; [`Error::TooManySubsteps`] when the
    /// stability limit needs more than `max_substeps`; [`Error::NonFiniteState`] if the step
    /// produced a NaN or infinity; [`Error::ElementCrushed`] if it crushed an element (see
    /// [`COLLAPSE_RATIO`](crate::integrate::COLLAPSE_RATIO)). On error the body is left as it
    /// was before the call.
    pub fn step(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<StepReport, Error> {
        Error::check_step(frame_dt, gravity)?;
        let needed = self.needed_substeps(body, frame_dt)?;
        let mut step = BodyInStep {
            body,
            constraints,
            workspace,
        };
        crate::parallel::on_pool(|| self.advance(&mut step, frame_dt, gravity, needed))
    }

    /// Runs a frame in `needed` substeps (as given by [`SymplecticEuler::needed_substeps`]),
    /// refusing more than `max_substeps` when they are automatic.
    pub(crate) fn advance(
        &self,
        step: &mut BodyInStep<'_>,
        frame_dt: f64,
        gravity: DVec3,
        needed: f64,
    ) -> Result<StepReport, Error> {
        let one = BodyInStep {
            body: step.body,
            constraints: step.constraints,
            workspace: step.workspace,
        };
        let reports = self.advance_together(&mut [one], &mut [], frame_dt, gravity, needed)?;
        Ok(reports[0])
    }

    /// Advances soft `bodies` in contact with each other through `between` (indices into
    /// `bodies`) by `frame_dt` (s) together, in the same substeps: as many as the least stable of
    /// them needs. A report per body, in order.
    ///
    /// # Errors
    /// Those of [`SymplecticEuler::step`], for the first body at fault; every body is then left
    /// as it was.
    pub(crate) fn step_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        between: &mut [BetweenContact],
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<Vec<StepReport>, Error> {
        Error::check_step(frame_dt, gravity)?;
        let mut needed: f64 = 1.0;
        for step in bodies.iter() {
            needed = needed.max(self.needed_substeps(step.body, frame_dt)?);
        }
        self.advance_together(bodies, between, frame_dt, gravity, needed)
    }

    /// [`SymplecticEuler::step_together`] in `needed` substeps.
    fn advance_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        between: &mut [BetweenContact],
        frame_dt: f64,
        gravity: DVec3,
        needed: f64,
    ) -> Result<Vec<StepReport>, Error> {
        let automatic = self.substeps == Substeps::Automatic;
        if automatic && (needed.is_nan() || needed > f64::from(self.max_substeps)) {
            return Err(Error::TooManySubsteps {
                frame_dt,
                needed,
                max: self.max_substeps,
            });
        }
        let mut h = frame_dt / needed;
        let mut left = needed as u32;
        let (mut taken, mut elapsed, mut smallest) = (0u32, 0.0, h);
        let mut histories = Vec::with_capacity(bodies.len());
        let watches: Vec<CrushWatch> = bodies.iter().map(|s| CrushWatch::new(s.body)).collect();
        for step in bodies.iter_mut() {
            step.save();
            histories.push(step.workspace.previous_step.take());
        }
        let fail = |bodies: &mut [BodyInStep<'_>], histories: Vec<_>, error| {
            for (step, history) in bodies.iter_mut().zip(histories) {
                step.restore();
                step.workspace.previous_step = history;
            }
            Err(error)
        };
        while left > 0 {
            substep(bodies, between, h, gravity);
            left -= 1;
            taken += 1;
            elapsed += h;
            // Crushing elements lowers the limit within a frame (an impact flattens a soft
            // body in a few substeps): re-evaluate it now and then and shorten the rest.
            if automatic && left > 0 && taken % RECHECK_INTERVAL == 0 {
                let stable = bodies
                    .iter()
                    .map(|step| self.stable_time_step(step.body))
                    .fold(f64::INFINITY, f64::min);
                if stable < h {
                    let remaining = frame_dt - elapsed;
                    let more = (remaining / stable).ceil();
                    if more.is_nan() || f64::from(taken) + more > f64::from(self.max_substeps) {
                        let needed = f64::from(taken) + more;
                        let max = self.max_substeps;
                        return fail(
                            bodies,
                            histories,
                            Error::TooManySubsteps {
                                frame_dt,
                                needed,
                                max,
                            },
                        );
                    }
                    left = more as u32;
                    h = remaining / more;
                    smallest = h;
                }
            }
        }
        if let Some(node) = bodies.iter().find_map(|s| s.body.first_non_finite_node()) {
            return fail(bodies, histories, Error::NonFiniteState { node });
        }
        // Substeps below the stability limit of the crushed shape do not undo a crush (the
        // limit is re-evaluated as elements flatten): a crushed element is the material's
        // answer to the load, refused at once.
        let inverted: Result<Vec<usize>, Error> = bodies
            .iter()
            .zip(&watches)
            .map(|(step, watch)| watch.check(step.body))
            .collect();
        match inverted {
            Ok(inverted) => Ok(inverted
                .into_iter()
                .map(|inverted_elements| StepReport {
                    substeps: taken,
                    substep_dt: smallest,
                    inverted_elements,
                })
                .collect()),
            Err(error) => fail(bodies, histories, error),
        }
    }

    /// The substeps a frame of `frame_dt` (s) takes: the fixed count, or as many as the
    /// stability limit of the body's current shape asks for (possibly infinite or more than
    /// `max_substeps`, which [`SymplecticEuler::step`] then refuses).
    pub(crate) fn needed_substeps(
        &self,
        body: &DeformableBody,
        frame_dt: f64,
    ) -> Result<f64, Error> {
        match self.substeps {
            Substeps::Fixed(0) => Err(Error::InvalidSetting {
                parameter: "substeps",
                value: 0.0,
                reason: "a fixed substep count must be at least 1",
            }),
            Substeps::Fixed(n) => Ok(f64::from(n)),
            Substeps::Automatic => {
                if !(self.safety_factor > 0.0 && self.safety_factor <= 1.0) {
                    return Err(Error::InvalidSetting {
                        parameter: "safety_factor",
                        value: self.safety_factor,
                        reason: "must lie in (0, 1]",
                    });
                }
                Ok((frame_dt / self.stable_time_step(body)).ceil().max(1.0))
            }
        }
    }
}

/// One symplectic Euler substep of length `h` (s) of `bodies` and the contacts `between` them.
fn substep(bodies: &mut [BodyInStep<'_>], between: &mut [BetweenContact], h: f64, gravity: DVec3) {
    for step in bodies.iter_mut() {
        update_velocities(step, h, gravity);
    }
    if !between.is_empty() {
        contact::prepare_between(between, &soft_bodies(bodies), h);
    }
    let coupled = !between.is_empty() || bodies.iter().any(|s| s.constraints.coupled());
    let sweeps = if coupled {
        bodies
            .iter()
            .map(|s| s.constraints.contacts.settings.velocity_iterations)
            .max()
            .unwrap_or(1)
            .max(1)
    } else {
        1
    };
    for _ in 0..sweeps {
        for step in bodies.iter_mut() {
            for kind in constraint::EXPLICIT {
                kind.sweep(step.body, step.constraints);
            }
        }
        if !between.is_empty() {
            contact::solve_between(between, &mut soft_bodies(bodies));
        }
    }
    for step in bodies.iter_mut() {
        update_positions(step, h);
    }
}

/// The bodies of `steps`, for the contacts between them.
fn soft_bodies<'a>(steps: &'a mut [BodyInStep<'_>]) -> Vec<&'a mut DeformableBody> {
    steps.iter_mut().map(|s| &mut *s.body).collect()
}

/// The substep's velocity update `v ← v + h (f/m + g)` (`f` the internal forces and the loads'),
/// then the constraints readied for the sweeps.
fn update_velocities(step: &mut BodyInStep<'_>, h: f64, gravity: DVec3) {
    step.workspace.compute_forces(step.body);
    let DeformableBody {
        velocities,
        masses,
        pinned,
        ..
    } = &mut *step.body;
    let forces = &step.workspace.forces;
    for n in 0..velocities.len() {
        if !pinned[n] {
            velocities[n] += (forces[n] / masses[n] + gravity) * h;
        }
    }
    // The rigid bodies touched fall too, as rapier will make them (unless held).
    for proxy in &mut step.constraints.rigid_proxies {
        proxy.fall(gravity, h);
    }
    for kind in constraint::EXPLICIT {
        kind.prepare(step.body, step.constraints, h);
    }
}

/// The substep's position update `x ← x + h v` of the nodes and the rigid bodies touched, after
/// the sweeps.
fn update_positions(step: &mut BodyInStep<'_>, h: f64) {
    for kind in constraint::EXPLICIT {
        kind.advance(step.body, step.constraints, h);
    }
    // The rigid bodies touched move too, as the nodes do (their colliders with them).
    for proxy in &mut step.constraints.rigid_proxies {
        proxy.advance(h);
    }
    let DeformableBody {
        positions,
        velocities,
        pinned,
        ..
    } = &mut *step.body;
    for n in 0..positions.len() {
        if pinned[n] {
            velocities[n] = DVec3::ZERO;
        } else {
            positions[n] += velocities[n] * h;
        }
    }
}
