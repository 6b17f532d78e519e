//! Self-contact: the nodes of a soft body against the triangles of its own boundary, away from
//! their own neighbourhood, so that a body folding over itself, or made of separate parts,
//! does not pass through itself.
//!
//! Detection puts the body's boundary triangles, where they are now, into a parry
//! bounding-volume hierarchy. A surface node within reach of a triangle gets a contact plane
//! through the triangle's point nearest to it, with the triangle's outward normal, as against a
//! collider. Skipped are the triangles that touch the node's boundary neighbours (they touch it
//! at rest) and those not facing the node's own surface (their normals do not point against
//! it), which keeps a node that crosses an edge from being held by the side face beyond it.
//!
//! The explicit integrator solves each such contact with the triangle's corners in the same
//! sweep, each corner taking its share of the opposite impulse by the contact point's
//! barycentric weights, and the plane follows the corners through the step: momentum is
//! conserved within the body.

use super::{ContactTarget, NodeContact, Obstacle};
use crate::body::SoftBody;
use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::glamx::{DVec3, Vec3};
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy};
use rapier3d::parry::query::PointQueryWithLocation;
use rapier3d::parry::shape::Triangle;

/// Padding (m) of the triangles' f32 bounding boxes, covering their rounding.
const AABB_PADDING: f32 = 1e-6;

/// The barycentric weights of the point of triangle `corners` (m) nearest to `x` (m), and that
/// point, recomposed in f64 from parry's f32 projection (taken relative to the first corner, so
/// that the rounding is relative to the triangle's size, not its distance from the origin).
fn nearest_point_on_triangle(corners: [DVec3; 3], x: DVec3) -> Option<([f64; 3], DVec3)> {
    let origin = corners[0];
    let local = corners.map(|c| (c - origin).as_vec3());
    let triangle = Triangle::new(local[0], local[1], local[2]);
    let (_, location) =
        triangle.project_local_point_and_get_location((x - origin).as_vec3(), false);
    let weights = location.barycentric_coordinates()?.map(f64::from);
    let point = corners[0] * weights[0] + corners[1] * weights[1] + corners[2] * weights[2];
    Some((weights, point))
}

impl SoftBody {
    /// Adds the self-contacts of the body's surface nodes within `reach` (m) of its own
    /// boundary triangles (see the module documentation).
    pub(crate) fn detect_self_contacts(&mut self, reach: f64) {
        let positions = &self.positions;
        let leaves: Vec<Aabb> = self
            .surface_triangles
            .iter()
            .map(|triangle| {
                let [a, b, c] = triangle.map(|n| positions[n as usize]);
                Aabb::new(
                    a.min(b).min(c).as_vec3() - Vec3::splat(AABB_PADDING),
                    a.max(b).max(c).as_vec3() + Vec3::splat(AABB_PADDING),
                )
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        let node_normals = self.surface_node_normals();
        let friction = f64::from(CoefficientCombineRule::combine(
            self.friction as f32,
            self.friction as f32,
            self.friction_combine_rule,
            self.friction_combine_rule,
        ));
        for &node in &self.surface_nodes {
            let n = node as usize;
            if self.pinned[n] {
                continue;
            }
            let x = positions[n];
            let query = Aabb::new(
                (x - DVec3::splat(reach)).as_vec3(),
                (x + DVec3::splat(reach)).as_vec3(),
            );
            let ring = &self.surface_rings[n];
            let mut nearest: Option<(usize, [f64; 3], DVec3, DVec3)> = None;
            let mut nearest_distance = reach;
            for leaf in bvh.intersect_aabb(&query) {
                let t = leaf as usize;
                let triangle = self.surface_triangles[t];
                if triangle.iter().any(|c| ring.binary_search(c).is_ok()) {
                    continue;
                }
                let corners = triangle.map(|c| positions[c as usize]);
                let normal = (corners[1] - corners[0])
                    .cross(corners[2] - corners[0])
                    .normalize_or_zero();
                if normal.dot(node_normals[n]) >= 0.0 {
                    continue;
                }
                if let Some((weights, point)) = nearest_point_on_triangle(corners, x)
                    && x.distance(point) <= nearest_distance
                {
                    nearest_distance = x.distance(point);
                    nearest = Some((t, weights, point, normal));
                }
            }
            if let Some((t, weights, point, normal)) = nearest {
                let triangle = self.surface_triangles[t];
                self.contacts.push(NodeContact::new(
                    node,
                    ContactTarget::OwnSurface { triangle },
                    point,
                    normal,
                    friction,
                    Obstacle::OwnTriangle {
                        nodes: triangle,
                        weights,
                    },
                ));
            }
        }
    }

    /// The outward normal of the body's surface at each node now: the sum of its boundary
    /// triangles' area vectors (zero for interior nodes).
    fn surface_node_normals(&self) -> Vec<DVec3> {
        let mut normals = vec![DVec3::ZERO; self.positions.len()];
        for triangle in &self.surface_triangles {
            let [a, b, c] = triangle.map(|n| self.positions[n as usize]);
            let area = (b - a).cross(c - a);
            for &n in triangle {
                normals[n as usize] += area;
            }
        }
        normals
    }
}
