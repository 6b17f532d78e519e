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
//! 4. `ExplicitSide::advance` for every kind (contact planes, anchors and rigid vertices move
//!    with their bodies), then the rigid proxies move (`RigidProxy::advance`) and `x ← x + h v`.
//!
//! An implicit step adds every kind's `ImplicitSide` terms to the incremental potential: an
//! energy `E_c` (J), its force `-∂E_c/∂x` (N) on a point of the body and its tangent
//! `∂²E_c/∂x²` (N/m), each point moving with the nodes of its stencil. Contacts give the
//! penalty `k/2 min(0, g)²` and the lagged friction (a self-contact's on the node relative to its
//! triangle, a rigid vertex's on the triangle's point relative to the vertex); attachments a
//! spring `k/2 |x − a|²` to their anchor `a`. A term against a rigid body depends on its point's
//! position relative to where the body carries its own point over the step, at the velocity the
//! step gives the body: a dynamic body's response is part of the step's solve
//! (`integrate::implicit::rigid_response`), so that the coupled system's energy cannot grow.
//! Contacts between soft bodies are solved with both bodies' nodes: explicitly in the same
//! sweeps, implicitly as one system whose potential adds each contact's penalty and friction on
//! the node relative to the other body's triangle (`contact::JointContacts`,
//! `integrate::implicit::group`).

mod set;

pub use set::BodyConstraints;

use crate::assembly::Stiffness;
use crate::attachment;
use crate::body::DeformableBody;
use crate::contact::{self, ImplicitStep};
use crate::rigid::{RigidPoint, RigidProxy};
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
    /// The dynamic rigid body's point the term acts against, if any: the term depends on the
    /// point's position relative to where that body carries it over the step, and the body takes
    /// the opposite force there.
    pub(crate) partner: Option<RigidPoint>,
    /// The term's energy (J).
    pub(crate) energy: f64,
    /// Its force on the point, `-∂E/∂x` (N); node `a` of the stencil takes `w_a` of it.
    pub(crate) force: DVec3,
    /// Its tangent `∂²E/∂x²` (N/m); it couples nodes `a, b` by `w_a w_b` of it.
    pub(crate) tangent: DMat3,
}

impl ImplicitTerm<'_> {
    /// Whether the term acts between nodes of the body alone (a self-contact: weights `1, −w_a,
    /// −w_b, −w_c`, no rigid partner): its forces sum to zero, and it takes no momentum from the
    /// body. The barycentric weights come from single-precision queries, so their sum is zero
    /// to within 1e-7 (a term against anything else has weights summing to one).
    pub(crate) fn is_internal(&self) -> bool {
        self.partner.is_none() && self.at.weights.iter().sum::<f64>().abs() < 1e-6
    }
}

