//! Hexahedra in files: linear (8-node) ones split into tetrahedra on their corners, 27-node
//! ones kept as elements of a [`QuadraticHexMesh`] cage and split on their lattice nodes.
//!
//! Both are cut by the conforming rule of `mesh::hex_split` (each face along its diagonal
//! through its corner of least index), node indices (their order in the file) giving the
//! order, so the tetrahedra of neighbouring hexahedra share their faces' cuts.
//! A hexahedron's tetrahedra follow one another in [`RawMesh::tets`], all at the hexahedron's
//! place in the file.
//!
//! The node orders of the files: corners `0 1 2 3` the bottom face counter-clockwise seen from
//! above, `4 5 6 7` above them (Gmsh and VTK alike); the 27-node hexahedron's edge, face and
//! centre nodes as tabled in [`GMSH_TRIQUADRATIC`] (Gmsh type 12) and [`VTK_TRIQUADRATIC`] (VTK
//! type 29, as `vtkTriQuadraticHexahedron::GetParametricCoords` lists them).

use super::RawMesh;
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::QuadraticHexMesh;
use crate::mesh::hex_split::{FILE_ORDER_CORNERS, TETS_PER_LATTICE, split_hexahedron};
use crate::shape::hex27;
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// The hexahedra a mesh file held, which its tetrahedra were split from.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Hexahedra {
    /// None: the file held tetrahedra.
    #[default]
    None,
    /// Linear (8-node) hexahedra, each split into six consecutive tetrahedra: the elements'
    /// corners (indices into [`RawMesh::positions`]) in the file's order.
    Linear(Vec<[u32; 8]>),
    /// 27-node hexahedra, each split into 48 consecutive tetrahedra on its lattice nodes: the
    /// elements' node indices (into [`RawMesh::positions`]) in the lattice order of
    /// [`crate::shape::hex27`].
    Triquadratic(Vec<[u32; hex27::NODES]>),
}

impl Hexahedra {
    /// Writes each hexahedron's tetrahedra, split by its node indices, over its block of
    /// `tets` (the readers' tetrahedra, one block per hexahedron in order); nothing for a
    /// file of tetrahedra.
    pub(super) fn split_into(&self, tets: &mut [[u32; 4]]) {
        match self {
            Self::Linear(elements) => {
                let blocks = tets.chunks_exact_mut(crate::mesh::hex_split::TETS_PER_HEXAHEDRON);
                for (block, corners) in blocks.zip(elements) {
                    block.copy_from_slice(&split_linear(corners));
                }
            }
            Self::Triquadratic(elements) => {
                for (block, lattice) in tets.chunks_exact_mut(TETS_PER_LATTICE).zip(elements) {
                    block.copy_from_slice(&crate::mesh::hex_split::split_lattice(lattice));
                }
            }
            Self::None => {}
        }
    }

    /// The consecutive tetrahedra each element of the file became: 1 for tetrahedra, 6 for
    /// linear hexahedra, 48 for 27-node ones.
    pub fn tets_per_element(&self) -> usize {
        match self {
            Self::None => 1,
            Self::Linear(_) => crate::mesh::hex_split::TETS_PER_HEXAHEDRON,
            Self::Triquadratic(_) => TETS_PER_LATTICE,
        }
    }
}

