//! A soft body's regions: the nodes its boxes (rest coordinates) select to be pinned, to start
//! at their own velocity, and to be glued to rigid bodies, each box refused at its key if it
//! holds no node.

use super::build::RigidEntry;
use crate::scene::soft_body::SoftBodySpec;
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::mesh::TetMesh;
use rapier3d::prelude::RigidBodyHandle;

/// Nodes glued to a rigid body, with the key of the attachment that glues them.
pub(super) struct Attachment {
    /// The nodes.
    pub(super) nodes: Vec<u32>,
    /// The rigid body.
    pub(super) rigid: RigidBodyHandle,
    /// The key path of the attachment (`soft_body[0].attach[1]`), for the library's refusals.
    pub(super) key: String,
}

/// The nodes a soft body's boxes select.
pub(super) struct BodyRegions {
    /// The nodes held fixed.
    pub(super) pinned: Vec<u32>,
    /// Nodes and the initial velocity (m/s) they start at, in scene order.
    pub(super) velocities: Vec<(Vec<u32>, DVec3)>,
    /// The nodes glued to rigid bodies.
    pub(super) attachments: Vec<Attachment>,
}

impl BodyRegions {
    /// The nodes of `mesh` (rest coordinates) in the boxes of `spec`, `key` in the scene of
    /// `source`, attachments bound to the bodies of `rigid`.
    ///
    /// # Errors
    /// A [`SceneError`] at a box that holds no node or an attachment to a rigid body not in
    /// `rigid`.
    pub(super) fn select(
        spec: &SoftBodySpec,
        mesh: &TetMesh,
        rigid: &[RigidEntry],
        (key, source): (&str, &SceneSource),
    ) -> Result<Self, SceneError> {
        let in_box = |nodes: Vec<u32>, at: &str| {
            if nodes.is_empty() {
                Err(source.error(at, "the box holds no node"))
            } else {
                Ok(nodes)
            }
        };
        let mut pinned = Vec::new();
        for (i, region) in spec.pinned.iter().enumerate() {
            pinned.extend(in_box(region.nodes(mesh), &format!("{key}.pinned[{i}]"))?);
        }
        let mut velocities = Vec::new();
        for (i, region) in spec.velocity.iter().enumerate() {
            let nodes = in_box(region.nodes(mesh), &format!("{key}.velocity[{i}]"))?;
            velocities.push((nodes, DVec3::from_array(region.linvel)));
        }
        let mut attachments = Vec::new();
        for (i, attachment) in spec.attach.iter().enumerate() {
            let key = format!("{key}.attach[{i}]");
            let nodes = in_box(attachment.nodes(mesh), &key)?;
            let body = rigid
                .iter()
                .find(|r| r.name == attachment.rigid)
                .ok_or_else(|| source.error(&format!("{key}.rigid"), "no such rigid body"))?;
            attachments.push(Attachment {
                nodes,
                rigid: body.handle,
                key,
            });
        }
        Ok(Self {
            pinned,
            velocities,
            attachments,
        })
    }
}
