//! Named parts of a mesh file (Gmsh physical groups; a `.vtu` or `.vtk` file's cell tags,
//! unnamed; a `TetGen` file's region attributes and boundary markers):
//! finding one by name or tag, numbering its nodes as the validated mesh does, and keeping one
//! volume's tetrahedra as a mesh of its own.
//!
//! A [`MeshRegion`] read from a file holds the nodes of its elements as indices into
//! [`RawMesh::positions`]. The validated mesh numbers the nodes its elements use in order of
//! first use ([`RawMesh::mesh_node_indices`]), so [`RawMesh::regions_in_mesh`] gives the regions
//! in that numbering: the node indices a pin, an attachment or a load takes. The tetrahedra of a
//! volume group keep their indices, since validation keeps the elements in file order.
//!
//! # Example
//! ```
//! use rapier_fvm::mesh::import::{self, RegionId};
//!
//! // One tetrahedron whose face x = 0 is the surface group "clamp" (Gmsh MSH 2.2).
//! let msh = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n\
//!     $PhysicalNames\n2\n2 1 \"clamp\"\n3 2 \"body\"\n$EndPhysicalNames\n\
//!     $Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n\
//!     $Elements\n2\n1 2 2 1 1 1 3 4\n2 4 2 2 1 1 2 3 4\n$EndElements\n";
//! let raw = import::gmsh::parse(msh, "tet.msh", 1.0)?;
//! let regions = raw.regions_in_mesh();
//! let clamp = import::MeshRegion::find(&regions, &RegionId::Name("clamp".into()), "tet.msh")?;
//! let mesh = raw.into_mesh()?;
//! for &node in &clamp.nodes {
//!     assert_eq!(mesh.positions()[node as usize].x, 0.0);
//! }
//! assert_eq!(clamp.nodes.len(), 3);
//! # Ok::<(), rapier_fvm::Error>(())
//! ```

use super::hexahedra::lattice_corners;
use super::{Hexahedra, RawMesh};
use crate::Error;
use crate::mesh::{QuadraticHexMesh, QuadraticTetMesh, TetMesh};
use crate::shape::tet10::EDGES;
use std::fmt;

/// A named part of a mesh file: a Gmsh physical group of points, curves, surfaces or volumes,
/// the cells of a `.vtu` or `.vtk` file that share a tag (unnamed), or a `TetGen` file's
/// tetrahedra of one region attribute (`"region N"`) or points of one boundary marker
/// (`"marker N"`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshRegion {
    /// Its name (`$PhysicalNames`), empty if the file gives none.
    pub name: String,
    /// Its dimension: 0 points, 1 curves, 2 surfaces, 3 volumes.
    pub dimension: u8,
    /// Its physical tag.
    pub tag: i64,
    /// The nodes of its elements, sorted, each once: indices into [`RawMesh::positions`] as
    /// read, into the validated mesh's nodes once [renumbered](RawMesh::regions_in_mesh).
    pub nodes: Vec<u32>,
    /// For a volume group, its tetrahedra (the quadratic elements of a second-order file), in
    /// file order: indices into [`RawMesh::tets`], which are also those of the validated mesh.
    pub tets: Vec<u32>,
}

/// How a program or a scene names a region: by the name the file gives it or by its tag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RegionId {
    /// The group's name (Gmsh's `$PhysicalNames`).
    Name(String),
    /// The group's physical tag.
    Tag(i64),
}

impl fmt::Display for RegionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Name(name) => write!(f, "region {name:?}"),
            Self::Tag(tag) => write!(f, "region tag {tag}"),
        }
    }
}

impl fmt::Display for MeshRegion {
    /// `"clamp" (surface, tag 1)`, or `unnamed (volume, tag 2)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = ["points", "curve", "surface", "volume"]
            .get(usize::from(self.dimension))
            .copied()
            .unwrap_or("group");
        if self.name.is_empty() {
            write!(f, "unnamed ({kind}, tag {})", self.tag)
        } else {
            write!(f, "{:?} ({kind}, tag {})", self.name, self.tag)
        }
    }
}

impl MeshRegion {
    /// The one region of `regions` that `id` names; `path` is the file they come from (for the
    /// error).
    ///
    /// # Errors
    /// [`Error::MeshRegion`] when no region or more than one answers to `id` (a tag a surface
    /// group and a volume group share: name it instead), listing the file's regions.
    pub fn find<'a>(regions: &'a [Self], id: &RegionId, path: &str) -> Result<&'a Self, Error> {
        let matching: Vec<&Self> = regions
            .iter()
            .filter(|region| match id {
                RegionId::Name(name) => region.name == *name,
                RegionId::Tag(tag) => region.tag == *tag,
            })
            .collect();
        let error = |reason: String| Error::MeshRegion {
            path: path.to_owned(),
            region: id.to_string(),
            reason,
        };
        match matching.as_slice() {
            [region] => Ok(region),
            [] if regions.is_empty() => Err(error(
                "the file names no regions (Gmsh physical groups)".into(),
            )),
            [] => Err(error(format!("the file's regions are {}", list(regions)))),
            several => Err(error(format!(
                "more than one group answers to it: {}; select one by its other identifier",
                list(several.iter().copied())
            ))),
        }
    }
}

