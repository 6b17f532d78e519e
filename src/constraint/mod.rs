//! The constraints on a body's nodes as the integrators see them: one interface with an
//! explicit side and an implicit side, implemented by each kind (contacts with colliders and
//! with the body's own surface, rigid vertices on the boundary, attachments to rigid bodies).
//!
//! Each body's constraints live in a [`BodyConstraints`], kept beside the body (by the
//! coupling, per body handle) and handed to the integrators with it.
//!
//! An explicit substep of length `h` ([`SymplecticEuler`](crate::integrate::SymplecticEuler)),
//! in order:
//! 1. `v ← v + h (f/m + g)` on the free nodes; the touched rigid bodies fall too;
//! 2. `ExplicitSide::prepare` for every kind, in `EXPLICIT`'s order: each readies its
//!    velocity constraints for the substep;
//! 3. sweeps: `ExplicitSide::sweep` for every kind in turn (then the contacts between soft
//!    bodies), once, or [`ContactSettings::velocity_iterations`](crate::contact::ContactSettings::velocity_iterations)
//!    times when dynamic rigid bodies, self-contacts, rigid vertices or other soft bodies couple
//!    the constraints;
//! 4. `ExplicitSide::advance` for every kind (anchors and rigid vertices move with their
//!    bodies), then `x ← x + h v`.
//!
//! An implicit step adds every kind's `ImplicitSide` terms to the incremental potential: an
//! energy `E_c` (J), its force `-∂E_c/∂x` (N) on a point of the body and its tangent
//! `∂²E_c/∂x²` (N/m), each point moving with the nodes of its stencil. Contacts give the
//! penalty `k/2 min(0, g)²` and the lagged friction (a self-contact's on the node relative to its
//! triangle, a rigid vertex's on the triangle's point relative to the vertex); attachments a
//! spring `k/2 |x − a|²` to their anchor `a`. Contacts between soft bodies have an explicit side
//! only: bodies touching each other are stepped together explicitly.

mod set;

pub use set::BodyConstraints;

use crate::assembly::Stiffness;
use crate::attachment;
use crate::body::DeformableBody;
use crate::contact;
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};

/// A constraint kind's explicit side: velocity constraints solved by sequential impulses.
pub(crate) trait ExplicitSide {
    /// Readies the kind's constraints for a substep of `h` (s), after the velocity update.
    fn prepare(&self, body: &mut DeformableBody, constraints: &mut BodyConstraints, h: f64);
    /// One sweep over the kind's constraints: impulses that correct the nodes' velocities (and
    /// the touched rigid bodies').
    fn sweep(&self, body: &mut DeformableBody, constraints: &mut BodyConstraints);
    /// Moves what the kind carries along with the rigid bodies over the substep of `h` (s),
    /// before the position update.
    fn advance(&self, body: &mut DeformableBody, constraints: &mut BodyConstraints, h: f64);
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
    fn begin(&self, body: &mut DeformableBody, constraints: &mut BodyConstraints, h: f64);
    /// Calls `each` with every term the kind adds for an effective step `h` (s) at the body's
    /// current positions.
    fn for_each_term(
        &self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        h: f64,
        each: &mut dyn FnMut(ImplicitTerm),
    );
    /// After the step of length `h` (s, effective length `effective_h`): records the impulses
    /// (N s) the terms gave, for the rigid bodies and the loads.
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        effective_h: f64,
        h: f64,
    );
    /// Calls `each` with every stencil the kind's terms may act on over the step, active or
    /// not: the tangent's pattern must couple their nodes.
    fn for_each_stencil(
        &self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        each: &mut dyn FnMut(Stencil),
    );
}

/// `each` called with a term given by its parts: the point, its energy (J), force (N) and
/// tangent (N/m).
fn from_parts<'e>(
    each: &'e mut dyn FnMut(ImplicitTerm),
) -> impl FnMut(Stencil, f64, DVec3, DMat3) + 'e {
    move |at, energy, force, tangent| {
        each(ImplicitTerm {
            at,
            energy,
            force,
            tangent,
        });
    }
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
pub(crate) const IMPLICIT: [&dyn ImplicitSide; 3] = [&NodeContacts, &CornerContacts, &Attachments];

impl ExplicitSide for NodeContacts {
    fn prepare(&self, body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::prepare_velocities(body, &mut c.contacts, &mut c.rigid_proxies, h);
    }
    fn sweep(&self, body: &mut DeformableBody, c: &mut BodyConstraints) {
        contact::solve_velocities(body, &mut c.contacts, &mut c.rigid_proxies);
    }
    fn advance(&self, _body: &mut DeformableBody, _c: &mut BodyConstraints, _h: f64) {}
}

impl ExplicitSide for CornerContacts {
    fn prepare(&self, body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::prepare_corners(body, &mut c.contacts, &c.rigid_proxies, h);
    }
    fn sweep(&self, body: &mut DeformableBody, c: &mut BodyConstraints) {
        contact::solve_corners(body, &mut c.contacts, &mut c.rigid_proxies);
    }
    fn advance(&self, _body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::advance_corners(&mut c.contacts, &c.rigid_proxies, h);
    }
}

