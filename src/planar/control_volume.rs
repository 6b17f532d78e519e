//! Control volumes of a triangle mesh: the region each node owns, the part of its boundary
//! inside each triangle, and the nodal areas the masses are lumped from.
//!
//! Within a triangle `a b c`, node `a`'s region is bounded inside the triangle by a path from
//! the midpoint of `ab` to the midpoint of `ac` through an interior point: the centroid for
//! [`ControlVolumes::Median`] (each corner owns `A/3`), the circumcentre for
//! [`ControlVolumes::Circumcentric`] (the Voronoi region: corner `a` owns
//! `(|ab|² cot C + |ac|² cot B)/8`, negative at the acute corners of an obtuse triangle).
//! The integral of the outward normal `n dl` along a path depends only on its end points, so
//! with the stress constant in the triangle the traction `∫ P n dl` on node `a` is the same for
//! both: `P b_a`, with `b_a` half the outward length-weighted normal of the edge opposite `a`
//! ([`super::TriangleRest`]). The masses differ, and each is consistent with its own regions.

use super::mesh::{TriangleMesh, signed_area};
use crate::Error;
use rapier3d::glamx::DVec2;

/// How a node's control volume is drawn inside each of its triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum ControlVolumes {
    /// Through the centroid (the median dual): a third of each triangle per corner.
    #[default]
    Median,
    /// Through the circumcentre (the Voronoi region of the corner).
    Circumcentric,
}

/// The circumcentre (m) of the triangle `a b c`.
fn circumcentre(a: DVec2, b: DVec2, c: DVec2) -> DVec2 {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * ab.perp_dot(ac);
    let (lb, lc) = (ab.length_squared(), ac.length_squared());
    a + DVec2::new(ac.y * lb - ab.y * lc, ab.x * lc - ac.x * lb) / d
}

impl ControlVolumes {
    /// The interior point (m) the boundaries of the triangle `corners`' regions meet at.
    pub fn centre(self, corners: [DVec2; 3]) -> DVec2 {
        let [a, b, c] = corners;
        match self {
            Self::Median => (a + b + c) / 3.0,
            Self::Circumcentric => circumcentre(a, b, c),
        }
    }

    /// The boundary of corner `i`'s region inside the triangle `corners`, from the midpoint of
    /// the edge to the next corner, through [`ControlVolumes::centre`], to the midpoint of the
    /// edge to the previous corner: counterclockwise around the region, as the outward normal of
    /// each segment `(dy, -dx)` expects.
    pub fn boundary(self, corners: [DVec2; 3], i: usize) -> [DVec2; 3] {
        let (a, next, previous) = (corners[i], corners[(i + 1) % 3], corners[(i + 2) % 3]);
        [(a + next) / 2.0, self.centre(corners), (a + previous) / 2.0]
    }

    /// The area (m²) corner `i` owns in the triangle `corners` (signed: the shoelace formula
    /// over the region's boundary).
    pub fn corner_area(self, corners: [DVec2; 3], i: usize) -> f64 {
        let [m_next, centre, m_previous] = self.boundary(corners, i);
        let a = corners[i];
        signed_area(a, m_next, centre) + signed_area(a, centre, m_previous)
    }

    /// Each node's control area (m²), summed over its triangles.
    ///
    /// # Errors
    /// [`Error::NonPositiveControlArea`] for a node whose area is not positive (circumcentric
    /// regions around obtuse triangles).
    pub fn nodal_areas(self, mesh: &TriangleMesh) -> Result<Vec<f64>, Error> {
        let mut areas = vec![0.0; mesh.rest_positions().len()];
        for (t, nodes) in mesh.triangles().iter().enumerate() {
            let corners = mesh.corners(t);
            for (i, &node) in nodes.iter().enumerate() {
                areas[node as usize] += self.corner_area(corners, i);
            }
        }
        match areas.iter().position(|&area| area <= 0.0) {
            Some(node) => Err(Error::NonPositiveControlArea {
                node,
                area: areas[node],
            }),
            None => Ok(areas),
        }
    }
}

/// `∫ P n dl` along the polyline `path` (m) for a constant first Piola–Kirchhoff stress `p`
/// (Pa, in-plane): the traction (N per m of thickness) on the region the path bounds, the path
/// running counterclockwise around it.
pub fn traction_along(p: &rapier3d::glamx::DMat2, path: &[DVec2]) -> DVec2 {
    path.windows(2)
        .map(|segment| {
            let d = segment[1] - segment[0];
            *p * DVec2::new(d.y, -d.x)
        })
        .sum()
}
