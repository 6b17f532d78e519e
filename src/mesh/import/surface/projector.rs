//! Point queries against a closed, outward-oriented surface: is a point inside, and which
//! surface point is closest.
//!
//! Containment is `parry3d`'s (its triangle mesh with pseudo-normals, in f32 about the
//! surface's bounding-box centre); closest points are recomputed in f64 on the triangle parry
//! finds. A surface parry rejects is an [`ImportErrorKind::InvalidSurface`](crate::ImportErrorKind::InvalidSurface) error.

use super::Surface;
use crate::Error;
use rapier3d::glamx::{DVec3, Vec3};
use rapier3d::parry::query::PointQueryWithLocation;
use rapier3d::parry::shape::{TriMesh, TriMeshFlags};

/// Point queries against the surface: containment by parry (f32, pseudo-normals), closest
/// points recomputed in f64 on the triangle parry finds.
pub(super) struct Projector<'s> {
    trimesh: TriMesh,
    /// The surface's vertices (m).
    vertices: &'s [DVec3],
    /// The triangles parry was given, outward-oriented.
    triangles: Vec<[u32; 3]>,
    /// The point parry's (f32) coordinates are relative to (m).
    centre: DVec3,
}

impl<'s> Projector<'s> {
    /// The queries against `surface`'s vertices joined by `triangles` (closed, normals
    /// outwards), in coordinates relative to `centre` (m); an
    /// [`ImportErrorKind::InvalidSurface`](crate::ImportErrorKind::InvalidSurface) error if parry rejects them.
    pub(super) fn new(
        surface: &'s Surface,
        triangles: Vec<[u32; 3]>,
        centre: DVec3,
    ) -> Result<Self, Error> {
        let local: Vec<Vec3> = surface
            .vertices
            .iter()
            .map(|&p| (p - centre).as_vec3())
            .collect();
        let trimesh = TriMesh::with_flags(local, triangles.clone(), TriMeshFlags::ORIENTED)
            .map_err(|e| surface.error(format!("parry rejects the surface: {e}")))?;
        Ok(Self {
            trimesh,
            vertices: &surface.vertices,
            triangles,
            centre,
        })
    }

    /// Whether `p` (m) lies inside the surface.
    pub(super) fn contains(&self, p: DVec3) -> bool {
        self.trimesh
            .project_local_point_and_get_location((p - self.centre).as_vec3(), true)
            .0
            .is_inside
    }

    /// The point of the surface closest to `p` (m).
    pub(super) fn closest_point(&self, p: DVec3) -> DVec3 {
        let (_, (triangle, _)) = self
            .trimesh
            .project_local_point_and_get_location((p - self.centre).as_vec3(), false);
        match self.triangles.get(triangle as usize) {
            Some(t) => {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                closest_on_triangle(p, a, b, c)
            }
            None => p,
        }
    }
}

/// The point of triangle `abc` closest to `p` (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac) = (b - a, c - a);
    // The edges' projections of p seen from each corner, and the barycentric areas.
    let (d1, d2) = (ab.dot(p - a), ac.dot(p - a));
    let (d3, d4) = (ab.dot(p - b), ac.dot(p - b));
    let (d5, d6) = (ab.dot(p - c), ac.dot(p - c));
    let (va, vb, vc) = (d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2);
    // Corner a, corner b, edge ab, corner c, edge ac, edge bc, then the face, in Ericson's
    // order.
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f64::MIN_POSITIVE {
        return a;
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}
