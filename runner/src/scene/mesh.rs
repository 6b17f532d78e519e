//! `mesh`: a soft body's tetrahedral mesh, from a generator or a file. Exactly one of
//! `cuboid`, `cylinder`, `sphere` or `file` is given.
//!
//! ```toml
//! mesh = { cuboid = { half_extents = [0.05, 0.05, 0.05], cells = [6, 6, 6] } }
//! mesh = { cylinder = { radius = 0.05, half_height = 0.1, cells_across = 6, cells_along = 8 } }
//! mesh = { sphere = { radius = 0.05, cells_across = 6 } }
//! mesh = { file = "../meshes/sphere.obj", scale = 0.05, cells_across = 8 }
//! mesh = { file = "../meshes/two_blocks.msh", region = "left" }
//! ```
//! Lengths in m; a file's `scale` is metres per file unit (default 1), and its path is relative
//! to the scene file. Surfaces (`.obj`, `.stl`) are filled with tetrahedra, `cells_across`
//! lattice cells over their largest extent (default 16). A file's `region` (a Gmsh physical
//! volume's name or tag) keeps only that volume's tetrahedra, so one file's volumes can be
//! bodies of their own; the file's other regions still select nodes of it.

use super::check::Checker;
use super::error::{SceneError, SceneSource};
use super::soft_body::RegionName;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::mesh::import::{MeshRegion, RawMesh};
use rapier_fvm::mesh::{self, QuadraticHexMesh, QuadraticTetMesh, TetMesh, import};
use serde::Deserialize;

/// What a cage of quadratic hexahedra is built over.
pub(crate) const CAGE_MESHES: &str =
    "\"quadratic_hex\" cages are built over a cuboid mesh or a file of hexahedra";

/// Where a soft body's mesh comes from.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// A box centred at the origin.
    pub cuboid: Option<CuboidSpec>,
    /// A cylinder along y centred at the origin.
    pub cylinder: Option<CylinderSpec>,
    /// A ball centred at the origin.
    pub sphere: Option<SphereSpec>,
    /// A mesh file (`.msh`, `.node`/`.ele`, `.vtu`, `.vtk`, `.obj`, `.stl`), relative to the
    /// scene file.
    pub file: Option<String>,
    /// Metres per file unit (only with `file`); default 1.
    pub scale: Option<f64>,
    /// Lattice cells across a surface file's largest extent when it is filled with tetrahedra
    /// (only with an `.obj` or `.stl` file), 2 to 128; default 16.
    pub cells_across: Option<usize>,
    /// The file's volume to keep (only with `file`); default all the file's tetrahedra.
    pub region: Option<RegionName>,
}

/// A mesh built from its description, with the named parts of its file.
pub struct BuiltMesh<M> {
    /// The mesh.
    pub mesh: M,
    /// The file's regions, their nodes numbered as the mesh's; empty for a generator's mesh.
    pub regions: Vec<MeshRegion>,
    /// The file the regions come from (for errors), empty for a generator's mesh.
    pub path: String,
}

/// `cuboid = { half_extents, cells }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CuboidSpec {
    /// Half extents (m).
    pub half_extents: [f64; 3],
    /// Cubes along each axis (each split into five tetrahedra).
    pub cells: [usize; 3],
}

/// `cylinder = { radius, half_height, cells_across, cells_along }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    /// Radius (m).
    pub radius: f64,
    /// Half height (m), along y.
    pub half_height: f64,
    /// Cells over the diameter (at least 2).
    pub cells_across: usize,
    /// Cells over the height (at least 1).
    pub cells_along: usize,
}

/// `sphere = { radius, cells_across }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// Radius (m).
    pub radius: f64,
    /// Cells over the diameter (at least 2).
    pub cells_across: usize,
}

