//! Scene queries on deformable surfaces, as rapier's query pipeline offers them for colliders:
//! a ray `x(t) = o + t d` cast against the bodies' boundary triangles where the nodes are now
//! (the first `t ≥ 0` with `x(t)` on a triangle), and a point projected on the nearest of them.
//! Each triangle is tested with parry's triangle queries (in rapier's `f32`, relative to the
//! triangle's first corner, so that rounding scales with the triangle, not with its distance
//! from the origin); a query costs one test per boundary triangle of the bodies asked, with no
//! acceleration structure to keep up to date as the bodies deform.

use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet};
use crate::contact::nearest_point_on_triangle;
use rapier3d::geometry::{Ray, Triangle};
use rapier3d::glamx::DVec3;
use rapier3d::parry::query::RayCast;

/// Where a ray meets a deformable body's surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceRayHit {
    /// The ray's parameter at the hit: the hit is at `origin + time_of_impact * direction`
    /// (s when the direction is a velocity, m when it is a unit vector).
    pub time_of_impact: f64,
    /// The hit point (m).
    pub point: DVec3,
    /// The surface's outward unit normal there.
    pub normal: DVec3,
    /// The boundary triangle hit: an index into [`DeformableBody::surface_triangles`].
    pub triangle: usize,
}

/// The point of a deformable body's surface nearest to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceProjection {
    /// The nearest surface point (m).
    pub point: DVec3,
    /// Its distance from the query point (m).
    pub distance: f64,
    /// The boundary triangle it lies on: an index into [`DeformableBody::surface_triangles`].
    pub triangle: usize,
}

impl DeformableBody {
    /// The boundary triangles, outward-oriented, as node indices into
    /// [`DeformableBody::positions`].
    pub fn surface_triangles(&self) -> &[[u32; 3]] {
        &self.surface.triangles
    }

    /// The corners (m) of boundary triangle `t` where the nodes are now.
    fn triangle_corners(&self, t: usize) -> [DVec3; 3] {
        self.surface.triangles[t].map(|n| self.positions[n as usize])
    }

    /// The first hit of the ray from `origin` (m) along `direction` within `max_time_of_impact`
    /// (in units of `direction`) on the body's surface, from either side; `None` if it misses or
    /// the ray is not finite. The surface is the simulation mesh's, also for a body carrying an
    /// embedded mesh.
    pub fn cast_ray(
        &self,
        origin: DVec3,
        direction: DVec3,
        max_time_of_impact: f64,
    ) -> Option<SurfaceRayHit> {
        if !(origin.is_finite() && direction.is_finite()) {
            return None;
        }
        let mut best: Option<SurfaceRayHit> = None;
        for t in 0..self.surface.triangles.len() {
            let reach = best.map_or(max_time_of_impact, |hit| hit.time_of_impact);
            // Relative to the first corner, so that f32 rounds relative to the triangle's size.
            let corners = self.triangle_corners(t);
            let local = corners.map(|c| (c - corners[0]).as_vec3());
            let triangle = Triangle::new(local[0], local[1], local[2]);
            let ray = Ray::new((origin - corners[0]).as_vec3(), direction.as_vec3());
            if let Some(hit) = triangle.cast_local_ray(&ray, reach as f32, true) {
                let time_of_impact = f64::from(hit);
                let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                best = Some(SurfaceRayHit {
                    time_of_impact,
                    point: origin + direction * time_of_impact,
                    normal: normal.normalize_or_zero(),
                    triangle: t,
                });
            }
        }
        best
    }

    /// The point of the body's surface nearest to `point` (m); `None` for a body without
    /// boundary triangles or a non-finite point.
    pub fn project_point(&self, point: DVec3) -> Option<SurfaceProjection> {
        if !point.is_finite() {
            return None;
        }
        let mut best: Option<SurfaceProjection> = None;
        for t in 0..self.surface.triangles.len() {
            let Some((_, nearest)) = nearest_point_on_triangle(self.triangle_corners(t), point)
            else {
                continue;
            };
            let distance = (nearest - point).length();
            if best.is_none_or(|b| distance < b.distance) {
                best = Some(SurfaceProjection {
                    point: nearest,
                    distance,
                    triangle: t,
                });
            }
        }
        best
    }
}

impl DeformableBodySet {
    /// The first hit of the ray from `origin` (m) along `direction` within `max_time_of_impact`
    /// on any body's surface, with the body hit; see [`DeformableBody::cast_ray`].
    pub fn cast_ray(
        &self,
        origin: DVec3,
        direction: DVec3,
        max_time_of_impact: f64,
    ) -> Option<(DeformableBodyHandle, SurfaceRayHit)> {
        let mut best: Option<(DeformableBodyHandle, SurfaceRayHit)> = None;
        for (handle, body) in self.iter() {
            let reach = best.map_or(max_time_of_impact, |(_, hit)| hit.time_of_impact);
            if let Some(hit) = body.cast_ray(origin, direction, reach) {
                best = Some((handle, hit));
            }
        }
        best
    }

    /// The point of any body's surface nearest to `point` (m), with its body; see
    /// [`DeformableBody::project_point`].
    pub fn project_point(&self, point: DVec3) -> Option<(DeformableBodyHandle, SurfaceProjection)> {
        self.iter()
            .filter_map(|(handle, body)| body.project_point(point).map(|p| (handle, p)))
            .min_by(|(_, a), (_, b)| a.distance.total_cmp(&b.distance))
    }
}
