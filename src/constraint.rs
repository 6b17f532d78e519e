//! The constraints on a body's nodes as the integrators see them: one interface with an
//! explicit side and an implicit side, implemented by each kind (contacts with colliders and
//! with the body's own surface, rigid vertices on the boundary, attachments to rigid bodies).
//!
//! An explicit substep of length `h` ([`SymplecticEuler`](crate::integrate::SymplecticEuler)),
//! in order:
//! 1. `v ← v + h (f/m + g)` on the free nodes; the touched rigid bodies fall too;
//! 2. [`ExplicitSide::prepare`] for every kind, in [`EXPLICIT`]'s order: each readies its
//!    velocity constraints for the substep;
//! 3. sweeps: [`ExplicitSide::sweep`] for every kind in turn (then the contacts between soft
//!    bodies), once, or [`ContactSettings::velocity_iterations`](crate::contact::ContactSettings::velocity_iterations)
//!    times when dynamic rigid bodies, self-contacts, rigid vertices or other soft bodies couple
//!    the constraints;
//! 4. [`ExplicitSide::advance`] for every kind (anchors and rigid vertices move with their
//!    bodies), then `x ← x + h v`.
//!
//! An implicit step adds every kind's [`ImplicitSide`] terms to the incremental potential: an
//! energy `E_c` (J), its force `-∂E_c/∂x` (N) on a point of the body and its tangent
//! `∂²E_c/∂x²` (N/m), each point moving with the nodes of its [`Stencil`]. Contacts give the
//! penalty `k/2 min(0, g)²` and the lagged friction; attachments a spring `k/2 |x − a|²` to
//! their anchor `a`. Self-contacts and rigid vertices have an explicit side only: the automatic
//! integrator steps a body with some explicitly, and a forced implicit step leaves them out.

use crate::body::DeformableBody;
use crate::contact::{self, Stencil};
use crate::{assembly::Stiffness, attachment};
use rapier3d::glamx::{DMat3, DVec3};

/// A constraint kind's explicit side: velocity constraints solved by sequential impulses.
pub(crate) trait ExplicitSide {
    /// Readies the kind's constraints for a substep of `h` (s), after the velocity update.
    fn prepare(&self, body: &mut DeformableBody, h: f64);
    /// One sweep over the kind's constraints: impulses that correct the nodes' velocities (and
    /// the touched rigid bodies').
    fn sweep(&self, body: &mut DeformableBody);
    /// Moves what the kind carries along with the rigid bodies over the substep of `h` (s),
    /// before the position update.
    fn advance(&self, body: &mut DeformableBody, h: f64);
}

/// One term of the incremental potential a constraint adds, on a point of the body.
pub(crate) struct ImplicitTerm<'a> {
    /// The point: the nodes it moves with and their weights.
    pub(crate) at: Stencil<'a>,
    /// The term's energy (J).
    pub(crate) energy: f64,
    /// Its force on the point, `-∂E/∂x` (N); node `a` of the stencil takes `w_a` of it.
    pub(crate) force: DVec3,
    /// Its tangent `∂²E/∂x²` (N/m); it couples nodes `a, b` by `w_a w_b` of it.
    pub(crate) tangent: DMat3,
}

/// A constraint kind's implicit side: terms of the incremental potential.
pub(crate) trait ImplicitSide {
    /// Called once at the start of an implicit step of effective length `h` (s), before Newton.
    fn begin(&self, body: &mut DeformableBody, h: f64);
    /// Calls `each` with every term the kind adds for an effective step `h` (s) at the body's
    /// current positions.
    fn for_each_term(&self, body: &DeformableBody, h: f64, each: &mut dyn FnMut(ImplicitTerm));
    /// After the step of length `h` (s, effective length `effective_h`): records the impulses
    /// (N s) the terms gave, for the rigid bodies and the loads.
    fn record_impulses(&self, body: &mut DeformableBody, effective_h: f64, h: f64);
}

/// Contacts of surface points with colliders and with the body's own surface.
pub(crate) struct NodeContacts;
/// Rigid vertices pressing on the body's boundary triangles.
pub(crate) struct CornerContacts;
/// Nodes glued to rigid bodies.
pub(crate) struct Attachments;

/// Every kind with an explicit side, in the order the substep prepares, sweeps and advances them.
pub(crate) const EXPLICIT: [&dyn ExplicitSide; 3] = [&NodeContacts, &CornerContacts, &Attachments];
/// Every kind with an implicit side, in the order its terms are added.
pub(crate) const IMPLICIT: [&dyn ImplicitSide; 2] = [&NodeContacts, &Attachments];

