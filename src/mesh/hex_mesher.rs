//! Builds a tetrahedral mesh from blocks of hexahedral cells: nodes shared between blocks are
//! merged by position, and each hexahedron is split into twelve tetrahedra around a centre node,
//! each face along the diagonal through its lowest-numbered node so that neighbours agree.

use super::generators::{check_node_budget, reserve};
use crate::Error;
use crate::mesh::{TetMesh, signed_volume};
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// The faces of a hexahedron whose corner `(i, j, k)` has local index `i + 2 j + 4 k`, each as its
/// four corners in cyclic order.
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 5, 7, 6],
];

/// Accumulates nodes and tetrahedra block by block.
pub(super) struct HexMesher {
    /// Positions are merged when equal after rounding to `scale / 2^30`.
    resolution: f64,
    positions: Vec<DVec3>,
    node_at: HashMap<[i64; 3], u32>,
    tets: Vec<[u32; 4]>,
}

impl HexMesher {
    /// An empty mesher for shapes of size about `scale` (m), with room for `blocks`: each
    /// `(copies, cells)` is that many blocks of `cells` hexahedra.
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] if the blocks could have more nodes than 32-bit
    /// indices address; [`Error::AllocationFailed`] if the machine cannot hold them.
    pub(super) fn with_capacity(scale: f64, blocks: &[(usize, [usize; 3])]) -> Result<Self, Error> {
        // Every block's lattice nodes plus a centre node per cell: shared nodes counted twice.
        let (mut nodes, mut cells) = (0.0, 0.0);
        for &(copies, block) in blocks {
            let block_cells: f64 = block.iter().map(|&c| c as f64).product();
            let block_nodes: f64 = block.iter().map(|&c| c as f64 + 1.0).product();
            nodes += copies as f64 * (block_nodes + block_cells);
            cells += copies as f64 * block_cells;
        }
        check_node_budget(nodes)?;
        // Within the node budget the node count fits a usize; twelve tetrahedra per cell may not
        // in a 32-bit one, where `as` saturates and the reservation fails.
        let mut node_at = HashMap::new();
        node_at
            .try_reserve(nodes as usize)
            .map_err(|_| Error::AllocationFailed {
                what: "the mesh's node lookup",
                bytes: nodes as u64 * std::mem::size_of::<([i64; 3], u32)>() as u64,
            })?;
        Ok(Self {
            resolution: scale / f64::from(1u32 << 30),
            positions: reserve(nodes as usize, "the mesh's nodes")?,
            node_at,
            tets: reserve((12.0 * cells) as usize, "the mesh's tetrahedra")?,
        })
    }

    /// Adds a block of `cells` hexahedra whose nodes are `map(u)` for `u` on the regular lattice
    /// of `[0, 1]^3`.
    pub(super) fn add_block(&mut self, cells: [usize; 3], map: impl Fn(DVec3) -> DVec3) {
        let [nx, ny, nz] = cells;
        let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let u = DVec3::new(
                        i as f64 / nx as f64,
                        j as f64 / ny as f64,
                        k as f64 / nz as f64,
                    );
                    nodes.push(self.node(map(u)));
                }
            }
        }
        let index = |i: usize, j: usize, k: usize| nodes[i + (nx + 1) * (j + (ny + 1) * k)];
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let corners = std::array::from_fn(|c| {
                        index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))
                    });
                    self.add_hex(corners);
                }
            }
        }
    }

    /// The validated mesh, renumbered in spatial order (nodes sorted by z, then y, then x;
    /// tetrahedra by their lowest node) so that consecutive tetrahedra share nearby nodes, which
    /// keeps the force loop's memory windows small.
    pub(super) fn finish(self) -> Result<TetMesh, Error> {
        let mut order: Vec<u32> = (0..self.positions.len() as u32).collect();
        let key = |n: &u32| {
            let p = self.positions[*n as usize];
            [p.z, p.y, p.x]
        };
        order.sort_by(|a, b| {
            let (ka, kb) = (key(a), key(b));
            ka[0]
                .total_cmp(&kb[0])
                .then(ka[1].total_cmp(&kb[1]))
                .then(ka[2].total_cmp(&kb[2]))
        });
        let mut new_index = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        let positions = order
            .iter()
            .map(|&old| self.positions[old as usize])
            .collect();
        let mut tets: Vec<[u32; 4]> = self
            .tets
            .iter()
            .map(|t| t.map(|n| new_index[n as usize]))
            .collect();
        tets.sort_by_key(|t| *t.iter().min().unwrap_or(&0));
        TetMesh::new(positions, tets)
    }

    /// The node at `p`, created unless one already sits there.
    fn node(&mut self, p: DVec3) -> u32 {
        let key = (p / self.resolution).round().to_array().map(|c| c as i64);
        let next = self.positions.len() as u32;
        *self.node_at.entry(key).or_insert_with(|| {
            self.positions.push(p);
            next
        })
    }

    fn add_hex(&mut self, corners: [u32; 8]) {
        let centre = corners
            .iter()
            .map(|&n| self.positions[n as usize])
            .sum::<DVec3>()
            / 8.0;
        let centre_node = self.positions.len() as u32;
        self.positions.push(centre);
        for face in HEX_FACES {
            let quad = face.map(|c| corners[c]);
            let lowest = (0..4).min_by_key(|&i| quad[i]).unwrap_or(0);
            let [a, b, c, d] = std::array::from_fn(|i| quad[(lowest + i) % 4]);
            for triangle in [[a, b, c], [a, c, d]] {
                let mut tet = [triangle[0], triangle[1], triangle[2], centre_node];
                if signed_volume(&self.positions, &tet) < 0.0 {
                    tet.swap(0, 1);
                }
                self.tets.push(tet);
            }
        }
    }
}
