//! The implicit side of surface-point contacts: each active contact adds `k/2 min(0, g)²` to the
//! incremental potential (`k` [`ContactSettings::penalty_factor`](super::ContactSettings::penalty_factor)
//! times the point's effective `m/h²`), with gradient and Hessian `k n nᵀ`, and friction as a
//! lagged dissipation potential; after the step, the penalty and friction forces become the
//! impulses handed to rigid bodies.
//!
//! Against a collider the point is the surface point itself (a node, or an embedded vertex with
//! its element's nodes). Against a triangle of the body's own surface it is the node relative to
//! the triangle's contact point, `x_n − Σ w_i x_i` (weights `1, −w_a, −w_b, −w_c`): the gap, the
//! slip and every force are then those of the node against the moving triangle, node and
//! triangle take equal and opposite forces, and the body's momentum is kept.

use super::{BodyPoint, ContactSet, NodeContact, Obstacle, partners};
use crate::body::DeformableBody;
use crate::embedding::Embedding;
use crate::rigid::RigidProxy;
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};

/// A contact's point as the implicit terms see it.
enum ContactPoint<'a> {
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
    fn stencil(&self) -> Stencil<'_> {
        match self {
            Self::Own(stencil) => *stencil,
            Self::Relative { nodes, weights, .. } => Stencil { nodes, weights },
        }
    }

    /// The point's position (m) with the nodes at `x`.
    fn position(&self, x: &[DVec3]) -> DVec3 {
        match self {
            Self::Own(stencil) => stencil.interpolate(x),
            Self::Relative { origin, .. } => self.stencil().interpolate(x) + *origin,
        }
    }
}

/// The point of `contact` the implicit terms act on; `embedding` is the body's.
fn contact_point<'a>(
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

/// Records the impulses (N s) the implicit penalty and friction gave the contact points over a
/// substep of length `h` (s), at the positions that ended it, and hands their opposite to the
/// rigid bodies (a self-contact's stay within the body).
pub(crate) fn record_penalty_impulses(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    proxies: &mut [RigidProxy],
    effective_h: f64,
    h: f64,
) {
    let settings = contacts.settings;
    let (positions, embedding, mut partners) = partners(body, proxies);
    for contact in &mut contacts.nodes {
        let point = contact_point(contact, embedding);
        let at = point.stencil();
        let x = point.position(positions);
        let mut force = contact
            .friction_term(x, &settings, effective_h)
            .map_or(DVec3::ZERO, |(_, force, _)| force);
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        if let Some((stiffness, gap)) = contact.penalty(x, mass, &settings, effective_h) {
            force -= contact.normal * (stiffness * gap);
        }
        let impulse = force * h;
        let own = matches!(contact.obstacle, Obstacle::OwnTriangle(_));
        if !own {
            partners.apply(&contact.obstacle, -impulse, x);
        }
        contact.impulse += impulse;
    }
}

/// Readies implicit friction for a step of effective length `h` (s) from the body's positions:
/// each contact's friction limit is its penalty force there, and slip is measured from there
/// (relative to a collider's surface moving at its velocity, or to the own triangle).
pub(crate) fn lag_friction(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    proxies: &mut [RigidProxy],
    h: f64,
) {
    let settings = contacts.settings;
    let (positions, embedding, partners) = partners(body, proxies);
    for contact in &mut contacts.nodes {
        let point = contact_point(contact, embedding);
        let x = point.position(positions);
        let mass = effective_mass(&point.stencil(), partners.masses, partners.pinned);
        let lagged = contact
            .penalty(x, mass, &settings, h)
            .map_or(0.0, |(stiffness, gap)| -stiffness * gap);
        let surface_velocity = match contact.obstacle {
            Obstacle::OwnTriangle(_) => DVec3::ZERO,
            Obstacle::Collider { .. } => partners.velocity_at(&contact.obstacle, x),
        };
        contact.lagged_normal_force = lagged;
        contact.slip_origin = x;
        contact.surface_velocity = surface_velocity;
    }
}

/// The effective mass (kg) of a contact point: `1 / Σ w² / m` over its free nodes, the node's
/// own mass for a node.
pub(super) fn effective_mass(at: &Stencil, masses: &[f64], pinned: &[bool]) -> f64 {
    at.inverse_mass(masses, pinned).recip()
}

/// Calls `each(point, energy (J), force (N), tangent (N/m))` for the implicit penalty and
/// friction of every contact for an effective step `h` (s), at the body's positions: the
/// penalty `k g²/2` of a point inside its plane (`g < 0`), with force `-k g n` and tangent
/// `k n nᵀ`, and the lagged friction of a point with a friction limit (see [`lag_friction`]).
/// The force acts on the contact point, so node `a` of its stencil takes `w_a f` and the
/// tangent couples nodes `a, b` by `w_a w_b T`.
pub(crate) fn for_each_contact_term(
    body: &DeformableBody,
    contacts: &ContactSet,
    h: f64,
    mut each: impl FnMut(Stencil, f64, DVec3, DMat3),
) {
    // Every penalty, then every friction term.
    for contact in &contacts.nodes {
        let point = contact_point(contact, body.embedding.as_ref());
        let at = point.stencil();
        let mass = effective_mass(&at, &body.masses, &body.pinned);
        let x = point.position(&body.positions);
        if let Some((stiffness, gap)) = contact.penalty(x, mass, &contacts.settings, h) {
            each(
                at,
                0.5 * stiffness * gap * gap,
                -contact.normal * (stiffness * gap),
                penalty_tangent(stiffness, contact.normal),
            );
        }
    }
    for contact in &contacts.nodes {
        let point = contact_point(contact, body.embedding.as_ref());
        let x = point.position(&body.positions);
        if let Some((energy, force, tangent)) = contact.friction_term(x, &contacts.settings, h) {
            each(point.stencil(), energy, force, tangent);
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
