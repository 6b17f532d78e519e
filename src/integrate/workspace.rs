//! What the integrators keep of a body between steps, beside the body itself: scratch forces,
//! the nodal state saved before a step (restored if it fails), the state at the start of the
//! last implicit step (for two-step schemes), the sparse tangent's pattern and symbolic
//! factorization, the chord method's last numeric factorization, the body's mean Newton
//! iterations (for the automatic choice), and what its last refused frame started from. None of
//! it is the body's
//! state: an empty workspace steps a body to the same result, except that BDF2 restarts with a
//! backward Euler step and the first Newton iteration refactors.

use super::cost::NewtonHistory;
use super::refusal::Refusals;
use crate::assembly::Stiffness;
use crate::body::DeformableBody;
use crate::chord::Chord;
use rapier3d::glamx::DVec3;

/// The solver caches of one deformable body.
///
/// [`SoftCoupling`](crate::coupling::SoftCoupling) keeps one per body; a program stepping a
/// body alone with an integrator keeps its own beside the body (see
/// [`BodyConstraints`](crate::constraint::BodyConstraints) for an example). Give each body its
/// own: a workspace used for another body is rebuilt.
///
/// With the feature `serde-serialize` it is written as the two-step history, the pause and
/// matrix of the kept factorization, and the node pairs the tangent couples beyond the mesh's;
/// read back, the tangent and the factorization are made again at the next implicit step, the
/// same as they were, so a restored run continues as the original.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(into = "WorkspaceRecord", from = "WorkspaceRecord")
)]
pub struct SolverWorkspace {
    /// The node and tetrahedron counts of the body the caches were made for.
    fitted: (usize, usize),
    /// The last internal forces computed (N per node).
    pub(crate) forces: Vec<DVec3>,
    /// Positions (m) saved before a step, restored if the step fails.
    saved_positions: Vec<DVec3>,
    /// Velocities (m/s) saved with them.
    saved_velocities: Vec<DVec3>,
    /// The state at the start of the last implicit substep, for two-step schemes.
    pub(crate) previous_step: Option<PreviousStep>,
    /// The sparse tangent's pattern and symbolic factorization, built by the first implicit or
    /// static solve and kept for the next.
    pub(crate) tangent: Option<Stiffness>,
    /// The tangent of the last group of touching bodies this body was the first of (see
    /// [`ImplicitIntegrator::step_together`](super::ImplicitIntegrator)), whose symbolic
    /// factorization the next group's tangent takes over when their patterns are the same.
    pub(crate) group_tangent: Option<Stiffness>,
    /// The implicit integrator's last factorization, kept for reuse by the chord method.
    pub(crate) chord: Chord,
    /// The body's Newton iterations per implicit substep, for the automatic choice's cost.
    pub(crate) newton: NewtonHistory,
    /// The last frame's refusal, if it was refused (see [`super::refusal`]); not written.
    pub(crate) refusals: Refusals,
    /// Read back: the node pairs the tangent coupled beyond the mesh's, for its next build.
    #[cfg(feature = "serde-serialize")]
    pending_pairs: Vec<[u32; 2]>,
}

/// What a [`SolverWorkspace`] is written as.
#[cfg(feature = "serde-serialize")]
#[derive(serde::Serialize, serde::Deserialize)]
struct WorkspaceRecord {
    fitted: (usize, usize),
    previous_step: Option<PreviousStep>,
    tangent_pairs: Vec<[u32; 2]>,
    chord: Chord,
    #[serde(default)]
    newton: NewtonHistory,
}

#[cfg(feature = "serde-serialize")]
impl From<SolverWorkspace> for WorkspaceRecord {
    fn from(workspace: SolverWorkspace) -> Self {
        let tangent_pairs = match &workspace.tangent {
            Some(tangent) => tangent.extra_pairs().to_vec(),
            None => workspace.pending_pairs,
        };
        Self {
            fitted: workspace.fitted,
            previous_step: workspace.previous_step,
            tangent_pairs,
            chord: workspace.chord,
            newton: workspace.newton,
        }
    }
}

