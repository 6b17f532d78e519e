//! The incremental potential of an implicit step of effective length `ĥ` from positions `x₀`:
//! `E(x) = Σ m/(2ĥ²) |x − x̂|² + Ψ(x) + ĥ D((x − x₀)/ĥ) − W(x)`, with `x̂` the inertial target
//! (backward Euler `x₀ + ĥ v₀`; BDF2 from the two previous states), `Ψ` the elastic energy, `D`
//! the damping's dissipation on the strain rate measured from the step's start, and `W` the work
//! of gravity, the body's loads ([`crate::load`]: the follower ones through their potentials),
//! contacts and attachments, plus the response `½ ιᵀ W ι` of the dynamic rigid
//! bodies those act against, minimized over their impulses `ι` for each `x`. Its gradient is the out-of-balance force and its Hessian
//! the Newton tangent; the new velocity is `(x − a)/ĥ`.

use super::ImplicitScheme;
use super::rigid_response::{Placement, RigidResponse};
use crate::assembly::Factor;
use crate::assembly::{Stiffness, solve};
use crate::body::DeformableBody;
use crate::chord::KeptCorrection;
use crate::constraint::{self, BodyConstraints};
use crate::contact;
use crate::integrate::PreviousStep;
use crate::load::ChamberSolve;
use crate::material::green_strain;
use crate::newton::{dot, norm};
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};
use std::cell::{Cell, RefCell};

/// Per-step data of the incremental potential.
pub(super) struct StepStart {
    /// The effective step `ĥ` (s).
    pub(super) h: f64,
    /// Positions (m) and velocities (m/s) at the start of the step.
    pub(super) positions: Vec<DVec3>,
    pub(super) velocities: Vec<DVec3>,
    /// `a` (m): the new velocity is `(x - a)/ĥ`.
    pub(super) anchor: Vec<DVec3>,
    /// `x̂` (m), the inertial target.
    pub(super) target: Vec<DVec3>,
    /// Per tetrahedron, the Green strain the damping's rate is measured from (when damped).
    pub(super) green: Vec<DMat3>,
    /// The constant force over the step (N): the weight, the dead loads and the follower
    /// loads' part no potential gives, at the step's start (see [`crate::load`]).
    pub(super) load: Vec<DVec3>,
    /// Per load, the point its potential's cone is measured from (m).
    pub(super) cone_origins: Vec<DVec3>,
}

impl StepStart {
    /// The potential of a step of length `h` from the body's state; BDF2 uses the previous
    /// step when it had the same length, backward Euler otherwise.
    pub(super) fn new(
        body: &DeformableBody,
        previous: Option<&PreviousStep>,
        h: f64,
        gravity: DVec3,
        scheme: ImplicitScheme,
    ) -> Self {
        let positions = body.positions.clone();
        let previous = match scheme {
            ImplicitScheme::Bdf2 => previous.filter(|p| p.h == h),
            ImplicitScheme::BackwardEuler => None,
        };
        let green_at = |x: &[DVec3]| -> Vec<DMat3> {
            body.elements
                .gradients(x)
                .iter()
                .map(green_strain)
                .collect()
        };
        let damped = body.damping.is_some();
        let (effective_h, anchor, velocity, green) = match previous {
            Some(previous) => {
                let combine = |now: &[DVec3], before: &[DVec3]| -> Vec<DVec3> {
                    now.iter()
                        .zip(before)
                        .map(|(a, b)| (*a * 4.0 - *b) / 3.0)
                        .collect()
                };
                let green = if damped {
                    let (now, before) = (green_at(&positions), green_at(&previous.positions));
                    now.iter()
                        .zip(&before)
                        .map(|(a, b)| (*a * 4.0 - *b) * (1.0 / 3.0))
                        .collect()
                } else {
                    Vec::new()
                };
                (
                    2.0 * h / 3.0,
                    combine(&positions, &previous.positions),
                    combine(&body.velocities, &previous.velocities),
                    green,
                )
            }
            None => {
                let green = if damped {
                    green_at(&positions)
                } else {
                    Vec::new()
                };
                (h, positions.clone(), body.velocities.clone(), green)
            }
        };
        let target = (0..positions.len())
            .map(|n| {
                if body.pinned[n] {
                    positions[n]
                } else {
                    anchor[n] + velocity[n] * effective_h
                }
            })
            .collect();
        let mut load = body.dead_load(gravity);
        let cone_origins = body.cone_origins();
        body.add_rim_forces(&cone_origins, &mut load);
        Self {
            h: effective_h,
            positions,
            velocities: body.velocities.clone(),
            anchor,
            target,
            green,
            load,
            cone_origins,
        }
    }
}

/// What a Newton system adds for contacts to act by the pieces of their penalty and friction a
/// direction lands on (see [`Potential::engaged`]).
pub(super) struct Engaged {
    /// Their forces (N per node), added to the system's right-hand side.
    pub(super) forces: Vec<DVec3>,
    /// Their tangents (N/m), each on a point's nodes with their weights.
    tangents: Vec<(Vec<u32>, Vec<f64>, DMat3)>,
}

