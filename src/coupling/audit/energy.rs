//! The energy side of the audit: `E = Σ_soft (K + Ψ + V_g + U) + Σ_dynamic rigid (K + V_g)`,
//! measured at the end of each frame and compared with the previous frame's plus the work
//! kinematic bodies and changes of loads did on the deformable bodies over the frame,
//! `gain = E_n - (E_{n-1} + W_n)`.
//!
//! - Soft bodies: kinetic `Σ m v²/2`, elastic `Ψ` (the material's strain energy), gravitational
//!   `-Σ m g·x`, the potential `U` of their loads
//!   ([`DeformableBody::load_potential_energy`]), and after an implicit step the energy its
//!   contact penalties hold: `k g²/2` for each node inside its contact plane (`g < 0`) and each
//!   rigid corner behind its face, with `k = penalty_factor m / h²` (`m` the node's or the
//!   face point's mass, `h` the effective step of the whole step the integrator took, however
//!   many substeps it cut it into) and the stiffenings the contact's load
//!   called for (see `contact::stiffening`), and `k |x − a|²/2` for each node glued to a rigid
//!   body's anchor `a` (its implicit spring, `k` counting the body's least effective mass there
//!   when dynamic). Embedded contact points' penalties are not counted.
//!   A sleeping body not stepped in the frame keeps the energy it had when it was last measured:
//!   its state does not change, and the penalty energy its last implicit step held is still
//!   there (measured afresh it would drop out, then count as a gain when the body wakes).
//! - Dynamic rigid bodies: `m v²/2 + ωᵀ I ω / 2`, and the gravitational energy `-m g·x` at the
//!   centre of mass half of rapier's integration step `h` back along the velocity, `x − v h/2`,
//!   which rapier's symplectic Euler step keeps exactly in free flight. `h` is the coupling substep
//!   divided by the solver iterations rapier runs in it (its TGS solver integrates positions once
//!   per iteration): with one coupling substep and rapier's default four iterations, a quarter of
//!   the frame (taking the whole frame, a 0.43 kg box falling freely within reach of a soft block
//!   measured a gain of 4.3 mJ every 1/60 s frame). The substeps in which an implicit soft step
//!   carried a body (it touches or is glued to a deformable body stepped implicitly, and
//!   rapier's contacts do not hold it) are measured at its centre of mass `x` itself: the
//!   implicit step solves its motion with the soft body's as one backward Euler step, whose
//!   energy `Σ m v²/2 − m g·x + Ψ` cannot rise, while the half-substep-back measure moves by
//!   `½ h m g·Δv` with each velocity change `Δv` the step gives it (the 20 kg ball on the 20 g
//!   rope at 1/60 s frames: +2.3e-3 J in a frame measured half a substep back, −1.0e-3 J at the
//!   centre of mass). So the frame's gain leaves out `½ h m g·Δv_c`, `Δv_c` the velocity change
//!   over those substeps (the impulses' `M⁻¹ι` and the fall `g h` along the body's free axes,
//!   recorded by the coupling, `carry::CarriedMotion`); a body carried in every substep is
//!   measured at its centre of mass, one carried in none half an integration step back, as
//!   rapier moves it (a 27 g box of the game scene landing on the ground through rapier's
//!   contact beside an implicit block gained 6.0e-5 J in a frame measured at its centre of mass
//!   over the whole frame, 3.5e-7 J so). A check made with no step since the last one (a state
//!   changed by hand) leaves nothing out. Fixed and kinematic bodies carry none.
//! - Work: a kinematic (or fixed) rigid body a deformable body pushed with the mean force `F` and
//!   torque `τ` over the frame ([`RigidLoad`](crate::coupling::RigidLoad)) while moving its centre
//!   of mass by `Δx` and turning by `Δθ` did `W = -(F·Δx + τ·Δθ)` on it. Gravity's work is in the
//!   gravitational terms. A load whose value the caller changed between frames
//!   ([`DeformableBody::set_load`]) did the change of its potential at the positions then. Nothing
//!   else is counted: forces the caller applies, joint motors,
//!   kinematic bodies pushing rigid bodies through rapier's contacts and state set between
//!   frames all show as gains.
//!
//! Bodies exchanging energy are checked together: a *cluster* is a set of deformable bodies and
//! dynamic rigid bodies joined by contacts and attachments (the rigid bodies each deformable
//! body touched in any substep of the frame or is glued to) or by overlapping bounding boxes
//! (deformable bodies that may touch), and each deformable body is given its cluster's check.

