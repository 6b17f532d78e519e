//! The implicit side of surface-point contacts: each active contact adds `k/2 min(0, g)²` to the
//! incremental potential (`k` [`ContactSettings::penalty_factor`](super::ContactSettings::penalty_factor)
//! times the point's effective `m/h²`), with gradient and Hessian `k n nᵀ`, and friction as a
//! lagged dissipation potential; after the step, the penalty and friction forces become the
//! impulses handed to rigid bodies.
//!
//! Against a collider the point is the surface point itself (a node, or an embedded vertex with
//! its element's nodes), and the plane travels with the collider's rigid body over the step (at
//! the velocity the step's solve gives a dynamic body, which takes the opposite force at the
//! plane's point). Against a triangle of the body's own surface it is the node relative to
//! the triangle's contact point, `x_n − Σ w_i x_i` (weights `1, −w_a, −w_b, −w_c`): the gap, the
//! slip and every force are then those of the node against the moving triangle, node and
//! triangle take equal and opposite forces, and the body's momentum is kept.

use super::{
    BodyPoint, ContactSet, ContactSettings, ImplicitStep, NodeContact, Obstacle, corner, partners,
};
use crate::body::DeformableBody;
use crate::embedding::Embedding;
use crate::rigid::{RigidPoint, RigidProxy};
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};

/// A contact's point as the implicit terms see it.
pub(super) enum ContactPoint<'a> {
    /// The surface point itself, against a collider.
    Own(Stencil<'a>),
    /// A node relative to its own triangle's contact point, placed at the contact plane's point
    /// `origin` (m) so that positions read as the node's against a fixed triangle.
    Relative {
        nodes: [u32; 4],
        weights: [f64; 4],
        origin: DVec3,
    },
}

impl ContactPoint<'_> {
    /// The nodes the point moves with and their weights.
    pub(super) fn stencil(&self) -> Stencil<'_> {
        match self {
            Self::Own(stencil) => *stencil,
            Self::Relative { nodes, weights, .. } => Stencil { nodes, weights },
        }
    }

    /// The point's position (m) with the nodes at `x`.
    pub(super) fn position(&self, x: &[DVec3]) -> DVec3 {
        match self {
            Self::Own(stencil) => stencil.interpolate(x),
            Self::Relative { origin, .. } => self.stencil().interpolate(x) + *origin,
        }
    }
}

/// The point of `contact` the implicit terms act on; `embedding` is the body's.
pub(super) fn contact_point<'a>(
    contact: &'a NodeContact,
    embedding: Option<&'a Embedding>,
) -> ContactPoint<'a> {
    match (contact.at, &contact.obstacle) {
        (BodyPoint::Node(node), Obstacle::OwnTriangle(triangle)) => {
            let [a, b, c] = triangle.nodes;
            let [wa, wb, wc] = triangle.weights;
            ContactPoint::Relative {
                nodes: [node, a, b, c],
                weights: [1.0, -wa, -wb, -wc],
                origin: contact.point,
            }
        }
        _ => ContactPoint::Own(contact.at.stencil(embedding)),
    }
}

/// A contact's obstacle over an implicit step.
struct Carried {
    /// How far (m) it carries its plane over the step: its rigid body's velocity at the plane's
    /// point times the step's length.
    travel: DVec3,
    /// The rigid point the contact acts against when that body is dynamic.
    partner: Option<RigidPoint>,
}

/// `contact`'s obstacle in the implicit `step`.
fn carried(contact: &NodeContact, step: &ImplicitStep) -> Carried {
    match contact.obstacle {
        Obstacle::Collider { proxy: Some(p), .. } => {
            let rigid = &step.rigid[p];
            Carried {
                travel: rigid.velocity_at(contact.point) * step.length,
                partner: rigid.is_dynamic().then_some(RigidPoint {
                    proxy: p,
                    point: contact.point,
                }),
            }
        }
        _ => Carried {
            travel: DVec3::ZERO,
            partner: None,
        },
    }
}

/// Whether the implicit `step` skips `contact`'s terms (see [`ImplicitStep::partners_only`]),
/// known before the obstacle's travel is found: the rigid bodies' response evaluates the few
/// terms against a dynamic body many times per step, and passes over the contacts with the
/// ground and other still colliders.
#[inline(always)]
fn skipped(contact: &NodeContact, step: &ImplicitStep) -> bool {
    step.partners_only
        && !matches!(
            contact.obstacle,
            Obstacle::Collider { proxy: Some(p), .. } if step.rigid[p].is_dynamic()
        )
}

/// The implicit force (N) on a contact's point at `x` (m, its position relative to the
/// obstacle's travel), of effective mass `mass` (kg), in the implicit `step`: the penalty and
/// the lagged friction.
fn implicit_force(
    contact: &NodeContact,
    x: DVec3,
    mass: f64,
    settings: &ContactSettings,
    step: &ImplicitStep,
) -> DVec3 {
    let friction = contact
        .friction_term(x, settings, step.effective)
        .map_or(DVec3::ZERO, |(_, force, _)| force);
    let penalty = contact
        .penalty(x, mass, settings, step.penalty_step)
        .map_or(DVec3::ZERO, |penalty| contact.normal * penalty.push);
    friction + penalty
}

