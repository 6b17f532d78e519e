//! An implicit step of soft bodies touching each other, solved as one system: the group's
//! incremental potential is the sum of its bodies' (each with its own contacts, attachments and
//! rigid partners, see [`super::potential`]) plus the contacts between them (see
//! [`crate::contact::JointContacts`]), and Newton minimizes it over every body's nodes at once.
//! The tangent is the bodies' tangents side by side with the blocks coupling each contact's node
//! and triangle ([`Stiffness::joint`]), factored whole; the rigid partners' response of each
//! body is taken into the direction with that factorization. The tangent's pattern and
//! symbolic factorization are kept for the next frame in the first body's workspace, the pattern
//! keeping the node pairs earlier contacts coupled ([`Stiffness::joint_after`]); each iteration
//! assembles and factors anew (no reuse of factorizations across iterations) and solves
//! directly, whatever
//! [`ImplicitIntegrator::linear_solver`] says; the scheme is BDF2 only when every body of the
//! group has the history for it, backward Euler otherwise, so that all take the same `ĥ`.

use super::direction::{UnengagedTangent, engaging};
use super::potential::{Engaged, Potential, StepStart};
use super::rigid_response::{Placement, RigidResponse};
use super::{
    CrushWatch, ImplicitIntegrator, ImplicitReport, Outcome, STIFFENING_ROUNDS, Stop, end_substep,
    on_round_off_floor, refinable,
};
use crate::Error;
use crate::assembly::Stiffness;
use crate::body::DeformableBody;
use crate::constraint::{self, BodyConstraints};
use crate::contact::{self, BetweenContact, ContactSettings, JointContacts, NodeSlices};
use crate::integrate::{BodyInStep, PreviousStep};
use crate::linear_solver::{Method, solve_newton_system};
use crate::load::{ChamberSolve, ChamberTerms};
use crate::newton::{Configuration, Search, descend, norm, round_off_floor};
use rapier3d::glamx::DVec3;

/// The group's bodies as Newton moves them, their nodes numbered body after body.
struct Group<'s, 'b> {
    bodies: &'s mut [&'b mut DeformableBody],
    /// Each body's first node in the group's numbering, then the group's node count.
    offsets: Vec<usize>,
    masses: Vec<f64>,
    pinned: Vec<bool>,
}

impl Configuration for Group<'_, '_> {
    type Vector = DVec3;
    fn copy_positions(&self) -> Vec<DVec3> {
        self.bodies
            .iter()
            .flat_map(|body| body.positions.iter().copied())
            .collect()
    }

    fn place(&mut self, start: &[DVec3], direction: &[DVec3], alpha: f64) {
        for (k, body) in self.bodies.iter_mut().enumerate() {
            let range = self.offsets[k]..self.offsets[k + 1];
            body.place(&start[range.clone()], &direction[range], alpha);
        }
    }
}

impl Group<'_, '_> {
    /// The group's node count.
    fn node_count(&self) -> usize {
        *self.offsets.last().unwrap_or(&0)
    }

    /// The group's node `node` as a node of its body.
    fn body_node(&self, node: usize) -> usize {
        let body = self.offsets.partition_point(|&first| first <= node) - 1;
        node - self.offsets[body]
    }
}

/// Stiffens the contacts with colliders that the group's bodies, at their positions, press
/// deeper than their resting depth from where `starts` began them (see
/// [`contact::stiffen_deep_contacts`]), each body's rigid
/// partners at the velocities their `responses` give them there (those of a body whose contacts
/// stiffened are to be solved again). Returns whether any did.
fn stiffen_deep_contacts(
    group: &Group,
    starts: &[StepStart],
    constraints: &mut [&mut BodyConstraints],
    responses: &mut [RigidResponse],
) -> bool {
    let mut stiffened = false;
    let members = group.bodies.iter().zip(starts).zip(constraints);
    for (((body, start), constraints), response) in members.zip(responses) {
        response.solve(body, constraints);
        let contacts = &mut constraints.contacts;
        if contact::stiffen_deep_contacts(body, contacts, response.step(), &start.positions) {
            response.forget_solution();
            stiffened = true;
        }
    }
    stiffened
}

