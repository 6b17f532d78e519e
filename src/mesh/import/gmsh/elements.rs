//! Gmsh's element types, as both MSH versions use them.
//!
//! Keeps linear tetrahedra (type 4) and quadratic ones (type 11), and hexahedra, linear (type
//! 5) and 27-node (type 12), split into tetrahedra (`import::hexahedra`); skips the
//! lower-dimensional types Gmsh saves beside the volume (points, lines, triangles, quadrangles
//! and their higher-order forms), and refuses every other volume type, an unknown type, and two
//! kinds of volume element mixed in one mesh ([`ImportErrorKind::UnsupportedElement`]).

use super::Reader;
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::hex_split::split_lattice;
use crate::mesh::import::hexahedra;
use crate::mesh::import::text::{Source, parse_token};

/// Gmsh's linear triangle.
const TRIANGLE: u32 = 2;
/// Gmsh's linear tetrahedron.
const TETRAHEDRON: u32 = 4;
/// Gmsh's quadratic (10-node) tetrahedron.
const QUADRATIC_TETRAHEDRON: u32 = 11;
/// Gmsh's linear (8-node) hexahedron.
pub(super) const HEXAHEDRON: u32 = 5;
/// Gmsh's 27-node hexahedron.
pub(super) const TRIQUADRATIC_HEXAHEDRON: u32 = 12;
/// The most nodes of an element of the types [`element_shape`] knows (type 31).
pub(super) const MAX_NODES: usize = 56;

/// The node count of Gmsh's element type `element_type`, or
/// [`ImportErrorKind::UnsupportedElement`] at `location` for a type it does not define.
pub(super) fn nodes_per_element(
    source: &Source<'_>,
    location: FileLocation,
    element_type: u32,
) -> Result<usize, Error> {
    element_shape(element_type)
        .map(|(nodes, _)| nodes)
        .ok_or_else(|| {
            source.error_at(
                location,
                ImportErrorKind::UnsupportedElement,
                format!("unknown element type {element_type}"),
            )
        })
}

/// Nodes per element and dimension of Gmsh's element types 1 to 31.
fn element_shape(element_type: u32) -> Option<(usize, u8)> {
    Some(match element_type {
        1 => (2, 1),
        2 => (3, 2),
        3 => (4, 2),
        4 => (4, 3),
        5 => (8, 3),
        6 => (6, 3),
        7 => (5, 3),
        8 => (3, 1),
        9 => (6, 2),
        10 => (9, 2),
        11 => (10, 3),
        12 => (27, 3),
        13 => (18, 3),
        14 => (14, 3),
        15 => (1, 0),
        16 => (8, 2),
        17 => (20, 3),
        18 => (15, 3),
        19 => (13, 3),
        20 => (9, 2),
        21 => (10, 2),
        22 => (12, 2),
        23 | 24 => (15, 2),
        25 => (21, 2),
        26 => (4, 1),
        27 => (5, 1),
        28 => (6, 1),
        29 => (20, 3),
        30 => (35, 3),
        31 => (56, 3),
        _ => return None,
    })
}

/// The indices `start..end` of a range of tetrahedra, saturated at `u32::MAX` (a mesh cannot
/// index more).
fn index_range(start: usize, end: usize) -> std::ops::Range<u32> {
    let index = |i: usize| u32::try_from(i).unwrap_or(u32::MAX);
    index(start)..index(end)
}

