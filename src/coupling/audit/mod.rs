//! The per-frame audit of a coupled world: after a frame of [`SoftCoupling::step`] (or
//! [`FvmWorld::step`](crate::world::FvmWorld::step)), [`Audit::check`] tells, per deformable
//! body and for the coupled system, whether the frame did something a correct step cannot do.
//! Contract: a frame is *clean* when
//!
//! 1. **Energy**: the coupled system's energy did not rise by more than the tolerance above the
//!    previous frame's plus the measured work done on it ([`EnergyCheck`]; what is counted is in
//!    the `energy` module's documentation: soft kinetic, elastic and gravitational energy,
//!    every coupled dynamic rigid body's kinetic and gravitational energy, the work of kinematic
//!    bodies on the deformable bodies). Each deformable body is checked with the rigid and
//!    deformable bodies it exchanges energy with, and the coupled system as one: every
//!    deformable body and every dynamic rigid body one of them touched or is glued to in the
//!    frame. A rigid body that met only rapier's own contacts in the frame is rapier's to
//!    answer for: rapier's position correction can lift a body that lands on an edge (a 100 kg
//!    box tumbling off a soft block onto the ground gained 0.64 J in one 1/30 s frame, the same
//!    with the block moved 10 m away before the frame). Rapier's contacts also carry energy
//!    between rigid bodies (a box falling onto a ball that rests against a block), so each check
//!    is made twice, with the dynamic bodies rapier's contacts held against the checked rigid
//!    bodies in the frame (one contact after another) and without them, and a gain counts only
//!    when both show it: the first counts rapier's own gains in those bodies, the second misses
//!    the energy they handed in.
//! 2. **Contacts**: no contact point of a body lies deeper than the penetration tolerance inside
//!    a collider or another deformable body, and none crossed a collider or another deformable
//!    body over the frame.
//! 3. **Elements**: no element is inverted (`V ≤ 0`) or collapsed (`V < J_min V₀`).
//! 4. **Step**: the body's step was not refused ([`BodyAudit::step_error`]): the integrators
//!    refuse a frame rather than keep one they could not resolve (an implicit Newton solve that
//!    does not converge in the most substeps allowed, an element crushed, a contact not held).
//!
//! Tolerances ([`AuditSettings`]):
//! - energy: `relative × (K + Ψ + |W|) + allowances + floor`, with `K + Ψ` the kinetic and
//!   elastic (and implicit penalty) energy of the bodies checked (the larger of the two frames),
//!   `|W|` the work counted, `relative` 1e-3 (Newton's tolerance, and the penalty energy counted
//!   with the node's own mass only), a floor of 1e-9 J, and allowances (now and before) for
//!   what is not a gain: rapier's f32 rounding of each dynamic rigid body, `1e-6 (K + m |g| |x|)`,
//!   and for a deformable body stepped explicitly the oscillation of symplectic Euler's measured
//!   energy about the shadow energy it conserves, `(h / h_crit)(K + Ψ)` with `h` its substep and
//!   `h_crit` its stability limit: a mode of frequency `ω` oscillates by about `hω/2` of its
//!   energy, and `ω ≤ 2 / h_crit`. (Measured on a 10 cm cube striking the ground at 3 m/s, the
//!   largest rise from one frame to the next is about 0.09 `(h / h_crit)(K + Ψ)` and falls in
//!   proportion to `h`.)
//! - penetration and crossing: `max(contact margin, fraction × smallest rest altitude)` of the
//!   body's tetrahedra: within the margin a point is in contact, and the contact response pushes
//!   it back out; deeper than a fraction of an element, the surface is no longer where the mesh
//!   says.
//! - collapse: `J_min`, 1 % of the rest volume by default: no solid compresses so far.
//!
//! State changed between frames (a velocity set, a rigid body moved by hand) counts as the
//! frame's: call [`Audit::restart`] after changing it.

mod cluster;
mod collider_path;
mod crossing;
mod elements;
mod energy;
mod penetration;

use crate::body::{DeformableBodyHandle, DeformableBodySet};
use crate::coupling::{SoftCoupling, SoftStepResults};
use crate::integrate::AutomaticReport;
use cluster::Cluster;
use collider_path::ColliderMotion;
use energy::{Member, MemberEnergy, RigidPose};
use penetration::Checked;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderHandle, ColliderSet};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use std::collections::HashMap;

pub use report::{BodyAudit, EnergyCheck, FrameAudit, PenetrationTarget, Penetrations};

mod report;

/// The audit's tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AuditSettings {
    /// Energy rise allowed per frame, as a fraction of the kinetic and elastic energy of the
    /// bodies checked plus the work counted (dimensionless), beyond the allowances for f32
    /// rounding and explicit oscillation (see the module's documentation); default 1e-3.
    pub energy_relative_tolerance: f64,
    /// Energy rise (J) allowed per frame whatever the energy; default 1e-9 J.
    pub energy_floor: f64,
    /// Penetration and crossing depth allowed beyond the contact margin, as a fraction of the
    /// body's smallest rest tetrahedron altitude (dimensionless); default 0.25.
    pub penetration_fraction: f64,
    /// An element whose volume is below this fraction of its rest volume (but positive) is
    /// collapsed (dimensionless); default 1e-2.
    pub collapse_ratio: f64,
}