impl ExplicitSide for Attachments {
    fn prepare(&self, body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        attachment::prepare_velocities(body, &mut c.attachments, &c.rigid_proxies, h);
    }
    fn sweep(&self, body: &mut DeformableBody, c: &mut BodyConstraints) {
        attachment::solve_velocities(body, &c.attachments, &mut c.rigid_proxies);
    }
    fn advance(&self, _body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        attachment::advance_anchors(&mut c.attachments, &c.rigid_proxies, h);
    }
}

impl ImplicitSide for NodeContacts {
    fn begin(&self, body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::lag_friction(body, &mut c.contacts, &mut c.rigid_proxies, h);
    }
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        h: f64,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        contact::for_each_contact_term(body, &c.contacts, h, from_parts(each));
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        effective_h: f64,
        h: f64,
    ) {
        contact::record_penalty_impulses(
            body,
            &mut c.contacts,
            &mut c.rigid_proxies,
            effective_h,
            h,
        );
    }
    fn for_each_stencil(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        each: &mut dyn FnMut(Stencil),
    ) {
        contact::for_each_contact_stencil(body, &c.contacts, each);
    }
}

impl ImplicitSide for CornerContacts {
    fn begin(&self, body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::lag_corner_friction(body, &mut c.contacts, &c.rigid_proxies, h);
    }
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        h: f64,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        let proxies = &c.rigid_proxies;
        contact::for_each_corner_term(body, &c.contacts, proxies, h, from_parts(each));
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        effective_h: f64,
        h: f64,
    ) {
        let proxies = &mut c.rigid_proxies;
        contact::record_corner_impulses(body, &mut c.contacts, proxies, effective_h, h);
    }
    fn for_each_stencil(
        &self,
        _body: &DeformableBody,
        c: &BodyConstraints,
        each: &mut dyn FnMut(Stencil),
    ) {
        contact::for_each_corner_stencil(&c.contacts, each);
    }
}

/// The weight of a point that is a node itself.
const UNIT_WEIGHT: [f64; 1] = [1.0];

impl ImplicitSide for Attachments {
    fn begin(&self, _body: &mut DeformableBody, _c: &mut BodyConstraints, _h: f64) {}
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        h: f64,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        let (proxies, settings) = (&c.rigid_proxies, &c.contacts.settings);
        attachment::for_each_spring(
            body,
            &c.attachments,
            proxies,
            settings,
            h,
            |a, k, target| {
                let offset = body.positions[a.node as usize] - target;
                each(ImplicitTerm {
                    at: Stencil {
                        nodes: std::slice::from_ref(&a.node),
                        weights: &UNIT_WEIGHT,
                    },
                    energy: 0.5 * k * offset.length_squared(),
                    force: -offset * k,
                    tangent: DMat3::IDENTITY * k,
                });
            },
        );
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        effective_h: f64,
        h: f64,
    ) {
        let BodyConstraints {
            attachments,
            rigid_proxies,
            contacts,
            ..
        } = c;
        let settings = &contacts.settings;
        attachment::record_spring_impulses(
            body,
            attachments,
            rigid_proxies,
            settings,
            effective_h,
            h,
        );
    }
    fn for_each_stencil(
        &self,
        _body: &DeformableBody,
        _c: &BodyConstraints,
        _each: &mut dyn FnMut(Stencil),
    ) {
        // A spring acts on its node alone.
    }
}

/// The pairs of nodes `[a, b]` (`a > b`) some implicit term of `constraints` may couple that
/// `stiffness`'s pattern does not hold (a self-contact's node and its triangle's corners).
pub(crate) fn uncoupled_pairs(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    stiffness: &Stiffness,
) -> Vec<[u32; 2]> {
    let mut missing = Vec::new();
    for kind in IMPLICIT {
        kind.for_each_stencil(body, constraints, &mut |at| {
            for &a in at.nodes {
                for &b in at.nodes {
                    if a > b && !stiffness.couples(a, b) {
                        missing.push([a, b]);
                    }
                }
            }
        });
    }
    missing.sort_unstable();
    missing.dedup();
    missing
}

/// Adds every implicit term's force (N) into `residual` (per node), for an effective step `h`.
pub(crate) fn add_implicit_forces(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    h: f64,
    residual: &mut [DVec3],
) {
    for kind in IMPLICIT {
        kind.for_each_term(body, constraints, h, &mut |term| {
            for (&node, w) in term.at.nodes.iter().zip(term.at.weights) {
                residual[node as usize] += term.force * *w;
            }
        });
    }
}

/// The implicit terms' total energy (J) for an effective step `h`.
pub(crate) fn implicit_energy(body: &DeformableBody, constraints: &BodyConstraints, h: f64) -> f64 {
    let mut energy = 0.0;
    for kind in IMPLICIT {
        kind.for_each_term(body, constraints, h, &mut |term| energy += term.energy);
    }
    energy
}

/// Adds every implicit term's tangent (N/m) into `stiffness`, for an effective step `h`.
pub(crate) fn add_implicit_tangents(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    h: f64,
    stiffness: &mut Stiffness,
) {
    for kind in IMPLICIT {
        kind.for_each_term(body, constraints, h, &mut |term| {
            stiffness.add_stencil_block(term.at, &term.tangent, &body.pinned);
        });
    }
}