impl MeshSpec {
    /// Checks that exactly one source is given and that the sizes are physical; `key` is the
    /// mesh's key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        let given = [
            self.cuboid.is_some(),
            self.cylinder.is_some(),
            self.sphere.is_some(),
            self.file.is_some(),
        ];
        if given.iter().filter(|&&g| g).count() != 1 {
            c.fail(
                key,
                "give exactly one of `cuboid`, `cylinder`, `sphere` or `file`",
            );
            return;
        }
        if self.file.is_none() {
            for (name, set) in [
                ("scale", self.scale.is_some()),
                ("cells_across", self.cells_across.is_some()),
                ("region", self.region.is_some()),
            ] {
                if set {
                    c.fail(&format!("{key}.{name}"), "only applies to a mesh `file`");
                }
            }
        }
        if let Some(scale) = self.scale {
            c.positive(&format!("{key}.scale"), scale, "m per file unit");
        }
        if let Some(cuboid) = &self.cuboid {
            for (i, h) in cuboid.half_extents.iter().enumerate() {
                c.positive(&format!("{key}.cuboid.half_extents[{i}]"), *h, "m");
            }
            if cuboid.cells.contains(&0) {
                c.fail(
                    &format!("{key}.cuboid.cells"),
                    "every count must be at least 1",
                );
            }
        }
        if let Some(cylinder) = &self.cylinder {
            c.positive(&format!("{key}.cylinder.radius"), cylinder.radius, "m");
            c.positive(
                &format!("{key}.cylinder.half_height"),
                cylinder.half_height,
                "m",
            );
        }
        if let Some(sphere) = &self.sphere {
            c.positive(&format!("{key}.sphere.radius"), sphere.radius, "m");
        }
    }

    /// Builds the mesh as quadratic tetrahedra: spheres and cylinders with boundary edges curved
    /// to the true surface, a Gmsh file of second-order tetrahedra with its own mid-edge nodes,
    /// any other mesh with nodes at its edges' midpoints (and a first-order file's regions
    /// [widened](MeshRegion::with_mid_edge_nodes) to them).
    ///
    /// # Errors
    /// A [`SceneError`] at `key` naming the generator's or the file's problem.
    pub fn build_quadratic(
        &self,
        key: &str,
        source: &SceneSource,
    ) -> Result<BuiltMesh<QuadraticTetMesh>, SceneError> {
        let library = |at: String| move |e: rapier_fvm::Error| source.error(&at, e.to_string());
        if let Some(raw) = self.read_file(key, source)? {
            let (path, second_order) = (raw.path.clone(), !raw.mid_edge_nodes.is_empty());
            let regions = raw.regions_in_mesh();
            let mesh = raw
                .into_quadratic_mesh()
                .map_err(library(format!("{key}.file")))?;
            let regions = if second_order {
                regions
            } else {
                regions
                    .iter()
                    .map(|r| r.with_mid_edge_nodes(&mesh))
                    .collect()
            };
            return Ok(BuiltMesh {
                mesh,
                regions,
                path,
            });
        }
        let mesh = if let Some(c) = &self.cylinder {
            QuadraticTetMesh::cylinder(c.radius, c.half_height, c.cells_across, c.cells_along)
                .map_err(library(format!("{key}.cylinder")))?
        } else if let Some(s) = &self.sphere {
            QuadraticTetMesh::sphere(s.radius, s.cells_across)
                .map_err(library(format!("{key}.sphere")))?
        } else {
            QuadraticTetMesh::from_linear(&self.build(key, source)?.mesh)
                .map_err(library(key.to_owned()))?
        };
        Ok(BuiltMesh::generated(mesh))
    }

    /// Builds a cage of quadratic hexahedra over a cuboid mesh's cells, or of a file's
    /// hexahedra (with its regions; a linear file's [widened](MeshRegion::with_cage_nodes) to
    /// the nodes its cage adds; a volume group's `tets` become the cage's hexahedra).
    ///
    /// # Errors
    /// A [`SceneError`] at `key` for another mesh, the generator's problem or a file without
    /// hexahedra.
    pub fn build_cage(
        &self,
        key: &str,
        source: &SceneSource,
    ) -> Result<BuiltMesh<QuadraticHexMesh>, SceneError> {
        if let Some(raw) = self.read_file(key, source)? {
            let (path, regions) = (raw.path.clone(), raw.regions_in_mesh());
            let linear = matches!(raw.hexahedra, import::Hexahedra::Linear(_));
            let per_hexahedron = raw.hexahedra.tets_per_element();
            let mesh = raw
                .into_cage()
                .map_err(|e| source.error(&format!("{key}.file"), e.to_string()))?;
            let regions = regions.into_iter().map(|region| {
                let mut region = if linear {
                    region.with_cage_nodes(&mesh)
                } else {
                    region
                };
                region.tets = region.cage_elements(per_hexahedron);
                region
            });
            let regions = regions.collect();
            return Ok(BuiltMesh {
                mesh,
                regions,
                path,
            });
        }
        let Some(c) = &self.cuboid else {
            return Err(source.error(key, CAGE_MESHES));
        };
        QuadraticHexMesh::cuboid(DVec3::from_array(c.half_extents), c.cells)
            .map(BuiltMesh::generated)
            .map_err(|e| source.error(&format!("{key}.cuboid"), e.to_string()))
    }

    /// Whether the mesh is a surface file (`.obj`, `.stl`), filled with tetrahedra when built.
    pub(crate) fn is_surface_file(&self) -> bool {
        self.file.as_deref().is_some_and(|file| {
            matches!(
                import::Format::from_path(std::path::Path::new(file)),
                Some(import::Format::Obj | import::Format::Stl)
            )
        })
    }

    /// How a surface file is filled.
    pub(crate) fn surface_options(&self) -> import::SurfaceOptions {
        import::SurfaceOptions {
            cells_across: self
                .cells_across
                .unwrap_or(import::SurfaceOptions::default().cells_across),
        }
    }

    /// The file's raw mesh (its `region` kept), `None` for a generator's mesh.
    fn read_file(&self, key: &str, source: &SceneSource) -> Result<Option<RawMesh>, SceneError> {
        let Some(file) = &self.file else {
            return Ok(None);
        };
        let raw = import::load_raw(
            source.folder().join(file),
            self.scale.unwrap_or(1.0),
            &self.surface_options(),
        )
        .map_err(|e| source.error(&format!("{key}.file"), e.to_string()))?;
        match &self.region {
            Some(region) => raw
                .keep_volume(&region.id())
                .map(Some)
                .map_err(|e| source.error(&format!("{key}.region"), e.to_string())),
            None => Ok(Some(raw)),
        }
    }

    /// Builds the mesh (rest positions in m); files are resolved from the scene's folder.
    ///
    /// # Errors
    /// A [`SceneError`] at `key` naming the generator's or the file's problem.
    pub fn build(&self, key: &str, source: &SceneSource) -> Result<BuiltMesh<TetMesh>, SceneError> {
        let library = |at: String| move |e: rapier_fvm::Error| source.error(&at, e.to_string());
        if let Some(raw) = self.read_file(key, source)? {
            let (path, regions) = (raw.path.clone(), raw.regions_in_mesh());
            let mesh = raw.into_mesh().map_err(library(format!("{key}.file")))?;
            return Ok(BuiltMesh {
                mesh,
                regions,
                path,
            });
        }
        let mesh = if let Some(c) = &self.cuboid {
            mesh::cuboid(DVec3::from_array(c.half_extents), c.cells)
                .map_err(library(format!("{key}.cuboid")))?
        } else if let Some(c) = &self.cylinder {
            mesh::cylinder(c.radius, c.half_height, c.cells_across, c.cells_along)
                .map_err(library(format!("{key}.cylinder")))?
        } else if let Some(s) = &self.sphere {
            mesh::sphere(s.radius, s.cells_across).map_err(library(format!("{key}.sphere")))?
        } else {
            return Err(source.error(key, "no mesh source"));
        };
        Ok(BuiltMesh::generated(mesh))
    }
}

impl<M> BuiltMesh<M> {
    /// A generator's mesh, without regions.
    fn generated(mesh: M) -> Self {
        Self {
            mesh,
            regions: Vec::new(),
            path: String::new(),
        }
    }
}