use super::{AuditInput, EnergyCheck};
use crate::attachment;
use crate::body::{DeformableBody, DeformableBodyHandle};
use crate::contact::{self, BodyPoint};
use crate::coupling::{SoftStepResults, iterations_per_substep};
use crate::integrate::SymplecticEuler;
use rapier3d::dynamics::{RigidBody, RigidBodyHandle};
use rapier3d::glamx::{DMat3, DQuat, DVec3};
use std::collections::HashMap;

/// A member of the coupled system.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Member {
    /// A deformable body.
    Soft(DeformableBodyHandle),
    /// A dynamic rigid body.
    Rigid(RigidBodyHandle),
}

/// A member's energy at the end of a frame (J): its total and the part in motion and strain
/// (kinetic and elastic), which sets the tolerance.
#[derive(Debug, Clone, Copy)]
pub(super) struct MemberEnergy {
    /// The total, a rigid body's gravitational energy taken at its centre of mass.
    pub(super) total: f64,
    /// What a rigid body's gravitational energy taken half an integration step `h` back along its
    /// velocity `v` adds to the total, `½ h m g·v`; zero for a deformable body.
    pub(super) half_step_back: f64,
    /// What the velocity changes `Δv` of the frame's substeps in which implicit soft steps carried
    /// a rigid body moved `half_step_back` by, `½ h m g·Δv`, which the frame's gain leaves out;
    /// zero for a deformable body.
    pub(super) carried_shift: f64,
    /// The energy in motion and strain (J): kinetic, and for a deformable body elastic and the
    /// implicit penalties'; the relative tolerance is taken of it.
    pub(super) moving: f64,
    /// The work (J) changes of a deformable body's loads did since it was built; zero for a
    /// rigid body.
    pub(super) load_change_work: f64,
    /// What the energy may change by without a gain (J): for a rigid body the f32 rounding of
    /// its state, `1e-6 (K + m |g| |x|)`; for a deformable body stepped explicitly the
    /// oscillation of symplectic Euler's measured energy about its conserved shadow energy,
    /// `(h / h_crit)(K + Ψ)` (a mode of frequency `ω` oscillates by about `hω/2` of its energy,
    /// and `ω ≤ 2 / h_crit`).
    pub(super) allowance: f64,
}

/// Every member's energy (J) now, the deformable bodies' last steps having returned `results`.
pub(super) fn energies(
    input: &AuditInput<'_>,
    results: &SoftStepResults,
) -> HashMap<Member, MemberEnergy> {
    let g = input.gravity;
    let h = rigid_integration_step(input);
    let mut all = HashMap::new();
    for (handle, body) in input.soft_bodies.iter() {
        let stand_in = (input.coupling.rigid_stand_in_of(handle)).and_then(|r| input.bodies.get(r));
        if let Some(rigid) = stand_in {
            // Its nodes are carried by its rigid body: rapier's energy, and its elastic energy.
            let mut energy = rigid_energy(rigid, g, h);
            let elastic = body.elastic_energy();
            energy.total += elastic + body.load_potential_energy();
            energy.moving += elastic;
            energy.load_change_work = body.load_change_work();
            all.insert(Member::Soft(handle), energy);
            continue;
        }
        let report = results
            .iter()
            .find(|(h, _)| *h == handle)
            .and_then(|(_, r)| r.as_ref().ok());
        let penalty = (report.and_then(|r| r.implicit))
            .map_or(0.0, |r| penalty_energy(input, handle, body, r.penalty_step));
        let moving = body.kinetic_energy() + body.elastic_energy() + penalty;
        let total = moving + body.gravity_potential_energy(g) + body.load_potential_energy();
        let ratio = report.and_then(|r| r.explicit).map_or(0.0, |e| {
            e.substep_dt / SymplecticEuler::critical_time_step(body)
        });
        all.insert(
            Member::Soft(handle),
            MemberEnergy {
                total,
                half_step_back: 0.0,
                carried_shift: 0.0,
                moving,
                load_change_work: body.load_change_work(),
                allowance: ratio.min(1.0) * moving,
            },
        );
    }
    let rigid = (input.bodies.iter())
        .filter(|(handle, b)| b.is_dynamic() && input.coupling.stand_in_for(*handle).is_none());
    for (handle, body) in rigid {
        let mut energy = rigid_energy(body, g, h);
        let carried = input.coupling.carried_velocity_change(handle);
        energy.carried_shift = f64::from(body.mass()) * g.dot(carried) * (h / 2.0);
        all.insert(Member::Rigid(handle), energy);
    }
    all
}