/// The group's incremental potential: its bodies' and the contacts between them.
struct GroupPotential<'a> {
    members: Vec<Potential<'a>>,
    between: &'a JointContacts,
    /// The effective step `ĥ` (s) every body of the group takes, and the penalty step (s, see
    /// [`ImplicitStep`](crate::contact::ImplicitStep)).
    effective: f64,
    penalty_step: f64,
}

impl GroupPotential<'_> {
    /// The effective step and the penalty step (s).
    fn steps(&self) -> (f64, f64) {
        (self.effective, self.penalty_step)
    }

    /// `E` (J) with the bodies where `group` has them.
    fn energy(&self, group: &Group) -> f64 {
        let own: f64 = self
            .members
            .iter()
            .zip(group.bodies.iter())
            .map(|(member, body)| member.energy(body))
            .sum();
        let positions = group.copy_positions();
        let mut between = 0.0;
        self.between
            .for_each_term(nodes(group, &positions), self.steps(), |_, e, _, _| {
                between += e;
            });
        own + between
    }

    /// `−∇E` (N per node of the group), zero on pinned nodes; `forces` is each body's scratch
    /// for its internal forces.
    fn residual(&self, group: &mut Group, forces: &mut [Vec<DVec3>]) -> Vec<DVec3> {
        let mut residual = Vec::with_capacity(group.node_count());
        for ((member, body), forces) in self.members.iter().zip(group.bodies.iter_mut()).zip(forces)
        {
            residual.extend(member.residual(body, forces));
        }
        let positions = group.copy_positions();
        self.between
            .for_each_term(nodes(group, &positions), self.steps(), |at, _, force, _| {
                for (&node, w) in at.nodes.iter().zip(at.weights) {
                    if !group.pinned[node as usize] {
                        residual[node as usize] += force * *w;
                    }
                }
            });
        residual
    }

    /// Fills `joint` with the group's tangent (N/m): each body's assembled on its own pattern in
    /// `parts` (`inertia` its `m/ĥ²` per node), side by side, plus the contacts' blocks; element
    /// stress tangents projected to be positive semi-definite if `project`.
    fn assemble(
        &self,
        group: &Group,
        (joint, parts): (&mut Stiffness, &mut [Stiffness]),
        inertia: &[Vec<f64>],
        project: bool,
    ) {
        joint.values.fill(0.0);
        for (k, member) in self.members.iter().enumerate() {
            member.assemble(group.bodies[k], &mut parts[k], &inertia[k], project);
            joint.add_part(&parts[k], group.offsets[k]);
        }
        let positions = group.copy_positions();
        self.between.for_each_term(
            nodes(group, &positions),
            self.steps(),
            |at, _, _, tangent| {
                joint.add_stencil_block(at, &tangent, &group.pinned);
            },
        );
    }

    /// The force scale the tolerance is relative to (N): the bodies' scales (see
    /// [`Potential::force_scale`]) combined, or the initial out-of-balance force if larger.
    fn force_scale(&self, group: &Group, initial_residual: &[DVec3]) -> f64 {
        let squares: f64 = self
            .members
            .iter()
            .enumerate()
            .map(|(k, member)| {
                let own = &initial_residual[group.offsets[k]..group.offsets[k + 1]];
                member.force_scale(group.bodies[k], own).powi(2)
            })
            .sum();
        squares.sqrt().max(norm(initial_residual))
    }
}

/// The group's nodes with positions `positions` (m).
fn nodes<'a>(group: &'a Group, positions: &'a [DVec3]) -> NodeSlices<'a> {
    NodeSlices {
        positions,
        masses: &group.masses,
        pinned: &group.pinned,
    }
}

/// What the group's steps keep across substeps: the contacts between the bodies, each body's
/// tangent on its own pattern, and the group's tangent.
struct GroupSolver {
    between: JointContacts,
    parts: Vec<Stiffness>,
    joint: Stiffness,
    /// Each body's first node in the group's numbering, then the group's node count.
    offsets: Vec<usize>,
}

