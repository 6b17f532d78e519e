//! Time integration of soft bodies: `M v̇ = f_int(x, v) + M g`, `ẋ = v`, with pinned nodes held.

mod automatic;
mod explicit;
mod implicit;
mod mesh_time_step;

pub use automatic::{AutomaticIntegrator, AutomaticReport, CostPrediction, IntegratorKind};
pub use explicit::{COURANT_NUMBER, StepReport, Substeps, SymplecticEuler};
pub use implicit::{ImplicitIntegrator, ImplicitReport, ImplicitScheme};
pub use mesh_time_step::MeshTimeSteps;

use crate::Error;
use rapier3d::glamx::DVec3;

/// The checks every integrator makes before stepping: a positive, finite frame step (s) and a
/// finite gravity (m/s²).
pub(crate) fn check_step(frame_dt: f64, gravity: DVec3) -> Result<(), Error> {
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
    Ok(())
}
