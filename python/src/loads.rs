//! Loads on soft bodies from Python, as a controller sets them every frame: pressure
//! (follower, Pa) and traction (dead, Pa) on boundary triangles, a body force (N/m³), a cable
//! through nodes (N). `add_*` returns the load's index on its body; `set_load` changes its
//! magnitude (see the library's `load` module for each load's law).

use crate::arrays::{indices_in, vector3};
use crate::errors::library;
use crate::handles::SoftBody;
use crate::world::World;
use pyo3::prelude::*;
use rapier_fvm::load::{Load, LoadHandle, LoadValue};

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
        triangles: &Bound<'_, PyAny>,
        pressure: f64,
    ) -> PyResult<u32> {
        let triangles = indices_in::<3>("triangles", triangles)?;
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
        triangles: &Bound<'_, PyAny>,
        traction: [f64; 3],
    ) -> PyResult<u32> {
        let triangles = indices_in::<3>("triangles", triangles)?;
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
