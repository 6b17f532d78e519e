//! A body's boundary as contacts see it: the mesh's outward-oriented boundary triangles, the
//! nodes on them, and each boundary node's ring (the boundary nodes sharing a triangle with it,
//! itself included), which self-contact leaves out of a node's candidates.

use crate::mesh::TetMesh;

/// The boundary of a body's mesh.
#[derive(Debug, Clone)]
pub(crate) struct BodySurface {
    /// The nodes on the boundary, sorted: contacts are detected for them (unless the body has
    /// an embedded mesh).
    pub(crate) nodes: Vec<u32>,
    /// The boundary triangles, outward-oriented, which self-contact pushes against.
    pub(crate) triangles: Vec<[u32; 3]>,
    /// Per node, the boundary nodes sharing a boundary triangle with it, itself included,
    /// sorted (empty for interior nodes).
    pub(crate) rings: Vec<Vec<u32>>,
}

impl BodySurface {
    /// The boundary of `mesh`.
    pub(crate) fn of(mesh: &TetMesh) -> Self {
        let triangles = mesh.surface_triangles();
        let mut rings = vec![Vec::new(); mesh.node_count()];
        for triangle in &triangles {
            for &n in triangle {
                rings[n as usize].extend(triangle);
            }
        }
        for ring in &mut rings {
            ring.sort_unstable();
            ring.dedup();
        }
        let mut nodes: Vec<u32> = triangles.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        Self {
            nodes,
            triangles,
            rings,
        }
    }
}
