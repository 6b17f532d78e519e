//! Bodies that need no coupling substeps step once per frame. Coupling substeps exist so that a
//! dynamic rigid body and a soft body (or two soft bodies) see each other a short time apart;
//! a body whose reach over the whole frame `dt`, `margin + 2 (|v|max + |g| dt) dt` around its
//! nodes and twice each collider's travel around that collider, holds no dynamic rigid body
//! (touched or glued) and no other deformable body exchanges nothing with anything that moves in
//! response. Fixed and kinematic colliders go where they go whatever it does, so stepping it
//! once over `dt` beside the rigid substeps, against the colliders carried at their velocities
//! over the frame, is the same physics in one step instead of [`SoftCoupling::substeps`]:
//! an implicit body then pays for one Newton solve per frame instead of one per substep (the
//! integrator's own [`substeps`](crate::integrate::ImplicitIntegrator::substeps) still set its
//! accuracy), and an explicit one takes the substeps its stability needs in one go. Its implicit
//! penalties are as stiff as in a coupling substep, `penalty_factor m / (dt/N)²` for `N`
//! substeps: the penalty's `m/h²` scaling would otherwise let a load press a point `N²` times
//! deeper (the showcase's fingers, pressed 2 mm into the gripped cube, squeezed it with 14.46 N
//! instead of 17.38 N; with the substeps' stiffness 17.37 N).
//!
//! They are found before the kinematic bodies are told the first part of their path, so that
//! their velocities are those of the whole frame. Sharing nothing with the bodies of the coupling
//! substeps, they are taken out of the sets ([`Uncoupled`]) and step at the same time as those
//! substeps (on another thread with the `parallel` feature); their outcomes, loads and stillness
//! are recorded after the substeps, and they may fall asleep then. A body found with a dynamic
//! partner, or near another deformable body, steps in the coupling substeps; so does a body with
//! [`self_contact`](crate::body::DeformableBody::self_contact) on, whose parts touch each other
//! as two bodies do (its contacts, found once per frame, would keep the arms they had at
//! detection over the whole frame: the halves of a body colliding in zero gravity changed its
//! angular momentum by 1.5e-2 kg m²/s, twenty times the margin's bound, instead of within it).

use super::bodies::{BodyLinks, LinkSet};
use super::groups::{GroupStep, step_groups};
use super::reach::{body_reach, overlap};
use super::{Outcome, RigidSets, SoftCoupling, rapier_view};
use crate::Error;
use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet};
use crate::contact::ContactSettings;
use crate::integrate::{AutomaticIntegrator, AutomaticReport};
use rapier3d::glamx::DVec3;

impl SoftCoupling {
    /// The awake bodies of `outcomes`, not stepped yet, whose state a step can take and that
    /// need no coupling over the frame `dt` (s) under `gravity` (m/s²) (see the module's
    /// documentation), their contacts found for the whole frame. A body that fails the tests
    /// is left to the substeps, which detect its contacts again (and report its errors).
    pub(super) fn find_uncoupled(
        &mut self,
        soft_bodies: &DeformableBodySet,
        rigid: &RigidSets<'_>,
        outcomes: &[(DeformableBodyHandle, Outcome)],
        (dt, gravity): (f64, DVec3),
    ) -> Vec<DeformableBodyHandle> {
        let margin = self.contact.margin;
        let reaches: Vec<_> = (soft_bodies.iter())
            .map(|(handle, body)| (handle, body_reach(body, margin, dt, gravity)))
            .collect();
        let near_another = |handle: DeformableBodyHandle| {
            let Some(&(_, own)) = reaches.iter().find(|(other, _)| *other == handle) else {
                return true;
            };
            (reaches.iter()).any(|&(other, reach)| other != handle && overlap(own, reach))
        };
        let substeps = f64::from(self.substeps.max(1));
        let settings = ContactSettings {
            penalty_factor: self.contact.penalty_factor * substeps * substeps,
            ..self.contact
        };
        let views = rapier_view::collider_views(rigid.colliders, rigid.bodies, dt);
        let lookup = rapier_view::rigid_lookup(rigid.bodies, dt);
        let mut alone = Vec::new();
        for (handle, outcome) in outcomes {
            let body = &soft_bodies[*handle];
            let coupled_before = (self.links.get(*handle))
                .is_some_and(|links| links.constraints.touches_dynamic_body());
            if outcome.is_some()
                || body.self_contact
                || self.sleeping.is_asleep(*handle)
                || self.stand_ins.contains(*handle)
                || coupled_before
                || near_another(*handle)
                || body.check_state().is_err()
            {
                continue;
            }
            let constraints = &mut self.links.entry(*handle).constraints;
            // Near no other deformable body: none strikes it.
            let colliders = (&views[..], 0.0);
            let detected =
                constraints.detect_among(body, colliders, &lookup, dt, gravity, &settings);
            if detected.is_ok() && !constraints.touches_dynamic_body() {
                alone.push(*handle);
            }
        }
        alone
    }
}

