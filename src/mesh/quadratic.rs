//! Meshes of 10-node quadratic tetrahedra: validation, elevation of a linear mesh (mid-edge
//! nodes), and the subdivision into linear tetrahedra on the same nodes that contacts, surface
//! extraction and output use.

use super::TetMesh;
use crate::Error;
use crate::shape::tet10::{self, EDGES, NODES, reference_nodes};
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// A validated mesh of quadratic tetrahedra in its rest configuration.
///
/// Each element lists its 4 corners then its 6 mid-edge nodes in VTK order (edges `(0,1) (1,2)
/// (0,2) (0,3) (1,3) (2,3)`, see [`crate::shape::tet10`]); neighbours share the mid-edge node of
/// a shared edge. Every element is also split into 8 linear tetrahedra on its own nodes (the
/// corners' 4 and 4 around the shortest diagonal of the inner octahedron), the
/// [`QuadraticTetMesh::subdivided`] mesh: it has exactly the same nodes, so its boundary
/// triangles, contacts and output act on the simulated nodes themselves.
///
/// # Example
/// ```
/// use rapier_fvm::{glamx::DVec3, mesh};
/// let linear = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [10, 1, 1])?;
/// let beam = mesh::QuadraticTetMesh::from_linear(&linear)?;
/// assert_eq!(beam.element_count(), linear.tet_count());
/// assert_eq!(beam.subdivided().tet_count(), 8 * linear.tet_count());
/// assert!((beam.subdivided().volume() - 0.01).abs() < 1e-15);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticTetMesh {
    elements: Vec<[u32; NODES]>,
    subdivided: TetMesh,
}

impl QuadraticTetMesh {
    /// Builds a mesh from rest positions (m) and elements (10 node indices each), rejecting any
    /// defect.
    ///
    /// # Errors
    /// The errors of [`TetMesh::new`] for the node indices and coordinates, naming the element;
    /// [`Error::NonConformingEdge`] when two elements put different mid-edge nodes on a shared
    /// edge; [`Error::FoldedElement`] naming the first element, its corners counter-clockwise,
    /// whose rest map folds (its Jacobian determinant not positive at a corner or quadrature
    /// point, where the elements' integration would meet it: a mid-edge node too far off its
    /// edge); [`Error::InvertedTet`] or [`Error::DegenerateTet`] naming the element when one of
    /// its linear sub-tetrahedra is inverted or flat (corners ordered clockwise).
    pub fn new(positions: Vec<DVec3>, elements: Vec<[u32; NODES]>) -> Result<Self, Error> {
        super::validate_topology(&positions, &elements)?;
        check_conforming(&elements)?;
        check_not_folded(&positions, &elements)?;
        let sub_tets = elements
            .iter()
            .flat_map(|e| subdivision(&positions, e))
            .collect();
        let subdivided = TetMesh::new(positions, sub_tets)
            .map_err(|error| super::name_parent_element(error, |tet| tet / SUB_TETS))?;
        Ok(Self {
            elements,
            subdivided,
        })
    }

    /// The quadratic mesh of the same tetrahedra as `mesh`: a node is added at the midpoint of
    /// every edge (after the existing nodes, in order of first appearance), so the elements are
    /// straight-sided and the body has the same shape and volume.
    ///
    /// # Errors
    /// Those of [`QuadraticTetMesh::new`]; none for a valid `mesh` unless a sub-tetrahedron falls
    /// below the degeneracy threshold.
    pub fn from_linear(mesh: &TetMesh) -> Result<Self, Error> {
        Self::from_linear_curved(mesh, |_, _| None)
    }

