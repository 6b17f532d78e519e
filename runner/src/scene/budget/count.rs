//! Counting a scene's meshes from their descriptions, as the generators of `rapier_fvm::mesh`
//! would make them, in `f64`: exact for generated meshes, an upper bound for filled surfaces.

use super::MeshCount;
use crate::scene::mesh::MeshSpec;
use crate::scene::soft_body::ElementsSpec;

/// The count of a soft body's `mesh` as `elements`, before anything is built (a volume file's
/// mesh counts as empty: it is counted once read).
pub fn estimate_mesh(mesh: &MeshSpec, elements: ElementsSpec) -> MeshCount {
    match elements {
        ElementsSpec::Linear => linear_count(mesh).as_count(),
        ElementsSpec::Quadratic => linear_count(mesh).quadratic(),
        ElementsSpec::QuadraticHex => cage_count(mesh),
    }
}

/// The count of an embedded `mesh` (linear tetrahedra, priced as a body's mesh is).
pub fn estimate_embedded(mesh: &MeshSpec) -> MeshCount {
    linear_count(mesh).as_count()
}

/// The linear tetrahedra `mesh` generates, counted as the generators of `rapier_fvm::mesh`
/// make them: exactly for cuboids, cylinders and spheres; for a surface file its fill lattice of
/// `cells_across` cubes and one more on each side, as if all of it fell inside.
fn linear_count(mesh: &MeshSpec) -> LinearCount {
    let f = |n: usize| n as f64;
    if let Some(cuboid) = &mesh.cuboid {
        let [x, y, z] = cuboid.cells.map(f);
        LinearCount {
            nodes: (x + 1.0) * (y + 1.0) * (z + 1.0),
            tets: 5.0 * x * y * z,
            boundary: 4.0 * (x * y + y * z + z * x),
        }
    } else if let Some(cylinder) = &mesh.cylinder {
        // A square core of `core`² cells ringed by `layers` of 4 `core` cells, `along` high;
        // each cell split into 12 tetrahedra around a centre node.
        let core = f((cylinder.cells_across / 2).max(1));
        let layers = f((cylinder.cells_across / 4).max(1));
        let along = f(cylinder.cells_along);
        let section_cells = core * core + 4.0 * core * layers;
        let section_nodes = (core + 1.0).powi(2) + 4.0 * core * layers;
        let cells = along * section_cells;
        LinearCount {
            nodes: (along + 1.0) * section_nodes + cells,
            tets: 12.0 * cells,
            boundary: 2.0 * (2.0 * section_cells + 4.0 * core * along),
        }
    } else if let Some(sphere) = &mesh.sphere {
        // A cubic core of `core`³ cells wrapped in `layers` shells of 6 `core`² cells.
        let core = (f(sphere.cells_across) * 0.4).round().max(1.0);
        let layers = (core * 0.6).round().max(1.0);
        let cells = core.powi(3) + 6.0 * core * core * layers;
        let surface_nodes = 6.0 * core * core + 2.0;
        LinearCount {
            nodes: (core + 1.0).powi(3) + layers * surface_nodes + cells,
            tets: 12.0 * cells,
            boundary: 2.0 * 6.0 * core * core,
        }
    } else if mesh.is_surface_file() {
        let cells = f(mesh.surface_options().cells_across) + 2.0;
        LinearCount {
            nodes: (cells + 1.0).powi(3) + cells.powi(3),
            tets: 12.0 * cells.powi(3),
            boundary: 24.0 * cells * cells,
        }
    } else {
        LinearCount::default()
    }
}

/// A cage of quadratic hexahedra over a cuboid's cells: its subdivision is the cuboid of twice
/// the cells.
fn cage_count(mesh: &MeshSpec) -> MeshCount {
    let Some(cuboid) = &mesh.cuboid else {
        return MeshCount::default();
    };
    let [x, y, z] = cuboid.cells.map(|n| n as f64);
    MeshCount {
        nodes: (2.0 * x + 1.0) * (2.0 * y + 1.0) * (2.0 * z + 1.0),
        tets: 40.0 * x * y * z,
        hexahedra: x * y * z,
    }
}

/// A linear tetrahedral mesh's nodes, tetrahedra and boundary triangles, counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct LinearCount {
    pub(crate) nodes: f64,
    pub(crate) tets: f64,
    pub(crate) boundary: f64,
}

impl LinearCount {
    fn as_count(self) -> MeshCount {
        MeshCount {
            nodes: self.nodes,
            tets: self.tets,
            hexahedra: 0.0,
        }
    }

    /// The count of the mesh's quadratic tetrahedra: a node on every edge, `E = V + T + B/2 - 1`
    /// (Euler's formula for a solid without holes), eight tetrahedra in each one's subdivision.
    fn quadratic(self) -> MeshCount {
        let edges = self.nodes + self.tets + self.boundary / 2.0 - 1.0;
        MeshCount {
            nodes: self.nodes + edges,
            tets: 8.0 * self.tets,
            hexahedra: 0.0,
        }
    }
}
