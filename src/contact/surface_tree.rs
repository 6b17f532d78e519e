//! A soft body's boundary triangles, where they are now, in a parry bounding-volume hierarchy
//! (kept by contact detection from one detection to the next and refitted, [`KeptTree`]):
//! the nearest triangle facing a point, for self-contact, contact between soft bodies and rigid
//! vertices; whether a point lies outside the body (the sign along the angle-weighted
//! pseudo-normal of its nearest feature), for rigid vertices behind a facing triangle's plane;
//! and the triangles within a box, for rounded rigid shapes' closest points.

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

/// The hierarchy a body's last detection built over its boundary, which the next one refits
/// ([`SurfaceTree::refitted`]); a clone starts without one (the queries answer the same with a
/// tree built afresh).
#[derive(Default)]
pub(crate) struct KeptTree(pub(crate) Option<Bvh>);

impl Clone for KeptTree {
    fn clone(&self) -> Self {
        Self(None)
    }
}

impl std::fmt::Debug for KeptTree {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let leaves = self.0.as_ref().map(Bvh::leaf_count);
        f.debug_struct("KeptTree").field("leaves", &leaves).finish()
    }
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
        Self::refitted(body, None)
    }

    /// The tree of `body`'s boundary as it is now: `kept` (the tree of an earlier detection, see
    /// [`SurfaceTree::into_kept`]) refitted to the triangles' bounds now, a pass over them, or,
    /// without one, a tree built afresh, a sort of them. A refitted tree keeps the branches of
    /// the shape it was built at, which a body that deforms only loosens; the queries answer the
    /// same whatever the branches (candidates taken in the order of their triangles).
    pub(crate) fn refitted(body: &DeformableBody, kept: Option<Bvh>) -> Self {
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
        let bvh = match kept {
            Some(mut bvh) if bvh.leaf_count() as usize == leaves.len() => {
                for (leaf, bounds) in (0u32..).zip(&leaves) {
                    bvh.update_partially_if_present(*bounds, leaf, 0.0);
                }
                bvh.refit_without_opt();
                bvh
            }
            _ => Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
        };
        Self { bvh, bounds }
    }

    /// The hierarchy, to be refitted by the next detection ([`SurfaceTree::refitted`]).
    pub(crate) fn into_kept(self) -> Bvh {
        self.bvh
    }

    /// The indices of the body's boundary triangles whose bounds overlap the box from `lo` to
    /// `hi` (m), in increasing order.
    pub(crate) fn triangles_in(&self, lo: DVec3, hi: DVec3) -> Vec<u32> {
        let query = Aabb::new(lo.as_vec3(), hi.as_vec3());
        let mut found: Vec<u32> = self.bvh.intersect_aabb(&query).collect();
        found.sort_unstable();
        found
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
        let mut nearest_leaf = u32::MAX;
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
            // Of equally near triangles the first: the answer does not hang on the branches.
            if let Some((weights, point)) = nearest_point_on_triangle(corners, x)
                && (x.distance(point) < nearest_distance
                    || (x.distance(point) == nearest_distance && leaf < nearest_leaf))
            {
                nearest_distance = x.distance(point);
                nearest_leaf = leaf;
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

    /// The boundary point of `body` (the tree's) nearest to `x` (m), among all its triangles
    /// within `reach` (m), with the unit direction from it to `x` as the normal, if `x` lies
    /// outside the body there; `None` if `x` lies inside (or on the boundary, or no triangle is
    /// within reach). Inside or outside is the sign of `x` minus the point along the
    /// angle-weighted pseudo-normal of the feature the point lies on (Bærentzen and Aanæs 2005):
    /// a face's normal, the sum of an edge's two faces' normals, or the sum of a node's faces'
    /// normals each weighted by its angle there; exact for a closed surface, where the plane of
    /// a facing triangle alone does not tell a point beyond the body's edge (above a block's
    /// top, behind the plane of its side face) from one within it.
    pub(crate) fn outside_point(
        &self,
        body: &DeformableBody,
        x: DVec3,
        reach: f64,
    ) -> Option<TrianglePoint> {
        let query = Aabb::new(
            (x - DVec3::splat(reach)).as_vec3(),
            (x + DVec3::splat(reach)).as_vec3(),
        );
        let mut near: Vec<u32> = self.bvh.intersect_aabb(&query).collect();
        // In the triangles' order: the nearest of equally near ones, and the pseudo-normal's
        // sum, do not hang on the branches.
        near.sort_unstable();
        let nodes_of = |t: u32| body.surface.triangles[t as usize];
        let corners = |t: u32| nodes_of(t).map(|n| body.positions[n as usize]);
        let (nearest, weights, point) = (near.iter())
            .filter_map(|&t| nearest_point_on_triangle(corners(t), x).map(|(w, p)| (t, w, p)))
            .min_by(|a, b| x.distance_squared(a.2).total_cmp(&x.distance_squared(b.2)))?;
        let triangle = nodes_of(nearest);
        let feature: Vec<u32> = (triangle.iter().zip(weights))
            .filter(|&(_, w)| w != 0.0)
            .map(|(&n, _)| n)
            .collect();
        let pseudo_normal: DVec3 = (near.iter())
            .filter(|&&t| feature.iter().all(|n| nodes_of(t).contains(n)))
            .map(|&t| {
                let [a, b, c] = corners(t);
                let normal = (b - a).cross(c - a).normalize_or_zero();
                match feature[..] {
                    [node] => angle_at(node, nodes_of(t), [a, b, c]) * normal,
                    _ => normal,
                }
            })
            .sum();
        let offset = x - point;
        (offset.dot(pseudo_normal) > 0.0).then(|| TrianglePoint {
            triangle,
            weights,
            point,
            normal: offset.normalize(),
        })
    }
}

/// The angle (rad) at its corner `node` of the triangle of `nodes` at `corners` (m).
fn angle_at(node: u32, nodes: [u32; 3], corners: [DVec3; 3]) -> f64 {
    let i = nodes.iter().position(|&n| n == node).unwrap_or(0);
    let at = corners[i];
    (corners[(i + 1) % 3] - at).angle_between(corners[(i + 2) % 3] - at)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::{DeformableBodyBuilder, Material, MaterialModel, mesh};

    /// A 10 cm cube of 3³ cells centred at the origin.
    fn cube() -> DeformableBody {
        let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
            .build()
            .unwrap()
    }

    // Points to 1e-7 m and normals to 1e-5: parry projects in f32, rounding a point by about
    // 1e-8 m, which over the 1-2 mm from it to the query point turns the normal by 1e-5.
    #[test]
    fn points_past_the_edges_and_corners_of_a_cube_lie_outside_it_and_points_within_inside() {
        let body = cube();
        let tree = SurfaceTree::of(&body);
        let outside = |x: DVec3| tree.outside_point(&body, x, 0.1);
        // Above the top face near its edge x = 0.05, behind the side face's plane by 17 mm: the
        // top face's point straight below, the normal up.
        let above = outside(DVec3::new(0.033, 0.08, 0.01)).expect("above the top");
        assert!((above.point - DVec3::new(0.033, 0.05, 0.01)).length() < 1e-7);
        assert!((above.normal - DVec3::Y).length() < 1e-5);
        // Past the edge between the top and the side x = 0.05, 2 mm out and 1 mm below the top
        // (behind the top's plane): the side's point, the normal along x; 1 mm above the top:
        // the edge's point, the normal from it.
        let past_edge = outside(DVec3::new(0.052, 0.049, 0.01)).expect("past the edge");
        assert!((past_edge.point - DVec3::new(0.05, 0.049, 0.01)).length() < 1e-7);
        assert!((past_edge.normal - DVec3::X).length() < 1e-5);
        let beyond_edge = outside(DVec3::new(0.052, 0.051, 0.01)).expect("beyond the edge");
        assert!((beyond_edge.point - DVec3::new(0.05, 0.05, 0.01)).length() < 1e-7);
        assert!((beyond_edge.normal - DVec3::new(2.0, 1.0, 0.0).normalize()).length() < 1e-5);
        // Beyond the corner (0.05, 0.05, 0.05) along the diagonal: the corner.
        let corner = outside(DVec3::splat(0.051)).expect("beyond the corner");
        assert!((corner.point - DVec3::splat(0.05)).length() < 1e-7);
        assert!((corner.normal - DVec3::ONE.normalize()).length() < 1e-5);
        // Within 1 mm of the edge, of the corner, of a face's centre, and at the centre: inside.
        for x in [
            DVec3::new(0.049, 0.049, 0.01),
            DVec3::splat(0.049),
            DVec3::new(0.0, 0.049, 0.0),
            DVec3::ZERO,
        ] {
            assert!(outside(x).is_none(), "{x}");
        }
    }

    /// A tree built at rest and refitted after the cube is sheared by 30 %, turned and moved
    /// answers every query as a tree built afresh there, to the bit: the nearest triangle facing
    /// a point, the point outside, and the triangles within a box, from points on a grid across
    /// the cube and from points 5 mm out from each boundary node along its normal (equally near
    /// every triangle around the node: the order decides among them).
    #[test]
    fn a_refitted_tree_answers_as_a_tree_built_afresh() {
        let mut body = cube();
        let kept = SurfaceTree::of(&body).into_kept();
        let turn =
            rapier3d::glamx::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.8);
        for x in &mut body.positions {
            *x = turn * DVec3::new(x.x + 0.3 * x.y, x.y, x.z) + DVec3::new(0.2, -0.1, 0.4);
        }
        let (refitted, fresh) = (
            SurfaceTree::refitted(&body, Some(kept)),
            SurfaceTree::of(&body),
        );
        let normals = body.surface_node_normals();
        let off_nodes = (body.surface.nodes.iter())
            .map(|&n| body.positions[n as usize] + normals[n as usize] * 0.005);
        let queries: Vec<DVec3> = (0..125)
            .map(|i| {
                let grid = DVec3::new((i % 5) as f64, (i / 5 % 5) as f64, (i / 25) as f64);
                turn * (grid * 0.03 - DVec3::splat(0.06)) + DVec3::new(0.2, -0.1, 0.4)
            })
            .chain(off_nodes)
            .collect();
        let key = |hit: Option<TrianglePoint>| {
            hit.map(|h| {
                (
                    h.triangle,
                    h.weights.map(f64::to_bits),
                    h.normal.to_array().map(f64::to_bits),
                )
            })
        };
        let mut found = 0;
        for x in queries {
            for facing in [
                DVec3::X,
                DVec3::NEG_Y,
                DVec3::new(1.0, 1.0, -1.0).normalize(),
            ] {
                let [a, b] = [&refitted, &fresh]
                    .map(|t| key(t.nearest_facing(&body, x, facing, 0.05, |_| false)));
                found += usize::from(a.is_some());
                assert_eq!(a, b, "nearest facing {facing} from {x}");
            }
            let [a, b] = [&refitted, &fresh].map(|t| key(t.outside_point(&body, x, 0.05)));
            assert_eq!(a, b, "outside point from {x}");
            let [a, b] = [&refitted, &fresh].map(|t| t.triangles_in(x, x + DVec3::splat(0.02)));
            assert_eq!(a, b, "triangles near {x}");
        }
        assert!(found > 100, "the queries meet the surface ({found} hits)");
    }
}
