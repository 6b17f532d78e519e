//! Explicit dynamics of a 2D body: symplectic Euler, `v ← v + h M⁻¹ (f_int(x, v) + M g + f_ext)`
//! then `x ← x + h v`, with held axes kept at rest, in substeps below the stability limit.
//!
//! The internal forces are the elastic ones plus the Rayleigh damping's on the Green strain
//! rate ([`PlaneModel::damping_stress`](super::PlaneModel::damping_stress)), which is zero for
//! every rigid motion. Both have no net force and, evaluated at one configuration, no net
//! torque, so a free body's linear and angular momentum are kept by each substep to round-off
//! (`L' = Σ m (x + h v') × v' = Σ m x × v' = L`).
//!
//! The stability limit: `ω_max² ≤ max_i Σ_j |K_ij| / m_i` (Gershgorin's bound on `M⁻¹K`, with
//! the tangent at the frame's start), and for damping of P-wave viscosity `η` against the
//! P-wave modulus `M_p` (`β = η / M_p`, `ζ = β ω / 2`), the limit `2 (√(1 + ζ²) − ζ) / ω`.
//! Substeps are that limit times [`SAFETY_FACTOR`]: the bound is an upper bound on `ω`, and the
//! factor leaves room for the stiffening of large deformation within the frame.

use super::body::PlanarBody;
use super::unknowns::Unknowns;
use crate::Error;
use rapier3d::glamx::DVec2;

/// The fraction of the stability limit a substep takes.
pub const SAFETY_FACTOR: f64 = 0.5;

/// The most substeps a frame may take.
const MAX_SUBSTEPS: u32 = 1_000_000;

/// What [`step_explicit`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarStepReport {
    /// Substeps taken.
    pub substeps: u32,
    /// Their length (s).
    pub substep_dt: f64,
    /// Whether the step was implicit (one backward Euler step, `planar::coupling`'s
    /// `PlanarIntegrator::Implicit`, feature `dim2`).
    pub implicit: bool,
}

impl PlanarBody {
    /// The explicit scheme's stability limit (s) where the body is (see the module's
    /// documentation); infinite for a body with every axis held.
    pub fn critical_time_step(&self) -> f64 {
        let free = Unknowns::new(&vec![[false; 2]; self.positions().len()]);
        let triplets = free.elastic_entries(self, self.positions());
        let mut row_sums = vec![0.0; 2 * self.positions().len()];
        for t in &triplets {
            row_sums[t.row] += t.val.abs();
        }
        let omega_squared = (row_sums.iter().enumerate())
            .filter(|(row, _)| !self.pinned[row / 2][row % 2])
            .map(|(row, sum)| sum / self.masses()[row / 2])
            .fold(0.0, f64::max);
        if omega_squared == 0.0 {
            return f64::INFINITY;
        }
        let omega = omega_squared.sqrt();
        let beta = self.damping().map_or(0.0, |d| {
            d.p_wave_viscosity() / self.material().lame().p_wave_modulus()
        });
        let zeta = 0.5 * beta * omega;
        2.0 / (omega * ((1.0 + zeta * zeta).sqrt() + zeta))
    }

    /// The internal forces (N): elastic and damping, where the body is and as it moves.
    pub fn internal_forces_with_damping(&self) -> Vec<DVec2> {
        let mut forces = self.internal_forces();
        let Some(damping) = self.damping() else {
            return forces;
        };
        let plane = self.plane();
        let points = self.points();
        for q in 0..points.len() {
            let f = points.gradient(q, self.positions());
            let f_dot = points.gradient(q, self.velocities());
            let p = plane.damping_stress(damping, &f, &f_dot);
            points.add_forces(q, &p, self.thickness(), &mut forces);
        }
        forces
    }
}

/// Advances `body` by `dt` (s) under `gravity` (m/s²) and the nodal `loads` (N, one per node),
/// in equal substeps below [`SAFETY_FACTOR`] times [`PlanarBody::critical_time_step`] at the
/// start.
///
/// # Errors
/// [`Error::InvalidTimeStep`] for a `dt` that is not positive and finite,
/// [`Error::NonFiniteInput`] for a non-finite gravity or load, [`Error::WrongNodeCount`] for
/// loads of the wrong length, [`Error::TooManySubsteps`] beyond a million substeps,
/// [`Error::NonFiniteState`] if the step made a position or velocity non-finite. On error the
/// body is left as it was.
pub fn step_explicit(
    body: &mut PlanarBody,
    dt: f64,
    gravity: DVec2,
    loads: &[DVec2],
) -> Result<PlanarStepReport, Error> {
    check_step(body, dt, gravity, loads)?;
    advance(body, dt, (gravity, loads), 0.0, &mut |_| None)
}

