//! What a body is made of, on the Python side: `Material` (model and constants in SI units),
//! `Mesh` (a checked tetrahedral mesh, generated, read from a file or given as arrays) and a
//! rigid body's `Shape`.

use crate::arrays::{indices_in, rows_out, scalar_f32, vectors_in, vectors_out};
use crate::errors::{argument, library};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::material::{Material as LibraryMaterial, MaterialModel};
use rapier_fvm::mesh::{self, TetMesh, import};
use rapier3d::prelude::SharedShape;

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

/// A rigid body's collision shape (m), as rapier's `SharedShape`: `Shape.cuboid((hx, hy, hz))`
/// by half extents, `Shape.ball(radius)`, `Shape.capsule(half_height, radius)` and
/// `Shape.cylinder(half_height, radius)` along y. Lengths must be positive and finite in
/// float32, as rapier holds them.
#[pyclass(module = "rapier_fvm", frozen)]
pub struct Shape {
    /// rapier's shape.
    pub inner: SharedShape,
    /// How it was made, for `repr` and pickling: the constructor's name and lengths (m).
    made: (&'static str, Vec<f64>),
}

/// A length given from Python (argument `name`), positive and finite in `f32`.
fn length(name: &str, value: f64) -> PyResult<f32> {
    let single = scalar_f32(name, value)?;
    if single > 0.0 {
        Ok(single)
    } else {
        Err(argument(name, format!("must be positive (m), got {value}")))
    }
}

#[pymethods]
impl Shape {
    /// A box of half extents `half_extents` (m).
    #[staticmethod]
    fn cuboid(half_extents: [f64; 3]) -> PyResult<Self> {
        let [x, y, z] = half_extents.map(|h| length("half_extents", h));
        Ok(Self {
            inner: SharedShape::cuboid(x?, y?, z?),
            made: ("cuboid", half_extents.to_vec()),
        })
    }

    /// A ball of radius `radius` (m).
    #[staticmethod]
    fn ball(radius: f64) -> PyResult<Self> {
        Ok(Self {
            inner: SharedShape::ball(length("radius", radius)?),
            made: ("ball", vec![radius]),
        })
    }

    /// A capsule along y: a cylinder of half height `half_height` (m) capped by half balls of
    /// radius `radius` (m).
    #[staticmethod]
    fn capsule(half_height: f64, radius: f64) -> PyResult<Self> {
        let shape = SharedShape::capsule_y(
            length("half_height", half_height)?,
            length("radius", radius)?,
        );
        Ok(Self {
            inner: shape,
            made: ("capsule", vec![half_height, radius]),
        })
    }

    /// A cylinder along y of half height `half_height` and radius `radius` (m).
    #[staticmethod]
    fn cylinder(half_height: f64, radius: f64) -> PyResult<Self> {
        let shape = SharedShape::cylinder(
            length("half_height", half_height)?,
            length("radius", radius)?,
        );
        Ok(Self {
            inner: shape,
            made: ("cylinder", vec![half_height, radius]),
        })
    }

    /// Pickling: the constructor and its lengths.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (name, lengths) = &self.made;
        let made = py.get_type::<Shape>().getattr(*name)?;
        let args = if *name == "cuboid" {
            PyTuple::new(py, [lengths.clone()])?
        } else {
            PyTuple::new(py, lengths)?
        };
        Ok((made, args))
    }

    fn __repr__(&self) -> String {
        let (name, lengths) = &self.made;
        format!("Shape.{name}{lengths:?}")
    }
}
