//! The checks every mesh passes when it is built: topology (elements refer to existing,
//! distinct nodes and use every node), coordinates `f64` can compute with, and elements of a
//! volume that is neither zero at their scale nor too small for `f64`.
//!
//! Contract: a mesh that passes has every coordinate finite and within ±[`MAX_COORDINATE`] m,
//! and every tetrahedron a volume `V > 1e-12 l³` (`l` its longest edge) that is a normal `f64`.
//! Every defect is an [`Error`] naming the first offending node or tetrahedron.

use crate::Error;
pub use crate::limits::MAX_COORDINATE;
use rapier3d::glamx::DVec3;

/// Relative volume below which a tetrahedron counts as degenerate: `|V| <= 1e-12 * l^3`, with `l`
/// the tetrahedron's longest edge.
pub(crate) const DEGENERATE_RELATIVE_VOLUME: f64 = 1e-12;

/// `Ok` if `position` (m) of node `node` is finite and within ±[`MAX_COORDINATE`].
///
/// # Errors
/// [`Error::NonFiniteCoordinate`] or [`Error::CoordinateOutOfRange`] naming `node`.
pub(crate) fn check_position(node: usize, position: DVec3) -> Result<(), Error> {
    if !position.is_finite() {
        return Err(Error::NonFiniteCoordinate {
            node,
            position: position.to_array(),
        });
    }
    if position.abs().max_element() > MAX_COORDINATE {
        return Err(Error::CoordinateOutOfRange {
            node,
            position: position.to_array(),
        });
    }
    Ok(())
}

/// Checks that the mesh is not empty, its coordinates usable ([`check_position`]), and every
/// element of `N` nodes refers to existing, distinct nodes, with every node used.
pub(crate) fn validate_topology<const N: usize>(
    positions: &[DVec3],
    tets: &[[u32; N]],
) -> Result<(), Error> {
    if positions.is_empty() || tets.is_empty() {
        return Err(Error::EmptyMesh {
            nodes: positions.len(),
            tets: tets.len(),
        });
    }
    for (node, &position) in positions.iter().enumerate() {
        check_position(node, position)?;
    }
    let mut referenced = vec![false; positions.len()];
    for (tet, nodes) in tets.iter().enumerate() {
        if let Some(&node) = nodes.iter().find(|&&n| n as usize >= positions.len()) {
            return Err(Error::NodeIndexOutOfRange {
                tet,
                node,
                node_count: positions.len(),
            });
        }
        for i in 0..N {
            if nodes[i + 1..].contains(&nodes[i]) {
                return Err(Error::RepeatedNode {
                    tet,
                    node: nodes[i],
                });
            }
            referenced[nodes[i] as usize] = true;
        }
    }
    match referenced.iter().position(|&r| !r) {
        Some(node) => Err(Error::UnreferencedNode { node }),
        None => Ok(()),
    }
}

/// Checks tetrahedron `tet` of `nodes`, of signed rest volume `volume` (m³), against its scale:
/// the degeneracy threshold `1e-12 l³` must be a normal number ([`Error::TetTooSmall`]
/// otherwise), and `|volume|` above it ([`Error::DegenerateTet`] otherwise). The nodes must have
/// passed [`check_position`]: within its bound, `l³` and the volume are finite.
pub(crate) fn check_element_volume(
    positions: &[DVec3],
    nodes: &[u32; 4],
    tet: usize,
    volume: f64,
) -> Result<(), Error> {
    let p = nodes.map(|i| positions[i as usize]);
    let mut longest_edge_sq: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            longest_edge_sq = longest_edge_sq.max(p[i].distance_squared(p[j]));
        }
    }
    let longest_edge = longest_edge_sq.sqrt();
    let threshold = DEGENERATE_RELATIVE_VOLUME * longest_edge_sq * longest_edge;
    if !threshold.is_normal() {
        return Err(Error::TetTooSmall { tet, longest_edge });
    }
    if volume.abs() <= threshold {
        return Err(Error::DegenerateTet { tet, volume });
    }
    Ok(())
}

/// An error of a subdivision's tetrahedron re-addressed to the element `parent(tet)` it lies in.
pub(crate) fn name_parent_element(error: Error, parent: impl Fn(usize) -> usize) -> Error {
    match error {
        Error::InvertedTet { tet, volume } => Error::InvertedTet {
            tet: parent(tet),
            volume,
        },
        Error::DegenerateTet { tet, volume } => Error::DegenerateTet {
            tet: parent(tet),
            volume,
        },
        Error::TetTooSmall { tet, longest_edge } => Error::TetTooSmall {
            tet: parent(tet),
            longest_edge,
        },
        Error::RepeatedNode { tet, node } => Error::RepeatedNode {
            tet: parent(tet),
            node,
        },
        other => other,
    }
}
