//! Automatic choice between explicit and implicit integration: for each frame, the cost of the
//! explicit substeps the stability limit requires is compared with the cost of an implicit step,
//! and the cheaper is taken. Explicit integration is preferred at equal cost: it has no numerical
//! damping.
//!
//! The costs per tetrahedron were measured on this crate's development machine (one core of a
//! 2-core AMD EPYC, undamped beams of 50 to 25 600 tetrahedra): an explicit substep costs about
//! 20 ns per tetrahedron (90 ns for the corotated model, whose polar decomposition dominates;
//! damping adds about half), an implicit Newton iteration about 6 µs (7 µs), and an implicit frame
//! takes about 3.5 Newton iterations. Only their ratio matters for the choice.

use super::{
    BodyInStep, ImplicitIntegrator, ImplicitReport, SolverWorkspace, StepReport, SymplecticEuler,
};
use crate::Error;
use crate::body::DeformableBody;
use crate::constraint::BodyConstraints;
use crate::contact::{BetweenContact, ContactSettings};
use crate::material::MaterialModel;
use rapier3d::glamx::DVec3;

/// Seconds per tetrahedron per explicit substep, for the model.
fn explicit_cost_per_tet(model: MaterialModel) -> f64 {
    match model {
        MaterialModel::Corotated => 90e-9,
        _ => 20e-9,
    }
}

/// Seconds per tetrahedron per Newton iteration, for the model.
fn newton_cost_per_tet(model: MaterialModel) -> f64 {
    match model {
        MaterialModel::Corotated => 7e-6,
        _ => 6e-6,
    }
}

/// Newton iterations an implicit frame typically takes.
const NEWTON_ITERATIONS_PER_FRAME: f64 = 3.5;

/// Which integrator advanced a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum IntegratorKind {
    /// [`SymplecticEuler`].
    Explicit,
    /// [`ImplicitIntegrator`].
    Implicit,
}

/// The predicted cost of a frame with each integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostPrediction {
    /// Substeps the explicit stability limit requires.
    pub explicit_substeps: f64,
    /// Predicted time of the explicit frame (s).
    pub explicit_seconds: f64,
    /// Predicted time of the implicit frame (s).
    pub implicit_seconds: f64,
}

impl CostPrediction {
    /// The cheaper integrator, explicit on a tie.
    pub fn cheaper(&self) -> IntegratorKind {
        if self.explicit_seconds <= self.implicit_seconds {
            IntegratorKind::Explicit
        } else {
            IntegratorKind::Implicit
        }
    }
}

/// What an automatic frame did and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutomaticReport {
    /// The integrator used.
    pub choice: IntegratorKind,
    /// The prediction the choice was made on.
    pub prediction: CostPrediction,
    /// The explicit frame's report, if explicit.
    pub explicit: Option<StepReport>,
    /// The implicit frame's report, if implicit.
    pub implicit: Option<ImplicitReport>,
    /// Whether the frame was chosen explicit but redone implicitly, because crushed elements
    /// lowered the stability limit partway below what `max_substeps` allows, or the explicit
    /// frame produced a non-finite state.
    pub fell_back: bool,
}

/// Picks, frame by frame, the cheaper of an explicit and an implicit integrator.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct AutomaticIntegrator {
    /// The explicit integrator (its automatic substeps set the explicit cost).
    pub explicit: SymplecticEuler,
    /// The implicit integrator.
    pub implicit: ImplicitIntegrator,
    /// Forces one integrator instead of choosing.
    pub force: Option<IntegratorKind>,
}

impl AutomaticIntegrator {
    /// The predicted cost of a frame of `frame_dt` (s) for `body` with each integrator; an
    /// invalid explicit setting predicts an infinite explicit cost.
    pub fn predict(&self, body: &DeformableBody, frame_dt: f64) -> CostPrediction {
        let needed = self
            .explicit
            .needed_substeps(body, frame_dt)
            .unwrap_or(f64::INFINITY);
        self.prediction(body, needed)
    }

    /// The prediction for a frame whose explicit version takes `explicit_substeps`.
    fn prediction(&self, body: &DeformableBody, explicit_substeps: f64) -> CostPrediction {
        let tets = body.mesh().tet_count() as f64;
        let model = body.material().model();
        let implicit_frames = f64::from(self.implicit.substeps.max(1));
        CostPrediction {
            explicit_substeps,
            explicit_seconds: explicit_substeps * tets * explicit_cost_per_tet(model),
            implicit_seconds: implicit_frames
                * NEWTON_ITERATIONS_PER_FRAME
                * tets
                * newton_cost_per_tet(model),
        }
    }

