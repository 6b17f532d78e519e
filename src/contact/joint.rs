//! The implicit side of contacts between soft bodies solved as one system. The group numbers its
//! nodes body after body (body `k`'s node `n` is the group's node `offset_k + n`), and each
//! [`BetweenContact`] becomes there what a self-contact is within one body (see
//! [`super::penalty`]): the node relative to the other body's triangle point,
//! `x_n − Σ w_i x_i` (weights `1, −w_a, −w_b, −w_c`), against the plane through the contact
//! point with the triangle's normal as detected. It adds the penalty `k/2 min(0, g)²` on the gap
//! `g`, `k` [`ContactSettings::penalty_factor`](super::ContactSettings::penalty_factor) times
//! the point's effective `m/h²` (`h` the penalty step, see [`ImplicitStep`]), and the lagged friction on the slip relative to the triangle.
//! The weights sum to zero, so node and triangle take equal and opposite forces: the group's
//! momentum changes only by the out-of-balance force Newton leaves.

use super::penalty::{NodeSlices, contact_point, for_each_term_at, lag_friction_at};
use super::{BetweenContact, ContactSettings, ImplicitStep, NodeContact};
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};

/// The contacts between the bodies of a group, in the group's numbering of nodes.
pub(crate) struct JointContacts {
    contacts: Vec<NodeContact>,
    settings: ContactSettings,
}

impl JointContacts {
    /// The contacts `between` (indices of bodies in the group) with the bodies' first nodes at
    /// `offsets` in the group's numbering.
    pub(crate) fn new(
        between: &[BetweenContact],
        offsets: &[u32],
        settings: &ContactSettings,
    ) -> Self {
        Self {
            contacts: between.iter().map(|c| c.in_group(offsets)).collect(),
            settings: *settings,
        }
    }

    /// The pairs of nodes `[a, b]` (`a > b`) the contacts couple: each node with the corners of
    /// its triangle, and the corners with each other. Sorted, without repeats.
    pub(crate) fn coupled_pairs(&self) -> Vec<[u32; 2]> {
        let mut pairs = Vec::new();
        for contact in &self.contacts {
            let at = contact_point(contact, None);
            let stencil = at.stencil();
            for &a in stencil.nodes {
                for &b in stencil.nodes {
                    if a > b {
                        pairs.push([a, b]);
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }

    /// Readies friction for an implicit step of effective length and penalty step `steps` (s,
    /// see [`ImplicitStep`]) from the nodes where they are at its start: each contact's friction
    /// limit is its penalty force there, and slip is measured from there.
    pub(crate) fn lag_friction(&mut self, nodes: NodeSlices, steps: (f64, f64)) {
        lag_friction_at(
            (nodes, None),
            &mut self.contacts,
            &self.settings,
            between_bodies(steps),
        );
    }

    /// Calls `each(point, energy (J), force (N), tangent (N/m))` for the penalty and friction of
    /// every contact with the nodes at `nodes`, in an implicit step of effective length and
    /// penalty step `steps` (s, see [`ImplicitStep`]): node `a` of the point's stencil takes
    /// `w_a` of the force.
    pub(crate) fn for_each_term(
        &self,
        nodes: NodeSlices,
        steps: (f64, f64),
        mut each: impl FnMut(Stencil, f64, DVec3, DMat3),
    ) {
        let step = between_bodies(steps);
        for_each_term_at(
            (nodes, None),
            &self.contacts,
            &self.settings,
            step,
            |at, _, e, f, t| {
                each(at, e, f, t);
            },
        );
    }
}

/// An implicit step of effective length and penalty step `steps` (s) as terms between soft
/// bodies see it: no rigid body, nothing carried.
fn between_bodies((effective, penalty_step): (f64, f64)) -> ImplicitStep<'static> {
    ImplicitStep {
        effective,
        penalty_step,
        length: effective,
        rigid: &[],
        partners_only: false,
    }
}
