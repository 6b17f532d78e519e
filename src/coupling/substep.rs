//! One coupling substep of the deformable bodies (stages 2 to 5 of the coupling's
//! documentation): contacts found, touching bodies grouped, the groups stepped, and what they
//! gave the rigid bodies handed to rapier and the loads; a body refused earlier in the frame holds
//! the rigid bodies it touches as a fixed obstacle would.

use super::bodies::BodyLinks;
use super::carry::Carried;
use super::groups::{GroupStep, step_groups, touching_groups};
use super::loads::FrameLoads;
use super::pull::RapierPull;
use super::{Outcome, RigidSets, SoftCoupling, rapier_view, reach};
use crate::Error;
use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet};
use crate::constraint::{self, BodyConstraints};
use crate::contact::{self, BetweenContact};
use crate::integrate::{AutomaticReport, BodyInStep, IntegratorKind};
use rapier3d::dynamics::RigidBodySet;
use rapier3d::glamx::DVec3;

impl SoftCoupling {
    /// One coupling substep of `h` (s): each body but those in `skip` (stepped over the whole
    /// frame beside the substeps, taken out of `soft_bodies` meanwhile) whose state passes
    /// [`DeformableBody::check_state`] finds its contacts with the colliders (the others keep
    /// their state and take its error), bodies touching each other are grouped and stepped
    /// together, the others alone, and the impulses they gave rigid bodies go to rapier and to
    /// the loads. Each body's outcome becomes its last report or its first error. A body whose
    /// step is refused, in this substep or an earlier one of the frame, stays where it was and
    /// holds the rigid bodies it touches or is glued to as a fixed obstacle would
    /// ([`constraint::hold_partners`]): rapier's step must not let them sink into it meanwhile.
    /// The rigid bodies rapier's contacts hold move in the soft step by what rapier's step did
    /// to them since the last substep ended ([`RapierPull`]). Returns the dynamic rigid bodies
    /// implicit steps moved, for rapier's step to carry them as those steps did
    /// ([`RapierCarry`](super::carry::RapierCarry)).
    pub(super) fn step_soft_bodies(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        mut rigid: RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        skip: &[DeformableBodyHandle],
        (h, gravity): (f64, DVec3),
    ) -> Vec<Carried> {
        let margin = self.contact.margin;
        let sleep = (h, gravity, margin);
        self.pull.measure(rigid.bodies);
        (self.sleeping).wake_disturbed(
            soft_bodies,
            &mut rigid,
            (&mut self.loads, skip),
            &self.sleep,
            sleep,
        );
        let started = std::time::Instant::now();
        let (live, held) = self.detect(soft_bodies, &rigid, outcomes, skip, (h, gravity));
        let between = {
            let bodies: Vec<&DeformableBody> = live.iter().map(|&h| &soft_bodies[h]).collect();
            contact::detect_between(&bodies, &self.contact, h, gravity)
        };
        self.timing.contact_detection += started.elapsed().as_secs_f64();
        let carried = self.step_live(
            soft_bodies,
            &mut rigid,
            outcomes,
            (&live, between),
            (h, gravity),
        );
        self.hold_refused(soft_bodies, &held, &mut rigid, h, gravity);
        self.settle_still(soft_bodies, &mut rigid, (h, gravity));
        (self.carried).add(&carried, rigid.bodies, (h, gravity));
        let proxies = (self.links.iter()).flat_map(|(_, l)| &l.constraints.rigid_proxies);
        self.pull.note_handed(proxies, rigid.bodies, h);
        carried
    }

    /// Puts to sleep, after a step of `h` (s) under `gravity` (m/s²), the bodies still long
    /// enough (`SleepSet::settle`); a stand-in is rapier's to put to
    /// sleep.
    pub(super) fn settle_still(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rigid: &mut RigidSets<'_>,
        (h, gravity): (f64, DVec3),
    ) {
        let links = &self.links;
        let constraints = |handle| links.get(handle).map(|l: &BodyLinks| &l.constraints);
        let standing = self.stand_ins.handles();
        let sleep = (h, gravity, self.contact.margin);
        let bodies = (soft_bodies, &standing[..]);
        (self.sleeping).settle(bodies, constraints, rigid, &self.sleep, sleep);
    }

