//! Refused frames that would be refused again. A refused frame leaves its body as it was; if
//! nothing the next frame reads changes (a body crushed by an impact it cannot take, alone on a
//! fixed ground), the next frame repeats the same computation to the same refusal, which on a
//! large implicit body costs seconds a frame. Contract: a frame of
//! [`AutomaticIntegrator::step`](super::AutomaticIntegrator::step) whose inputs equal, bit for
//! bit, those of the last frame refused after a refusal is refused at once with the same error,
//! without the work. The inputs are the body's positions, velocities and loads, its
//! constraints (contacts as detected, attachments, the rigid bodies' proxies), the frame's
//! length and gravity, the integrator's plan for the frame (the choice, the substeps and the
//! implicit integrator's settings) and the two-step history; the only other cache a step reads,
//! the chord method's kept factorization, is dropped at every refusal, so a frame's outcome is a
//! function of these inputs alone. The first refusal records nothing (its inputs are not kept on
//! frames that succeed, to cost nothing there); the frame after it is tried, and its inputs kept
//! if it is refused too.

use super::workspace::PreviousStep;
use super::{ImplicitIntegrator, IntegratorKind};
use crate::Error;
use crate::body::DeformableBody;
use crate::constraint::BodyConstraints;
use crate::load::Load;
use rapier3d::glamx::DVec3;

/// What a frame of the automatic integrator reads (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct FrameInputs {
    positions: Vec<DVec3>,
    velocities: Vec<DVec3>,
    loads: Vec<Load>,
    constraints: BodyConstraints,
    /// The frame's length (s) and gravity (m/s²).
    frame: (f64, DVec3),
    /// The integrator chosen, the explicit substeps needed, and the implicit integrator's
    /// settings for the frame.
    plan: (IntegratorKind, f64, ImplicitIntegrator),
    previous_step: Option<PreviousStep>,
}

impl FrameInputs {
    /// The inputs of a frame of `frame` (length in s, gravity in m/s²) by `plan` for `body`
    /// against `constraints`, with the two-step history `previous_step`.
    pub(crate) fn of(
        (body, constraints): (&DeformableBody, &BodyConstraints),
        frame: (f64, DVec3),
        plan: (IntegratorKind, f64, ImplicitIntegrator),
        previous_step: Option<&PreviousStep>,
    ) -> Self {
        Self {
            positions: body.positions.clone(),
            velocities: body.velocities.clone(),
            loads: body.loads.clone(),
            constraints: constraints.clone(),
            frame,
            plan,
            previous_step: previous_step.cloned(),
        }
    }
}

impl PartialEq for FrameInputs {
    fn eq(&self, other: &Self) -> bool {
        self.frame == other.frame
            && self.plan == other.plan
            && self.positions == other.positions
            && self.velocities == other.velocities
            && self.loads == other.loads
            && self.previous_step == other.previous_step
            && self.constraints.same_as(&other.constraints)
    }
}

/// A body's refused frames, as its workspace remembers them.
#[derive(Debug, Clone, Default)]
pub(crate) enum Refusals {
    /// The last frame was not refused.
    #[default]
    None,
    /// The last frame was refused; its inputs were not kept.
    Refused,
    /// The last frame was refused from `inputs` with `error`.
    Recorded {
        inputs: Box<FrameInputs>,
        error: Error,
    },
}

impl Refusals {
    /// Whether the next frame's inputs are to be kept: the last frame was refused.
    pub(crate) fn watching(&self) -> bool {
        !matches!(self, Self::None)
    }

    /// The error of the last refused frame if `inputs` are its inputs.
    pub(crate) fn repeated(&self, inputs: &FrameInputs) -> Option<Error> {
        match self {
            Self::Recorded {
                inputs: recorded,
                error,
            } if **recorded == *inputs => Some(error.clone()),
            _ => None,
        }
    }

    /// Takes in a frame's `outcome`, from `inputs` if they were kept.
    pub(crate) fn record<T>(&mut self, outcome: &Result<T, Error>, inputs: Option<FrameInputs>) {
        *self = match (outcome, inputs) {
            (Ok(_), _) => Self::None,
            (Err(error), Some(inputs)) => Self::Recorded {
                inputs: Box::new(inputs),
                error: error.clone(),
            },
            (Err(_), None) => Self::Refused,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::Refusals;
    use crate::Error;
    use crate::body::{DeformableBody, DeformableBodyBuilder};
    use crate::constraint::BodyConstraints;
    use crate::integrate::cost::NewtonHistory;
    use crate::integrate::{AutomaticIntegrator, IntegratorKind, SolverWorkspace};
    use crate::material::{Material, MaterialModel};
    use crate::mesh::TetMesh;
    use rapier3d::glamx::DVec3;

    /// One tetrahedron (h = 0.1 m, E = 1 Pa) whose base is pinned and whose apex falls through
    /// the base at 12 m/s: 0.2 m in a 1/60 s frame, so every frame crushes it and is refused.
    fn falling_apex() -> DeformableBody {
        let h = 0.1;
        let positions = vec![DVec3::ZERO, DVec3::X * h, DVec3::Y * h, DVec3::Z * h];
        let mesh = TetMesh::new(positions, vec![[0, 1, 2, 3]]).unwrap();
        let material = Material::new(MaterialModel::StableNeoHookean, 1.0, 0.3, 1000.0).unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, material)
            .pinned_nodes(vec![0, 1, 2])
            .build()
            .unwrap();
        body.set_node_velocity(3, DVec3::new(0.0, 0.0, -12.0))
            .unwrap();
        body
    }

    /// A refused frame is tried again once (its inputs then kept); a third frame from the same
    /// inputs is refused at once with the same error: the body's mean Newton iterations, emptied
    /// before it, are not filled by an implicit attempt (the forced choice does not read them).
    /// A changed velocity is a new input, tried again; a frame that succeeds forgets the
    /// refusals.
    #[test]
    fn a_frame_refused_from_the_same_inputs_is_not_recomputed() {
        let mut body = falling_apex();
        let integrator = AutomaticIntegrator {
            force: Some(IntegratorKind::Implicit),
            ..AutomaticIntegrator::default()
        };
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let mut frame = |body: &mut DeformableBody, workspace: &mut SolverWorkspace| {
            let outcome =
                integrator.step(body, &mut constraints, workspace, 1.0 / 60.0, DVec3::ZERO);
            outcome.map(|_| ())
        };
        let attempted = |workspace: &SolverWorkspace| workspace.newton.has_history();
        let first = frame(&mut body, &mut workspace);
        let Err(error @ Error::ElementCrushed { .. }) = first else {
            panic!("{first:?}");
        };
        assert!(matches!(workspace.refusals, Refusals::Refused));
        assert_eq!(frame(&mut body, &mut workspace), Err(error.clone()));
        assert!(matches!(workspace.refusals, Refusals::Recorded { .. }));
        workspace.newton = NewtonHistory::default();
        assert_eq!(frame(&mut body, &mut workspace), Err(error.clone()));
        assert!(!attempted(&workspace), "no attempt was made");
        body.set_node_velocity(3, DVec3::new(0.0, 0.0, -11.0))
            .unwrap();
        assert!(frame(&mut body, &mut workspace).is_err());
        assert!(attempted(&workspace), "a new input is tried");
        body.set_node_velocity(3, DVec3::ZERO).unwrap();
        assert_eq!(frame(&mut body, &mut workspace), Ok(()));
        assert!(matches!(workspace.refusals, Refusals::None));
    }
}
