//! What the integrators keep of a body between steps, apart from the body itself: scratch
//! forces, the nodal state saved before a step (restored if it fails), the state at the start of
//! the last implicit step (for two-step schemes), the sparse tangent's pattern and symbolic
//! factorization, and the chord method's last numeric factorization.

use super::PreviousStep;
use crate::assembly::Stiffness;
use crate::chord::Chord;
use rapier3d::glamx::DVec3;

/// The solver caches of one body.
#[derive(Debug, Clone, Default)]
pub(crate) struct SolverWorkspace {
    /// The last internal forces computed (N per node).
    pub(crate) forces: Vec<DVec3>,
    /// Positions (m) saved before a step, restored if the step fails.
    pub(crate) saved_positions: Vec<DVec3>,
    /// Velocities (m/s) saved with them.
    pub(crate) saved_velocities: Vec<DVec3>,
    /// The state at the start of the last implicit substep, for two-step schemes; cleared by any
    /// other change of the state.
    pub(crate) previous_step: Option<PreviousStep>,
    /// The sparse tangent's pattern and symbolic factorization, built by the first implicit or
    /// static solve and kept for the next.
    pub(crate) tangent: Option<Stiffness>,
    /// The implicit integrator's last factorization, kept for reuse by the chord method.
    pub(crate) chord: Chord,
}

impl SolverWorkspace {
    /// An empty workspace for a body of `node_count` nodes.
    pub(crate) fn new(node_count: usize) -> Self {
        Self {
            forces: vec![DVec3::ZERO; node_count],
            saved_positions: Vec::with_capacity(node_count),
            saved_velocities: Vec::with_capacity(node_count),
            ..Self::default()
        }
    }
}