impl Engaged {
    /// The terms of bodies solved as one system of `total` nodes, each body's `parts` placed
    /// from its first node's number; `None` if none has any.
    pub(super) fn gather(
        parts: impl IntoIterator<Item = (usize, Option<Engaged>)>,
        total: usize,
    ) -> Option<Self> {
        let mut all = Self {
            forces: vec![DVec3::ZERO; total],
            tangents: Vec::new(),
        };
        for (offset, part) in parts {
            let Some(part) = part else { continue };
            all.forces[offset..offset + part.forces.len()].copy_from_slice(&part.forces);
            let placed = (part.tangents.into_iter()).map(|(nodes, weights, tangent)| {
                let nodes = nodes.iter().map(|n| n + offset as u32).collect();
                (nodes, weights, tangent)
            });
            all.tangents.extend(placed);
        }
        (!all.tangents.is_empty()).then_some(all)
    }

    /// Adds the tangents to `stiffness`, none on the `pinned` nodes.
    pub(super) fn add_to(&self, stiffness: &mut Stiffness, pinned: &[bool]) {
        for (nodes, weights, tangent) in &self.tangents {
            stiffness.add_stencil_block(Stencil { nodes, weights }, tangent, pinned);
        }
    }
}

/// The incremental potential of one step: the step's start, the constraints' terms and the
/// response of the dynamic rigid bodies they act against (solved anew wherever the potential is
/// evaluated, see [`RigidResponse`]).
pub(super) struct Potential<'a> {
    pub(super) start: &'a StepStart,
    pub(super) constraints: &'a BodyConstraints,
    pub(super) rigid: RefCell<RigidResponse>,
    /// Evaluations of [`Potential::energy`] so far (reported as
    /// [`ImplicitReport::energy_evaluations`](super::ImplicitReport::energy_evaluations)).
    evaluations: Cell<usize>,
}

impl<'a> Potential<'a> {
    /// The potential of the step from `start`, with the `constraints`' terms and the dynamic
    /// rigid bodies' `response`; not yet evaluated.
    pub(super) fn new(
        start: &'a StepStart,
        constraints: &'a BodyConstraints,
        response: RigidResponse,
    ) -> Self {
        Self {
            start,
            constraints,
            rigid: RefCell::new(response),
            evaluations: Cell::new(0),
        }
    }

    /// Evaluations of the energy so far.
    pub(super) fn evaluations(&self) -> usize {
        self.evaluations.get()
    }

    /// `-∇E` (N): elastic and damping forces, gravity and loads, contact penalties and the inertial pull
    /// toward `x̂`; zero on pinned nodes. `forces` is scratch for the internal forces.
    pub(super) fn residual(
        &self,
        body: &mut DeformableBody,
        forces: &mut Vec<DVec3>,
    ) -> Vec<DVec3> {
        let start = self.start;
        body.step_forces_into((&start.green, start.h), forces);
        body.add_potential_forces(&start.cone_origins, forces);
        let mut residual: Vec<DVec3> = (0..body.positions.len())
            .map(|n| {
                let inertial =
                    (start.target[n] - body.positions[n]) * (body.masses[n] / (start.h * start.h));
                forces[n] + start.load[n] + inertial
            })
            .collect();
        let mut rigid = self.rigid.borrow_mut();
        rigid.solve(body, self.constraints);
        constraint::add_implicit_forces(body, self.constraints, rigid.step(), &mut residual);
        for (r, &pinned) in residual.iter_mut().zip(&body.pinned) {
            if pinned {
                *r = DVec3::ZERO;
            }
        }
        residual
    }

    /// The force scale the tolerance is relative to (N): the largest of gravity, the inertial
    /// pull and the initial out-of-balance force.
    pub(super) fn force_scale(&self, body: &DeformableBody, initial_residual: &[DVec3]) -> f64 {
        let inertial: Vec<DVec3> = (0..body.positions.len())
            .map(|n| {
                (self.start.target[n] - self.start.positions[n])
                    * (body.masses[n] / (self.start.h * self.start.h))
            })
            .collect();
        norm(&self.start.load)
            .max(norm(&inertial))
            .max(norm(initial_residual))
            .max(f64::MIN_POSITIVE)
    }

    /// The incremental potential `E(x)` (J) at the body's positions.
    pub(super) fn energy(&self, body: &DeformableBody) -> f64 {
        self.evaluations.set(self.evaluations.get() + 1);
        let inertia: f64 = (0..body.positions.len())
            .map(|n| {
                0.5 * body.masses[n] * (body.positions[n] - self.start.target[n]).length_squared()
            })
            .sum::<f64>()
            / (self.start.h * self.start.h);
        // The load's work is measured from the start of the step.
        let load: f64 = self
            .start
            .load
            .iter()
            .zip(body.positions.iter().zip(&self.start.positions))
            .map(|(f, (x, x0))| f.dot(*x - *x0))
            .sum();
        let mut rigid = self.rigid.borrow_mut();
        let response = rigid.solve(body, self.constraints);
        let penalty = constraint::implicit_energy(body, self.constraints, rigid.step());
        let follower = body.follower_potential(&self.start.cone_origins, &self.start.positions);
        let elastic_and_dissipation = body.step_energy((&self.start.green, self.start.h));
        inertia + elastic_and_dissipation + follower + penalty + response - load
    }