    /// Steps the bodies `live` over `h` (s) under `gravity` (m/s²), in the groups the contacts
    /// `between` them (indices into `live`) link: each group at once, the rigid bodies they
    /// touch that rest on something held within the step; then records the steps
    /// ([`SoftCoupling::record_steps`]). Returns the dynamic rigid bodies implicit steps moved.
    pub(super) fn step_live(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rigid: &mut RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        (live, between): (&[DeformableBodyHandle], Vec<BetweenContact>),
        (h, gravity): (f64, DVec3),
    ) -> Vec<Carried> {
        let groups = touching_groups(live.len(), between);
        let handles: Vec<DeformableBodyHandle> = (groups.iter())
            .flat_map(|(group, _)| group.iter().map(|&i| live[i]))
            .collect();
        let expected: Vec<f64> = (groups.iter())
            .map(|(group, _)| self.links.last_seconds(group.iter().map(|&i| live[i])))
            .collect();
        let mut steps = (self.links.many_mut(&handles).into_iter())
            .zip(soft_bodies.get_many_mut(&handles))
            .map(|(links, body)| links.with(body));
        let mut ready: Vec<GroupStep> = (groups.into_iter().zip(expected))
            .map(|((group, between), expected_seconds)| GroupStep {
                bodies: steps.by_ref().take(group.len()).collect(),
                between,
                expected_seconds,
            })
            .collect();
        for step in ready.iter_mut().flat_map(|group| group.bodies.iter_mut()) {
            hold_supported_bodies(step.constraints, rigid, &self.pull);
        }
        let stepped = step_groups(&mut ready, &self.integrator, &self.contact, (h, gravity));
        let stepped = stepped.into_iter().flatten().collect();
        self.record_steps(
            soft_bodies,
            rigid,
            outcomes,
            (&handles, stepped),
            (h, gravity),
        )
    }

    /// Records the results `stepped` of the bodies `handles` over a step of `h` (s) under
    /// `gravity` (m/s²): each body's outcome, its stillness observed and its impulses handed to
    /// rapier and the loads (a refused body holding the rigid bodies it touches as a fixed
    /// obstacle would). Returns the dynamic rigid bodies implicit steps moved.
    pub(super) fn record_steps(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        rigid: &mut RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        (handles, stepped): (&[DeformableBodyHandle], Vec<Result<AutomaticReport, Error>>),
        (h, gravity): (f64, DVec3),
    ) -> Vec<Carried> {
        let margin = self.contact.margin;
        let steps = (self.links.many_mut(handles).into_iter())
            .zip(soft_bodies.get_many_mut(handles))
            .map(|(links, body)| links.with(body));
        let seconds: Vec<f64> = (stepped.iter())
            .map(|result| result.as_ref().map_or(0.0, |report| report.seconds))
            .collect();
        for report in stepped.iter().flatten() {
            let explicit = report.explicit.is_some();
            let with_partners = report.prediction.rigid_partners > 0;
            (self.timing).add_step(report.seconds, explicit, with_partners);
        }
        let mut carried = Vec::new();
        for ((handle, mut step), result) in handles.iter().zip(steps).zip(stepped) {
            if result.is_err() {
                constraint::hold_partners(step.body, step.constraints, h, gravity);
            }
            if result
                .as_ref()
                .is_ok_and(|r| r.choice == IntegratorKind::Implicit)
            {
                Carried::add(&mut carried, &step.constraints.rigid_proxies);
            }
            self.sleeping.observe(
                (*handle, step.body, step.constraints),
                (rigid.bodies, rigid.colliders),
                &self.sleep,
                (h, result.is_ok(), margin),
            );
            hand_over(&mut self.loads, *handle, &mut step, rigid.bodies);
            if let Some((_, outcome)) = outcomes.iter_mut().find(|(h, _)| h == handle) {
                // A step refused in an earlier substep of the frame stays reported.
                if !matches!(outcome, Some(Err(_))) {
                    *outcome = Some(result);
                }
            }
        }
        self.links.set_last_step(handles, h, &seconds);
        carried
    }

    /// Holds, for a substep of `h` (s) under `gravity` (m/s²), the rigid bodies that the bodies
    /// `held` (whose step was refused earlier in the frame) touch or are glued to, as a fixed
    /// obstacle would ([`constraint::hold_partners`]), and hands those impulses over.
    fn hold_refused(
        &mut self,
        soft_bodies: &mut DeformableBodySet,
        held: &[DeformableBodyHandle],
        rigid: &mut RigidSets<'_>,
        h: f64,
        gravity: DVec3,
    ) {
        let holds = (self.links.many_mut(held).into_iter())
            .zip(soft_bodies.get_many_mut(held))
            .map(|(links, body)| links.with(body));
        for (handle, mut step) in held.iter().zip(holds) {
            hold_supported_bodies(step.constraints, rigid, &self.pull);
            constraint::hold_partners(step.body, step.constraints, h, gravity);
            self.sleeping.observe(
                (*handle, step.body, step.constraints),
                (rigid.bodies, rigid.colliders),
                &self.sleep,
                (h, false, self.contact.margin),
            );
            hand_over(&mut self.loads, *handle, &mut step, rigid.bodies);
        }
        self.links.set_last_step(held, h, &vec![0.0; held.len()]);
    }