/// Records the impulses (N s) the implicit penalty and friction gave the contact points over a
/// substep of length `step.length` (s), at the positions that ended it and the rigid bodies'
/// velocities of `step`, hands their opposite to the rigid bodies' `proxies` at the planes'
/// points (a self-contact's stay within the body), and carries the planes along with their
/// rigid bodies.
pub(crate) fn record_penalty_impulses(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    step: ImplicitStep,
    proxies: &mut [RigidProxy],
) {
    let settings = contacts.settings;
    let (positions, embedding, mut partners) = partners(body, proxies);
    for contact in &mut contacts.nodes {
        let point = contact_point(contact, embedding);
        let at = point.stencil();
        let obstacle = carried(contact, &step);
        let x = point.position(positions) - obstacle.travel;
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        let impulse = implicit_force(contact, x, mass, &settings, &step) * step.length;
        if !matches!(contact.obstacle, Obstacle::OwnTriangle(_)) {
            partners.apply(&contact.obstacle, -impulse, contact.point);
        }
        contact.point += obstacle.travel;
        contact.impulse += impulse;
    }
}

/// Stiffens the penalty of every contact with a collider whose point the implicit `step` (its
/// rigid bodies at the velocities the step's solve gave them) took from where it was at
/// `start` (the body's positions at the step's start, m) to deeper than
/// [`ContactSettings::resting_depth`] behind its plane (see [`NodeContact::stiffen_if_deep`]):
/// the load, not the point's own mass, then sets how deep it rests. Returns whether any was
/// stiffened (the step must then be solved again).
pub(crate) fn stiffen_deep_contacts(
    body: &DeformableBody,
    contacts: &mut ContactSet,
    step: ImplicitStep,
    start: &[DVec3],
) -> bool {
    let settings = contacts.settings;
    let nodes = NodeSlices::of(body);
    let mut stiffened = false;
    for contact in &mut contacts.nodes {
        if !matches!(contact.obstacle, Obstacle::Collider { .. }) {
            continue;
        }
        let point = contact_point(contact, body.embedding.as_ref());
        let obstacle = carried(contact, &step);
        let mass = effective_mass(&point.stencil(), nodes.masses, nodes.pinned);
        let end = point.position(nodes.positions) - obstacle.travel;
        let path = (point.position(start), end);
        stiffened |= contact.stiffen_if_deep(path, mass, &settings, step.penalty_step);
    }
    let corners = (&mut contacts.corners[..], &settings);
    stiffened | corner::stiffen_deep_corners((body, start), corners, step)
}

/// Readies implicit friction for the implicit `step` from the body's positions: each contact's
/// friction limit is its penalty force there, against the obstacle where it is at the step's
/// start, and slip is measured from there (relative to the collider's surface as it travels,
/// or to the own triangle).
pub(crate) fn lag_friction(body: &DeformableBody, contacts: &mut ContactSet, step: ImplicitStep) {
    let settings = contacts.settings;
    let nodes = NodeSlices::of(body);
    lag_friction_at(
        (nodes, body.embedding.as_ref()),
        &mut contacts.nodes,
        &settings,
        step,
    );
}

/// [`lag_friction`] for `contacts` on the nodes `nodes` (with the body's `embedding`, if its
/// points are embedded ones), found and enforced with `settings`.
pub(super) fn lag_friction_at(
    (nodes, embedding): (NodeSlices, Option<&Embedding>),
    contacts: &mut [NodeContact],
    settings: &ContactSettings,
    step: ImplicitStep,
) {
    for contact in contacts {
        let point = contact_point(contact, embedding);
        let x = point.position(nodes.positions);
        let mass = effective_mass(&point.stencil(), nodes.masses, nodes.pinned);
        contact.lagged_normal_force = contact
            .penalty(x, mass, settings, step.penalty_step)
            .map_or(0.0, |penalty| penalty.push);
        contact.slip_origin = x;
    }
}

/// The effective mass (kg) of a contact point: `1 / Σ w² / m` over its free nodes, the node's
/// own mass for a node.
pub(super) fn effective_mass(at: &Stencil, masses: &[f64], pinned: &[bool]) -> f64 {
    at.inverse_mass(masses, pinned).recip()
}

/// Calls `each(point, partner, energy (J), force (N), tangent (N/m))` for the implicit penalty
/// and friction of every contact in the implicit `step`, at the body's positions: the penalty
/// `k g²/2` of a point inside its plane (`g < 0`, the plane carried over the step by its rigid
/// body), with force `-k g n` and tangent `k n nᵀ`, and the lagged friction of a point with a
/// friction limit (see [`lag_friction`]). The force acts on the contact point, so node `a` of
/// its stencil takes `w_a f` and the tangent couples nodes `a, b` by `w_a w_b T`; `partner` is
/// the dynamic rigid body's point that takes the opposite force.
pub(crate) fn for_each_contact_term(
    body: &DeformableBody,
    contacts: &ContactSet,
    step: ImplicitStep,
    each: impl FnMut(Stencil, Option<RigidPoint>, f64, DVec3, DMat3),
) {
    let nodes = NodeSlices::of(body);
    let at = (nodes, body.embedding.as_ref());
    for_each_term_at(at, &contacts.nodes, &contacts.settings, step, each);
}