/// Gives every deformable body of `input` that slept through the frame (no result in
/// `results`) its energy of `before` in `now`.
pub(super) fn keep_sleeping(
    input: &AuditInput<'_>,
    results: &SoftStepResults,
    before: &HashMap<Member, MemberEnergy>,
    now: &mut HashMap<Member, MemberEnergy>,
) {
    for (handle, _) in input.soft_bodies.iter() {
        let stepped = results.iter().any(|(h, _)| *h == handle);
        if !stepped
            && input.coupling.is_sleeping(handle)
            && let Some(energy) = before.get(&Member::Soft(handle))
        {
            now.insert(Member::Soft(handle), *energy);
        }
    }
}

/// The step (s) of rapier's position integration in a frame of `input`: each coupling substep
/// of `dt / substeps` runs `⌈num_solver_iterations / substeps⌉` solver iterations (at least
/// one), each of which integrates positions over its share of the substep (rapier's TGS solver).
fn rigid_integration_step(input: &AuditInput<'_>) -> f64 {
    let substeps = input.coupling.substeps.max(1);
    let iterations = iterations_per_substep(input.solver_iterations, substeps);
    input.dt / (substeps as usize * iterations) as f64
}

/// The energy (J) the implicit contact penalties of the deformable body `handle` hold now (its
/// points' and the rigid corners' against its faces) and its attachments' implicit springs,
/// after an implicit step whose penalty step
/// ([`ImplicitReport::penalty_step`](crate::integrate::ImplicitReport::penalty_step)) was
/// `penalty_step` (s).
fn penalty_energy(
    input: &AuditInput<'_>,
    handle: DeformableBodyHandle,
    body: &DeformableBody,
    penalty_step: f64,
) -> f64 {
    let Some(constraints) = input.coupling.constraints(handle) else {
        return 0.0;
    };
    let settings = &constraints.contacts.settings;
    let nodes = constraints
        .contacts()
        .iter()
        .filter_map(|contact| match contact.at {
            BodyPoint::Node(n) => {
                let n = n as usize;
                let penalty = contact.penalty(
                    body.positions()[n],
                    body.masses()[n],
                    settings,
                    penalty_step,
                );
                Some(penalty.map_or(0.0, |penalty| penalty.energy))
            }
            BodyPoint::Embedded(_) => None,
        })
        .sum::<f64>();
    let springs = (&constraints.rigid_proxies[..], settings);
    nodes
        + contact::corner_penalty_energy(body, &constraints.contacts, penalty_step)
        + attachment::spring_energy(body, &constraints.attachments, springs, penalty_step)
}