/// Checks a step of `dt` (s) of `body` under `gravity` (m/s²) and nodal `loads` (N).
///
/// # Errors
/// [`Error::InvalidTimeStep`] for a `dt` that is not positive and finite,
/// [`Error::NonFiniteInput`] for a non-finite gravity or load, [`Error::WrongNodeCount`] for
/// loads of the wrong length.
pub(super) fn check_step(
    body: &PlanarBody,
    dt: f64,
    gravity: DVec2,
    loads: &[DVec2],
) -> Result<(), Error> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::InvalidTimeStep {
            dt,
            reason: "a frame step must be positive and finite",
        });
    }
    if !gravity.is_finite() || loads.iter().any(|f| !f.is_finite()) {
        return Err(Error::NonFiniteInput {
            parameter: "gravity or loads",
        });
    }
    let node_count = body.positions().len();
    if loads.len() != node_count {
        return Err(Error::WrongNodeCount {
            given: loads.len(),
            node_count,
        });
    }
    Ok(())
}

/// Forces (N per node) a step adds at each substep, computed where the body is and as it
/// moves, or `None` for none: contacts with colliders (`planar::coupling`, feature `dim2`).
pub(super) type ExtraForces<'a> = dyn FnMut(&PlanarBody) -> Option<Vec<DVec2>> + 'a;

/// How many explicit substeps (not rounded) a step of `dt` (s) of `body` needs: `dt` over
/// [`SAFETY_FACTOR`] times its stability limit, lowered for a frequency `ω_extra²` (1/s²) that
/// extra forces (contacts) add to its highest.
pub(super) fn explicit_substeps(body: &PlanarBody, dt: f64, extra_frequency_squared: f64) -> f64 {
    let undamped = body.critical_time_step();
    let limit = if extra_frequency_squared > 0.0 {
        let omega = 2.0 / undamped;
        SAFETY_FACTOR * undamped * omega / (omega * omega + extra_frequency_squared).sqrt()
    } else {
        SAFETY_FACTOR * undamped
    };
    dt / limit
}

/// [`step_explicit`]'s substeps, with `extra` forces added at each and the stability limit
/// lowered for a frequency `ω_extra²` (1/s²) they add to the highest.
pub(super) fn advance(
    body: &mut PlanarBody,
    dt: f64,
    (gravity, loads): (DVec2, &[DVec2]),
    extra_frequency_squared: f64,
    extra: &mut ExtraForces<'_>,
) -> Result<PlanarStepReport, Error> {
    let needed = explicit_substeps(body, dt, extra_frequency_squared).ceil();
    if needed.is_nan() || needed > f64::from(MAX_SUBSTEPS) {
        return Err(Error::TooManySubsteps {
            frame_dt: dt,
            needed,
            max: MAX_SUBSTEPS,
        });
    }
    let substeps = (needed as u32).max(1);
    let h = dt / f64::from(substeps);
    let saved = (body.positions().to_vec(), body.velocities().to_vec());
    for _ in 0..substeps {
        let extra_forces = extra(body);
        substep(body, h, gravity, loads, extra_forces.as_deref());
    }
    let state = body.positions().iter().zip(body.velocities());
    if let Some(node) = state
        .clone()
        .position(|(x, v)| !(x.is_finite() && v.is_finite()))
    {
        body.positions_mut().copy_from_slice(&saved.0);
        body.velocities_mut().copy_from_slice(&saved.1);
        return Err(Error::NonFiniteState { node });
    }
    Ok(PlanarStepReport {
        substeps,
        substep_dt: h,
        implicit: false,
    })
}

/// One symplectic Euler substep of `h` (s), with the `extra` forces (N per node) if any.
fn substep(
    body: &mut PlanarBody,
    h: f64,
    gravity: DVec2,
    loads: &[DVec2],
    extra: Option<&[DVec2]>,
) {
    let mut forces = body.internal_forces_with_damping();
    if let Some(extra) = extra {
        for (f, e) in forces.iter_mut().zip(extra) {
            *f += *e;
        }
    }
    for (f, load) in forces.iter_mut().zip(loads) {
        *f += *load;
    }
    body.kick_and_drift(h, &forces, gravity);
}
