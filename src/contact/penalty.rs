//! The implicit side of contacts: each active contact adds `k/2 min(0, g)²` to the incremental
//! potential (`k` [`ContactSettings::penalty_factor`](super::ContactSettings::penalty_factor)
//! times the node's `m/h²`), with gradient and Hessian `k n nᵀ`, and friction as a lagged
//! dissipation potential; after the step, the penalty and friction forces become the impulses
//! handed to rigid bodies.

use super::{NodeContact, Stencil, contacts_and_partners};
use crate::body::DeformableBody;
use rapier3d::glamx::{DMat3, DVec3};

/// The contacts the implicit integrator enforces: those with colliders (it leaves self-contact
/// to the explicit integrator).
pub(super) fn implicit_contacts(
    contacts: &mut [NodeContact],
) -> impl Iterator<Item = &mut NodeContact> {
    contacts.iter_mut().filter(|c| c.is_implicit())
}

/// Records the impulses (N s) the implicit penalty and friction gave the nodes over a substep of
/// length `h` (s), at the positions that ended it, and hands their opposite to the rigid bodies.
pub(crate) fn record_penalty_impulses(body: &mut DeformableBody, effective_h: f64, h: f64) {
    let settings = body.constraints.settings;
    let (contacts, positions, embedding, mut partners) = contacts_and_partners(body);
    for contact in implicit_contacts(contacts) {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        let mut force = contact
            .friction_term(x, &settings, effective_h)
            .map_or(DVec3::ZERO, |(_, force, _)| force);
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        if let Some((stiffness, gap)) = contact.penalty(x, mass, &settings, effective_h) {
            force -= contact.normal * (stiffness * gap);
        }
        let impulse = force * h;
        contact.impulse += impulse;
        partners.apply(&contact.obstacle, -impulse, x);
    }
}

/// Readies implicit friction for a step of effective length `h` (s) from the body's positions:
/// each contact's friction limit is its penalty force there, and slip is measured from there.
pub(crate) fn lag_friction(body: &mut DeformableBody, h: f64) {
    let settings = body.constraints.settings;
    let (contacts, positions, embedding, partners) = contacts_and_partners(body);
    for contact in implicit_contacts(contacts) {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        contact.lagged_normal_force = contact
            .penalty(x, mass, &settings, h)
            .map_or(0.0, |(stiffness, gap)| -stiffness * gap);
        contact.slip_origin = x;
        contact.surface_velocity = partners.velocity_at(&contact.obstacle, x);
    }
}

/// The effective mass (kg) of a contact point: `1 / Σ w² / m` over its free nodes, the node's
/// own mass for a node.
pub(super) fn effective_mass(at: &Stencil, masses: &[f64], pinned: &[bool]) -> f64 {
    at.inverse_mass(masses, pinned).recip()
}

/// The implicit friction of the contacts for an effective step `h` (s), at the body's positions:
/// calls `each(point, energy (J), force (N), tangent (N/m))` for every contact with a friction
/// limit (see [`lag_friction`]); the force acts on the contact point, so node `a` of its stencil
/// takes `w_a f` and the tangent couples nodes `a, b` by `w_a w_b T`.
pub(crate) fn for_each_friction(
    body: &DeformableBody,
    h: f64,
    mut each: impl FnMut(Stencil, f64, DVec3, DMat3),
) {
    for contact in body.constraints.contacts.iter().filter(|c| c.is_implicit()) {
        let at = contact.at.stencil(body.embedding.as_ref());
        if let Some((energy, force, tangent)) = contact.friction_term(
            at.interpolate(&body.positions),
            &body.constraints.settings,
            h,
        ) {
            each(at, energy, force, tangent);
        }
    }
}

/// The implicit penalty of the contacts for an effective step `h` (s), at the body's positions:
/// calls `each(point, stiffness k (N/m), gap g (m), normal)` for every contact whose point is
/// inside its plane (`g < 0`); the penalty energy is `Σ k g²/2`, its force on the point `-k g n`
/// (on node `a` of its stencil, `w_a` of it) and its tangent `w_a w_b k n nᵀ`.
pub(crate) fn for_each_active_penalty(
    body: &DeformableBody,
    h: f64,
    mut each: impl FnMut(Stencil, f64, f64, DVec3),
) {
    for contact in body.constraints.contacts.iter().filter(|c| c.is_implicit()) {
        let at = contact.at.stencil(body.embedding.as_ref());
        let mass = effective_mass(&at, &body.masses, &body.pinned);
        if let Some((stiffness, gap)) = contact.penalty(
            at.interpolate(&body.positions),
            mass,
            &body.constraints.settings,
            h,
        ) {
            each(at, stiffness, gap, contact.normal);
        }
    }
}

/// `k n nᵀ` (N/m).
pub(crate) fn penalty_tangent(stiffness: f64, normal: DVec3) -> DMat3 {
    DMat3::from_cols(normal * normal.x, normal * normal.y, normal * normal.z) * stiffness
}