/// A constraint kind's implicit side: terms of the incremental potential.
pub(crate) trait ImplicitSide {
    /// Called once at the start of an implicit `step`, before Newton (the rigid bodies of
    /// `step` at their velocities at its start).
    fn begin(&self, body: &DeformableBody, constraints: &mut BodyConstraints, step: ImplicitStep);
    /// Calls `each` with every term the kind adds in the implicit `step` at the body's current
    /// positions.
    fn for_each_term(
        &self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        step: ImplicitStep,
        each: &mut dyn FnMut(ImplicitTerm),
    );
    /// After the `step`, whose solve gave the rigid bodies the velocities of `step`: records the
    /// impulses (N s) the terms gave, hands their opposite to the constraints' rigid proxies, and
    /// carries what the rigid bodies carry over the step.
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        constraints: &mut BodyConstraints,
        step: ImplicitStep,
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

/// `each` called with a term given by its parts: the point, its rigid partner, its energy (J),
/// force (N) and tangent (N/m).
fn from_parts<'e>(
    each: &'e mut dyn FnMut(ImplicitTerm),
) -> impl FnMut(Stencil, Option<RigidPoint>, f64, DVec3, DMat3) + 'e {
    move |at, partner, energy, force, tangent| {
        each(ImplicitTerm {
            at,
            partner,
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
    fn advance(&self, _body: &mut DeformableBody, c: &mut BodyConstraints, h: f64) {
        contact::advance_planes(&mut c.contacts, &c.rigid_proxies, h);
    }
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
    fn begin(&self, body: &DeformableBody, c: &mut BodyConstraints, step: ImplicitStep) {
        contact::lag_friction(body, &mut c.contacts, step);
    }
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        step: ImplicitStep,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        contact::for_each_contact_term(body, &c.contacts, step, from_parts(each));
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        step: ImplicitStep,
    ) {
        contact::record_penalty_impulses(body, &mut c.contacts, step, &mut c.rigid_proxies);
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
    fn begin(&self, body: &DeformableBody, c: &mut BodyConstraints, step: ImplicitStep) {
        contact::lag_corner_friction(body, &mut c.contacts, step);
    }
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        step: ImplicitStep,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        contact::for_each_corner_term(body, &c.contacts, step, from_parts(each));
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        step: ImplicitStep,
    ) {
        contact::record_corner_impulses(body, &mut c.contacts, step, &mut c.rigid_proxies);
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
    fn begin(&self, _body: &DeformableBody, _c: &mut BodyConstraints, _step: ImplicitStep) {}
    fn for_each_term(
        &self,
        body: &DeformableBody,
        c: &BodyConstraints,
        step: ImplicitStep,
        each: &mut dyn FnMut(ImplicitTerm),
    ) {
        let settings = &c.contacts.settings;
        attachment::for_each_spring(body, &c.attachments, settings, &step, |a, k, target| {
            let offset = body.positions[a.node as usize] - target;
            each(ImplicitTerm {
                at: Stencil {
                    nodes: std::slice::from_ref(&a.node),
                    weights: &UNIT_WEIGHT,
                },
                partner: a.partner(&step),
                energy: 0.5 * k * offset.length_squared(),
                force: -offset * k,
                tangent: DMat3::IDENTITY * k,
            });
        });
    }
    fn record_impulses(
        &self,
        body: &mut DeformableBody,
        c: &mut BodyConstraints,
        step: ImplicitStep,
    ) {
        let BodyConstraints {
            attachments,
            rigid_proxies,
            contacts,
            ..
        } = c;
        let settings = &contacts.settings;
        attachment::record_spring_impulses(body, attachments, settings, &step, rigid_proxies);
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

/// Holds the dynamic rigid bodies `constraints` couple to `body` for a substep of `h` (s) under
/// `gravity` (m/s²) in which the body did not move (its step was refused): they meet it as the
/// fixed obstacle it was over the substep. One explicit substep's sweeps run with every node
/// held at rest, so their impulses all go to the rigid bodies' proxies (whose falls are the
/// sweeps' too): a body pressing on it stops there, a glued one is held at its anchors, and
/// neither sinks into nor passes through it while its steps are refused. The body is left as it
/// was; the impulses are handed over as a step's are.
pub(crate) fn hold_partners(
    body: &mut DeformableBody,
    constraints: &mut BodyConstraints,
    h: f64,
    gravity: DVec3,
) {
    if !constraints.rigid_proxies.iter().any(RigidProxy::is_dynamic) {
        return;
    }
    let n = body.positions.len();
    let velocities = std::mem::replace(&mut body.velocities, vec![DVec3::ZERO; n]);
    let pinned = std::mem::replace(&mut body.pinned, vec![true; n]);
    constraints.contacts.clear_impulses();
    for proxy in &mut constraints.rigid_proxies {
        proxy.fall(gravity, h);
    }
    for kind in EXPLICIT {
        kind.prepare(body, constraints, h);
    }
    for _ in 0..constraints.contacts.settings.velocity_iterations.max(1) {
        for kind in EXPLICIT {
            kind.sweep(body, constraints);
        }
    }
    body.velocities = velocities;
    body.pinned = pinned;
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

/// Calls `each` with every implicit term of every kind in the implicit `step`.
pub(crate) fn for_each_implicit_term(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
    each: &mut dyn FnMut(ImplicitTerm),
) {
    for kind in IMPLICIT {
        kind.for_each_term(body, constraints, step, each);
    }
}

/// The angular impulse (N m s, about the origin) the implicit terms in the implicit `step` of
/// length `h` give the body, counted where the dynamic rigid bodies take the opposite: `Σ a × F h`
/// over the terms, `F` each term's force on the body where the step ends and `a` its rigid
/// body's point, fixed over the step (a corner's vertex, a contact plane's point, an anchor);
/// `None` when a term pushes the body against something else (a fixed or kinematic collider or
/// anchor), which takes angular momentum anyway; its own surface (a self-contact, internal)
/// gives none. The body receives `F h` at its own point, where its nodes end the step; the two
/// differ by the points' relative travel.
pub(crate) fn partner_angular_impulse(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
) -> Option<DVec3> {
    let mut impulse = Some(DVec3::ZERO);
    for_each_implicit_term(body, constraints, step, &mut |term| match term.partner {
        Some(partner) => {
            impulse = impulse.map(|sum| sum + partner.point.cross(term.force * step.length));
        }
        None if term.force != DVec3::ZERO && !term.is_internal() => impulse = None,
        None => {}
    });
    impulse
}

/// Adds every implicit term's force (N) into `residual` (per node), in the implicit `step`.
pub(crate) fn add_implicit_forces(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
    residual: &mut [DVec3],
) {
    for_each_implicit_term(body, constraints, step, &mut |term| {
        for (&node, w) in term.at.nodes.iter().zip(term.at.weights) {
            residual[node as usize] += term.force * *w;
        }
    });
}

/// The implicit terms' total energy (J) in the implicit `step`.
pub(crate) fn implicit_energy(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
) -> f64 {
    let mut energy = 0.0;
    for_each_implicit_term(body, constraints, step, &mut |term| energy += term.energy);
    energy
}

/// Whether an implicit term of `constraints` in the implicit `step` pushes the body against
/// something else (a term with energy that is not [internal](ImplicitTerm::is_internal)).
pub(crate) fn pushed_from_outside(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
) -> bool {
    let mut pushed = false;
    for_each_implicit_term(body, constraints, step, &mut |term| {
        pushed |= term.energy != 0.0 && !term.is_internal();
    });
    pushed
}

/// Adds every implicit term's tangent (N/m) into `stiffness`, in the implicit `step`, as if the
/// rigid bodies' velocities were held (their response is added to the Newton direction apart).
pub(crate) fn add_implicit_tangents(
    body: &DeformableBody,
    constraints: &BodyConstraints,
    step: ImplicitStep,
    stiffness: &mut Stiffness,
) {
    for_each_implicit_term(body, constraints, step, &mut |term| {
        stiffness.add_stencil_block(term.at, &term.tangent, &body.pinned);
    });
}