impl SoftCoupling {
    /// Puts the bodies of `uncoupled` back, once the coupling substeps of the frame (`dt`, s,
    /// cut into substeps of `h`, s, under `gravity`, m/s²) are done, and records their results
    /// `stepped` as a coupling substep records its bodies' (outcomes, stillness, loads); those
    /// still long enough fall asleep.
    pub(super) fn finish_uncoupled(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        mut rigid: RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        (uncoupled, stepped): (Uncoupled, Vec<Result<AutomaticReport, Error>>),
        (dt, h, gravity): (f64, f64, DVec3),
    ) {
        if uncoupled.is_empty() {
            return;
        }
        let alone = uncoupled.give_back(soft_bodies, &mut self.links);
        let results = (&alone[..], stepped);
        self.record_steps(soft_bodies, &mut rigid, outcomes, results, (dt, gravity));
        self.settle_still(soft_bodies, &mut rigid, (h, gravity));
    }
}

/// The bodies that need no coupling, taken out of the sets with their links while they step.
pub(super) struct Uncoupled {
    bodies: Vec<(DeformableBodyHandle, DeformableBody)>,
    links: Vec<(DeformableBodyHandle, BodyLinks)>,
}

impl Uncoupled {
    /// Takes the bodies `alone` and their links out of `soft_bodies` and `links`.
    pub(super) fn take(
        alone: &[DeformableBodyHandle],
        soft_bodies: &mut DeformableBodySet,
        links: &mut LinkSet,
    ) -> Self {
        Self {
            bodies: soft_bodies.lend(alone),
            links: links.lend(alone),
        }
    }

    /// Whether no body was taken.
    pub(super) fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// Steps each body over the frame `dt` (s) under `gravity` (m/s²) with `integrator`, each a
    /// group of its own ([`step_groups`]; `settings` serve contacts between bodies, which
    /// these have none of): a result per body, in the order taken.
    pub(super) fn step(
        &mut self,
        (integrator, settings): (&AutomaticIntegrator, &ContactSettings),
        (dt, gravity): (f64, DVec3),
    ) -> Vec<Result<AutomaticReport, Error>> {
        let mut groups: Vec<GroupStep> = (self.bodies.iter_mut())
            .zip(self.links.iter_mut())
            .map(|((_, body), (_, links))| GroupStep {
                expected_seconds: links.last_seconds,
                bodies: vec![links.with(body)],
                between: Vec::new(),
            })
            .collect();
        let stepped = step_groups(&mut groups, integrator, settings, (dt, gravity));
        stepped.into_iter().flatten().collect()
    }

    /// Puts the bodies and their links back into `soft_bodies` and `links`; returns their handles.
    fn give_back(
        self,
        soft_bodies: &mut DeformableBodySet,
        links: &mut LinkSet,
    ) -> Vec<DeformableBodyHandle> {
        let handles = self.bodies.iter().map(|(handle, _)| *handle).collect();
        soft_bodies.give_back(self.bodies);
        links.give_back(self.links);
        handles
    }
}