    /// Like [`QuadraticTetMesh::from_linear`], but the mid-edge node of every boundary edge
    /// `(a, b)` (rest positions, m) is placed at `curve(a, b)` when that is `Some`: the point of
    /// the true, curved surface between them. Curved boundary elements follow a round shape
    /// with far fewer elements than flat ones. [`mesh::sphere`](super::sphere) and
    /// [`mesh::cylinder`](super::cylinder) have curved versions, [`QuadraticTetMesh::sphere`]
    /// and [`QuadraticTetMesh::cylinder`].
    ///
    /// # Errors
    /// Those of [`QuadraticTetMesh::new`], e.g. [`Error::InvertedTet`] for an element that
    /// a midpoint moved too far folds; [`Error::InvalidGeneratorParameter`] if the mid-edge nodes
    /// would take the node count past what 32-bit indices address.
    pub fn from_linear_curved(
        mesh: &TetMesh,
        curve: impl Fn(DVec3, DVec3) -> Option<DVec3>,
    ) -> Result<Self, Error> {
        let mut boundary_edges = std::collections::HashSet::new();
        for triangle in mesh.surface_triangles() {
            for k in 0..3 {
                let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
                boundary_edges.insert([a.min(b), a.max(b)]);
            }
        }
        let mut positions = mesh.positions().to_vec();
        let mut midpoints: HashMap<[u32; 2], u32> = HashMap::new();
        let mut elements = Vec::with_capacity(mesh.tet_count());
        for tet in mesh.tets() {
            let mut nodes = [0u32; NODES];
            nodes[..4].copy_from_slice(tet);
            for (k, [i, j]) in EDGES.iter().enumerate() {
                let edge = [tet[*i].min(tet[*j]), tet[*i].max(tet[*j])];
                if let Some(&node) = midpoints.get(&edge) {
                    nodes[4 + k] = node;
                    continue;
                }
                let node = u32::try_from(positions.len()).map_err(|_| {
                    Error::InvalidGeneratorParameter {
                        parameter: "mesh",
                        value: positions.len() as f64,
                        reason: "the quadratic mesh would have more nodes than 32-bit indices \
                                 address",
                    }
                })?;
                let [a, b] = edge.map(|n| positions[n as usize]);
                let curved = boundary_edges
                    .contains(&edge)
                    .then(|| curve(a, b))
                    .flatten();
                positions.push(curved.unwrap_or(0.5 * (a + b)));
                midpoints.insert(edge, node);
                nodes[4 + k] = node;
            }
            elements.push(nodes);
        }
        Self::new(positions, elements)
    }

    /// [`mesh::sphere`](super::sphere) with quadratic elements whose boundary edges follow the
    /// sphere.
    ///
    /// # Errors
    /// Those of [`mesh::sphere`](super::sphere) and [`QuadraticTetMesh::new`].
    pub fn sphere(radius: f64, cells_across: usize) -> Result<Self, Error> {
        Self::from_linear_curved(&super::sphere(radius, cells_across)?, |a, b| {
            Some((a + b).normalize() * radius)
        })
    }

    /// [`mesh::cylinder`](super::cylinder) with quadratic elements whose edges on the round side
    /// follow the circle (the flat caps stay flat).
    ///
    /// # Errors
    /// Those of [`mesh::cylinder`](super::cylinder) and [`QuadraticTetMesh::new`].
    pub fn cylinder(
        radius: f64,
        half_height: f64,
        cells_across: usize,
        cells_along: usize,
    ) -> Result<Self, Error> {
        let linear = super::cylinder(radius, half_height, cells_across, cells_along)?;
        let radial = |p: DVec3| DVec3::new(p.x, 0.0, p.z);
        let on_side = |p: DVec3| (radial(p).length() - radius).abs() <= 1e-9 * radius;
        Self::from_linear_curved(&linear, |a, b| {
            (on_side(a) && on_side(b)).then(|| {
                let mid = 0.5 * (a + b);
                radial(mid).normalize() * radius + DVec3::Y * mid.y
            })
        })
    }

    /// Rest positions of all nodes, corners and mid-edge (m).
    pub fn positions(&self) -> &[DVec3] {
        self.subdivided.positions()
    }

    /// The elements: 4 corners then 6 mid-edge nodes each.
    pub fn elements(&self) -> &[[u32; NODES]] {
        &self.elements
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.subdivided.node_count()
    }

    /// Number of quadratic elements.
    pub fn element_count(&self) -> usize {
        self.elements.len()
    }

    /// The 8 linear tetrahedra per element on the same nodes (element `e` owns tetrahedra
    /// `8e .. 8e + 8`): the boundary, contact and output mesh.
    pub fn subdivided(&self) -> &TetMesh {
        &self.subdivided
    }

    /// Indices of the nodes whose rest position satisfies `predicate`, ascending, as
    /// [`TetMesh::nodes_where`].
    pub fn nodes_where(&self, predicate: impl Fn(DVec3) -> bool) -> Vec<u32> {
        self.subdivided.nodes_where(predicate)
    }

    /// The index of the node whose rest position is nearest to `point` (m).
    pub fn nearest_node(&self, point: DVec3) -> u32 {
        self.subdivided.nearest_node(point)
    }
}

/// Linear sub-tetrahedra per quadratic element.
pub(crate) const SUB_TETS: usize = 8;

