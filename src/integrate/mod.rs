//! Time integration of soft bodies: `M v̇ = f_int(x, v) + M g`, `ẋ = v`, with pinned nodes held.
//!
//! An integrator steps a [`DeformableBody`] against its [`BodyConstraints`] with its
//! [`SolverWorkspace`]: the body holds the state, the constraints what acts on it from outside,
//! the workspace the solver's caches.

mod automatic;
mod choice;
mod cost;
mod crush;
mod explicit;
mod implicit;
mod mesh_time_step;
mod refusal;
mod workspace;

pub use automatic::AutomaticIntegrator;
pub use choice::{AutomaticReport, CostPrediction, IntegratorKind, SWITCH_MARGIN};
pub use cost::{CostModel, NewtonWork};
pub use crush::COLLAPSE_RATIO;
pub(crate) use crush::CrushWatch;
pub use explicit::{COURANT_NUMBER, StepReport, Substeps, SymplecticEuler};
pub use implicit::{ImplicitIntegrator, ImplicitReport, ImplicitScheme, MAX_REFINEMENT};
pub use mesh_time_step::MeshTimeSteps;
pub(crate) use workspace::PreviousStep;
pub use workspace::SolverWorkspace;

use crate::body::DeformableBody;
use crate::constraint::BodyConstraints;

/// A body as a step sees it: the body, the constraints it is stepped against, and its solver
/// caches.
pub(crate) struct BodyInStep<'a> {
    pub(crate) body: &'a mut DeformableBody,
    pub(crate) constraints: &'a mut BodyConstraints,
    pub(crate) workspace: &'a mut SolverWorkspace,
}

impl BodyInStep<'_> {
    /// Sets the body's state and its constraints' moving parts aside before a step.
    pub(crate) fn save(&mut self) {
        self.workspace.save_state(self.body);
        self.constraints.save();
    }

    /// Puts back what [`BodyInStep::save`] set aside.
    pub(crate) fn restore(&mut self) {
        self.workspace.restore_state(self.body);
        self.constraints.restore();
    }
}