    /// Advances `body` by `frame_dt` (s) under gravity (m/s²) against its `constraints`, with
    /// `workspace` its solver caches, by the cheaper integrator (or the forced one); explicit
    /// while the body has self-contacts or rigid corners against its surface.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `frame_dt`, [`Error::NonFiniteInput`]
    /// for a non-finite gravity,
    /// [`Error::InvalidSetting`] for an invalid explicit setting, then the errors of
    /// [`SymplecticEuler::step`] or [`ImplicitIntegrator::step`], whichever ran.
    pub fn step(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        workspace: &mut SolverWorkspace,
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<AutomaticReport, Error> {
        Error::check_step(frame_dt, gravity)?;
        // The stability limit is evaluated once and serves both the prediction and the step.
        let needed = self.explicit.needed_substeps(body, frame_dt)?;
        let prediction = self.prediction(body, needed);
        // Self-contacts and rigid corners keep the explicit integrator: the cost model does not
        // price their implicit terms (a forced implicit step solves them).
        let choice = self.force.unwrap_or_else(|| {
            if constraints.needs_explicit_contacts() {
                IntegratorKind::Explicit
            } else {
                prediction.cheaper()
            }
        });
        let explicit = match choice {
            IntegratorKind::Explicit => {
                let mut step = BodyInStep {
                    body,
                    constraints,
                    workspace,
                };
                Some(self.explicit.advance(&mut step, frame_dt, gravity, needed))
            }
            IntegratorKind::Implicit => None,
        };
        let (explicit, fell_back) = self.explicit_outcome(explicit)?;
        let implicit = match explicit {
            Some(_) => None,
            None => Some(
                self.implicit
                    .step(body, constraints, workspace, frame_dt, gravity)?,
            ),
        };
        Ok(AutomaticReport {
            choice: if fell_back {
                IntegratorKind::Implicit
            } else {
                choice
            },
            prediction,
            explicit,
            implicit,
            fell_back,
        })
    }

    /// What an explicit frame (if one ran) leaves: its report, and whether the frame must be
    /// redone implicitly because it would take too many substeps or gave a non-finite state
    /// (the explicit integrator then left the bodies as they were), unless a choice is forced.
    ///
    /// # Errors
    /// The explicit frame's other errors, and those two when explicit is forced.
    fn explicit_outcome<T>(
        &self,
        explicit: Option<Result<T, Error>>,
    ) -> Result<(Option<T>, bool), Error> {
        match explicit {
            Some(Ok(report)) => Ok((Some(report), false)),
            Some(Err(Error::TooManySubsteps { .. } | Error::NonFiniteState { .. }))
                if self.force.is_none() =>
            {
                Ok((None, true))
            }
            Some(Err(error)) => Err(error),
            None => Ok((None, false)),
        }
    }

    /// Advances soft `bodies` touching each other through `between` (indices into `bodies`)
    /// by `frame_dt` (s) together, with `settings` for the contacts between them: forced
    /// implicit, as one implicit system; otherwise explicitly, their contacts solved in the
    /// explicit sweeps with both bodies' nodes, and, unless explicit is forced, redone as one
    /// implicit system when the explicit frame would take more than `max_substeps` or gave a
    /// non-finite state. A report per body, in order.
    ///
    /// # Errors
    /// Those of [`SymplecticEuler::step`] or [`ImplicitIntegrator::step`], whichever ran last;
    /// every body is then left as it was.
    pub(crate) fn step_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        (between, settings): (&mut [BetweenContact], &ContactSettings),
        frame_dt: f64,
        gravity: DVec3,
    ) -> Result<Vec<AutomaticReport>, Error> {
        let predictions: Vec<CostPrediction> = bodies
            .iter()
            .map(|step| self.predict(step.body, frame_dt))
            .collect();
        let explicit = match self.force {
            Some(IntegratorKind::Implicit) => None,
            _ => Some(
                self.explicit
                    .step_together(bodies, between, frame_dt, gravity),
            ),
        };
        let (explicit, fell_back) = self.explicit_outcome(explicit)?;
        let reports: Vec<(Option<StepReport>, Option<ImplicitReport>)> = match explicit {
            Some(reports) => reports.into_iter().map(|r| (Some(r), None)).collect(),
            None => self
                .implicit
                .step_together(bodies, between, settings, (frame_dt, gravity))?
                .into_iter()
                .map(|r| (None, Some(r)))
                .collect(),
        };
        Ok(reports
            .into_iter()
            .zip(predictions)
            .map(|((explicit, implicit), prediction)| AutomaticReport {
                choice: if explicit.is_some() {
                    IntegratorKind::Explicit
                } else {
                    IntegratorKind::Implicit
                },
                prediction,
                explicit,
                implicit,
                fell_back,
            })
            .collect())
    }
}
