//! Tetrahedral meshes: a validated [`TetMesh`] of rest positions (m) and positively oriented
//! tetrahedra, its boundary surface, generators for boxes, cylinders and spheres, and readers for
//! the files of other meshing tools (`import`, with the `import` feature).
//!
//! A tetrahedron `[a, b, c, d]` is positively oriented when `((b - a) x (c - a)) . (d - a) > 0`,
//! i.e. its signed volume is positive.

mod generators;
mod hex_mesher;
pub(crate) mod hex_split;
#[cfg(feature = "import")]
pub mod import;
mod quadratic;
mod quadratic_hex;
mod surface;
mod validate;

pub use generators::{cuboid, cylinder, sphere, tube};
pub use quadratic::QuadraticTetMesh;
pub(crate) use quadratic::SUB_TETS;
pub use quadratic_hex::QuadraticHexMesh;
#[cfg(feature = "import")]
pub(crate) use validate::DEGENERATE_RELATIVE_VOLUME;
pub use validate::MAX_COORDINATE;
pub(crate) use validate::check_position;
use validate::{check_element_volume, name_parent_element, validate_topology};

use crate::Error;
use rapier3d::glamx::DVec3;

/// A validated tetrahedral mesh in its rest configuration.
///
/// Every tetrahedron refers to existing, distinct nodes, every coordinate is finite and within
/// ±[`MAX_COORDINATE`] m, and every tetrahedron has a positive rest volume, a normal `f64` above
/// `1e-12 l³` (`l` its longest edge). Construction never panics: each defect is an [`Error`]
/// naming the offending node or tetrahedron.
///
/// # Example
/// ```
/// use rapier_fvm::mesh::TetMesh;
/// use rapier_fvm::glamx::DVec3;
///
/// let mesh = TetMesh::new(
///     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
///     vec![[0, 1, 2, 3]],
/// )?;
/// assert!((mesh.volume() - 1.0 / 6.0).abs() < 1e-15);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "TetMeshParts")
)]
pub struct TetMesh {
    positions: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
}

/// A [`TetMesh`] as written (feature `serde-serialize`); read back through [`TetMesh::new`],
/// so that a file's mesh passes the same checks.
#[cfg(feature = "serde-serialize")]
#[derive(serde::Deserialize)]
struct TetMeshParts {
    positions: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
}

#[cfg(feature = "serde-serialize")]
impl TryFrom<TetMeshParts> for TetMesh {
    type Error = Error;

    fn try_from(parts: TetMeshParts) -> Result<Self, Error> {
        Self::new(parts.positions, parts.tets)
    }
}

impl TetMesh {
    /// Builds a mesh from rest positions (m) and tetrahedra (node indices), rejecting any defect.
    ///
    /// # Errors
    /// [`Error::EmptyMesh`], [`Error::NonFiniteCoordinate`], [`Error::CoordinateOutOfRange`],
    /// [`Error::NodeIndexOutOfRange`], [`Error::RepeatedNode`], [`Error::UnreferencedNode`],
    /// [`Error::TetTooSmall`], [`Error::DegenerateTet`] or [`Error::InvertedTet`], naming the
    /// first offending node or tetrahedron.
    pub fn new(positions: Vec<DVec3>, tets: Vec<[u32; 4]>) -> Result<Self, Error> {
        validate_topology(&positions, &tets)?;
        for (tet, nodes) in tets.iter().enumerate() {
            let volume = signed_volume(&positions, nodes);
            check_element_volume(&positions, nodes, tet, volume)?;
            if volume < 0.0 {
                return Err(Error::InvertedTet { tet, volume });
            }
        }
        Ok(Self { positions, tets })
    }

    /// Like [`TetMesh::new`], but tetrahedra with negative volume are fixed by swapping two of
    /// their nodes instead of being rejected. Returns the mesh and how many tetrahedra were flipped.
    ///
    /// # Errors
    /// The errors of [`TetMesh::new`] except [`Error::InvertedTet`].
    pub fn new_reoriented(
        positions: Vec<DVec3>,
        mut tets: Vec<[u32; 4]>,
    ) -> Result<(Self, usize), Error> {
        validate_topology(&positions, &tets)?;
        let mut flipped = 0;
        for (tet, nodes) in tets.iter_mut().enumerate() {
            let volume = signed_volume(&positions, nodes);
            check_element_volume(&positions, nodes, tet, volume)?;
            if volume < 0.0 {
                nodes.swap(2, 3);
                flipped += 1;
            }
        }
        Ok((Self { positions, tets }, flipped))
    }

