//! Self-contact: the nodes of a soft body against the triangles of its own boundary, away from
//! their own neighbourhood, so that a body folding over itself, or made of separate parts,
//! does not pass through itself.
//!
//! A surface node within reach of a triangle of the body's [`SurfaceTree`] gets a contact plane
//! through the triangle's point nearest to it, with the triangle's outward normal, as against a
//! collider. Skipped are the triangles that touch the node's boundary neighbours (they touch it
//! at rest) and those not facing the node's own surface.
//!
//! The explicit integrator solves each such contact with the triangle's corners in the same
//! sweep, each corner taking its share of the opposite impulse by the contact point's
//! barycentric weights, and the plane follows the corners through the step: momentum is
//! conserved within the body. The implicit integrator's penalty acts on the node relative to
//! the triangle's point (see [`super::penalty`]), equally and oppositely.

use super::surface_tree::SurfaceTree;
use super::{BodyPoint, ContactTarget, NodeContact, Obstacle, SurfaceCoefficients};
use crate::body::DeformableBody;

/// The self-contacts of `body`'s surface nodes within `reach` (m) of its own boundary triangles
/// (see the module documentation).
pub(crate) fn detect_self_contacts(body: &DeformableBody, reach: f64) -> Vec<NodeContact> {
    let tree = SurfaceTree::of(body);
    let node_normals = body.surface_node_normals();
    let own = SurfaceCoefficients::of_body(body);
    let coefficients = own.combine(own);
    let mut found = Vec::new();
    for &node in &body.surface.nodes {
        let n = node as usize;
        if body.pinned[n] {
            continue;
        }
        let ring = &body.surface.rings[n];
        let near = |triangle: &[u32; 3]| triangle.iter().any(|c| ring.binary_search(c).is_ok());
        if let Some(hit) =
            tree.nearest_facing(body, body.positions[n], node_normals[n], reach, near)
        {
            found.push(NodeContact::new(
                BodyPoint::Node(node),
                ContactTarget::OwnSurface {
                    triangle: hit.triangle,
                },
                hit.point,
                hit.normal,
                coefficients,
                Obstacle::OwnTriangle(hit.soft_point()),
            ));
        }
    }
    found
}
