//! The constraints acting on a body over the coming step, as the last contact detection left
//! them: contacts of its surface with colliders and with itself, rigid vertices against its
//! boundary triangles, nodes glued to rigid bodies, and the proxies of the rigid bodies they
//! touch (frozen in pose, their velocities following the impulses). A step saves what it moves
//! of them and puts it back if it fails.

use crate::attachment::Attachment;
use crate::contact::{ContactSettings, CornerContact, NodeContact, RigidProxy};
use rapier3d::glamx::DVec3;

/// A body's constraints and the settings they were detected with.
#[derive(Debug, Clone, Default)]
pub(crate) struct BodyConstraints {
    /// The contacts the integrators enforce, from the last detection.
    pub(crate) contacts: Vec<NodeContact>,
    /// Rigid vertices against the body's boundary triangles, from the last detection.
    pub(crate) corner_contacts: Vec<CornerContact>,
    /// The nodes glued to rigid bodies.
    pub(crate) attachments: Vec<Attachment>,
    /// The rigid bodies the contacts and attachments touch, as the soft step sees them.
    pub(crate) rigid_proxies: Vec<RigidProxy>,
    /// The settings of the last contact detection.
    pub(crate) settings: ContactSettings,
    /// What [`BodyConstraints::save`] set aside.
    saved: SavedConstraints,
}

/// The proxies, attachment anchors (m) and contact planes (point and normal) saved with the
/// state before a step: explicit substeps move them.
#[derive(Debug, Clone, Default)]
struct SavedConstraints {
    proxies: Vec<RigidProxy>,
    anchors: Vec<DVec3>,
    planes: Vec<(DVec3, DVec3)>,
}

impl BodyConstraints {
    /// Sets aside what a step moves (no allocation after the first call), and starts counting
    /// the contact impulses of a new step.
    pub(crate) fn save(&mut self) {
        self.clear_impulses();
        self.saved.proxies.clone_from(&self.rigid_proxies);
        self.saved.anchors.clear();
        self.saved
            .anchors
            .extend(self.attachments.iter().map(|a| a.anchor));
        self.saved.planes.clear();
        self.saved
            .planes
            .extend(self.contacts.iter().map(|c| (c.point, c.normal)));
    }

    /// Puts back what [`BodyConstraints::save`] set aside.
    pub(crate) fn restore(&mut self) {
        self.clear_impulses();
        self.rigid_proxies.clone_from(&self.saved.proxies);
        for (attachment, anchor) in self.attachments.iter_mut().zip(&self.saved.anchors) {
            attachment.anchor = *anchor;
        }
        for (contact, (point, normal)) in self.contacts.iter_mut().zip(&self.saved.planes) {
            contact.point = *point;
            contact.normal = *normal;
        }
    }

    /// Zeroes the impulses the contacts gave over the last step.
    fn clear_impulses(&mut self) {
        for contact in &mut self.contacts {
            contact.impulse = DVec3::ZERO;
        }
        for contact in &mut self.corner_contacts {
            contact.impulse = DVec3::ZERO;
        }
    }
}
