//! What a body is made of, on the Python side: `Material` (model and constants in SI units)
//! and `Mesh` (a checked tetrahedral mesh, generated, read from a file or given as arrays).

use crate::arrays::{indices_in, rows_out, vectors_in, vectors_out};
use crate::errors::{argument, library};
use numpy::PyArray2;
use pyo3::prelude::*;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::material::{Material as LibraryMaterial, MaterialModel};
use rapier_fvm::mesh::{self, TetMesh, import};

/// The material model names Python takes (those of scene files), and the models they stand for.
const MODELS: [(&str, MaterialModel); 4] = [
    ("linear", MaterialModel::Linear),
    ("st_venant_kirchhoff", MaterialModel::StVenantKirchhoff),
    ("corotated", MaterialModel::Corotated),
    ("stable_neo_hookean", MaterialModel::StableNeoHookean),
];

/// An elastic material: `Material("stable_neo_hookean", young=1e6, poisson=0.3, density=1000.0)`.
///
/// `model` is `"linear"` (small strain, small rotation), `"st_venant_kirchhoff"`,
/// `"corotated"` or `"stable_neo_hookean"` (the most robust at large strain), as in scene files;
/// `young` is Young's modulus (Pa, positive), `poisson` Poisson's ratio (in (-1, 0.5)),
/// `density` in kg/m³ (positive).
#[pyclass(module = "rapier_fvm", frozen)]
#[derive(Clone, Copy)]
pub struct Material {
    /// The library's material.
    pub inner: LibraryMaterial,
}

impl Material {
    /// The model's name as Python gives it.
    fn model_name(&self) -> &'static str {
        (MODELS.iter())
            .find(|(_, model)| *model == self.inner.model())
            .map_or("?", |(name, _)| name)
    }
}

#[pymethods]
impl Material {
    #[new]
    #[pyo3(signature = (model, young, poisson, density))]
    fn new(model: &str, young: f64, poisson: f64, density: f64) -> PyResult<Self> {
        let Some((_, model)) = MODELS.iter().find(|(name, _)| *name == model) else {
            let names: Vec<&str> = MODELS.iter().map(|(name, _)| *name).collect();
            return Err(argument(
                "model",
                format!("{model:?} is not one of {names:?}"),
            ));
        };
        let inner = LibraryMaterial::new(*model, young, poisson, density).map_err(library)?;
        Ok(Self { inner })
    }

    /// Young's modulus (Pa).
    #[getter]
    fn young(&self) -> f64 {
        self.inner.elasticity().young_modulus
    }

    /// Poisson's ratio.
    #[getter]
    fn poisson(&self) -> f64 {
        self.inner.elasticity().poisson_ratio
    }

    /// The density (kg/m³).
    #[getter]
    fn density(&self) -> f64 {
        self.inner.density()
    }

    /// The arguments that make this material again (for pickling).
    fn __getnewargs__(&self) -> (&'static str, f64, f64, f64) {
        (
            self.model_name(),
            self.young(),
            self.poisson(),
            self.density(),
        )
    }

    fn __repr__(&self) -> String {
        let name = self.model_name();
        format!(
            "Material({name:?}, young={}, poisson={}, density={})",
            self.young(),
            self.poisson(),
            self.density()
        )
    }
}

/// A tetrahedral mesh (lengths in m), checked as the library checks every mesh: a defect is a
/// `rapier_fvm.Error` naming the tetrahedron or node.
#[pyclass(module = "rapier_fvm", frozen)]
#[derive(Clone)]
pub struct Mesh {
    /// The library's mesh.
    pub inner: TetMesh,
}

#[pymethods]
impl Mesh {
    /// A mesh of the nodes `nodes` (an `(n, 3)` float array, m) and tetrahedra `tets` (an
    /// `(m, 4)` integer array of node indices, positively oriented).
    #[new]
    fn new(nodes: &Bound<'_, PyAny>, tets: &Bound<'_, PyAny>) -> PyResult<Self> {
        let nodes = vectors_in("nodes", nodes)?;
        let tets = indices_in::<4>("tets", tets)?;
        let inner = TetMesh::new(nodes, tets).map_err(library)?;
        Ok(Self { inner })
    }

    /// A box of half extents `half_extents` (m) centred at the origin, `cells` hexahedra along
    /// x, y and z, each split into tetrahedra.
    #[staticmethod]
    fn cuboid(half_extents: [f64; 3], cells: [usize; 3]) -> PyResult<Self> {
        let inner = mesh::cuboid(DVec3::from_array(half_extents), cells).map_err(library)?;
        Ok(Self { inner })
    }

    /// A ball of radius `radius` (m) centred at the origin, `cells_across` cells across.
    #[staticmethod]
    fn sphere(radius: f64, cells_across: usize) -> PyResult<Self> {
        let inner = mesh::sphere(radius, cells_across).map_err(library)?;
        Ok(Self { inner })
    }

    /// A cylinder along y of radius `radius` and half height `half_height` (m).
    #[staticmethod]
    fn cylinder(
        radius: f64,
        half_height: f64,
        cells_across: usize,
        cells_along: usize,
    ) -> PyResult<Self> {
        let inner =
            mesh::cylinder(radius, half_height, cells_across, cells_along).map_err(library)?;
        Ok(Self { inner })
    }

    /// The tetrahedral mesh in the file `path` (Gmsh `.msh`, tetgen `.node`/`.ele`, VTK `.vtk`
    /// and `.vtu`; OBJ and STL surfaces are filled with tetrahedra), lengths multiplied by
    /// `scale` (0.001 for a file in millimetres).
    #[staticmethod]
    #[pyo3(signature = (path, scale = 1.0))]
    fn load(path: std::path::PathBuf, scale: f64) -> PyResult<Self> {
        let options = import::SurfaceOptions::default();
        let inner = import::load(path, scale, &options).map_err(library)?;
        Ok(Self { inner })
    }

    /// The arguments that make this mesh again (for pickling): its nodes and tetrahedra.
    #[allow(clippy::type_complexity)]
    fn __getnewargs__<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>) {
        (self.nodes(py), self.tets(py))
    }

    /// The node positions, an `(n, 3)` array (m).
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors_out(py, self.inner.positions())
    }

    /// The tetrahedra, an `(m, 4)` uint32 array of node indices.
    #[getter]
    fn tets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        rows_out(py, self.inner.tets().iter().flatten().copied().collect(), 4)
    }

    /// The number of nodes.
    #[getter]
    fn node_count(&self) -> usize {
        self.inner.node_count()
    }

    /// The number of tetrahedra.
    #[getter]
    fn tet_count(&self) -> usize {
        self.inner.tet_count()
    }

    /// The volume (m³).
    #[getter]
    fn volume(&self) -> f64 {
        self.inner.volume()
    }

    fn __repr__(&self) -> String {
        format!(
            "Mesh({} nodes, {} tetrahedra)",
            self.inner.node_count(),
            self.inner.tet_count()
        )
    }
}
