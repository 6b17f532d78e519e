//! A soft body's boundary triangles, where they are now, in a parry bounding-volume hierarchy:
//! the nearest triangle facing a point, for self-contact, contact between soft bodies and rigid
//! vertices, and the triangles within a box, for rounded rigid shapes' closest points.

use super::SoftPoint;
use crate::body::DeformableBody;
use rapier3d::glamx::{DVec3, Vec3};
use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy};
use rapier3d::parry::query::PointQueryWithLocation;
use rapier3d::parry::shape::Triangle;

/// Padding (m) of the triangles' f32 bounding boxes, covering their rounding.
const AABB_PADDING: f32 = 1e-6;

/// A boundary triangle's point nearest to a query point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TrianglePoint {
    /// The triangle's nodes.
    pub(crate) triangle: [u32; 3],
    /// The point's barycentric weights.
    pub(crate) weights: [f64; 3],
    /// The point (m).
    pub(crate) point: DVec3,
    /// The triangle's outward unit normal.
    pub(crate) normal: DVec3,
}

/// The hierarchy over a body's boundary triangles.
pub(crate) struct SurfaceTree {
    bvh: Bvh,
    /// The hierarchy's bounds (m).
    pub(crate) bounds: Aabb,
}

impl TrianglePoint {
    /// The point as a side of a contact.
    pub(crate) fn soft_point(&self) -> SoftPoint {
        SoftPoint {
            nodes: self.triangle,
            weights: self.weights,
        }
    }
}

impl SurfaceTree {
    /// The tree of `body`'s boundary as it is now.
    pub(crate) fn of(body: &DeformableBody) -> Self {
        let leaves: Vec<Aabb> = body
            .surface
            .triangles
            .iter()
            .map(|triangle| {
                let [a, b, c] = triangle.map(|n| body.positions[n as usize]);
                Aabb::new(
                    a.min(b).min(c).as_vec3() - Vec3::splat(AABB_PADDING),
                    a.max(b).max(c).as_vec3() + Vec3::splat(AABB_PADDING),
                )
            })
            .collect();
        let bounds = leaves
            .iter()
            .fold(Aabb::new_invalid(), |all, leaf| all.merged(leaf));
        Self {
            bvh: Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
            bounds,
        }
    }

    /// The indices of the body's boundary triangles whose bounds overlap the box from `lo` to
    /// `hi` (m).
    pub(crate) fn triangles_in(&self, lo: DVec3, hi: DVec3) -> Vec<u32> {
        let query = Aabb::new(lo.as_vec3(), hi.as_vec3());
        self.bvh.intersect_aabb(&query).collect()
    }

    /// The triangle of `body` (the tree's) nearest to `x` (m) within `reach` (m), among those
    /// facing `facing` (the touching surface's outward normal there: their normals point
    /// against it) and not `skipped`. Facing keeps a node that crosses an edge from being held by
    /// the side face beyond it, which it lies on.
    pub(crate) fn nearest_facing(
        &self,
        body: &DeformableBody,
        x: DVec3,
        facing: DVec3,
        reach: f64,
        skipped: impl Fn(&[u32; 3]) -> bool,
    ) -> Option<TrianglePoint> {
        let query = Aabb::new(
            (x - DVec3::splat(reach)).as_vec3(),
            (x + DVec3::splat(reach)).as_vec3(),
        );
        let mut nearest = None;
        let mut nearest_distance = reach;
        for leaf in self.bvh.intersect_aabb(&query) {
            let triangle = body.surface.triangles[leaf as usize];
            if skipped(&triangle) {
                continue;
            }
            let corners = triangle.map(|c| body.positions[c as usize]);
            let normal = (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .normalize_or_zero();
            if normal.dot(facing) >= 0.0 {
                continue;
            }
            if let Some((weights, point)) = nearest_point_on_triangle(corners, x)
                && x.distance(point) <= nearest_distance
            {
                nearest_distance = x.distance(point);
                nearest = Some(TrianglePoint {
                    triangle,
                    weights,
                    point,
                    normal,
                });
            }
        }
        nearest
    }
}

/// The barycentric weights of the point of triangle `corners` (m) nearest to `x` (m), and that
/// point, recomposed in f64 from parry's f32 projection (taken relative to the first corner, so
/// that the rounding is relative to the triangle's size, not its distance from the origin).
pub(crate) fn nearest_point_on_triangle(
    corners: [DVec3; 3],
    x: DVec3,
) -> Option<([f64; 3], DVec3)> {
    let origin = corners[0];
    let local = corners.map(|c| (c - origin).as_vec3());
    let triangle = Triangle::new(local[0], local[1], local[2]);
    let (_, location) =
        triangle.project_local_point_and_get_location((x - origin).as_vec3(), false);
    let weights = location.barycentric_coordinates()?.map(f64::from);
    let point = corners[0] * weights[0] + corners[1] * weights[1] + corners[2] * weights[2];
    Some((weights, point))
}

impl DeformableBody {
    /// The outward normal of the body's surface at each node now: the sum of its boundary
    /// triangles' area vectors (zero for interior nodes).
    pub(crate) fn surface_node_normals(&self) -> Vec<DVec3> {
        let mut normals = vec![DVec3::ZERO; self.positions.len()];
        for triangle in &self.surface.triangles {
            let [a, b, c] = triangle.map(|n| self.positions[n as usize]);
            let area = (b - a).cross(c - a);
            for &n in triangle {
                normals[n as usize] += area;
            }
        }
        normals
    }

    /// The corners (m) of the box bounding the body's nodes now.
    pub(crate) fn position_bounds(&self) -> (DVec3, DVec3) {
        crate::mesh::bounding_box(self.positions.iter().copied())
    }

    /// The body's fastest node speed (m/s).
    pub(crate) fn fastest_node_speed(&self) -> f64 {
        self.velocities
            .iter()
            .map(|v| v.length())
            .fold(0.0, f64::max)
    }
}