    /// `M/h² + K_elastic + K_damping + K_contact`, each element's stress tangent projected to be positive
    /// semi-definite if `project`.
    pub(super) fn assemble(
        &self,
        body: &DeformableBody,
        stiffness: &mut Stiffness,
        inertia: &[f64],
        project: bool,
    ) {
        let damping = body.damping;
        stiffness.assemble(body, Some(inertia), project, |t, f| match &damping {
            Some(d) => d.step_first_piola_unit_differentials(f, &self.start.green[t], self.start.h),
            None => [DMat3::ZERO; 9],
        });
        let mut rigid = self.rigid.borrow_mut();
        rigid.solve(body, self.constraints);
        constraint::add_implicit_tangents(body, self.constraints, rigid.step(), stiffness);
    }

    /// The contacts the Newton `direction` (m per node) would carry onto stiffer pieces of their
    /// penalty or friction ([`contact::for_each_engaged_term`]), for the Newton system to be
    /// solved again with those pieces; `None` if there are none.
    pub(super) fn engaged(&self, body: &DeformableBody, direction: &[DVec3]) -> Option<Engaged> {
        let rigid = self.rigid.borrow();
        let mut engaged = Engaged {
            forces: vec![DVec3::ZERO; body.positions.len()],
            tangents: Vec::new(),
        };
        let contacts = &self.constraints.contacts;
        contact::for_each_engaged_term(body, contacts, rigid.step(), direction, |at, f, t| {
            for (&node, weight) in at.nodes.iter().zip(at.weights) {
                if !body.pinned[node as usize] {
                    engaged.forces[node as usize] += f * *weight;
                }
            }
            engaged
                .tangents
                .push((at.nodes.to_vec(), at.weights.to_vec(), t));
        });
        (!engaged.tangents.is_empty()).then_some(engaged)
    }

    /// The Newton direction (m per node) for `residual` (N) solved with `factor`, an earlier
    /// iteration's, with the unassembled terms taken in: the `correction` that iteration took in
    /// (kept where the body has no chamber, see [`crate::chord`]), else the current ones; and
    /// whether it took in the kept correction.
    pub(super) fn reused_direction(
        &self,
        body: &DeformableBody,
        (factor, correction): (&Factor, Option<&KeptCorrection>),
        residual: &[DVec3],
    ) -> (Vec<DVec3>, bool) {
        let direction = solve(factor, residual);
        let kept = correction.filter(|_| !body.has_chambers());
        if let Some(corrected) = kept.and_then(|c| c.apply(&direction))
            && dot(residual, &corrected) > 0.0
        {
            return (corrected, true);
        }
        let taken_in = self.take_in_unassembled(body, (factor, true), residual, direction);
        (taken_in, false)
    }

    /// The correction the last direction's solve took in, to be kept with its factorization
    /// (none for a body with chambers, whose solves take the chambers in too).
    pub(super) fn kept_correction(&self, body: &DeformableBody) -> Option<KeptCorrection> {
        (!body.has_chambers())
            .then(|| self.rigid.borrow().kept_correction())
            .flatten()
    }

    /// The Newton direction `direction` (m per node), solved with `factor` (the one of the last
    /// call if `true`), with the tangent's terms that are not assembled taken in: the chambers'
    /// liquids' ([`ChamberSolve`]), then the rigid bodies' response (see
    /// [`RigidResponse::take_in`]) with solves that take the chambers in.
    pub(super) fn take_in_unassembled(
        &self,
        body: &DeformableBody,
        (factor, same_factor): (&Factor, bool),
        residual: &[DVec3],
        direction: Vec<DVec3>,
    ) -> Vec<DVec3> {
        let placement = Placement {
            offset: 0,
            total: body.positions.len(),
        };
        let chambers = body.chamber_terms();
        let solver = ChamberSolve::new(factor, &chambers);
        let direction = solver.take_in(residual, direction);
        self.take_in_placed(body, (&solver, same_factor), placement, residual, direction)
    }

    /// The rigid bodies' response taken into `direction` for a body placed among the nodes of a
    /// system (a group of bodies solved as one, or the body alone): `residual`, `direction` and
    /// `solver` (the chambers taken in, the factorization the last call's if `true`) are the
    /// system's.
    pub(super) fn take_in_placed(
        &self,
        body: &DeformableBody,
        factor: (&ChamberSolve, bool),
        placement: Placement,
        residual: &[DVec3],
        direction: Vec<DVec3>,
    ) -> Vec<DVec3> {
        let mut rigid = self.rigid.borrow_mut();
        rigid.solve(body, self.constraints);
        rigid.take_in(
            (body, self.constraints),
            factor,
            placement,
            residual,
            direction,
        )
    }
}
