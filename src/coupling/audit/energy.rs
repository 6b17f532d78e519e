//! The energy side of the audit: `E = Σ_soft (K + Ψ + V_g) + Σ_dynamic rigid (K + V_g)`, measured
//! at the end of each frame and compared with the previous frame's plus the work kinematic bodies
//! did on the deformable bodies over the frame, `gain = E_n - (E_{n-1} + W_n)`.
//!
//! - Soft bodies: kinetic `Σ m v²/2`, elastic `Ψ` (the material's strain energy), gravitational
//!   `-Σ m g·x`. The implicit contact penalty's stored energy is not counted.
//! - Dynamic rigid bodies: `m v²/2 + ωᵀ I ω / 2`, and the gravitational energy at the centre of
//!   mass half a coupling substep back along the velocity, which rapier's symplectic Euler step
//!   keeps exactly in free flight. Fixed and kinematic bodies carry none.
//! - Work: a kinematic (or fixed) rigid body a deformable body pushed with the mean force `F` and
//!   torque `τ` over the frame ([`RigidLoad`](crate::coupling::RigidLoad)) while moving its centre
//!   of mass by `Δx` and turning by `Δθ` did `W = -(F·Δx + τ·Δθ)` on it. Gravity's work is in the
//!   gravitational terms. Nothing else is counted: forces the caller applies, joint motors,
//!   kinematic bodies pushing rigid bodies through rapier's contacts and state set between
//!   frames all show as gains.
//!
//! Bodies exchanging energy are checked together: a *cluster* is a set of deformable bodies and
//! dynamic rigid bodies joined by contacts and attachments (the rigid bodies each deformable
//! body's last substep touched or is glued to) or by overlapping bounding boxes (deformable bodies
//! that may touch), and each deformable body is given its cluster's check.

use super::{AuditInput, EnergyCheck};
use crate::body::DeformableBodyHandle;
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
    pub(super) total: f64,
    pub(super) moving: f64,
    /// What f32 rounding of a rigid body's state can change its energy by (J).
    pub(super) rounding: f64,
}

/// Every member's energy (J) now.
pub(super) fn energies(input: &AuditInput<'_>) -> HashMap<Member, MemberEnergy> {
    let g = input.gravity;
    let mut all = HashMap::new();
    for (handle, body) in input.soft_bodies.iter() {
        let moving = body.kinetic_energy() + body.elastic_energy();
        let total = moving + body.gravity_potential_energy(g);
        all.insert(
            Member::Soft(handle),
            MemberEnergy {
                total,
                moving,
                rounding: 0.0,
            },
        );
    }
    let h = input.dt / f64::from(input.coupling.substeps.max(1));
    for (handle, body) in input.bodies.iter().filter(|(_, b)| b.is_dynamic()) {
        all.insert(Member::Rigid(handle), rigid_energy(body, g, h));
    }
    all
}

/// The energy (J) of a dynamic rigid body under gravity `g` (m/s²), its gravitational part half
/// a substep of `h` (s) back along its velocity.
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
    let potential = -mass * g.dot(com - v * (h / 2.0));
    MemberEnergy {
        total: moving + potential,
        moving,
        // f32 keeps about 7 digits of the position and velocity.
        rounding: 1e-6 * (moving + mass * g.length() * com.length()),
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
/// plus the rigid bodies' f32 rounding plus `floor` (J). Members absent before count as
/// unchanged.
pub(super) fn check(
    members: &[Member],
    now: &HashMap<Member, MemberEnergy>,
    before: &HashMap<Member, MemberEnergy>,
    work: f64,
    relative: f64,
    floor: f64,
) -> EnergyCheck {
    let (mut energy, mut previous, mut moving, mut rounding) = (0.0, 0.0, 0.0, 0.0);
    for member in members {
        let Some(here) = now.get(member) else {
            continue;
        };
        let then = before.get(member).unwrap_or(here);
        energy += here.total;
        previous += then.total;
        moving += here.moving.max(then.moving);
        rounding += here.rounding.max(then.rounding);
    }
    EnergyCheck {
        energy,
        expected: previous + work,
        work,
        gain: energy - (previous + work),
        tolerance: relative * (moving + work.abs()) + rounding + floor,
    }
}
