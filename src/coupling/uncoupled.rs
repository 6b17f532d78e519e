//! Bodies that need no coupling substeps step once per frame. Coupling substeps exist so that a
//! dynamic rigid body and a soft body (or two soft bodies) see each other a short time apart;
//! a body whose reach over the whole frame `dt`, `margin + 2 (|v|max + |g| dt) dt` around its
//! nodes and twice each collider's travel around that collider, holds no dynamic rigid body
//! (touched or glued) and no other deformable body exchanges nothing with anything that moves in
//! response. Fixed and kinematic colliders go where they go whatever it does, so stepping it
//! once over `dt` before the rigid substeps, against the colliders carried at their velocities
//! over the frame, is the same physics in one step instead of [`SoftCoupling::substeps`]:
//! an implicit body then pays for one Newton solve per frame instead of one per substep (the
//! integrator's own [`substeps`](crate::integrate::ImplicitIntegrator::substeps) still set its
//! accuracy), and an explicit one takes the substeps its stability needs in one go. Its implicit
//! penalties are as stiff as in a coupling substep, `penalty_factor m / (dt/N)²` for `N`
//! substeps: the penalty's `m/h²` scaling would otherwise let a load press a point `N²` times
//! deeper (the showcase's fingers, pressed 2 mm into the gripped cube, squeezed it with 14.46 N
//! instead of 17.38 N; with the substeps' stiffness 17.37 N).
//!
//! The pass runs before the kinematic bodies are told the first part of their path, so that their
//! velocities are those of the whole frame. A body found with a dynamic partner, or near another
//! deformable body, steps in the coupling substeps as before; so does a body with
//! [`self_contact`](crate::body::DeformableBody::self_contact) on, whose parts touch each other
//! as two bodies do (its contacts, found once per frame, would keep the arms they had at
//! detection over the whole frame: the halves of a body colliding in zero gravity changed its
//! angular momentum by 1.5e-2 kg m²/s, twenty times the margin's bound, instead of within it).

use super::reach::{body_reach, overlap};
use super::{Outcome, RigidSets, SoftCoupling, rapier_view};
use crate::body::{DeformableBodyHandle, DeformableBodySet};
use crate::contact::ContactSettings;
use rapier3d::glamx::DVec3;

impl SoftCoupling {
    /// Steps over the whole frame `dt` (s) under `gravity` (m/s²) every awake body of
    /// `outcomes`, not stepped yet, whose state a step can take and that needs no coupling (see
    /// the module's documentation), recording its outcome; returns those bodies, for the
    /// coupling substeps to skip. A body that fails the tests is left to the substeps, which
    /// detect its contacts again (and report its errors).
    pub(super) fn step_uncoupled(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        mut rigid: RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        (dt, gravity): (f64, DVec3),
    ) -> Vec<DeformableBodyHandle> {
        self.links.prune(soft_bodies);
        self.sleeping.prune(soft_bodies);
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
        let alone: Vec<DeformableBodyHandle> = {
            let views = rapier_view::collider_views(rigid.colliders, rigid.bodies, dt);
            let lookup = rapier_view::rigid_lookup(rigid.bodies, dt);
            let mut alone = Vec::new();
            for (handle, outcome) in outcomes.iter() {
                let body = &soft_bodies[*handle];
                let coupled_before = (self.links.get(*handle))
                    .is_some_and(|links| links.constraints.touches_dynamic_body());
                if outcome.is_some()
                    || body.self_contact
                    || self.sleeping.is_asleep(*handle)
                    || coupled_before
                    || near_another(*handle)
                    || body.check_state().is_err()
                {
                    continue;
                }
                let constraints = &mut self.links.entry(*handle).constraints;
                let detected =
                    constraints.detect_among(body, &views, &lookup, dt, gravity, &settings);
                if detected.is_ok() && !constraints.touches_dynamic_body() {
                    alone.push(*handle);
                }
            }
            alone
        };
        if !alone.is_empty() {
            let live = (&alone[..], Vec::new());
            self.step_live(soft_bodies, &mut rigid, outcomes, live, (dt, gravity));
        }
        alone
    }
}
