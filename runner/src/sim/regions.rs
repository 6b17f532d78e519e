//! A soft body's regions: the nodes its boxes (rest coordinates) or its mesh file's regions
//! select to be pinned, to start at their own velocity, and to be glued to rigid bodies, each
//! refused at its key if it holds no node or names no region of the file.

use super::build::RigidEntry;
use crate::scene::soft_body::{Selection, SoftBodySpec};
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::mesh::TetMesh;
use rapier_fvm::mesh::import::MeshRegion;
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
    /// The nodes of `mesh` (rest coordinates) in the boxes or `regions` (of the file `path`)
    /// that `spec` selects, `key` in the scene of `source`, attachments bound to the bodies of
    /// `rigid`.
    ///
    /// # Errors
    /// A [`SceneError`] at a selection that holds no node or names no region of the file, or an
    /// attachment to a rigid body not in `rigid`.
    pub(super) fn select(
        spec: &SoftBodySpec,
        (mesh, regions, path): (&TetMesh, &[MeshRegion], &str),
        rigid: &[RigidEntry],
        (key, source): (&str, &SceneSource),
    ) -> Result<Self, SceneError> {
        let nodes = |selection: Selection<'_>, at: &str| {
            let nodes = selection
                .nodes(mesh, regions, path)
                .map_err(|e| source.error(&format!("{at}.region"), e.to_string()))?;
            if nodes.is_empty() {
                let what = if selection.region.is_some() {
                    "region"
                } else {
                    "box"
                };
                Err(source.error(at, format!("the {what} holds no node")))
            } else {
                Ok(nodes)
            }
        };
        let mut pinned = Vec::new();
        for (i, region) in spec.pinned.iter().enumerate() {
            pinned.extend(nodes(region.selection(), &format!("{key}.pinned[{i}]"))?);
        }
        let mut velocities = Vec::new();
        for (i, region) in spec.velocity.iter().enumerate() {
            let nodes = nodes(region.selection(), &format!("{key}.velocity[{i}]"))?;
            velocities.push((nodes, DVec3::from_array(region.linvel)));
        }
        let mut attachments = Vec::new();
        for (i, attachment) in spec.attach.iter().enumerate() {
            let key = format!("{key}.attach[{i}]");
            let nodes = nodes(attachment.selection(), &key)?;
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
