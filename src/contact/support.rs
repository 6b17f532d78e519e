//! Rounded rigid shapes against soft faces: a bounded convex shape without vertices (ball,
//! capsule, cylinder, cone, segment, triangle and the rounded shapes) meets each soft boundary
//! triangle within reach at their closest points (parry's contact query, GJK and EPA): the
//! shape's point `s` nearest to (or deepest into) the triangle, the triangle's point `p`, and the
//! unit normal `n` from the triangle toward the shape, `(s − p)·n` their signed distance.
//!
//! Per triangle facing the shape (the centre of the shape's bounding box outside its plane, the
//! normal on its outer side) within reach (`(s − p)·n ≤ reach`), `s` becomes a rigid vertex of a
//! [`CornerContact`](super::CornerContact) against the triangle at `p` with normal `n`: so a ball
//! smaller than a coarse mesh's cells is held by the faces it presses on instead of passing
//! between their nodes. Where `s` faces the triangle's interior, `n` is the triangle's normal
//! (and follows it as it turns); on an edge or a corner, `n` points from there to the shape
//! (in a valley between faces, the bisector). Triangles sharing the closest points (coplanar
//! neighbours, or the two sides of an edge) give one contact.

use super::surface_tree::{SurfaceTree, TrianglePoint};
use crate::body::DeformableBody;
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::parry::query;
use rapier3d::parry::shape::{Shape, Triangle};

/// Two contacts whose shape points are closer than this fraction of the shape's size (m/m) and
/// whose normals differ by less than it are one (the same contact found from two triangles).
const SAME_CONTACT: f64 = 1e-7;
/// A contact's normal within this of the triangle's (`1 − n·n_face`) faces its interior.
const FACING_INTERIOR: f64 = 1e-9;

/// A rounded shape's contact with a triangle: the shape's point (m), the triangle's point and
/// normal (toward the shape), and whether the normal is the triangle's own.
pub(super) struct SupportContact {
    pub(super) vertex: DVec3,
    pub(super) on_triangle: TrianglePoint,
    pub(super) follows_face: bool,
}

/// Calls `each` with the contacts of `part` at `pose` (a bounded convex shape without vertices)
/// with the boundary triangles of `body` in `tree` within `reach` (m) of it, skipping the
/// `skipped` triangles.
pub(super) fn for_each_support_contact(
    (body, tree): (&DeformableBody, &SurfaceTree),
    (part, pose): (&dyn Shape, &Pose),
    reach: f64,
    skipped: impl Fn(&[u32; 3]) -> bool,
    each: &mut impl FnMut(SupportContact),
) {
    let bounds = part.compute_aabb(pose);
    let (lo, hi) = (bounds.mins.as_dvec3(), bounds.maxs.as_dvec3());
    let (size, centre) = ((hi - lo).length(), (lo + hi) * 0.5);
    let mut found: Vec<(DVec3, DVec3)> = Vec::new();
    for leaf in tree.triangles_in(lo - DVec3::splat(reach), hi + DVec3::splat(reach)) {
        let triangle = body.surface.triangles[leaf as usize];
        if skipped(&triangle) {
            continue;
        }
        let corners = triangle.map(|n| body.positions[n as usize]);
        let area = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let face = area.normalize_or_zero();
        if face == DVec3::ZERO || (centre - corners[0]).dot(face) <= 0.0 {
            continue;
        }
        let Some((vertex, point, normal)) = closest_points(corners, (part, pose), reach) else {
            continue;
        };
        let same = |(v, n): &(DVec3, DVec3)| {
            v.distance(vertex) <= SAME_CONTACT * size && n.distance(normal) <= SAME_CONTACT
        };
        if normal.dot(face) <= 0.0 || found.iter().any(same) {
            continue;
        }
        found.push((vertex, normal));
        let follows_face = 1.0 - normal.dot(face) <= FACING_INTERIOR;
        each(SupportContact {
            vertex,
            on_triangle: TrianglePoint {
                triangle,
                weights: weights_of(corners, area, point),
                point,
                normal: if follows_face { face } else { normal },
            },
            follows_face,
        });
    }
}