impl Default for AuditSettings {
    fn default() -> Self {
        Self {
            energy_relative_tolerance: 1e-3,
            energy_floor: 1e-9,
            penetration_fraction: 0.25,
            collapse_ratio: crate::integrate::COLLAPSE_RATIO,
        }
    }
}

/// What the audit reads of a world after a frame: the deformable bodies, the coupling that
/// stepped them (its contacts, attachments and loads), the rigid bodies and colliders, gravity
/// (m/s²), the frame step (s) and rapier's solver iterations.
#[derive(Clone, Copy)]
pub struct AuditInput<'a> {
    /// The deformable bodies.
    pub soft_bodies: &'a DeformableBodySet,
    /// The coupling that stepped them.
    pub coupling: &'a SoftCoupling,
    /// The rigid bodies.
    pub bodies: &'a RigidBodySet,
    /// The colliders.
    pub colliders: &'a ColliderSet,
    /// Gravity (m/s²).
    pub gravity: DVec3,
    /// The frame step (s).
    pub dt: f64,
    /// rapier's `num_solver_iterations` for the frame, which the coupling divides among its
    /// substeps: each is a substep of rapier's position integration (its TGS solver).
    pub solver_iterations: usize,
}

/// The state a frame is compared with: the previous frame's.
#[derive(Debug, Clone, Default)]
struct Snapshot {
    energies: HashMap<Member, MemberEnergy>,
    /// The coupling's frames begun ([`SoftCoupling::frames_begun`]) when it was taken.
    frames_begun: u64,
    rigid_poses: HashMap<RigidBodyHandle, RigidPose>,
    collider_poses: HashMap<ColliderHandle, Pose>,
    positions: HashMap<DeformableBodyHandle, Vec<DVec3>>,
}

/// The per-frame audit (see the module's documentation): it keeps the previous frame's state.
#[derive(Debug, Clone, Default)]
pub struct Audit {
    /// The tolerances.
    pub settings: AuditSettings,
    previous: Option<Snapshot>,
}

impl Audit {
    /// An audit with `settings`, which has seen no frame yet.
    pub fn new(settings: AuditSettings) -> Self {
        Self {
            settings,
            previous: None,
        }
    }

    /// Takes the world as it is now as the state the next frame is compared with (before the
    /// first frame, or after changing the state by hand). Without a step's results it counts no
    /// implicit penalty energy: restarting while a body rests on implicit penalties undercounts
    /// the state's energy by what they hold (a few µJ per contact node at rest), which the next
    /// frame may show as a gain.
    pub fn restart(&mut self, input: AuditInput<'_>) {
        self.previous = Some(snapshot(&input, &Vec::new()));
    }

    /// Checks the frame that just ended, whose step returned `results`, against the previous
    /// frame (or the state given to [`Audit::restart`]); the first frame seen has no energy
    /// check nor crossing check. The world as it is now becomes the state the next frame is
    /// compared with.
    pub fn check(&mut self, input: AuditInput<'_>, results: &SoftStepResults) -> FrameAudit {
        let mut now = snapshot(&input, results);
        let settings = self.settings;
        let previous = self.previous.as_ref();
        if let Some(before) = previous {
            energy::keep_sleeping(&input, results, &before.energies, &mut now.energies);
            if before.frames_begun == now.frames_begun {
                // No step since: the carried changes are the last frame's, already counted.
                now.energies
                    .values_mut()
                    .for_each(|e| e.carried_shift = 0.0);
            }
        }
        let energy_of = |members: &[Member]| {
            previous.map(|before| {
                let work = (members.iter())
                    .filter_map(|m| match m {
                        Member::Soft(soft) => {
                            let key = Member::Soft(*soft);
                            let loads = match (now.energies.get(&key), before.energies.get(&key)) {
                                (Some(now), Some(then)) => {
                                    now.load_change_work - then.load_change_work
                                }
                                _ => 0.0,
                            };
                            Some(energy::kinematic_work(&input, *soft, &before.rigid_poses) + loads)
                        }
                        Member::Rigid(_) => None,
                    })
                    .sum();
                energy::check(
                    members,
                    (&now.energies, &before.energies),
                    work,
                    (settings.energy_relative_tolerance, settings.energy_floor),
                )
            })
        };
        let checked = |cluster: &Cluster| {
            let closed = energy_of(&cluster.members);
            if cluster.exchanging.len() == cluster.members.len() {
                return closed;
            }
            smaller_excess(closed, energy_of(&cluster.exchanging))
        };
        let clusters = cluster::clusters(&input);
        let system = checked(&Cluster {
            members: clusters.iter().flat_map(|c| c.members.clone()).collect(),
            exchanging: clusters.iter().flat_map(|c| c.exchanging.clone()).collect(),
        });
        let mut handles: Vec<_> = input.soft_bodies.iter().map(|(handle, _)| handle).collect();
        let motions = collider_motions(&input, previous);
        let audits = crate::parallel::map_chunks(&mut handles, 1, |_, handle| {
            self.body_audit(&input, handle[0], (previous, &motions), results)
        });
        let bodies = (handles.into_iter().zip(audits))
            .map(|(handle, mut audit)| {
                let cluster = clusters
                    .iter()
                    .find(|c| c.members.contains(&Member::Soft(handle)));
                audit.energy = cluster.map_or_else(|| energy_of(&[]), checked);
                (handle, audit)
            })
            .collect();
        self.previous = Some(now);
        FrameAudit { system, bodies }
    }