impl ExplicitSide for NodeContacts {
    fn prepare(&self, body: &mut DeformableBody, h: f64) {
        contact::prepare_velocities(body, h);
    }
    fn sweep(&self, body: &mut DeformableBody) {
        contact::solve_velocities(body);
    }
    fn advance(&self, _body: &mut DeformableBody, _h: f64) {}
}

impl ExplicitSide for CornerContacts {
    fn prepare(&self, body: &mut DeformableBody, h: f64) {
        contact::prepare_corners(body, h);
    }
    fn sweep(&self, body: &mut DeformableBody) {
        contact::solve_corners(body);
    }
    fn advance(&self, body: &mut DeformableBody, h: f64) {
        contact::advance_corners(body, h);
    }
}

impl ExplicitSide for Attachments {
    fn prepare(&self, body: &mut DeformableBody, h: f64) {
        attachment::prepare_velocities(body, h);
    }
    fn sweep(&self, body: &mut DeformableBody) {
        attachment::solve_velocities(body);
    }
    fn advance(&self, body: &mut DeformableBody, h: f64) {
        attachment::advance_anchors(body, h);
    }
}

impl ImplicitSide for NodeContacts {
    fn begin(&self, body: &mut DeformableBody, h: f64) {
        contact::lag_friction(body, h);
    }
    fn for_each_term(&self, body: &DeformableBody, h: f64, each: &mut dyn FnMut(ImplicitTerm)) {
        contact::for_each_active_penalty(body, h, |at, stiffness, gap, normal| {
            each(ImplicitTerm {
                at,
                energy: 0.5 * stiffness * gap * gap,
                force: -normal * (stiffness * gap),
                tangent: contact::penalty_tangent(stiffness, normal),
            });
        });
        contact::for_each_friction(body, h, |at, energy, force, tangent| {
            each(ImplicitTerm {
                at,
                energy,
                force,
                tangent,
            });
        });
    }
    fn record_impulses(&self, body: &mut DeformableBody, effective_h: f64, h: f64) {
        contact::record_penalty_impulses(body, effective_h, h);
    }
}

/// The weight of a point that is a node itself.
const UNIT_WEIGHT: [f64; 1] = [1.0];

impl ImplicitSide for Attachments {
    fn begin(&self, _body: &mut DeformableBody, _h: f64) {}
    fn for_each_term(&self, body: &DeformableBody, h: f64, each: &mut dyn FnMut(ImplicitTerm)) {
        attachment::for_each_spring(body, h, |attachment, stiffness, target| {
            let offset = body.positions[attachment.node as usize] - target;
            each(ImplicitTerm {
                at: Stencil {
                    nodes: std::slice::from_ref(&attachment.node),
                    weights: &UNIT_WEIGHT,
                },
                energy: 0.5 * stiffness * offset.length_squared(),
                force: -offset * stiffness,
                tangent: DMat3::IDENTITY * stiffness,
            });
        });
    }
    fn record_impulses(&self, body: &mut DeformableBody, effective_h: f64, h: f64) {
        attachment::record_spring_impulses(body, effective_h, h);
    }
}

/// Adds every implicit term's force (N) into `residual` (per node), for an effective step `h`.
pub(crate) fn add_implicit_forces(body: &DeformableBody, h: f64, residual: &mut [DVec3]) {
    for kind in IMPLICIT {
        kind.for_each_term(body, h, &mut |term| {
            for (&node, w) in term.at.nodes.iter().zip(term.at.weights) {
                residual[node as usize] += term.force * *w;
            }
        });
    }
}

/// The implicit terms' total energy (J) for an effective step `h`.
pub(crate) fn implicit_energy(body: &DeformableBody, h: f64) -> f64 {
    let mut energy = 0.0;
    for kind in IMPLICIT {
        kind.for_each_term(body, h, &mut |term| energy += term.energy);
    }
    energy
}

/// Adds every implicit term's tangent (N/m) into `stiffness`, for an effective step `h`.
pub(crate) fn add_implicit_tangents(body: &DeformableBody, h: f64, stiffness: &mut Stiffness) {
    for kind in IMPLICIT {
        kind.for_each_term(body, h, &mut |term| {
            stiffness.add_stencil_block(term.at, &term.tangent, &body.pinned);
        });
    }
}
