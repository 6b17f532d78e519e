//! Coarse cages of 27-node quadratic hexahedra: a box of cells, each carrying the 3 x 3 x 3
//! lattice of nodes of [`crate::shape::hex27`], with its subdivision into linear tetrahedra on
//! the same nodes for contacts, surface extraction and output.

use super::TetMesh;
use super::hex_split::{TETS_PER_LATTICE, split_lattice};
use crate::Error;
use crate::shape::hex27::{self, NODES};
use rapier3d::glamx::DVec3;

/// A box of quadratic hexahedra in its rest configuration: the coarse cage of a bending-dominated
/// body (beams, plates, fingers), where one element across the section already bends as a
/// continuum.
///
/// Element `e` of cell `(ex, ey, ez)` lists the nodes of its 3 x 3 x 3 lattice in the order of
/// [`crate::shape::hex27`]; neighbours share the nodes of their common face. The
/// [`QuadraticHexMesh::subdivided`] mesh splits every cell's 8 lattice sub-cubes into 5
/// tetrahedra on the same nodes, so the body's surface, contacts, pins and output act on the
/// simulated nodes themselves.
///
/// # Example
/// ```
/// use rapier_fvm::{glamx::DVec3, mesh};
/// let cage = mesh::QuadraticHexMesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [5, 1, 1])?;
/// assert_eq!(cage.element_count(), 5);
/// assert_eq!(cage.node_count(), 11 * 3 * 3);
/// assert!((cage.subdivided().volume() - 0.01).abs() < 1e-15);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticHexMesh {
    elements: Vec<[u32; NODES]>,
    subdivided: TetMesh,
    parents: Vec<u32>,
}

