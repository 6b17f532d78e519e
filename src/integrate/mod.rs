//! Time integration of soft bodies: `M v̇ = f_int(x, v) + M g`, `ẋ = v`, with pinned nodes held.

mod automatic;
mod explicit;
mod implicit;
mod mesh_time_step;

pub use automatic::{AutomaticIntegrator, AutomaticReport, CostPrediction, IntegratorKind};
pub use explicit::{COURANT_NUMBER, StepReport, Substeps, SymplecticEuler};
pub use implicit::{ImplicitIntegrator, ImplicitReport, ImplicitScheme};
pub use mesh_time_step::MeshTimeSteps;