/// The closest points of the triangle `corners` (m) and `shape` at `pose` within `reach` (m):
/// the shape's, the triangle's, and the unit normal from the triangle toward the shape; taken
/// relative to the triangle's first corner, so that parry's f32 rounding is relative to the
/// triangle's size, not its distance from the origin. `None` beyond reach, or for a pair parry
/// does not support.
fn closest_points(
    corners: [DVec3; 3],
    (shape, pose): (&dyn Shape, &Pose),
    reach: f64,
) -> Option<(DVec3, DVec3, DVec3)> {
    let origin = corners[0];
    let local = corners.map(|c| (c - origin).as_vec3());
    let triangle = Triangle::new(local[0], local[1], local[2]);
    let shifted = Pose::from_translation((-origin).as_vec3()) * *pose;
    let contact = query::contact(&Pose::IDENTITY, &triangle, &shifted, shape, reach as f32)
        .ok()
        .flatten()?;
    let normal = contact.normal1.as_dvec3().normalize_or_zero();
    (normal != DVec3::ZERO).then(|| {
        (
            origin + contact.point2.as_dvec3(),
            origin + contact.point1.as_dvec3(),
            normal,
        )
    })
}

/// The barycentric weights of `point` (m) on the triangle `corners`, whose `(b − a) × (c − a)`
/// is `area` (m²): clamped to the triangle (the point is on it up to round-off). In f64, unlike
/// [`nearest_point_on_triangle`](super::surface_tree::nearest_point_on_triangle)'s f32
/// projection: that rounding moves the point by 1e-8 of the triangle, which doubled the
/// angular momentum error of `tests/coupling.rs`'s ball (9.6e-8 against its bound of 1e-7).
fn weights_of(corners: [DVec3; 3], area: DVec3, point: DVec3) -> [f64; 3] {
    let [a, b, c] = corners;
    let squared = area.length_squared();
    let wa = (c - b).cross(point - b).dot(area) / squared;
    let wb = (a - c).cross(point - c).dot(area) / squared;
    let clamped = [wa, wb, 1.0 - wa - wb].map(|w| w.max(0.0));
    let sum: f64 = clamped.iter().sum();
    clamped.map(|w| w / sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_recompose_a_point_on_the_triangle() {
        let corners = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let point = DVec3::new(0.2, 0.3, 0.0);
        let weights = weights_of(corners, DVec3::Z, point);
        let back = corners[0] * weights[0] + corners[1] * weights[1] + corners[2] * weights[2];
        assert!((back - point).length() < 1e-15);
        // A point off the triangle by round-off is taken onto it.
        let edge = weights_of(corners, DVec3::Z, DVec3::new(-1e-17, 0.5, 0.0));
        assert!(edge.iter().all(|w| *w >= 0.0) && (edge.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_ball_over_a_triangle_meets_it_below_its_centre_and_over_an_edge_at_the_edge() {
        // A unit triangle in the plane z = 0 and a ball of radius 0.1 sunk 0.01 into it over its
        // interior: the contact is the ball's lowest point, the triangle's normal, 0.01 deep.
        let corners = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let ball = rapier3d::parry::shape::Ball::new(0.1);
        let over = Pose::from_translation(rapier3d::math::Vector::new(0.2, 0.2, 0.09));
        let (vertex, point, normal) = closest_points(corners, (&ball, &over), 0.05).unwrap();
        assert!((vertex - DVec3::new(0.2, 0.2, -0.01)).length() < 1e-6);
        assert!((point - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-6);
        assert!((normal - DVec3::Z).length() < 1e-6);
        // Beyond the edge y = 0, its centre 0.05 out and 0.05 up: the edge point nearest to it.
        let beside = Pose::from_translation(rapier3d::math::Vector::new(0.5, -0.05, 0.05));
        let (_, point, normal) = closest_points(corners, (&ball, &beside), 0.05).unwrap();
        assert!((point - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
        let expected = DVec3::new(0.0, -1.0, 1.0).normalize();
        assert!((normal - expected).length() < 1e-6);
    }
}