/// [`for_each_contact_term`] for `contacts` on the nodes `nodes` (with the body's `embedding`,
/// if its points are embedded ones), enforced with `settings`.
pub(super) fn for_each_term_at(
    (nodes, embedding): (NodeSlices, Option<&Embedding>),
    contacts: &[NodeContact],
    settings: &ContactSettings,
    step: ImplicitStep,
    mut each: impl FnMut(Stencil, Option<RigidPoint>, f64, DVec3, DMat3),
) {
    // Every penalty, then every friction term.
    for contact in contacts {
        if skipped(contact, &step) {
            continue;
        }
        let obstacle = carried(contact, &step);
        let point = contact_point(contact, embedding);
        let at = point.stencil();
        let mass = effective_mass(&at, nodes.masses, nodes.pinned);
        let x = point.position(nodes.positions) - obstacle.travel;
        if let Some(penalty) = contact.penalty(x, mass, settings, step.penalty_step) {
            each(
                at,
                obstacle.partner,
                penalty.energy,
                contact.normal * penalty.push,
                penalty_tangent(penalty.stiffness, contact.normal),
            );
        }
    }
    for contact in contacts {
        if skipped(contact, &step) {
            continue;
        }
        let obstacle = carried(contact, &step);
        let point = contact_point(contact, embedding);
        let x = point.position(nodes.positions) - obstacle.travel;
        if let Some((energy, force, tangent)) = contact.friction_term(x, settings, step.effective) {
            each(point.stencil(), obstacle.partner, energy, force, tangent);
        }
    }
}

/// Calls `each(point, force (N), tangent (N/m))` for every contact of `contacts` with a collider
/// that no dynamic rigid body carries whose point the nodes' move by `direction` (m per node)
/// would take onto a stiffer piece of its penalty or friction, in the implicit `step`: from in
/// front of its plane to behind it, past the depth of a stiffening, or with its slip through
/// the friction's stick zone. The force and tangent are what the Newton system must add for the
/// point's penalty or friction to be that piece's quadratic ([`NodeContact::penalty_towards`],
/// [`NodeContact::friction_towards`]): a direction computed with the piece the point is on
/// carries it deep into the stiffer one, where the line search keeps a sliver of the step, and
/// each iteration brings only the next few points there (see `integrate::implicit::direction`).
pub(crate) fn for_each_engaged_term(
    body: &DeformableBody,
    contacts: &ContactSet,
    step: ImplicitStep,
    direction: &[DVec3],
    mut each: impl FnMut(Stencil, DVec3, DMat3),
) {
    let nodes = NodeSlices::of(body);
    for contact in &contacts.nodes {
        let obstacle = carried(contact, &step);
        if !matches!(contact.obstacle, Obstacle::Collider { .. }) || obstacle.partner.is_some() {
            continue;
        }
        let point = contact_point(contact, body.embedding.as_ref());
        let at = point.stencil();
        let x = point.position(nodes.positions) - obstacle.travel;
        let moved = (x, x + at.interpolate(direction));
        let mass = effective_mass(&at, nodes.masses, nodes.pinned);
        let settings = &contacts.settings;
        if let Some((force, tangent)) =
            contact.penalty_towards(moved, mass, settings, step.penalty_step)
        {
            each(at, force, tangent);
        }
        if let Some((force, tangent)) = contact.friction_towards(moved, settings, step.effective) {
            each(at, force, tangent);
        }
    }
}

/// The nodes contact terms act on: positions (m), masses (kg) and which are pinned; one
/// body's, or a group's side by side (see [`super::joint`]).
#[derive(Clone, Copy)]
pub(crate) struct NodeSlices<'a> {
    pub(crate) positions: &'a [DVec3],
    pub(crate) masses: &'a [f64],
    pub(crate) pinned: &'a [bool],
}

impl<'a> NodeSlices<'a> {
    /// `body`'s nodes.
    fn of(body: &'a DeformableBody) -> Self {
        Self {
            positions: &body.positions,
            masses: &body.masses,
            pinned: &body.pinned,
        }
    }
}

/// Calls `each` with the stencil of every contact's point: the nodes its implicit terms may
/// couple.
pub(crate) fn for_each_contact_stencil(
    body: &DeformableBody,
    contacts: &ContactSet,
    mut each: impl FnMut(Stencil),
) {
    for contact in &contacts.nodes {
        each(contact_point(contact, body.embedding.as_ref()).stencil());
    }
}

/// `k n nᵀ` (N/m).
pub(crate) fn penalty_tangent(stiffness: f64, normal: DVec3) -> DMat3 {
    DMat3::from_cols(normal * normal.x, normal * normal.y, normal * normal.z) * stiffness
}
