//! Loads on soft bodies from Python, as a controller sets them every frame: pressure
//! (follower, Pa) and traction (dead, Pa) on boundary triangles, a body force (N/m³), a cable
//! through nodes (N). `add_*` returns the load's index on its body; `set_load` changes its
//! magnitude (see the library's `load` module for each load's law).

use crate::arrays::vector3;
use crate::errors::{argument, library};
use crate::handles::SoftBody;
use crate::world::World;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use rapier_fvm::load::{Load, LoadHandle, LoadValue};

/// Triangles given as an `(k, 3)` integer array of node indices (argument `triangles`).
fn triangles_in(triangles: &PyReadonlyArray2<'_, i64>) -> PyResult<Vec<[u32; 3]>> {
    let view = triangles.as_array();
    if view.ncols() != 3 {
        return Err(argument(
            "triangles",
            format!("expected a (k, 3) array, got {:?}", view.shape()),
        ));
    }
    (view.rows().into_iter().enumerate())
        .map(|(i, row)| {
            let mut triangle = [0u32; 3];
            for (slot, &n) in triangle.iter_mut().zip(row.iter()) {
                *slot = u32::try_from(n).map_err(|_| {
                    argument("triangles", format!("row {i}: node {n} out of range"))
                })?;
            }
            Ok(triangle)
        })
        .collect()
}

impl World {
    /// Adds `load` to `body`; its index on the body.
    fn add_load(&mut self, body: SoftBody, load: Load) -> PyResult<u32> {
        Ok(self.soft_mut(body)?.add_load(load).map_err(library)?.0)
    }
}

#[pymethods]
impl World {
    /// Adds a follower pressure `pressure` (Pa, positive pushing into the body) on the boundary
    /// triangles `triangles` of `body` (a `(k, 3)` array, node indices oriented out of the
    /// body, as `surface_triangles` gives them); returns the load's index.
    fn add_pressure(
        &mut self,
        body: SoftBody,
        triangles: PyReadonlyArray2<'_, i64>,
        pressure: f64,
    ) -> PyResult<u32> {
        let triangles = triangles_in(&triangles)?;
        self.add_load(
            body,
            Load::Pressure {
                triangles,
                pressure,
            },
        )
    }

    /// Adds a dead traction `traction` (Pa, world frame) on the rest area of the boundary
    /// triangles `triangles` of `body`; returns the load's index.
    fn add_traction(
        &mut self,
        body: SoftBody,
        triangles: PyReadonlyArray2<'_, i64>,
        traction: [f64; 3],
    ) -> PyResult<u32> {
        let triangles = triangles_in(&triangles)?;
        let traction = vector3("traction", traction)?;
        self.add_load(
            body,
            Load::Traction {
                triangles,
                traction,
            },
        )
    }

    /// Adds a force per unit volume `density` (N/m³, world frame) on every node of `body`;
    /// returns the load's index.
    fn add_body_force(&mut self, body: SoftBody, density: [f64; 3]) -> PyResult<u32> {
        let density = vector3("density", density)?;
        self.add_load(body, Load::BodyForce { density })
    }

    /// Adds a cable of tension `tension` (N) through the nodes `path` of `body`, in order,
    /// anchored in the body at both ends; returns the load's index.
    fn add_cable(&mut self, body: SoftBody, path: Vec<u32>, tension: f64) -> PyResult<u32> {
        self.add_load(body, Load::Cable { path, tension })
    }

    /// Sets the magnitude of the load `load` of `body` for the coming frames: a number
    /// (pressure in Pa, tension in N) or three (traction in Pa, body force in N/m³).
    fn set_load(&mut self, body: SoftBody, load: u32, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let value = match value.extract::<f64>() {
            Ok(scalar) => LoadValue::Scalar(scalar),
            Err(_) => LoadValue::Vector(vector3("value", value.extract()?)?),
        };
        (self.soft_mut(body)?.set_load(LoadHandle(load), value)).map_err(library)
    }
}