/// The lattice place `(i, j, k)` of each node of Gmsh's 27-node hexahedron (type 12): corners,
/// the edges `(0,1) (0,3) (0,4) (1,2) (1,5) (2,3) (2,6) (3,7) (4,5) (4,7) (5,6) (6,7)`, the faces
/// `z = 0, y = 0, x = 0, x = 1, y = 1, z = 1`, the centre.
#[rustfmt::skip]
pub const GMSH_TRIQUADRATIC: [[u8; 3]; 27] = [
    [0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [0, 0, 2], [2, 0, 2], [2, 2, 2], [0, 2, 2],
    [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 1, 0], [2, 0, 1], [1, 2, 0], [2, 2, 1], [0, 2, 1],
    [1, 0, 2], [0, 1, 2], [2, 1, 2], [1, 2, 2],
    [1, 1, 0], [1, 0, 1], [0, 1, 1], [2, 1, 1], [1, 2, 1], [1, 1, 2],
    [1, 1, 1],
];

/// The lattice place `(i, j, k)` of each node of VTK's triquadratic hexahedron (type 29):
/// corners, the edges `(0,1) (1,2) (2,3) (3,0) (4,5) (5,6) (6,7) (7,4) (0,4) (1,5) (2,6) (3,7)`,
/// the faces `x = 0, x = 1, y = 0, y = 1, z = 0, z = 1`, the centre.
#[rustfmt::skip]
pub const VTK_TRIQUADRATIC: [[u8; 3]; 27] = [
    [0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [0, 0, 2], [2, 0, 2], [2, 2, 2], [0, 2, 2],
    [1, 0, 0], [2, 1, 0], [1, 2, 0], [0, 1, 0], [1, 0, 2], [2, 1, 2], [1, 2, 2], [0, 1, 2],
    [0, 0, 1], [2, 0, 1], [2, 2, 1], [0, 2, 1],
    [0, 1, 1], [2, 1, 1], [1, 0, 1], [1, 2, 1], [1, 1, 0], [1, 1, 2],
    [1, 1, 1],
];

/// The six tetrahedra of the linear hexahedron of `nodes` in file order (8 entries).
pub(super) fn split_linear<T: Ord + Copy>(nodes: &[T]) -> [[T; 4]; 6] {
    let mut by_place = [nodes[0]; 8];
    for (file, &place) in FILE_ORDER_CORNERS.iter().enumerate() {
        by_place[place] = nodes[file];
    }
    split_hexahedron(by_place)
}

/// The nodes of the 27-node hexahedron of `nodes` in file order (27 entries, placed by
/// `places`) in the lattice order of [`crate::shape::hex27`].
pub(super) fn lattice<T: Copy>(nodes: &[T], places: &[[u8; 3]; 27]) -> [T; 27] {
    let mut lattice = [nodes[0]; 27];
    for (&node, [i, j, k]) in nodes.iter().zip(places) {
        lattice[usize::from(*i) + 3 * usize::from(*j) + 9 * usize::from(*k)] = node;
    }
    lattice
}

impl RawMesh {
    /// The cage of the file's hexahedra. 27-node ones keep the nodes they use in their order
    /// in the file (so that the cage's [subdivision](QuadraticHexMesh::subdivided) holds the
    /// tetrahedra of [`RawMesh::tets`], renumbered); linear ones keep their corners, numbered as by
    /// [`RawMesh::into_mesh`], and gain a node at the middle of each edge, face and hexahedron
    /// (the trilinear map's, so the cage has the straight-sided shape of the file's elements),
    /// numbered after the corners in order of first use. Each element is checked and oriented
    /// by [`QuadraticHexMesh::new`]. [`MeshRegion::with_cage_nodes`](super::MeshRegion::with_cage_nodes) widens the file's regions
    /// to the added nodes.
    ///
    /// # Errors
    /// [`ImportErrorKind::UnsupportedElement`] for a file of tetrahedra;
    /// [`ImportErrorKind::InvalidMesh`] at the element's place in the file when
    /// [`QuadraticHexMesh::new`] rejects it, and the coordinate errors of
    /// [`RawMesh::into_mesh`].
    pub fn into_cage(self) -> Result<QuadraticHexMesh, Error> {
        let (positions, elements) = match &self.hexahedra {
            Hexahedra::Triquadratic(elements) => self.in_file_order(elements)?,
            Hexahedra::Linear(corners) => self.elevated(corners)?,
            Hexahedra::None => {
                return Err(self.error(
                    FileLocation::Whole,
                    ImportErrorKind::UnsupportedElement,
                    "a cage needs a file of hexahedra (Gmsh type 5 or 12, VTK type 12 or 29)"
                        .into(),
                ));
            }
        };
        let tets_per_element = self.hexahedra.tets_per_element();
        QuadraticHexMesh::new(positions, elements).map_err(|e| {
            // The errors name the element (as their `tet`), whose tetrahedra all sit at its
            // place in the file.
            let element = match e {
                Error::DegenerateTet { tet, .. }
                | Error::TetTooSmall { tet, .. }
                | Error::InvertedTet { tet, .. }
                | Error::RepeatedNode { tet, .. } => Some(tet),
                _ => None,
            };
            let at = element.map_or(FileLocation::Whole, |element| {
                self.location(element * tets_per_element)
            });
            let message = format!("a hexahedron's subdivision: {e}");
            self.error(at, ImportErrorKind::InvalidMesh, message)
        })
    }

    /// The 27-node elements of the linear hexahedra `corners` (file order): the corners'
    /// positions as [`RawMesh::into_mesh`] numbers them, then the edge, face and centre nodes,
    /// each shared by the elements around it (keyed by its corners).
    fn elevated(
        &self,
        corners: &[[u32; 8]],
    ) -> Result<(Vec<DVec3>, Vec<[u32; hex27::NODES]>), Error> {
        let index = self.mesh_node_indices();
        let mut positions = vec![DVec3::ZERO; index.iter().flatten().count()];
        for (node, new) in index.iter().enumerate() {
            if let Some(new) = new {
                positions[*new as usize] = self.positions[node];
            }
        }
        let mut added: HashMap<Vec<u32>, u32> = HashMap::new();
        let mut elements = Vec::with_capacity(corners.len());
        for (e, hexahedron) in corners.iter().enumerate() {
            let tet = e * self.hexahedra.tets_per_element();
            // The corners by unit-cube place, renumbered.
            let mut by_place = [0u32; 8];
            for (file, &place) in FILE_ORDER_CORNERS.iter().enumerate() {
                let node = hexahedron[file];
                if let Some(&position) = self.positions.get(node as usize) {
                    crate::mesh::check_position(node as usize, position)
                        .map_err(|error| self.coordinate_error(tet, &error))?;
                }
                by_place[place] = index.get(node as usize).copied().flatten().ok_or_else(|| {
                    self.error(
                        self.location(tet),
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "hexahedron {e} refers to node {node}, not one of its tetrahedra's"
                        ),
                    )
                })?;
            }
            let element = std::array::from_fn(|a| {
                let places = lattice_corners(a);
                if let [single] = places.as_slice() {
                    return by_place[*single];
                }
                let mut key: Vec<u32> = places.iter().map(|&b| by_place[b]).collect();
                key.sort_unstable();
                *added.entry(key).or_insert_with_key(|key| {
                    let sum: DVec3 = key.iter().map(|&n| positions[n as usize]).sum();
                    positions.push(sum / key.len() as f64);
                    (positions.len() - 1) as u32
                })
            });
            elements.push(element);
        }
        Ok((positions, elements))
    }
}

/// The unit-cube places of the corners lattice node `a` (order of [`crate::shape::hex27`]) lies
/// in the middle of: itself for a corner, two for an edge's middle, four for a face's, eight
/// for the centre.
pub(crate) fn lattice_corners(a: usize) -> Vec<usize> {
    let [i, j, k] = hex27::lattice(a);
    // Along each axis: the lattice place 0 or 2 is one end, 1 both.
    let ends = |c: usize| match c {
        0 => vec![0],
        2 => vec![1],
        _ => vec![0, 1],
    };
    let mut places = Vec::with_capacity(8);
    for z in ends(k) {
        for y in ends(j) {
            for x in ends(i) {
                places.push(x + 2 * y + 4 * z);
            }
        }
    }
    places
}

impl RawMesh {
    /// The positions the 27-node hexahedra `elements` use, in file order, and the elements
    /// renumbered to them ([`RawMesh::mesh_node_indices`]); a node that is not finite or too far
    /// out is an error at the first element using it.
    fn in_file_order(
        &self,
        elements: &[[u32; hex27::NODES]],
    ) -> Result<(Vec<DVec3>, Vec<[u32; hex27::NODES]>), Error> {
        let index = self.mesh_node_indices();
        let mut positions = Vec::new();
        for (node, new) in index.iter().enumerate() {
            if new.is_some() {
                positions.push(self.positions[node]);
            }
        }
        let mut renumbered = Vec::with_capacity(elements.len());
        for (e, element) in elements.iter().enumerate() {
            let mut nodes = [0; hex27::NODES];
            for (slot, &node) in nodes.iter_mut().zip(element) {
                let tet = e * TETS_PER_LATTICE;
                let Some(new) = index.get(node as usize).copied().flatten() else {
                    return Err(self.error(
                        self.location(tet),
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "hexahedron {e} refers to node {node}, but there are {} nodes",
                            self.positions.len()
                        ),
                    ));
                };
                crate::mesh::check_position(node as usize, self.positions[node as usize])
                    .map_err(|error| self.coordinate_error(tet, &error))?;
                *slot = new;
            }
            renumbered.push(nodes);
        }
        Ok((positions, renumbered))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_orders_place_every_lattice_node_once() {
        for places in [&GMSH_TRIQUADRATIC, &VTK_TRIQUADRATIC] {
            let nodes: [usize; 27] = std::array::from_fn(|n| n);
            let mut seen = lattice(&nodes, places).to_vec();
            seen.sort_unstable();
            assert_eq!(seen, nodes.to_vec());
            // Corners first, then edges (one coordinate 1), faces (two), the centre (three).
            let ones = |p: &[u8; 3]| p.iter().filter(|&&c| c == 1).count();
            let counts: Vec<usize> = places.iter().map(ones).collect();
            let expected: Vec<usize> = [(0, 8), (1, 12), (2, 6), (3, 1)]
                .iter()
                .flat_map(|&(ones, n)| std::iter::repeat_n(ones, n))
                .collect();
            assert_eq!(counts, expected);
        }
    }
}
