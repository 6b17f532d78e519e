//! A soft body's meshes built from its description: the elements' mesh (linear tetrahedra, or
//! the quadratic tetrahedra or the cage of hexahedra with their subdivision) and the embedded
//! mesh, each counted against the scene's memory budget as soon as it is built, before a body
//! is made of it, so that a mesh file too big for the machine is refused with the estimate.

use crate::scene::budget::{MemoryUse, MeshCount};
use crate::scene::soft_body::{ElementsSpec, SoftBodySpec};
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::mesh::import::MeshRegion;
use rapier_fvm::mesh::{QuadraticHexMesh, QuadraticTetMesh, TetMesh};

/// The meshes of a soft body.
pub(super) struct BodyMeshes {
    /// The linear tetrahedra: the elements, or the subdivision of the quadratic ones.
    pub(super) mesh: TetMesh,
    /// The quadratic tetrahedra, for a body of them.
    pub(super) quadratic: Option<QuadraticTetMesh>,
    /// The cage of quadratic hexahedra, for a body of them.
    pub(super) cage: Option<QuadraticHexMesh>,
    /// The fine mesh the elements carry, if any.
    pub(super) embedded: Option<TetMesh>,
    /// The mesh file's regions, their nodes numbered as `mesh`'s; empty for a generator's mesh.
    pub(super) regions: Vec<MeshRegion>,
    /// The mesh file, for the regions' errors; empty for a generator's mesh.
    pub(super) path: String,
}

impl BodyMeshes {
    /// The meshes of `spec`, `key` in the scene of `source`, each added to `memory` once built
    /// and refused if it takes the scene past its budget.
    pub(super) fn build(
        spec: &SoftBodySpec,
        (key, source): (&str, &SceneSource),
        memory: &mut MemoryUse,
    ) -> Result<Self, SceneError> {
        let mesh_key = format!("{key}.mesh");
        let (mesh, quadratic, cage, regions, path) = match spec.elements {
            ElementsSpec::Linear => {
                let built = spec.mesh.build(&mesh_key, source)?;
                (built.mesh, None, None, built.regions, built.path)
            }
            ElementsSpec::Quadratic => {
                let built = spec.mesh.build_quadratic(&mesh_key, source)?;
                let subdivided = built.mesh.subdivided().clone();
                (
                    subdivided,
                    Some(built.mesh),
                    None,
                    built.regions,
                    built.path,
                )
            }
            ElementsSpec::QuadraticHex => {
                let built = spec.mesh.build_cage(&mesh_key, source)?;
                let subdivided = built.mesh.subdivided().clone();
                (
                    subdivided,
                    None,
                    Some(built.mesh),
                    built.regions,
                    built.path,
                )
            }
        };
        let hexahedra = cage.as_ref().map_or(0, QuadraticHexMesh::element_count);
        memory.add(MeshCount::of(&mesh, hexahedra), &mesh_key, source)?;
        let embedded_key = format!("{key}.embedded");
        let embedded = match &spec.embedded {
            Some(embedded) => Some(embedded.build(&embedded_key, source)?.mesh),
            None => None,
        };
        if let Some(fine) = &embedded {
            memory.add(MeshCount::of(fine, 0), &embedded_key, source)?;
        }
        Ok(Self {
            mesh,
            quadratic,
            cage,
            embedded,
            regions,
            path,
        })
    }
}