    /// Rest positions of the nodes (m).
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// The tetrahedra, as four node indices each, positively oriented.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of tetrahedra.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// Rest volume of tetrahedron `tet` (m^3).
    ///
    /// # Panics
    /// If `tet >= self.tet_count()`.
    pub fn tet_volume(&self, tet: usize) -> f64 {
        signed_volume(&self.positions, &self.tets[tet])
    }

    /// Total rest volume (m^3).
    pub fn volume(&self) -> f64 {
        (0..self.tet_count()).map(|t| self.tet_volume(t)).sum()
    }

    /// The smallest altitude (vertex to opposite face distance) over all tetrahedra (m), a measure
    /// of the thinnest element.
    pub fn min_altitude(&self) -> f64 {
        self.tets
            .iter()
            .map(|t| min_tet_altitude(&self.positions, t))
            .fold(f64::INFINITY, f64::min)
    }

    /// Shape quality of tetrahedron `tet` (dimensionless): its smallest altitude over its longest
    /// edge, `sqrt(2/3) ≈ 0.82` for a regular tetrahedron, 0 for a flat one. Slivers make the
    /// explicit step tiny and the implicit systems ill-conditioned.
    ///
    /// # Panics
    /// If `tet >= self.tet_count()`.
    pub fn tet_quality(&self, tet: usize) -> f64 {
        let nodes = &self.tets[tet];
        let p = nodes.map(|i| self.positions[i as usize]);
        let mut longest: f64 = 0.0;
        for i in 0..4 {
            for j in i + 1..4 {
                longest = longest.max(p[i].distance(p[j]));
            }
        }
        min_tet_altitude(&self.positions, nodes) / longest
    }

    /// The tetrahedron of lowest [`TetMesh::tet_quality`] and its quality.
    pub fn worst_tet(&self) -> (usize, f64) {
        (0..self.tets.len())
            .map(|t| (t, self.tet_quality(t)))
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a })
    }

    /// Indices of the nodes whose rest position satisfies `predicate`, ascending; e.g. the nodes of
    /// a clamped face: `mesh.nodes_where(|p| p.x <= 1e-9)`.
    pub fn nodes_where(&self, predicate: impl Fn(DVec3) -> bool) -> Vec<u32> {
        (0..self.positions.len() as u32)
            .filter(|&i| predicate(self.positions[i as usize]))
            .collect()
    }

    /// The index of the node whose rest position is nearest to `point` (m).
    pub fn nearest_node(&self, point: DVec3) -> u32 {
        let mut best = (0, f64::INFINITY);
        for (i, p) in self.positions.iter().enumerate() {
            let d = p.distance_squared(point);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0 as u32
    }

    /// Boundary triangles (faces belonging to exactly one tetrahedron), ordered so that their
    /// normals `(b - a) x (c - a)` point out of the body.
    pub fn surface_triangles(&self) -> Vec<[u32; 3]> {
        surface::boundary_faces(&self.tets)
    }

    /// The boundary triangles (as [`TetMesh::surface_triangles`]) whose three corners' rest
    /// positions satisfy `predicate`: the face a traction or a pressure acts on, e.g. a beam's
    /// free end `mesh.surface_triangles_where(|p| p.x >= 1.0 - 1e-9)`.
    pub fn surface_triangles_where(&self, predicate: impl Fn(DVec3) -> bool) -> Vec<[u32; 3]> {
        let mut triangles = self.surface_triangles();
        triangles.retain(|t| t.iter().all(|&n| predicate(self.positions[n as usize])));
        triangles
    }
}

/// The smallest box `(lo, hi)` (m) holding `points`; `lo` above `hi` (infinite) if there are
/// none.
pub(crate) fn bounding_box(points: impl IntoIterator<Item = DVec3>) -> (DVec3, DVec3) {
    (points.into_iter()).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// Signed volume of a tetrahedron (m^3): positive when positively oriented.
#[inline]
pub(crate) fn signed_volume(positions: &[DVec3], tet: &[u32; 4]) -> f64 {
    let node = |k: usize| positions[tet[k] as usize];
    let (a, b, c, d) = (node(0), node(1), node(2), node(3));
    (b - a).cross(c - a).dot(d - a) / 6.0
}

fn min_tet_altitude(positions: &[DVec3], tet: &[u32; 4]) -> f64 {
    let p = tet.map(|i| positions[i as usize]);
    let volume = signed_volume(positions, tet).abs();
    // Altitude from vertex i = 3 V / area of the opposite face.
    (0..4)
        .map(|i| {
            let [a, b, c] = [p[(i + 1) % 4], p[(i + 2) % 4], p[(i + 3) % 4]];
            let area = 0.5 * (b - a).cross(c - a).length();
            3.0 * volume / area
        })
        .fold(f64::INFINITY, f64::min)
}