    /// Finds the contacts of every awake body of `outcomes` not in `skip` whose state a step can
    /// take, for a substep of `h` (s) under `gravity` (m/s²), and returns
    /// those to step (no error yet in the frame) and those to hold only (a step refused earlier
    /// in the frame); a body whose state fails [`DeformableBody::check_state`] or whose
    /// detection fails takes that error and neither.
    fn detect(
        &mut self,
        soft_bodies: &DeformableBodySet,
        rigid: &RigidSets<'_>,
        outcomes: &mut [(DeformableBodyHandle, Outcome)],
        skip: &[DeformableBodyHandle],
        (h, gravity): (f64, DVec3),
    ) -> (Vec<DeformableBodyHandle>, Vec<DeformableBodyHandle>) {
        let views = rapier_view::collider_views(rigid.colliders, rigid.bodies, h);
        let lookup = rapier_view::rigid_lookup(rigid.bodies, h);
        let (mut live, mut held) = (Vec::new(), Vec::new());
        let awake: Vec<usize> = (outcomes.iter().enumerate())
            .filter(|(_, (handle, _))| {
                !(self.sleeping.is_asleep(*handle)
                    || self.stand_ins.contains(*handle)
                    || skip.contains(handle))
            })
            .map(|(i, _)| i)
            .collect();
        let bodies: Vec<&DeformableBody> = (awake.iter())
            .map(|&i| &soft_bodies[outcomes[i].0])
            .collect();
        let struck = reach::struck_by(&bodies, self.contact.margin, h, gravity);
        let handles: Vec<DeformableBodyHandle> = awake.iter().map(|&i| outcomes[i].0).collect();
        let settings = &self.contact;
        let mut detections: Vec<_> = (self.links.many_mut(&handles).into_iter())
            .zip(bodies.into_iter().zip(struck))
            .map(|(links, (body, struck))| (links, body, struck, Ok(())))
            .collect();
        // Each body's detection reads the rigid sets and writes its own constraints only: the
        // bodies are detected at once on the pool, the same bit for bit in any order.
        crate::parallel::for_each(&mut detections, |(links, body, struck, detected)| {
            *detected = body.check_state().and_then(|()| {
                let colliders = (&views[..], *struck);
                let constraints = &mut links.constraints;
                constraints.detect_among(body, colliders, &lookup, h, gravity, settings)?;
                Ok(())
            });
        });
        for (&i, (_, _, _, detected)) in awake.iter().zip(detections) {
            let (handle, outcome) = &mut outcomes[i];
            let refused_before = matches!(outcome, Some(Err(_)));
            match detected {
                Err(error) if !refused_before => *outcome = Some(Err(error)),
                Err(_) => {}
                Ok(()) if refused_before => held.push(*handle),
                Ok(()) => live.push(*handle),
            }
        }
        (live, held)
    }
}

/// Hands the impulses `step`'s body (`handle`) gave rigid bodies over its substep to rapier's
/// `bodies` and adds them, and those on colliders, to the frame's `loads`.
fn hand_over(
    loads: &mut FrameLoads,
    handle: DeformableBodyHandle,
    step: &mut BodyInStep<'_>,
    bodies: &mut RigidBodySet,
) {
    loads.add_body(handle, step.body, step.constraints);
    step.constraints.transfer_contact_impulses(bodies);
}

/// Holds the rigid bodies a body's `constraints` touch that rigid contacts support, moving them
/// in the soft step by rapier's `pull` on them instead of gravity: they would otherwise fall
/// freely there, the ground that holds them acting only in rapier's step.
fn hold_supported_bodies(
    constraints: &mut BodyConstraints,
    rigid: &RigidSets<'_>,
    pull: &RapierPull,
) {
    let (bodies, narrow_phase) = (&*rigid.bodies, rigid.narrow_phase);
    for proxy in &mut constraints.rigid_proxies {
        let supported = bodies.get(proxy.handle).is_some_and(|rigid| {
            rigid.colliders().iter().any(|&collider| {
                narrow_phase
                    .contact_pairs_with(collider)
                    .any(|pair| pair.has_any_active_contact())
            })
        });
        if supported {
            proxy.hold(pull.on(proxy.handle));
        }
    }
}