/// The energy (J) of a dynamic rigid body under gravity `g` (m/s²), its gravitational part at
/// its centre of mass, and what taking it half a substep of `h` (s) back along its velocity adds.
fn rigid_energy(body: &RigidBody, g: DVec3, h: f64) -> MemberEnergy {
    let mass = f64::from(body.mass());
    let v = body.linvel().as_dvec3();
    let w = body.angvel().as_dvec3();
    let spin = if w == DVec3::ZERO {
        0.0
    } else {
        let i = body.mass_properties().effective_world_inv_inertia;
        let inverse = DMat3::from_cols_array(
            &[
                i.m11, i.m12, i.m13, i.m12, i.m22, i.m23, i.m13, i.m23, i.m33,
            ]
            .map(f64::from),
        );
        // A body with locked rotations has a singular inverse inertia: no spin energy.
        if inverse.determinant().abs() > 0.0 {
            0.5 * w.dot(inverse.inverse() * w)
        } else {
            0.0
        }
    };
    let com = body.center_of_mass().as_dvec3();
    let moving = 0.5 * mass * v.length_squared() + spin;
    MemberEnergy {
        total: moving - mass * g.dot(com),
        half_step_back: mass * g.dot(v) * (h / 2.0),
        carried_shift: 0.0,
        moving,
        load_change_work: 0.0,
        // f32 keeps about 7 digits of the position and velocity.
        allowance: 1e-6 * (moving + mass * g.length() * com.length()),
    }
}

/// A rigid body's pose at the end of a frame: centre of mass (m) and orientation.
#[derive(Debug, Clone, Copy)]
pub(super) struct RigidPose {
    pub(super) com: DVec3,
    pub(super) rotation: DQuat,
}

/// Every rigid body's pose now.
pub(super) fn rigid_poses(input: &AuditInput<'_>) -> HashMap<RigidBodyHandle, RigidPose> {
    input
        .bodies
        .iter()
        .map(|(handle, body)| {
            let rotation = body.position().rotation;
            (
                handle,
                RigidPose {
                    com: body.center_of_mass().as_dvec3(),
                    rotation: DQuat::from_xyzw(
                        f64::from(rotation.x),
                        f64::from(rotation.y),
                        f64::from(rotation.z),
                        f64::from(rotation.w),
                    ),
                },
            )
        })
        .collect()
}

/// The work (J) kinematic and fixed bodies did on the deformable body `soft` over the frame,
/// from the loads it exerted on them and their motion since `before`.
pub(super) fn kinematic_work(
    input: &AuditInput<'_>,
    soft: DeformableBodyHandle,
    before: &HashMap<RigidBodyHandle, RigidPose>,
) -> f64 {
    input
        .coupling
        .rigid_loads()
        .iter()
        .filter(|load| load.soft_body == soft)
        .filter_map(|load| {
            let body = input.bodies.get(load.rigid_body)?;
            if body.is_dynamic() {
                return None;
            }
            let then = before.get(&load.rigid_body)?;
            let rotation = body.position().rotation;
            let now = DQuat::from_xyzw(
                f64::from(rotation.x),
                f64::from(rotation.y),
                f64::from(rotation.z),
                f64::from(rotation.w),
            );
            let turn = (now * then.rotation.inverse()).to_scaled_axis();
            let moved = body.center_of_mass().as_dvec3() - then.com;
            Some(-(load.force.dot(moved) + load.torque.dot(turn)))
        })
        .sum()
}

/// The energy check of `members`: their energy now against `before` plus `work` (J), with the
/// tolerance `relative` times the energy in motion and strain (the larger of now and before)
/// plus the members' allowances (now and before: an oscillation may go down then up) plus
/// `floor` (J). Members absent before count as unchanged. A rigid body's gravitational energy is
/// taken half an integration step back in both frames, less now what the substeps in which
/// implicit soft steps carried it moved that by (see the module's documentation).
pub(super) fn check(
    members: &[Member],
    (now, before): (
        &HashMap<Member, MemberEnergy>,
        &HashMap<Member, MemberEnergy>,
    ),
    work: f64,
    (relative, floor): (f64, f64),
) -> EnergyCheck {
    let (mut energy, mut previous, mut moving, mut allowance) = (0.0, 0.0, 0.0, 0.0);
    for member in members {
        let Some(here) = now.get(member) else {
            continue;
        };
        let then = before.get(member);
        let measured = here.total + here.half_step_back - here.carried_shift;
        energy += measured;
        previous += then.map_or(measured, |e| e.total + e.half_step_back);
        let then = then.unwrap_or(here);
        moving += here.moving.max(then.moving);
        allowance += here.allowance + then.allowance;
    }
    EnergyCheck {
        energy,
        expected: previous + work,
        work,
        gain: energy - (previous + work),
        tolerance: relative * (moving + work.abs()) + allowance + floor,
    }
}