/// The regions as `"clamp" (surface, tag 1), "body" (volume, tag 2)`.
fn list<'a>(regions: impl IntoIterator<Item = &'a MeshRegion>) -> String {
    let names: Vec<String> = regions.into_iter().map(ToString::to_string).collect();
    names.join(", ")
}

impl RawMesh {
    /// The index each node of [`RawMesh::positions`] gets in the mesh [`RawMesh::into_mesh`],
    /// [`RawMesh::into_quadratic_mesh`] and [`RawMesh::into_cage`] build (nodes numbered in
    /// order of first use by the elements, corners then mid-edge nodes; a cage's in their
    /// order in the file), `None` for a node no element uses or past the
    /// positions; with it, a [`MeshRegion`]'s nodes select the validated mesh's nodes.
    pub fn mesh_node_indices(&self) -> Vec<Option<u32>> {
        let mut index = vec![None; self.positions.len()];
        let mut next = 0u32;
        let mut number = |node: u32| {
            if let Some(slot @ None) = index.get_mut(node as usize) {
                *slot = Some(next);
                next += 1;
            }
        };
        if let Hexahedra::Triquadratic(elements) = &self.hexahedra {
            // A cage keeps its nodes' order, so that its subdivision is the file's.
            let mut used = vec![false; self.positions.len()];
            for &node in elements.iter().flatten() {
                if let Some(slot) = used.get_mut(node as usize) {
                    *slot = true;
                }
            }
            (0..used.len())
                .filter(|&n| used[n])
                .for_each(|n| number(n as u32));
            return index;
        }
        let mids = self
            .mid_edge_nodes
            .iter()
            .map(Some)
            .chain(std::iter::repeat(None));
        for (corners, mids) in self.tets.iter().zip(mids) {
            for &node in corners.iter().chain(mids.into_iter().flatten()) {
                number(node);
            }
        }
        index
    }

    /// The file's regions with their nodes numbered as in the mesh [`RawMesh::into_mesh`] and
    /// [`RawMesh::into_quadratic_mesh`] build, sorted; nodes no element uses (a surface group's
    /// nodes outside the volume [kept](RawMesh::keep_volume)) are left out.
    pub fn regions_in_mesh(&self) -> Vec<MeshRegion> {
        let index = self.mesh_node_indices();
        self.regions
            .iter()
            .map(|region| {
                let mut nodes: Vec<u32> = region
                    .nodes
                    .iter()
                    .filter_map(|&node| index.get(node as usize).copied().flatten())
                    .collect();
                nodes.sort_unstable();
                MeshRegion {
                    nodes,
                    ..region.clone()
                }
            })
            .collect()
    }

    /// The mesh of one volume group's tetrahedra, so that a file's volumes can become bodies
    /// of their own: the other tetrahedra are dropped, the positions kept (validation drops the
    /// nodes left unused), and every region's tetrahedra renumbered to those kept.
    ///
    /// # Errors
    /// [`Error::MeshRegion`] when `id` names no region, more than one, or a region that is not
    /// a volume of tetrahedra.
    pub fn keep_volume(mut self, id: &RegionId) -> Result<Self, Error> {
        let region = MeshRegion::find(&self.regions, id, &self.path)?;
        if region.dimension != 3 || region.tets.is_empty() {
            return Err(Error::MeshRegion {
                path: self.path.clone(),
                region: id.to_string(),
                reason: format!("{region} is not a volume of tetrahedra"),
            });
        }
        let kept = region.tets.clone();
        let mut new_index = vec![None; self.tets.len()];
        for (new, &old) in kept.iter().enumerate() {
            new_index[old as usize] = Some(new as u32);
        }
        let pick = |i: &u32| kept_element(&new_index, *i);
        self.tets = kept.iter().map(|&i| self.tets[i as usize]).collect();
        self.tet_locations = kept
            .iter()
            .map(|&i| self.tet_locations[i as usize])
            .collect();
        if !self.mid_edge_nodes.is_empty() {
            self.mid_edge_nodes = kept
                .iter()
                .map(|&i| self.mid_edge_nodes[i as usize])
                .collect();
        }
        for region in &mut self.regions {
            region.tets = region.tets.iter().filter_map(pick).collect();
        }
        // A region holds all of a hexahedron's tetrahedra or none.
        let per_element = self.hexahedra.tets_per_element();
        let kept_element = |e: usize| new_index[e * per_element].is_some();
        match &mut self.hexahedra {
            Hexahedra::Linear(elements) => retain_indexed(elements, kept_element),
            Hexahedra::Triquadratic(elements) => retain_indexed(elements, kept_element),
            Hexahedra::None => {}
        }
        Ok(self)
    }
}

