//! Rigid corners pressing into 2D bodies between their nodes (feature `dim2`): a vertex of a
//! polygonal collider (cuboid, convex polygon, triangle) found inside a body is pushed out
//! towards the nearest point `q = a + s (b − a)` of the boundary (along the segment's outward
//! normal, or from its end), by the penalty of the node contacts ([`super::coupling`]); the
//! segment's two nodes take the opposite force in the shares `1 − s` and `s`. The force pair is
//! equal and opposite and its normal part acts along the line through `p` and `q`, so it has
//! no net torque; friction `F_t`, across that line, leaves an angular impulse of `d F_t` per
//! unit time uncompensated (`d` the depth).

use super::body::PlanarBody;
use rapier2d::geometry::SharedShape;
use rapier2d::glamx::DVec2;
use rapier2d::math::Pose;

/// The vertices (m) of a polygonal collider `shape` at `pose`; none for a curved one (its
/// contacts are the nodes it holds, see [`super::coupling`]).
pub(super) fn corners_of(shape: &SharedShape, pose: &Pose) -> Vec<DVec2> {
    let local: Vec<rapier2d::glamx::Vec2> = if let Some(cuboid) = shape.as_cuboid() {
        let h = cuboid.half_extents;
        vec![
            h,
            h * rapier2d::glamx::Vec2::new(-1.0, 1.0),
            -h,
            h * rapier2d::glamx::Vec2::new(1.0, -1.0),
        ]
    } else if let Some(polygon) = shape.as_convex_polygon() {
        polygon.points().to_vec()
    } else if let Some(triangle) = shape.as_triangle() {
        vec![triangle.a, triangle.b, triangle.c]
    } else {
        Vec::new()
    };
    local
        .into_iter()
        .map(|p| pose.transform_point(p).as_dvec2())
        .collect()
}

/// A vertex inside a body: the boundary segment (its two nodes) it is pushed out through, the
/// parameter `s` of the nearest point on it, the depth (m) and the direction out, towards that
/// point.
pub(super) struct Corner {
    pub(super) segment: [u32; 2],
    pub(super) s: f64,
    pub(super) depth: f64,
    pub(super) normal: DVec2,
}

/// Whether `p` (m) lies inside `body` where it is: the crossing number of a ray along +x with
/// its boundary.
fn inside(body: &PlanarBody, p: DVec2) -> bool {
    let x = body.positions();
    let mut crossings = 0;
    for &[a, b] in body.boundary() {
        let (a, b) = (x[a as usize], x[b as usize]);
        if (a.y > p.y) != (b.y > p.y) {
            let t = (p.y - a.y) / (b.y - a.y);
            if a.x + t * (b.x - a.x) > p.x {
                crossings += 1;
            }
        }
    }
    crossings % 2 == 1
}

/// The vertex `p` (m) inside `body` if it is: pushed out towards the nearest boundary point.
pub(super) fn corner_inside(body: &PlanarBody, p: DVec2) -> Option<Corner> {
    if !inside(body, p) {
        return None;
    }
    let x = body.positions();
    let (segment, s, q) = (body.boundary().iter())
        .map(|&[a, b]| {
            let (xa, xb) = (x[a as usize], x[b as usize]);
            let edge = xb - xa;
            let s = ((p - xa).dot(edge) / edge.length_squared()).clamp(0.0, 1.0);
            ([a, b], s, xa + edge * s)
        })
        .min_by(|l, r| p.distance(l.2).total_cmp(&p.distance(r.2)))?;
    let depth = p.distance(q);
    let normal = (q - p) / depth;
    (depth > 0.0 && normal.is_finite()).then_some(Corner {
        segment,
        s,
        depth,
        normal,
    })
}