impl QuadraticHexMesh {
    /// A box of the given half extents (m) centred at the origin, `cells` elements along x, y
    /// and z.
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] for a non-positive or non-finite half extent, an axis
    /// without cells, or more nodes than a mesh can index.
    pub fn cuboid(half_extents: DVec3, cells: [usize; 3]) -> Result<Self, Error> {
        // The lattice of every element's nodes is the tetrahedral box of twice the cells.
        // Saturating: a count that overflows is refused by the node budget all the same.
        let subdivided = super::cuboid(half_extents, cells.map(|c| c.saturating_mul(2)))?;
        let [nx, ny, nz] = cells;
        let node =
            |i: usize, j: usize, k: usize| (i + (2 * nx + 1) * (j + (2 * ny + 1) * k)) as u32;
        let mut elements = Vec::with_capacity(nx * ny * nz);
        for ez in 0..nz {
            for ey in 0..ny {
                for ex in 0..nx {
                    elements.push(std::array::from_fn(|a| {
                        let [i, j, k] = hex27::lattice(a);
                        node(2 * ex + i, 2 * ey + j, 2 * ez + k)
                    }));
                }
            }
        }
        // The cell a sub-tetrahedron lies in, from its centroid.
        let cell = |coordinate: f64, half: f64, count: usize| {
            (((coordinate / half + 1.0) / 2.0 * count as f64) as usize).min(count - 1)
        };
        let positions = subdivided.positions();
        let parents = subdivided
            .tets()
            .iter()
            .map(|tet| {
                let c = tet.iter().map(|&n| positions[n as usize]).sum::<DVec3>() * 0.25;
                let (ex, ey, ez) = (
                    cell(c.x, half_extents.x, nx),
                    cell(c.y, half_extents.y, ny),
                    cell(c.z, half_extents.z, nz),
                );
                (ex + nx * (ey + ny * ez)) as u32
            })
            .collect();
        Ok(Self {
            elements,
            subdivided,
            parents,
        })
    }

    /// A mesh of 27-node hexahedra on `positions` (m), each element's nodes in the lattice
    /// order of [`crate::shape::hex27`] (as read from a file by
    /// [`RawMesh::into_cage`](crate::mesh::import::RawMesh::into_cage)). An element numbered
    /// left-handed (negative volume) is mirrored to right-handed. Its
    /// [subdivision](QuadraticHexMesh::subdivided) cuts each lattice sub-cube into six
    /// tetrahedra, every face along its diagonal through its node of least index, so
    /// neighbours conform whatever their numbering.
    ///
    /// # Errors
    /// [`Error::NodeIndexOutOfRange`] for an element naming a node past `positions` (its `tet`
    /// is the element); [`Error::EmptyMesh`] for no elements; [`Error::NonFiniteCoordinate`] or
    /// [`Error::CoordinateOutOfRange`] for a node; the errors of
    /// [`TetMesh::new`] naming the element a subdivision tetrahedron lies in (a folded,
    /// flattened or inconsistently numbered element).
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::{glamx::DVec3, mesh::QuadraticHexMesh};
    /// // One element on the 3 x 3 x 3 lattice of the cube [0, 2]^3.
    /// let positions = (0..27)
    ///     .map(|n| DVec3::new((n % 3) as f64, (n / 3 % 3) as f64, (n / 9) as f64))
    ///     .collect();
    /// let cage = QuadraticHexMesh::new(positions, vec![std::array::from_fn(|n| n as u32)])?;
    /// assert_eq!(cage.subdivided().tet_count(), 48);
    /// assert!((cage.subdivided().volume() - 8.0).abs() < 1e-12);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn new(positions: Vec<DVec3>, mut elements: Vec<[u32; NODES]>) -> Result<Self, Error> {
        if elements.is_empty() {
            return Err(Error::EmptyMesh {
                nodes: positions.len(),
                tets: 0,
            });
        }
        let mut tets = Vec::with_capacity(elements.len() * TETS_PER_LATTICE);
        let mut parents = Vec::with_capacity(tets.capacity());
        for (e, element) in elements.iter_mut().enumerate() {
            if let Some(&node) = element.iter().find(|&&n| n as usize >= positions.len()) {
                return Err(Error::NodeIndexOutOfRange {
                    tet: e,
                    node,
                    node_count: positions.len(),
                });
            }
            for &node in element.iter() {
                super::check_position(node as usize, positions[node as usize])?;
            }
            let mut split = split_lattice(element);
            let volume: f64 = split
                .iter()
                .map(|t| super::signed_volume(&positions, t))
                .sum();
            if volume < 0.0 {
                *element = hex27::mirrored(element);
                split = split_lattice(element);
            }
            tets.extend_from_slice(&split);
            parents.extend(std::iter::repeat_n(e as u32, TETS_PER_LATTICE));
        }
        let subdivided = TetMesh::new(positions, tets)
            .map_err(|error| super::name_parent_element(error, |t| t / TETS_PER_LATTICE))?;
        Ok(Self {
            elements,
            subdivided,
            parents,
        })
    }

    /// The same cage with every node moved to `map(p)` (m), e.g. sheared, bent or curved to fit
    /// a shape; elements stay conforming, and their lattice is no longer a box's.
    ///
    /// # Errors
    /// [`Error::NonFiniteCoordinate`] for a non-finite image; [`Error::InvertedTet`] or
    /// [`Error::DegenerateTet`] naming the element a folded or flattened subdivision tetrahedron
    /// lies in (a body built from it also refuses an element whose map folds between nodes).
    pub fn map_positions(&self, map: impl Fn(DVec3) -> DVec3) -> Result<Self, Error> {
        let positions = self.positions().iter().map(|p| map(*p)).collect();
        let parent = |tet: usize| self.parents[tet] as usize;
        let subdivided = TetMesh::new(positions, self.subdivided.tets().to_vec())
            .map_err(|error| super::name_parent_element(error, parent))?;
        Ok(Self {
            elements: self.elements.clone(),
            subdivided,
            parents: self.parents.clone(),
        })
    }

    /// Rest positions of all nodes (m).
    pub fn positions(&self) -> &[DVec3] {
        self.subdivided.positions()
    }

    /// The elements: 27 nodes each, in the order of [`crate::shape::hex27`].
    pub fn elements(&self) -> &[[u32; NODES]] {
        &self.elements
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.subdivided.node_count()
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.elements.len()
    }

    /// The linear tetrahedra on the same nodes (40 per element of a [cuboid](Self::cuboid), 48
    /// of [one read](Self::new)): the boundary, contact and output mesh.
    pub fn subdivided(&self) -> &TetMesh {
        &self.subdivided
    }

    /// The element each tetrahedron of [`QuadraticHexMesh::subdivided`] lies in.
    pub fn subdivision_parents(&self) -> &[u32] {
        &self.parents
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_sit_on_their_lattice_and_parents_contain_their_tetrahedra() {
        let half = DVec3::new(0.6, 0.2, 0.1);
        let cage = QuadraticHexMesh::cuboid(half, [3, 2, 1]).unwrap();
        let p = cage.positions();
        let reference = hex27::reference_nodes();
        let cell = DVec3::new(0.4, 0.2, 0.2);
        for (e, element) in cage.elements().iter().enumerate() {
            // Node a of an element lies at its centre plus ξ_a times half a cell.
            let centre = p[element[13] as usize];
            for (a, &n) in element.iter().enumerate() {
                let expected = centre + reference[a] * cell * 0.5;
                assert!(
                    p[n as usize].distance(expected) < 1e-12,
                    "element {e}, node {a}"
                );
            }
        }
        for (t, tet) in cage.subdivided().tets().iter().enumerate() {
            let element = &cage.elements()[cage.subdivision_parents()[t] as usize];
            assert!(tet.iter().all(|n| element.contains(n)), "tetrahedron {t}");
        }
        assert_eq!(cage.subdivided().tet_count(), 40 * 6);
    }
}