/// Keeps the elements `e` of `elements` for which `keep(e)`.
fn retain_indexed<T>(elements: &mut Vec<T>, keep: impl Fn(usize) -> bool) {
    let mut e = 0;
    elements.retain(|_| {
        e += 1;
        keep(e - 1)
    });
}

/// The new index of element `old`, if kept.
fn kept_element(new_index: &[Option<u32>], old: u32) -> Option<u32> {
    new_index.get(old as usize).copied().flatten()
}

impl MeshRegion {
    /// The region on `mesh`, a quadratic mesh built from the linear one its nodes number (by
    /// [`QuadraticTetMesh::from_linear`], which keeps the corners' numbers): with the mid-edge
    /// node of each edge whose two ends it holds, if that node lies on the boundary (or the
    /// region is a volume), so that a surface group of a first-order file selects its whole
    /// face of the quadratic body. A second-order file's groups hold their mid-edge nodes
    /// already and need no widening.
    #[must_use]
    pub fn with_mid_edge_nodes(&self, mesh: &QuadraticTetMesh) -> Self {
        let mids = mesh.elements().iter().flat_map(|element| {
            (EDGES.iter().enumerate())
                .map(|(k, [i, j])| (element[4 + k], vec![element[*i], element[*j]]))
        });
        self.widened_by(mesh.subdivided(), mids)
    }

    /// The region with each node of `candidates` (a node and the nodes it lies between) whose
    /// ends it all holds, if that node lies on the boundary of `subdivided` (or the region is a
    /// volume); nodes sorted, each once.
    fn widened_by(
        &self,
        subdivided: &TetMesh,
        candidates: impl Iterator<Item = (u32, Vec<u32>)>,
    ) -> Self {
        let node_count = subdivided.node_count();
        let mut inside = vec![false; node_count];
        for &node in &self.nodes {
            if let Some(slot) = inside.get_mut(node as usize) {
                *slot = true;
            }
        }
        let mut on_boundary = vec![self.dimension == 3; node_count];
        for triangle in subdivided.surface_triangles() {
            for node in triangle {
                on_boundary[node as usize] = true;
            }
        }
        let mut nodes = self.nodes.clone();
        for (node, ends) in candidates {
            let ends_inside = ends.iter().all(|&end| inside[end as usize]);
            if ends_inside && on_boundary[node as usize] && !inside[node as usize] {
                inside[node as usize] = true;
                nodes.push(node);
            }
        }
        nodes.sort_unstable();
        Self {
            nodes,
            ..self.clone()
        }
    }
}

impl MeshRegion {
    /// The region of a file of linear hexahedra on `cage`, the cage
    /// [`RawMesh::into_cage`] builds of them (which keeps the corners' numbers): with each
    /// edge, face and centre node of an element whose corners (two, four or eight) it all
    /// holds, if that node lies on the boundary (or the region is a volume), so that a surface
    /// group selects its whole face of the cage. The region knows its nodes, not its faces: one
    /// whose nodes surround a boundary face it does not hold (the four sides of a beam one
    /// element across hold its end faces' corners) gains that face's nodes too. Its
    /// tetrahedra stay the file's (six per hexahedron; [`MeshRegion::cage_elements`] gives its
    /// hexahedra). A 27-node file's regions hold their nodes already and need no widening.
    #[must_use]
    pub fn with_cage_nodes(&self, cage: &QuadraticHexMesh) -> Self {
        const CORNER_LATTICE: [usize; 8] = [0, 2, 6, 8, 18, 20, 24, 26];
        let middles = cage.elements().iter().flat_map(|element| {
            element.iter().enumerate().map(|(a, &node)| {
                let corners = lattice_corners(a).into_iter();
                let ends = corners.map(|place| element[CORNER_LATTICE[place]]);
                (node, ends.collect())
            })
        });
        self.widened_by(cage.subdivided(), middles)
    }

    /// The cage elements of a volume group of a file of hexahedra: the hexahedra its
    /// tetrahedra were split from (each into `tets_per_hexahedron` consecutive ones,
    /// [`Hexahedra::tets_per_element`]), which are the elements of the cage
    /// [`RawMesh::into_cage`] builds, in order: the indices
    /// [`region_material`](crate::body::DeformableBodyBuilder::region_material) takes for a
    /// cage body.
    ///
    /// # Panics
    /// If `tets_per_hexahedron` is zero.
    pub fn cage_elements(&self, tets_per_hexahedron: usize) -> Vec<u32> {
        let per = tets_per_hexahedron as u32;
        let mut elements: Vec<u32> = self.tets.iter().map(|t| t / per).collect();
        elements.dedup();
        elements
    }
}