impl Reader {
    /// Handles an element of `element_type` with node tags `nodes`: keeps tetrahedra and
    /// hexahedra, skips lower-dimensional elements, rejects other volume elements.
    pub(super) fn add_element(
        &mut self,
        source: &Source<'_>,
        location: FileLocation,
        element_type: u32,
        nodes: &[u64],
    ) -> Result<(), Error> {
        match element_type {
            TETRAHEDRON | QUADRATIC_TETRAHEDRON | HEXAHEDRON | TRIQUADRATIC_HEXAHEDRON => {
                self.add_volume_element(source, location, element_type, nodes)
            }
            TRIANGLE => {
                self.regions.record(2, nodes, 0..0);
                self.triangles
                    .push(([nodes[0], nodes[1], nodes[2]], location));
                Ok(())
            }
            _ => match element_shape(element_type) {
                Some((_, 3)) => Err(source.error_at(
                    location,
                    ImportErrorKind::UnsupportedElement,
                    format!(
                        "volume element type {element_type}: only tetrahedra (types 4 and 11) \
                         and hexahedra (types 5 and 12) can be used"
                    ),
                )),
                Some((_, 2)) => {
                    self.regions.record(2, nodes, 0..0);
                    // Quadrangles, curved triangles: not part of a surface this crate fills.
                    self.other_surface_element
                        .get_or_insert((element_type, location));
                    Ok(())
                }
                Some((_, dim)) => {
                    self.regions.record(dim, nodes, 0..0);
                    Ok(())
                }
                None => Err(source.error_at(
                    location,
                    ImportErrorKind::UnsupportedElement,
                    format!("unknown element type {element_type}"),
                )),
            },
        }
    }

    /// Adds a tetrahedron or a hexahedron (split into tetrahedra) of `element_type`, refusing a
    /// type other than the file's first volume element's.
    fn add_volume_element(
        &mut self,
        source: &Source<'_>,
        location: FileLocation,
        element_type: u32,
        nodes: &[u64],
    ) -> Result<(), Error> {
        match self.volume_type {
            Some(first) if first != element_type => {
                return Err(source.error_at(
                    location,
                    ImportErrorKind::UnsupportedElement,
                    format!(
                        "element type {element_type} mixed with type {first}: one kind of \
                         volume element per mesh"
                    ),
                ));
            }
            _ => self.volume_type = Some(element_type),
        }
        let first_tet = self.tets.len();
        match element_type {
            HEXAHEDRON => {
                let tets = hexahedra::split_linear(nodes);
                self.tets
                    .extend(tets.into_iter().map(|tet| (tet, location)));
                self.hexahedron_tags
                    .push(std::array::from_fn(|corner| nodes[corner]));
            }
            TRIQUADRATIC_HEXAHEDRON => {
                let lattice = hexahedra::lattice(nodes, &hexahedra::GMSH_TRIQUADRATIC);
                let tets = split_lattice(&lattice);
                self.tets
                    .extend(tets.into_iter().map(|tet| (tet, location)));
                self.cage_tags.push(lattice);
            }
            _ => {
                self.tets
                    .push(([nodes[0], nodes[1], nodes[2], nodes[3]], location));
                if element_type == QUADRATIC_TETRAHEDRON {
                    // Gmsh numbers the edges (0,1) (1,2) (0,2) (0,3) (2,3) (1,3); the last two
                    // are swapped into VTK's order.
                    self.mid_edge_tags
                        .push([nodes[4], nodes[5], nodes[6], nodes[7], nodes[9], nodes[8]]);
                }
            }
        }
        let tets = index_range(first_tet, self.tets.len());
        self.regions.record(3, nodes, tets);
        Ok(())
    }

    /// The node tags of an ASCII element line (after its type and tags), checked against the
    /// type's node count.
    pub(super) fn element_line<'t>(
        &mut self,
        source: &Source<'_>,
        element_type: u32,
        tokens: impl Iterator<Item = &'t str>,
    ) -> Result<(), Error> {
        let location = source.location();
        let node_count = nodes_per_element(source, location, element_type)?;
        let mut nodes = [0u64; MAX_NODES];
        let mut n = 0;
        for token in tokens {
            if n == node_count {
                return Err(source.error(
                    ImportErrorKind::BadCount,
                    format!("more than the {node_count} nodes of element type {element_type}"),
                ));
            }
            nodes[n] = parse_token(source, Some(token), "node tag")?;
            n += 1;
        }
        if n < node_count {
            return Err(source.error(
                ImportErrorKind::BadCount,
                format!("{n} nodes, but element type {element_type} has {node_count}"),
            ));
        }
        self.add_element(source, location, element_type, &nodes[..node_count])
    }
}
