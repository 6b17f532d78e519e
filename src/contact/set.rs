//! A body's contacts from the last detection: its surface points against colliders and against
//! its own boundary, rigid vertices against its boundary triangles, and the settings they were
//! found with and are enforced by.

use super::{ContactSettings, CornerContact, Depenetration, NodeContact, Obstacle};
use crate::body::DeformableBody;
use rapier3d::glamx::DVec3;

/// The contacts one detection found for a body.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct ContactSet {
    /// Surface points against colliders and against the body's own triangles.
    pub(crate) nodes: Vec<NodeContact>,
    /// Rigid vertices against the body's boundary triangles.
    pub(crate) corners: Vec<CornerContact>,
    /// The settings of the detection.
    pub(crate) settings: ContactSettings,
    /// The step (s) the detection was for: a point found inside is pushed out over it.
    pub(crate) step: f64,
}

impl ContactSet {
    /// How the explicit contacts push a point found inside back out: over the detection's step,
    /// at most at [`ContactSettings::depenetration_speed`].
    pub(crate) fn depenetration(&self) -> Depenetration {
        Depenetration {
            speed: self.settings.depenetration_speed,
            time: self.step,
        }
    }

    /// The contact points in the set: surface points against colliders and the body itself,
    /// and rigid corners against its triangles.
    pub(crate) fn point_count(&self) -> usize {
        self.nodes.len() + self.corners.len()
    }

    /// Whether the set holds self-contacts or rigid corners: contacts that couple several of
    /// the body's nodes (a triangle's), so that one explicit sweep does not solve them.
    pub(crate) fn couples_nodes(&self) -> bool {
        !self.corners.is_empty() || self.has_self_contacts()
    }

    /// How deep (m) the deepest surface point lay behind its collider's plane, or rigid corner
    /// behind its soft face, when the contacts were found (zero when none did).
    pub(crate) fn deepest_found(&self) -> f64 {
        let points = (self.nodes.iter())
            .filter(|c| matches!(c.obstacle, Obstacle::Collider { .. }))
            .map(|c| -c.gap(c.detected_at));
        let corners = self.corners.iter().map(CornerContact::depth_found);
        points.chain(corners).fold(0.0, f64::max)
    }

    /// Whether the set holds self-contacts (points against the body's own triangles).
    pub(crate) fn has_self_contacts(&self) -> bool {
        self.nodes
            .iter()
            .any(|c| matches!(c.obstacle, Obstacle::OwnTriangle(_)))
    }

    /// Whether a surface point of `body` is behind its collider contact's plane by more than
    /// half the collider's thickness there (see [`NodeContact::past_middle`]): the step that
    /// left it so was too long for the contact to hold.
    pub(crate) fn past_middle(&self, body: &DeformableBody) -> bool {
        self.nodes.iter().any(|c| {
            matches!(c.obstacle, Obstacle::Collider { .. })
                && c.past_middle(
                    c.at.stencil(body.embedding.as_ref())
                        .interpolate(&body.positions),
                )
        })
    }

    /// Zeroes the impulses the contacts gave over the last step.
    pub(crate) fn clear_impulses(&mut self) {
        for contact in &mut self.nodes {
            contact.impulse = DVec3::ZERO;
        }
        for contact in &mut self.corners {
            contact.impulse = DVec3::ZERO;
        }
    }
}