/// The 8 sub-tetrahedra of element `nodes` (local indices), positively oriented for a
/// positively oriented straight element: the four corner tetrahedra, and the inner octahedron
/// cut along its shortest diagonal at the rest positions.
fn subdivision(positions: &[DVec3], nodes: &[u32; NODES]) -> [[u32; 4]; SUB_TETS] {
    // Mid-edge node of the edge between corners i and j.
    let mid = |i: usize, j: usize| {
        let k = EDGES
            .iter()
            .position(|e| *e == [i.min(j), i.max(j)])
            .expect("every corner pair is an edge");
        4 + k
    };
    let corner_tets = [
        [0, mid(0, 1), mid(0, 2), mid(0, 3)],
        [mid(0, 1), 1, mid(1, 2), mid(1, 3)],
        [mid(0, 2), mid(1, 2), 2, mid(2, 3)],
        [mid(0, 3), mid(1, 3), mid(2, 3), 3],
    ];
    // The octahedron's opposite pairs are the midpoints of opposite edges.
    let diagonals = [
        (mid(0, 1), mid(2, 3)),
        (mid(0, 2), mid(1, 3)),
        (mid(0, 3), mid(1, 2)),
    ];
    let length = |(a, b): (usize, usize)| {
        positions[nodes[a] as usize].distance_squared(positions[nodes[b] as usize])
    };
    let (a, b) = diagonals
        .into_iter()
        .min_by(|p, q| length(*p).total_cmp(&length(*q)))
        .expect("three diagonals");
    // The other four octahedron vertices, in a cycle around the diagonal.
    let ring: Vec<usize> = diagonals
        .into_iter()
        .filter(|d| *d != (a, b))
        .flat_map(|(c, d)| [c, d])
        .collect();
    let cycle = [ring[0], ring[2], ring[1], ring[3]];
    let mut tets = local_tets(&corner_tets, a, b, &cycle).map(|local| local.map(|i| nodes[i]));
    // Orient by the reference element, so that an element given clockwise stays inverted.
    let reference = reference_nodes();
    for (tet, local) in tets.iter_mut().zip(local_tets(&corner_tets, a, b, &cycle)) {
        if super::signed_volume(&reference, &local.map(|i| i as u32)) < 0.0 {
            tet.swap(2, 3);
        }
    }
    tets
}

/// The local indices of the sub-tetrahedra, in the order [`subdivision`] lists them.
fn local_tets(
    corner_tets: &[[usize; 4]; 4],
    a: usize,
    b: usize,
    cycle: &[usize; 4],
) -> [[usize; 4]; SUB_TETS] {
    std::array::from_fn(|t| match t {
        0..4 => corner_tets[t],
        _ => [a, b, cycle[t - 4], cycle[(t - 3) % 4]],
    })
}

/// [`Error::FoldedElement`] for the first of `elements` (nodes at `positions`) whose corners
/// are ordered counter-clockwise but whose rest map folds (clockwise or flat corners are the
/// subdivision's [`Error::InvertedTet`] or [`Error::DegenerateTet`]).
fn check_not_folded(positions: &[DVec3], elements: &[[u32; NODES]]) -> Result<(), Error> {
    for (element, nodes) in elements.iter().enumerate() {
        let corners = [nodes[0], nodes[1], nodes[2], nodes[3]];
        // NaN volumes (non-finite nodes) are `TetMesh::new`'s to refuse.
        if super::signed_volume(positions, &corners).partial_cmp(&0.0)
            != Some(std::cmp::Ordering::Greater)
        {
            continue;
        }
        let determinant =
            tet10::smallest_jacobian_determinant(&nodes.map(|n| positions[n as usize]));
        if !tet10::unfolded(determinant) {
            return Err(Error::FoldedElement {
                element,
                determinant,
            });
        }
    }
    Ok(())
}

/// Checks that elements sharing an edge share its mid-edge node.
fn check_conforming(elements: &[[u32; NODES]]) -> Result<(), Error> {
    let mut midpoints: HashMap<[u32; 2], u32> = HashMap::new();
    for (tet, nodes) in elements.iter().enumerate() {
        for (k, [i, j]) in EDGES.iter().enumerate() {
            let (a, b) = (nodes[*i], nodes[*j]);
            let node = nodes[4 + k];
            let first = *midpoints.entry([a.min(b), a.max(b)]).or_insert(node);
            if first != node {
                return Err(Error::NonConformingEdge {
                    tet,
                    corners: [a, b],
                    node,
                    other: first,
                });
            }
        }
    }
    Ok(())
}
