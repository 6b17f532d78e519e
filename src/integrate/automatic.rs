//! Automatic choice between explicit and implicit integration: for each frame, the cost of the
//! explicit substeps the stability limit requires (with the body's contacts) is compared with
//! the cost of an implicit step (with the body's own recent implicit work, [`NewtonWork`]), both
//! predicted by the [`CostModel`] measured on the machine, and the cheaper is taken, the body
//! keeping its last frame's integrator unless the other is
//! [`SWITCH_MARGIN`](super::SWITCH_MARGIN) times cheaper. Explicit integration is preferred at
//! equal cost: it has no numerical damping.

use super::choice::{AutomaticReport, CostPrediction, IntegratorKind};
use super::cost::{CostModel, NewtonHistory, NewtonWork, Workload};
use super::refusal::FrameInputs;
use super::{
    BodyInStep, ImplicitIntegrator, ImplicitReport, SolverWorkspace, StepReport, SymplecticEuler,
};
use crate::Error;
use crate::body::DeformableBody;
use crate::chord::Chord;
use crate::constraint::BodyConstraints;
use crate::contact::{BetweenContact, ContactSettings};
use rapier3d::glamx::DVec3;
use std::time::Instant;

/// Newton iterations per substep an implicit frame the automatic choice took is given at least
/// before it is handed to the explicit integrator (see [`AutomaticIntegrator::implicit_for`]):
/// smooth motion takes one to three, an impact or a change of contacts up to about ten.
const NEWTON_BUDGET_FLOOR: usize = 10;

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
    /// The measured costs the choice compares.
    pub cost: CostModel,
}

impl AutomaticIntegrator {
    /// The predicted cost of a frame of `frame_dt` (s) for `body` with each integrator, free of
    /// contacts and before any implicit step; an invalid explicit setting predicts an infinite
    /// explicit cost.
    pub fn predict(&self, body: &DeformableBody, frame_dt: f64) -> CostPrediction {
        let needed = self
            .explicit
            .needed_substeps(body, frame_dt)
            .unwrap_or(f64::INFINITY);
        let work = self.workload(body, None, None, frame_dt);
        self.prediction(&work, needed)
    }

    /// What the cost of a frame of `frame_dt` (s) of `body` depends on, with its `constraints`
    /// (contacts) and `workspace` (Newton history) where known.
    fn workload(
        &self,
        body: &DeformableBody,
        constraints: Option<&BodyConstraints>,
        workspace: Option<&SolverWorkspace>,
        frame_dt: f64,
    ) -> Workload {
        let (contact_points, sweeps, rigid_partners) = constraints.map_or((0, 1, 0), |c| {
            let sweeps = if c.coupled() {
                c.contacts.settings.velocity_iterations.max(1)
            } else {
                1
            };
            (c.contacts.point_count(), sweeps, c.dynamic_body_count())
        });
        let assumed = || self.assumed_work(body, frame_dt);
        Workload {
            tets: body.mesh().tet_count() as f64,
            model: body.material().model(),
            damped: body.damping.is_some(),
            contact_points: contact_points as f64,
            sweeps: f64::from(sweeps),
            rigid_partners: rigid_partners as f64,
            newton: workspace.map_or_else(assumed, |w| w.newton.or(assumed)),
        }
    }

    /// The work per implicit substep assumed for `body` before its own implicit frames (and
    /// which explicit frames draw its history back to): [`CostModel::newton_iterations`]
    /// solved directly ([`NewtonWork::assumed_direct`]), or, where the linear solver would take
    /// the conjugate gradient for substeps of a frame of `frame_dt` (s), with the iterations it
    /// predicts and no factorization.
    fn assumed_work(&self, body: &DeformableBody, frame_dt: f64) -> NewtonWork {
        let iterations = self.cost.newton_iterations;
        let h = frame_dt / f64::from(self.implicit.substeps.max(1));
        let direct = NewtonWork::assumed_direct(iterations, self.implicit.reuse_factorization);
        match (self.implicit.linear_solver).predicted_cg_iterations(body, h) {
            None => direct,
            Some(per_solve) => NewtonWork {
                factorizations: 0.0,
                linear_iterations: iterations * per_solve,
                ..direct
            },
        }
    }

    /// The prediction for `work` whose explicit frame takes `explicit_substeps`.
    fn prediction(&self, work: &Workload, explicit_substeps: f64) -> CostPrediction {
        let implicit_substeps = f64::from(self.implicit.substeps.max(1));
        CostPrediction {
            explicit_substeps,
            contact_points: work.contact_points as usize,
            rigid_partners: work.rigid_partners as usize,
            newton: work.newton,
            explicit_seconds: self.cost.explicit_seconds(work, explicit_substeps),
            implicit_seconds: self.cost.implicit_seconds(work, implicit_substeps),
        }
    }