impl GroupSolver {
    /// The solver of `bodies` touching through `between`: each body's tangent from its
    /// workspace, widened where its constraints or the contacts couple nodes its mesh does not.
    fn new(
        bodies: &mut [BodyInStep<'_>],
        between: &[BetweenContact],
        settings: &ContactSettings,
    ) -> Self {
        let mut offsets = vec![0];
        for step in bodies.iter() {
            offsets.push(offsets[offsets.len() - 1] + step.body.positions.len());
        }
        let first_nodes: Vec<u32> = offsets.iter().map(|&o| o as u32).collect();
        let between = JointContacts::new(between, &first_nodes, settings);
        let body_of = |node: u32| offsets.partition_point(|&first| first <= node as usize) - 1;
        let (mut own, mut cross): (Vec<Vec<[u32; 2]>>, Vec<[u32; 2]>) =
            (vec![Vec::new(); bodies.len()], Vec::new());
        for [a, b] in between.coupled_pairs() {
            let (ka, kb) = (body_of(a), body_of(b));
            if ka == kb {
                let first = offsets[ka] as u32;
                own[ka].push([a - first, b - first]);
            } else {
                cross.push([a, b]);
            }
        }
        let parts: Vec<Stiffness> = bodies
            .iter_mut()
            .zip(own)
            .map(|(step, own)| {
                let mut tangent = step.workspace.take_tangent(step.body);
                let mut missing =
                    constraint::uncoupled_pairs(step.body, step.constraints, &tangent);
                missing.extend(own.into_iter().filter(|&[a, b]| !tangent.couples(a, b)));
                missing.sort_unstable();
                missing.dedup();
                if !missing.is_empty()
                    && let Some(widened) = tangent.widened(&missing)
                {
                    tangent = widened;
                }
                tangent
            })
            .collect();
        let refs: Vec<&Stiffness> = parts.iter().collect();
        let earlier = (bodies.first_mut()).and_then(|step| step.workspace.group_tangent.take());
        let joint = Stiffness::joint_after(&refs, &cross, earlier)
            .expect("the contacts couple nodes of the group's bodies, ordered");
        Self {
            between,
            parts,
            joint,
            offsets,
        }
    }

    /// Gives each body's tangent back to its workspace, and the group's to the first body's.
    fn give_back(self, bodies: &mut [BodyInStep<'_>]) {
        for (step, part) in bodies.iter_mut().zip(self.parts) {
            step.workspace.tangent = Some(part);
        }
        if let Some(first) = bodies.first_mut() {
            first.workspace.group_tangent = Some(self.joint);
        }
    }
}

impl ImplicitIntegrator {
    /// Advances soft `bodies` touching each other through `between` (indices into `bodies`) by
    /// `frame_dt` (s) under `gravity` (m/s²) as one system (see the module documentation), with
    /// `settings` for the contacts between them, refined and refused as
    /// [`ImplicitIntegrator::step`] refines and refuses a body's frame. A report per body, in
    /// order; the Newton counts are the group's.
    ///
    /// # Errors
    /// Those of [`ImplicitIntegrator::step`]; every body is then left as it was.
    pub(crate) fn step_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        between: &[BetweenContact],
        settings: &ContactSettings,
        (frame_dt, gravity): (f64, DVec3),
    ) -> Result<Vec<ImplicitReport>, Error> {
        Error::check_step(frame_dt, gravity)?;
        self.check()?;
        let watches: Vec<CrushWatch> = bodies.iter().map(|s| CrushWatch::new(s.body)).collect();
        let limit = self.substeps.saturating_mul(self.max_refinement);
        let mut refined = *self;
        loop {
            let attempt = refined.attempt_together(
                bodies,
                (between, settings),
                (frame_dt, gravity),
                &watches,
            );
            match attempt {
                Err(error) if refinable(&error) && refined.substeps < limit => {
                    refined.substeps = refined.substeps.saturating_mul(2).min(limit);
                }
                outcome => return outcome,
            }
        }
    }

    /// [`ImplicitIntegrator::step_together`] in [`ImplicitIntegrator::substeps`], refused (every
    /// body left as it was) at the first failed Newton solve, or when the frame ends with a body
    /// past a collider's middle or crushing an element its watch did not see crushed.
    fn attempt_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        (between, settings): (&[BetweenContact], &ContactSettings),
        (frame_dt, gravity): (f64, DVec3),
        watches: &[CrushWatch],
    ) -> Result<Vec<ImplicitReport>, Error> {
        let mut histories = Vec::with_capacity(bodies.len());
        for step in bodies.iter_mut() {
            step.save();
            histories.push(step.workspace.history(step.body).cloned());
        }
        let mut solver = GroupSolver::new(bodies, between, settings);
        let h = frame_dt / f64::from(self.substeps);
        let mut report = ImplicitReport::empty(self.substeps, h);
        let mut last: Vec<Option<PreviousStep>> = histories.clone();
        let mut failure = None;
        for _ in 0..self.substeps {
            match self.substep_together(bodies, &mut solver, &mut last, (h, gravity)) {
                Ok(outcome) => {
                    report.add(&outcome);
                    failure = outcome.failure(self.substeps);
                }
                Err(error) => failure = Some(error),
            }
            if failure.is_some() {
                break;
            }
        }
        solver.give_back(bodies);
        let checked: Result<Vec<usize>, Error> = match failure {
            Some(error) => Err(error),
            None => bodies
                .iter()
                .zip(watches)
                .map(|(step, watch)| self.frame_failure(step.body, step.constraints, watch))
                .collect(),
        };
        match checked {
            Ok(inverted) => Ok(bodies
                .iter_mut()
                .zip(last)
                .zip(inverted)
                .map(|((step, last), inverted_elements)| {
                    step.workspace.previous_step = last;
                    ImplicitReport {
                        inverted_elements,
                        ..report
                    }
                })
                .collect()),
            Err(error) => {
                for (step, history) in bodies.iter_mut().zip(histories) {
                    step.restore();
                    step.workspace.previous_step = history;
                }
                Err(error)
            }
        }
    }

