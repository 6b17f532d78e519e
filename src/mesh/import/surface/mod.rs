//! Closed surface meshes (Wavefront OBJ, STL) filled with tetrahedra.
//!
//! The surface is read with the `tobj` or `stl_io` crate, checked closed and consistently
//! oriented, and filled by [`fill`]:
//!
//! 1. a body-centred cubic (BCC) lattice of spacing `h` (the surface's largest bounding-box
//!    extent over [`SurfaceOptions::cells_across`]) is laid over the surface: cube corners and
//!    cube centres, each pair of neighbouring centres with the four corners of their shared
//!    face making four tetrahedra whose dihedral angles are 60° and 90°;
//! 2. the tetrahedra whose centroid lies inside the surface are kept (point containment by
//!    `parry3d`'s triangle mesh with pseudo-normals, as re-exported by rapier);
//! 3. the nodes on the boundary of the kept set are moved to their closest point on the
//!    surface, each move shortened (3/4, 1/2, 1/4, none) when it would push an incident
//!    tetrahedron's shape quality below a threshold; then interior nodes next to the boundary
//!    are relaxed towards the mean of their neighbours when that improves their worst element.
//!
//! The result conforms to the surface only approximately: its boundary nodes lie on the
//! surface, but sharp edges and corners narrower than about `h` are rounded, so the volume
//! differs from the enclosed one by a fraction of a percent to a few percent (measured in
//! `tests/mesh_import.rs` on a 642-vertex icosphere: -2.2 % at 8 cells across, -0.41 % at 16,
//! -0.24 % at 32, with minimum dihedral angles of 10.0°, 9.0° and 8.7° and no inverted
//! element; boundary nodes whose full move would flatten an element stay up to 0.24 cell
//! outside the surface). Conforming tetrahedralizers (`TetGen` through `tritet`) are
//! AGPL-licensed, and `parry3d`'s own `volume_mesh` encloses the shape (1.26 times its volume
//! on the same sphere), hence this lattice approach.
//!
//! This module holds the surface and its checks; the submodules read the files (`reading`),
//! lay the lattice and keep its inside (`lattice`), answer point queries against the surface
//! (`projector`) and move the boundary nodes onto it (`snap`).

mod lattice;
mod projector;
mod reading;
mod snap;

pub use lattice::fill;
pub use reading::{parse_obj, parse_stl};

use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// How [`fill`] tetrahedralizes a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceOptions {
    /// Lattice cells across the surface's largest bounding-box extent, 2 to 128 (default 16):
    /// the element size is about that extent over this number.
    pub cells_across: usize,
}

impl Default for SurfaceOptions {
    fn default() -> Self {
        Self { cells_across: 16 }
    }
}

/// A closed triangulated surface as read from a file, positions in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The file it was read from (for error messages).
    pub path: String,
    /// Vertex positions (m).
    pub vertices: Vec<DVec3>,
    /// Triangles, three indices into `vertices` each.
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// The volume enclosed by the surface (m³), by the divergence theorem: positive when the
    /// triangles' normals `(b - a) x (c - a)` point outwards.
    pub fn enclosed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|i| self.vertices.get(i as usize).copied());
                Some(a?.dot(b?.cross(c?)) / 6.0)
            })
            .sum()
    }

    /// An [`ImportErrorKind::InvalidSurface`] error about the whole file.
    fn error(&self, message: impl Into<String>) -> Error {
        Error::MeshImport {
            path: self.path.clone(),
            location: FileLocation::Whole,
            kind: ImportErrorKind::InvalidSurface,
            message: message.into(),
        }
    }

    /// The triangles without degenerate ones, or an error if the surface is empty, open,
    /// non-manifold or inconsistently oriented.
    fn closed_triangles(&self) -> Result<Vec<[u32; 3]>, Error> {
        let n = self.vertices.len();
        let triangles: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .copied()
            .filter(|&[a, b, c]| a != b && b != c && a != c)
            .collect();
        if triangles.is_empty() {
            return Err(self.error("the surface has no triangles"));
        }
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
        for &[a, b, c] in &triangles {
            for edge in [(a, b), (b, c), (c, a)] {
                if edge.0 as usize >= n || edge.1 as usize >= n {
                    return Err(self.error(format!(
                        "a triangle refers to vertex {}, but there are {n}",
                        edge.0.max(edge.1)
                    )));
                }
                *directed.entry(edge).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            if count != 1 || directed.get(&(b, a)) != Some(&1) {
                return Err(self.error(format!(
                    "the surface is not closed and consistently oriented: edge {a}-{b} is used \
                     {count} time(s) in this direction and {} in the other",
                    directed.get(&(b, a)).copied().unwrap_or(0)
                )));
            }
        }
        Ok(triangles)
    }

    /// The smallest and largest corner of the vertices' bounding box (m).
    fn bounds(&self) -> (DVec3, DVec3) {
        crate::mesh::bounding_box(self.vertices.iter().copied())
    }
}