#[cfg(feature = "serde-serialize")]
impl From<WorkspaceRecord> for SolverWorkspace {
    fn from(record: WorkspaceRecord) -> Self {
        Self {
            fitted: record.fitted,
            forces: vec![DVec3::ZERO; record.fitted.0],
            previous_step: record.previous_step,
            chord: record.chord,
            newton: record.newton,
            pending_pairs: record.tangent_pairs,
            ..Self::default()
        }
    }
}

/// The state at the start of an implicit substep of length `h` (s), kept for the next one.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct PreviousStep {
    pub(crate) h: f64,
    pub(crate) positions: Vec<DVec3>,
    pub(crate) velocities: Vec<DVec3>,
    /// The body's [`DeformableBody::state_edits`] when the step ended: an edit of the state since
    /// then makes it stale.
    pub(crate) edits: u64,
}

impl SolverWorkspace {
    /// An empty workspace.
    pub fn new() -> Self {
        Self::default()
    }

    /// Fits the workspace to `body`: caches made for a body of other node or tetrahedron counts
    /// are dropped.
    pub(crate) fn fit(&mut self, body: &DeformableBody) {
        let fitted = (body.node_count(), body.mesh().tet_count());
        if self.fitted != fitted || self.forces.len() != fitted.0 {
            *self = Self {
                fitted,
                forces: vec![DVec3::ZERO; fitted.0],
                ..Self::default()
            };
        }
    }

    /// The state at the start of the last implicit substep, if the body was not edited since
    /// that step ended.
    pub(crate) fn history(&self, body: &DeformableBody) -> Option<&PreviousStep> {
        let nodes = body.node_count();
        self.previous_step.as_ref().filter(|p| {
            p.edits == body.state_edits()
                && p.positions.len() == nodes
                && p.velocities.len() == nodes
        })
    }

    /// Recomputes [`SolverWorkspace::forces`] for `body`: its internal forces and its loads'
    /// but gravity's.
    pub(crate) fn compute_forces(&mut self, body: &mut DeformableBody) {
        self.fit(body);
        body.internal_forces_into(&mut self.forces);
        body.add_load_forces(&mut self.forces);
    }

    /// Copies `body`'s positions and velocities aside (no allocation after the first call).
    pub(crate) fn save_state(&mut self, body: &DeformableBody) {
        self.fit(body);
        self.saved_positions.clone_from(&body.positions);
        self.saved_velocities.clone_from(&body.velocities);
    }

    /// Puts back the state saved by [`SolverWorkspace::save_state`].
    pub(crate) fn restore_state(&self, body: &mut DeformableBody) {
        body.positions.clone_from(&self.saved_positions);
        body.velocities.clone_from(&self.saved_velocities);
    }

    /// The tangent workspace for `body`, built on first use; give it back with
    /// `self.tangent = Some(..)`.
    pub(crate) fn take_tangent(&mut self, body: &DeformableBody) -> Stiffness {
        self.fit(body);
        let load_pairs = body.load_pairs();
        if let Some(tangent) = self.tangent.take() {
            // A load added since the pattern was made may couple nodes it does not.
            let missing: Vec<[u32; 2]> = (load_pairs.into_iter())
                .filter(|&[a, b]| !tangent.couples(a, b))
                .collect();
            return match missing.is_empty() {
                true => tangent,
                false => tangent
                    .widened(&missing)
                    .unwrap_or_else(|| Stiffness::new(body)),
            };
        }
        self.tangent.take().unwrap_or_else(|| {
            let mesh = Stiffness::new(body);
            #[cfg(feature = "serde-serialize")]
            if let Some(widened) = mesh.widened(&std::mem::take(&mut self.pending_pairs)) {
                return widened;
            }
            mesh
        })
    }
}