    /// One substep of `h` (s) of the group: `last` holds each body's last substep start, and is
    /// updated.
    fn substep_together(
        &self,
        bodies: &mut [BodyInStep<'_>],
        solver: &mut GroupSolver,
        last: &mut [Option<PreviousStep>],
        (h, gravity): (f64, DVec3),
    ) -> Result<Outcome, Error> {
        // One `ĥ` for all: two-step only if every body can.
        let bdf2 = last.iter().all(|p| p.as_ref().is_some_and(|p| p.h == h));
        let mut starts = Vec::with_capacity(bodies.len());
        let mut responses = Vec::with_capacity(bodies.len());
        for (step, previous) in bodies.iter_mut().zip(last.iter()) {
            let previous = previous.as_ref().filter(|_| bdf2);
            let (start, response) =
                self.begin_substep(step.body, step.constraints, previous, (h, gravity));
            starts.push(start);
            responses.push(response);
        }
        let (mut body_refs, mut constraints): (
            Vec<&mut DeformableBody>,
            Vec<&mut BodyConstraints>,
        ) = bodies
            .iter_mut()
            .map(|step| (&mut *step.body, &mut *step.constraints))
            .unzip();
        let mut group = Group {
            masses: body_refs.iter().flat_map(|b| b.masses.clone()).collect(),
            pinned: body_refs.iter().flat_map(|b| b.pinned.clone()).collect(),
            bodies: &mut body_refs,
            offsets: solver.offsets.clone(),
        };
        let effective = starts[0].h;
        let penalty_step = self.penalty_step(effective);
        let positions = group.copy_positions();
        solver
            .between
            .lag_friction(nodes(&group, &positions), (effective, penalty_step));
        let mut solved: Option<Outcome> = None;
        for round in 0..=STIFFENING_ROUNDS {
            let potential = GroupPotential {
                members: starts
                    .iter()
                    .zip(&constraints)
                    .zip(responses)
                    .map(|((start, constraints), response)| {
                        Potential::new(start, constraints, response)
                    })
                    .collect(),
                between: &solver.between,
                effective,
                penalty_step,
            };
            let parts = (&mut solver.joint, &mut solver.parts[..]);
            let outcome = if round == 0 {
                self.minimize_group(&mut group, &potential, parts)
            } else {
                let energy = potential.energy(&group);
                self.newton_group(&mut group, &potential, parts, energy)
            };
            // Each evaluation of the group's energy evaluates every member's once.
            let evaluations = potential.members.first().map_or(0, Potential::evaluations);
            let outcome = outcome.map(|o| Outcome {
                energy_evaluations: evaluations,
                ..o
            });
            responses = (potential.members.into_iter())
                .map(|member| member.rigid.into_inner())
                .collect();
            let outcome = outcome?;
            let failed = outcome.stop == Stop::Failed;
            solved = Some(match solved {
                Some(earlier) => earlier.then(outcome),
                None => outcome,
            });
            if failed
                || round == STIFFENING_ROUNDS
                || !stiffen_deep_contacts(&group, &starts, &mut constraints, &mut responses)
            {
                break;
            }
        }
        let ends = (starts.into_iter().zip(responses)).zip(last.iter_mut());
        for ((body, constraints), ended) in body_refs.into_iter().zip(constraints).zip(ends) {
            end_member_substep(body, constraints, ended, h);
        }
        Ok(solved.unwrap_or_else(|| Outcome::start(penalty_step)))
    }

    /// Newton's method on the group's potential, from the inertial prediction or from where
    /// the bodies are, whichever is lower (as [`ImplicitIntegrator::step`] does for one body).
    fn minimize_group(
        &self,
        group: &mut Group,
        potential: &GroupPotential,
        (joint, parts): (&mut Stiffness, &mut [Stiffness]),
    ) -> Result<Outcome, Error> {
        let here = potential.energy(group);
        let starts: Vec<DVec3> = potential
            .members
            .iter()
            .flat_map(|m| m.start.positions.iter().copied())
            .collect();
        let targets: Vec<DVec3> = potential
            .members
            .iter()
            .flat_map(|m| m.start.target.iter().copied())
            .collect();
        group.set(&targets);
        let mut energy = potential.energy(group);
        if energy.is_nan() || energy > here {
            group.set(&starts);
            energy = here;
        }
        self.newton_group(group, potential, (joint, parts), energy)
    }

    /// Newton's method on the group's potential from where the bodies are, where it is
    /// `energy` (J).
    fn newton_group(
        &self,
        group: &mut Group,
        potential: &GroupPotential,
        (joint, parts): (&mut Stiffness, &mut [Stiffness]),
        mut energy: f64,
    ) -> Result<Outcome, Error> {
        let inertia: Vec<Vec<f64>> = group
            .bodies
            .iter()
            .map(|body| {
                let h = potential.effective;
                body.masses.iter().map(|m| m / (h * h)).collect()
            })
            .collect();
        let mut forces: Vec<Vec<DVec3>> = group.bodies.iter().map(|_| Vec::new()).collect();
        let mut residual = potential.residual(group, &mut forces);
        let reference = potential.force_scale(group, &residual);
        let mut history: Vec<f64> = Vec::new();
        let mut outcome = Outcome::start(potential.penalty_step);
        loop {
            let relative = norm(&residual) / reference;
            outcome.residual = relative;
            if !relative.is_finite() {
                let at = residual.iter().position(|r| !r.is_finite()).unwrap_or(0);
                return Err(Error::NonFiniteState {
                    node: group.body_node(at),
                });
            }
            let floor = |group: &mut Group, forces: &mut [Vec<DVec3>]| {
                round_off_floor(group, &residual, |g| potential.residual(g, forces)) / reference
            };
            let stop = self.stop(relative, &history, outcome.iterations, || {
                floor(group, &mut forces)
            });
            if let Some(stop) = stop {
                outcome.stop = stop;
                return Ok(outcome);
            }
            history.push(relative);
            let direction = self.group_direction(
                group,
                potential,
                (&mut *joint, &mut *parts),
                (&inertia, &residual),
                &mut outcome,
            )?;
            let next = descend(
                group,
                &residual,
                energy,
                &direction,
                Search::Thorough,
                |group| potential.energy(group),
                |group| potential.residual(group, &mut forces),
            );
            outcome.iterations += 1;
            match next {
                Some((next, value)) => (residual, energy) = (next, value),
                None => {
                    // No descent left: round-off on its floor, a failure above it.
                    if on_round_off_floor(outcome.residual, || floor(group, &mut forces)) {
                        outcome.stop = Stop::Stalled;
                    }
                    return Ok(outcome);
                }
            }
        }
    }

    /// The Newton direction (m per node of the group) of the group's exact tangent (projected
    /// where it is not positive definite), solved again with the contact pieces it lands on (see
    /// [`super::direction`]).
    fn group_direction(
        &self,
        group: &Group,
        potential: &GroupPotential,
        (joint, parts): (&mut Stiffness, &mut [Stiffness]),
        (inertia, residual): (&[Vec<f64>], &[DVec3]),
        outcome: &mut Outcome,
    ) -> Result<Vec<DVec3>, Error> {
        let mut tangent = UnengagedTangent::default();
        let solve = |rhs: &[DVec3], engaged: Option<&Engaged>| {
            let system = (inertia, rhs, engaged);
            let tangents = (&mut *joint, &mut *parts, &mut tangent);
            let direction = self.solve_group(group, potential, tangents, system, &mut *outcome)?;
            Ok((direction, ()))
        };
        let engaged_for = |direction: &[DVec3]| {
            let members = (potential.members.iter().enumerate()).map(|(k, member)| {
                let own = &direction[group.offsets[k]..group.offsets[k + 1]];
                (group.offsets[k], member.engaged(group.bodies[k], own))
            });
            Engaged::gather(members, group.node_count())
        };
        Ok(engaging(residual, solve, engaged_for)?.0)
    }

    /// The solution (m per node of the group) of the Newton system for the right-hand side `rhs`
    /// (N) with the group's exact tangent (assembled once per projection into `tangent`) and the
    /// `engaged` contacts' tangents, with the members' chambers' liquids taken in, then each
    /// body's rigid partners' response.
    fn solve_group(
        &self,
        group: &Group,
        potential: &GroupPotential,
        (joint, parts, tangent): (&mut Stiffness, &mut [Stiffness], &mut UnengagedTangent),
        (inertia, residual, engaged): (&[Vec<f64>], &[DVec3], Option<&Engaged>),
        outcome: &mut Outcome,
    ) -> Result<Vec<DVec3>, Error> {
        let solution = solve_newton_system(
            Method::Direct,
            self.tolerance / outcome.residual,
            joint,
            residual,
            outcome.iterations,
            |joint, project| {
                tangent.fill(joint, project, (engaged, &group.pinned), |joint| {
                    potential.assemble(group, (joint, &mut *parts), inertia, project);
                });
            },
        )?;
        outcome.factorizations += solution.factorizations;
        outcome.projected_tangents += usize::from(solution.projected);
        let mut direction = solution.direction;
        if let Some(factor) = &solution.factor {
            // The last offset is the group's node count.
            let placements: Vec<Placement> = (group.offsets[..group.bodies.len()].iter())
                .map(|&offset| Placement {
                    offset,
                    total: group.node_count(),
                })
                .collect();
            let mut chambers = ChamberTerms::default();
            for (body, placement) in group.bodies.iter().zip(&placements) {
                let terms = body.chamber_terms();
                (chambers.columns).extend(placement.embed(&terms.columns).into_owned());
                chambers.weights.extend(terms.weights);
            }
            let solver = ChamberSolve::new(factor, &chambers);
            direction = solver.take_in(residual, direction);
            for (k, member) in potential.members.iter().enumerate() {
                let placement = placements[k];
                direction = member.take_in_placed(
                    group.bodies[k],
                    (&solver, false),
                    placement,
                    residual,
                    direction,
                );
            }
        }
        Ok(direction)
    }
}

/// Ends a group member's implicit substep of `h` (s) from its `start`, recording it as the
/// member's `last` step ([`end_substep`]).
fn end_member_substep(
    body: &mut DeformableBody,
    constraints: &mut BodyConstraints,
    ((start, response), last): ((StepStart, RigidResponse), &mut Option<PreviousStep>),
    h: f64,
) {
    let previous = last.as_ref().map(|step| step.h);
    *last = Some(end_substep(
        body,
        constraints,
        (start, response),
        (h, previous),
        false,
    ));
}