    /// Advances `body` by `frame_dt` (s) under gravity (m/s²) against its `constraints`, with
    /// `workspace` its solver caches, by the cheaper integrator (or the forced one); explicit
    /// while points or corners are found deeper behind their contact planes than twice the
    /// contacts' resting depth.
    ///
    /// A frame refused again from exactly what the last refused frame started from (the body's
    /// positions, velocities and loads, its constraints, the frame's length and gravity, the
    /// plan for it and the two-step history) is refused at once with the same error, without
    /// redoing the work: a refused frame leaves the body as it was, and its kept factorization
    /// is dropped, so the same inputs give the same refusal. The first refusal's inputs are not
    /// kept (frames that succeed keep nothing); the frame after it is tried again.
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
        let prediction = self.prediction(
            &self.workload(body, Some(constraints), Some(workspace), frame_dt),
            needed,
        );
        let choice = self.force.unwrap_or_else(|| {
            if constraints.needs_explicit_contacts() {
                IntegratorKind::Explicit
            } else {
                prediction.cheaper_after(last_kind(workspace.newton.last_implicit()))
            }
        });
        let implicit = self.implicit_for(&prediction, [&workspace.newton]);
        let inputs = workspace.refusals.watching().then(|| {
            let plan = (choice, needed, implicit);
            let previous = workspace.previous_step.as_ref();
            FrameInputs::of((body, constraints), (frame_dt, gravity), plan, previous)
        });
        if let Some(error) = (inputs.as_ref()).and_then(|i| workspace.refusals.repeated(i)) {
            return Err(error);
        }
        let outcome = self.frame(
            BodyInStep {
                body,
                constraints,
                workspace,
            },
            (frame_dt, gravity),
            (choice, prediction, needed),
            &implicit,
        );
        if outcome.is_err() {
            // The factorization a refused frame kept is not reused: the next frame's outcome is
            // then a function of its inputs alone.
            workspace.chord = Chord::default();
        }
        workspace.refusals.record(&outcome, inputs);
        outcome
    }

    /// A frame of `frame_dt` (s) under `gravity` (m/s²) of `step`'s body by the integrator
    /// `choice`, predicted as `prediction`, the explicit frame taking `needed` substeps, the
    /// implicit one run by `implicit` when chosen.
    fn frame(
        &self,
        mut step: BodyInStep<'_>,
        (frame_dt, gravity): (f64, DVec3),
        (choice, prediction, needed): (IntegratorKind, CostPrediction, f64),
        implicit: &ImplicitIntegrator,
    ) -> Result<AutomaticReport, Error> {
        let started = Instant::now();
        let explicit_frame = |step: &mut BodyInStep<'_>| {
            crate::parallel::on_pool(|| self.explicit.advance(step, frame_dt, gravity, needed))
        };
        let implicit_frame = |step: &mut BodyInStep<'_>, implicit: &ImplicitIntegrator| {
            let outcome = implicit.step(
                step.body,
                step.constraints,
                step.workspace,
                frame_dt,
                gravity,
            );
            step.workspace.newton.record_outcome(&outcome, implicit);
            outcome
        };
        let (explicit, implicit, fell_back) = self.with_fallback(
            (choice, implicit),
            &mut step,
            explicit_frame,
            implicit_frame,
        )?;
        if explicit.is_some() {
            let assumed = self.assumed_work(step.body, frame_dt);
            step.workspace.newton.forget(&assumed);
        }
        Ok(AutomaticReport::of(
            prediction,
            (explicit, implicit),
            fell_back,
            started.elapsed().as_secs_f64(),
        ))
    }

    /// The implicit integrator a frame predicted as `prediction` runs with, for bodies of Newton
    /// `histories`. Chosen, not forced, while the explicit frame can be taken (within
    /// `max_substeps`), it gives the frame up to the explicit integrator (see
    /// [`AutomaticIntegrator::with_fallback`]) as soon as it would cost more than the explicit
    /// frame was predicted to: a failing frame is not refined, and its substeps' Newton
    /// iterations stop at what the explicit frame's predicted time buys, with what the bodies'
    /// last implicit frames saved of theirs ([`NewtonHistory::budget`]; at least
    /// [`NEWTON_BUDGET_FLOOR`]). Forced, or where the explicit frame cannot be taken, it is
    /// [`AutomaticIntegrator::implicit`] as set.
    fn implicit_for<'h>(
        &self,
        prediction: &CostPrediction,
        histories: impl IntoIterator<Item = &'h NewtonHistory>,
    ) -> ImplicitIntegrator {
        let explicit_possible =
            prediction.explicit_substeps <= f64::from(self.explicit.max_substeps);
        if self.force.is_some() || !explicit_possible || prediction.implicit_seconds <= 0.0 {
            return self.implicit;
        }
        let substeps = f64::from(self.implicit.substeps.max(1));
        let per_iteration =
            prediction.implicit_seconds / (prediction.newton.iterations.max(1.0) * substeps);
        let affordable = prediction.explicit_seconds / per_iteration / substeps;
        let budget = (histories.into_iter())
            .map(|history| history.budget(affordable))
            .fold(f64::INFINITY, f64::min)
            .ceil();
        ImplicitIntegrator {
            max_refinement: 1,
            max_newton_iterations: (budget.min(usize::MAX as f64) as usize)
                .max(NEWTON_BUDGET_FLOOR)
                .min(self.implicit.max_newton_iterations),
            ..self.implicit
        }
    }

    /// Runs a frame of `target` (one body or a group) with the integrator `choice`, by
    /// `explicit` or `implicit` (which steps with the implicit integrator it is given: `chosen`
    /// when implicit was chosen); unless a choice is forced, a frame the one cannot take is
    /// redone by the other (each leaves the bodies as they were when it fails): an explicit
    /// frame that would need more than `max_substeps` or gave a non-finite state, by
    /// [`AutomaticIntegrator::implicit`] as set; an implicit frame, chosen, whose Newton solve,
    /// factorization or contacts failed, or that crushed an element (a step too long to follow
    /// an impact), within what [`AutomaticIntegrator::implicit_for`] allows. The explicit
    /// report, the implicit report (one of them), and whether the frame was redone.
    ///
    /// # Errors
    /// The error of the integrator that ran last; for a redone frame that failed again, the
    /// first integrator's error.
    fn with_fallback<T, E, I>(
        &self,
        (choice, chosen): (IntegratorKind, &ImplicitIntegrator),
        target: &mut T,
        mut explicit: impl FnMut(&mut T) -> Result<E, Error>,
        mut implicit: impl FnMut(&mut T, &ImplicitIntegrator) -> Result<I, Error>,
    ) -> Result<(Option<E>, Option<I>, bool), Error> {
        let free = self.force.is_none();
        match choice {
            IntegratorKind::Explicit => match explicit(target) {
                Ok(report) => Ok((Some(report), None, false)),
                Err(Error::TooManySubsteps { .. } | Error::NonFiniteState { .. }) if free => {
                    Ok((None, Some(implicit(target, &self.implicit)?), true))
                }
                Err(error) => Err(error),
            },
            IntegratorKind::Implicit => match implicit(target, chosen) {
                Ok(report) => Ok((None, Some(report), false)),
                Err(
                    error @ (Error::NewtonDidNotConverge { .. }
                    | Error::IndefiniteStiffness { .. }
                    | Error::ContactNotResolved { .. }
                    | Error::ElementCrushed { .. }),
                ) if free => match explicit(target) {
                    Ok(report) => Ok((Some(report), None, true)),
                    Err(_) => Err(error),
                },
                Err(error) => Err(error),
            },
        }
    }

    /// The predictions for soft `bodies` stepping together with `between` contact points among
    /// them, in order (the explicit substeps those of the stiffest body: the group takes the
    /// shortest stable step), the group's (their sum), and the integrator for the group: the
    /// forced one, else explicit while a member's contacts need it
    /// ([`BodyConstraints::needs_explicit_contacts`]), else the cheaper. The contacts between
    /// the bodies exchange angular momentum within the contact margin times the impulse either
    /// way (the penalty acts at the triangle's point, its reaction at the node;
    /// `tests/soft_contact.rs`); the group's implicit cost is its bodies' (the showcase's stack
    /// measured 3.5 times its prediction).
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] for an invalid explicit setting.
    fn group_choice(
        &self,
        bodies: &[BodyInStep<'_>],
        between: usize,
        frame_dt: f64,
    ) -> Result<(Vec<CostPrediction>, CostPrediction, IntegratorKind), Error> {
        let mut needed = 1.0f64;
        for step in bodies {
            needed = needed.max(self.explicit.needed_substeps(step.body, frame_dt)?);
        }
        let works: Vec<Workload> = (bodies.iter())
            .map(|s| self.workload(s.body, Some(s.constraints), Some(s.workspace), frame_dt))
            .collect();
        let predictions: Vec<CostPrediction> =
            works.iter().map(|w| self.prediction(w, needed)).collect();
        let sweeps = works.iter().map(|w| w.sweeps).fold(1.0, f64::max);
        let between_seconds = self.cost.contact_seconds(between as f64, sweeps, needed);
        let explicit =
            between_seconds + predictions.iter().map(|p| p.explicit_seconds).sum::<f64>();
        let total = CostPrediction {
            explicit_substeps: needed,
            contact_points: between + predictions.iter().map(|p| p.contact_points).sum::<usize>(),
            rigid_partners: predictions.iter().map(|p| p.rigid_partners).sum(),
            newton: (works.iter().map(|w| w.newton))
                .reduce(|a, b| if b.iterations > a.iterations { b } else { a })
                .unwrap_or_default(),
            explicit_seconds: explicit,
            implicit_seconds: predictions.iter().map(|p| p.implicit_seconds).sum(),
        };
        let choice = self.force.unwrap_or_else(|| {
            if bodies
                .iter()
                .any(|s| s.constraints.needs_explicit_contacts())
            {
                IntegratorKind::Explicit
            } else {
                let lasts: Vec<Option<bool>> = (bodies.iter())
                    .map(|s| s.workspace.newton.last_implicit())
                    .collect();
                let shared = lasts.windows(2).all(|w| w[0] == w[1]);
                let last = if shared {
                    lasts.first().copied().flatten()
                } else {
                    None
                };
                total.cheaper_after(last_kind(last))
            }
        });
        Ok((predictions, total, choice))
    }

    /// Advances soft `bodies` touching each other through `between` (indices into `bodies`)
    /// by `frame_dt` (s) together, with `settings` for the contacts between them, by the
    /// integrator [`AutomaticIntegrator::group_choice`] picks: implicit as one system; explicit
    /// with their contacts solved in the explicit sweeps with both bodies' nodes, and, unless
    /// explicit is forced, redone as one implicit system when the explicit frame would take
    /// more than `max_substeps` or gave a non-finite state. A report per body, in order.
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
        let (predictions, total, choice) = self.group_choice(bodies, between.len(), frame_dt)?;
        let started = Instant::now();
        type Group<'g, 'b> = (&'g mut [BodyInStep<'b>], &'g mut [BetweenContact]);
        let explicit_frame = |(bodies, between): &mut Group<'_, '_>| {
            self.explicit
                .step_together(bodies, between, frame_dt, gravity)
        };
        let implicit_frame = |(bodies, between): &mut Group<'_, '_>,
                              implicit: &ImplicitIntegrator| {
            let outcome = implicit.step_together(bodies, between, settings, (frame_dt, gravity));
            for (n, step) in bodies.iter_mut().enumerate() {
                let own = outcome
                    .as_ref()
                    .map(|reports| reports[n])
                    .map_err(Clone::clone);
                step.workspace.newton.record_outcome(&own, implicit);
            }
            outcome
        };
        let chosen = self.implicit_for(&total, bodies.iter().map(|b| &b.workspace.newton));
        let mut group: Group<'_, '_> = (&mut *bodies, &mut *between);
        let (explicit, implicit, fell_back) = self.with_fallback(
            (choice, &chosen),
            &mut group,
            explicit_frame,
            implicit_frame,
        )?;
        let reports: Vec<(Option<StepReport>, Option<ImplicitReport>)> = match (explicit, implicit)
        {
            (Some(reports), _) => {
                for step in bodies.iter_mut() {
                    let assumed = self.assumed_work(step.body, frame_dt);
                    step.workspace.newton.forget(&assumed);
                }
                reports.into_iter().map(|r| (Some(r), None)).collect()
            }
            (None, reports) => (reports.unwrap_or_default().into_iter())
                .map(|r| (None, Some(r)))
                .collect(),
        };
        let used = match reports.first() {
            Some((Some(_), _)) => IntegratorKind::Explicit,
            _ => IntegratorKind::Implicit,
        };
        let seconds = shares(started.elapsed().as_secs_f64(), &predictions, used);
        Ok((reports.into_iter().zip(predictions).zip(seconds))
            .map(|((frame, prediction), seconds)| {
                AutomaticReport::of(prediction, frame, fell_back, seconds)
            })
            .collect())
    }
}

/// The integrator of a last frame that was implicit or not (`None` before any frame).
fn last_kind(last_implicit: Option<bool>) -> Option<IntegratorKind> {
    last_implicit.map(|implicit| {
        if implicit {
            IntegratorKind::Implicit
        } else {
            IntegratorKind::Explicit
        }
    })
}

/// `seconds` a group's frame took, shared among its bodies in proportion to their `predictions`
/// for the integrator `used`, equally where those are all zero.
fn shares(seconds: f64, predictions: &[CostPrediction], used: IntegratorKind) -> Vec<f64> {
    let sum: f64 = predictions.iter().map(|p| p.seconds(used)).sum();
    let count = predictions.len() as f64;
    (predictions.iter())
        .map(|p| {
            if sum > 0.0 {
                seconds * p.seconds(used) / sum
            } else {
                seconds / count
            }
        })
        .collect()
}