    /// The contact, element and solver checks of the deformable body `handle` (its energy is
    /// its cluster's, set by the caller), against the `previous` frame in which the colliders
    /// made their `motions`.
    fn body_audit(
        &self,
        input: &AuditInput<'_>,
        handle: DeformableBodyHandle,
        (previous, motions): (Option<&Snapshot>, &HashMap<ColliderHandle, ColliderMotion>),
        results: &SoftStepResults,
    ) -> BodyAudit {
        let body = &input.soft_bodies[handle];
        let tolerance = input
            .coupling
            .contact
            .margin
            .max(self.settings.penetration_fraction * body.mesh().min_altitude());
        let glued = input.coupling.constraints(handle).map_or(Vec::new(), |c| {
            c.attachments.iter().map(|a| (a.body, a.node)).collect()
        });
        let before = previous.and_then(|p| p.positions.get(&handle).map(Vec::as_slice));
        let checked = Checked::new(body, glued, before, tolerance);
        let mut penetrations = Penetrations::default();
        // A body standing in as a rigid body meets colliders through rapier's contacts, as
        // rigid bodies do: rapier answers for them.
        if input.coupling.rigid_stand_in_of(handle).is_none() {
            penetration::against_colliders(
                &checked,
                input.colliders,
                input.bodies,
                motions,
                &mut penetrations,
            );
            penetration::colliders_inside(&checked, input.colliders, &mut penetrations);
        }
        for (other_handle, other) in input.soft_bodies.iter() {
            if other_handle != handle {
                penetration::against_soft(&checked, other, other_handle, &mut penetrations);
                if let Some(before) = previous.and_then(|p| p.positions.get(&other_handle)) {
                    let other = (other, other_handle);
                    crossing::through_soft(&checked, other, before, &mut penetrations);
                }
            }
        }
        let elements = elements::element_state(body, self.settings.collapse_ratio);
        let result = results.iter().find(|(h, _)| *h == handle).map(|(_, r)| r);
        let report: Option<&AutomaticReport> = result.and_then(|r| r.as_ref().ok());
        BodyAudit {
            energy: None,
            penetration_tolerance: tolerance,
            penetrations,
            inverted_elements: elements.inverted,
            collapsed_elements: elements.collapsed,
            smallest_volume_ratio: elements.smallest_ratio,
            newton_stalled_substeps: report
                .and_then(|r| r.implicit)
                .map_or(0, |i| i.stalled_substeps),
            step_error: result.and_then(|r| r.as_ref().err()).cloned(),
        }
    }
}

/// Each collider's motion since the `previous` frame, for those that were there then.
fn collider_motions(
    input: &AuditInput<'_>,
    previous: Option<&Snapshot>,
) -> HashMap<ColliderHandle, ColliderMotion> {
    let Some(previous) = previous else {
        return HashMap::new();
    };
    (input.colliders.iter())
        .filter_map(|(handle, collider)| {
            let then = previous.collider_poses.get(&handle)?;
            Some((handle, ColliderMotion::new(then, collider)))
        })
        .collect()
}

/// What a frame is compared with: the world now.
fn snapshot(input: &AuditInput<'_>, results: &SoftStepResults) -> Snapshot {
    Snapshot {
        energies: energy::energies(input, results),
        frames_begun: input.coupling.frames_begun(),
        rigid_poses: energy::rigid_poses(input),
        collider_poses: (input.colliders.iter())
            .map(|(handle, collider)| (handle, *collider.position()))
            .collect(),
        positions: (input.soft_bodies.iter())
            .map(|(handle, body)| (handle, body.positions().to_vec()))
            .collect(),
    }
}

/// Of the energy checks of a cluster with the rigid bodies rapier's contacts joined (`closed`)
/// and without them (`open`), the one whose gain exceeds its tolerance less (the closed one when
/// either is not a number).
fn smaller_excess(closed: Option<EnergyCheck>, open: Option<EnergyCheck>) -> Option<EnergyCheck> {
    match (closed, open) {
        (Some(closed), Some(open))
            if open.gain - open.tolerance < closed.gain - closed.tolerance =>
        {
            Some(open)
        }
        (closed, _) => closed,
    }
}
