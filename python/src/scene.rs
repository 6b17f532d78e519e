//! Scene files from Python: a world read from a scene (`World.from_scene`), with values
//! overridden at key paths (`{"soft_body[0].material.young": 2e6}`, see `overrides`), its
//! bodies found by name and its probes read; a whole run (`run_scene`) as `rapier-fvm run`
//! does it, returning the report; and the advisor (`advise`) as `rapier-fvm advise` runs it,
//! returning the advice.

use crate::arrays::rows_out;
use crate::errors::{Error, argument, scene as scene_error};
use crate::handles::{RigidBody, SoftBody};
use crate::overrides::scene_text;
use crate::world::World;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rapier_fvm_runner::advise::{self as advisor, AdviseError, AdviseOptions};
use rapier_fvm_runner::planar::{self, PlanarScene};
use rapier_fvm_runner::scene::{Scene, dimension_of};
use rapier_fvm_runner::sim::{self, RunError, RunOptions, Simulation};
use std::path::PathBuf;

#[pymethods]
impl World {
    /// The world of the 3D scene file `path` (its `[world]` dt and gravity, bodies, contact and
    /// integrator settings, keyframes and probes), with `overrides` (a dict of key paths such as
    /// `"soft_body[0].material.young"` to values) applied first. Scene errors raise
    /// `rapier_fvm.SceneError` naming the file, line and key.
    #[staticmethod]
    #[pyo3(signature = (path, overrides = None))]
    fn from_scene(path: PathBuf, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        // Absolute, so that a pickle of the world finds the scene's mesh files from anywhere.
        let path = std::fs::canonicalize(&path).unwrap_or(path);
        let text = scene_text(&path, overrides)?;
        let scene = Scene::parse(&path, text).map_err(scene_error)?;
        let mut sim = Simulation::build(&scene).map_err(scene_error)?;
        sim.sample_probes(0.0);
        let dt = scene.world.dt;
        Ok(Self {
            sim,
            scene: Some(scene),
            frame: 0,
            dt,
        })
    }

    /// The soft body named `name` in the scene, or a `KeyError`.
    fn soft_body(&self, name: &str) -> PyResult<SoftBody> {
        (self.sim.soft.iter().find(|s| s.name == name))
            .map(|s| SoftBody::of(s.handle))
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(format!("no soft body {name:?}")))
    }

    /// The rigid body named `name` in the scene, or a `KeyError`.
    fn rigid_body(&self, name: &str) -> PyResult<RigidBody> {
        (self.sim.rigid.iter().find(|r| r.name == name))
            .map(|r| RigidBody::of(r.handle))
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(format!("no rigid body {name:?}")))
    }

    /// The scene's probes sampled so far: a dict from each probe's name to an `(n, 2)` array
    /// of `(time (s), value)` rows, one per frame from time 0 (the probe's unit as the scene
    /// gives it).
    fn probes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for probe in &self.sim.probes {
            let flat = probe
                .series
                .samples
                .iter()
                .flat_map(|&(t, v)| [t, v])
                .collect();
            let array: Bound<'_, PyArray2<f64>> = rows_out(py, flat, 2);
            out.set_item(&probe.series.name, array)?;
        }
        Ok(out)
    }
}

/// Runs the scene file `path` (3D or 2D) as `rapier-fvm run` does, writing its output into
/// `out` (`report.json`, the `.vtu` series, pictures, plots), for `duration` (s) if given instead
/// of the scene's, with `overrides` applied; returns the report as a dict. The GIL is released
/// during the run.
#[pyfunction]
#[pyo3(signature = (path, out, *, duration = None, overrides = None))]
pub fn run_scene<'py>(
    py: Python<'py>,
    path: PathBuf,
    out: PathBuf,
    duration: Option<f64>,
    overrides: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let text = scene_text(&path, overrides)?;
    let options = RunOptions {
        out,
        duration,
        progress: false,
    };
    let report = py.detach(|| -> PyResult<String> {
        let json = if dimension_of(&text) == Some(2) {
            let scene = PlanarScene::parse(&path, text).map_err(scene_error)?;
            serde_json::to_string(&planar::run_planar(&scene, &options).map_err(run_error)?)
        } else {
            let scene = Scene::parse(&path, text).map_err(scene_error)?;
            serde_json::to_string(&sim::run(&scene, &options).map_err(run_error)?)
        };
        json.map_err(|e| Error::new_err(format!("the report could not be written: {e}")))
    })?;
    py.import("json")?.call_method1("loads", (report,))
}

/// Advises on the 3D scene file `path` as `rapier-fvm advise` does: runs it, each alternative
/// (another model, linear elements, half the cells per soft body; another integrator, a looser
/// Newton tolerance, half the coupling substeps) and the set of changes chosen greedily whose
/// probe errors add up to at most `target` (relative), each for
/// `duration` (s) if given instead of the scene's, with `overrides` applied first (the scene
/// so edited is the reference); writes `recommended.toml`, `advice.json` and
/// `trials/` into `out`, and returns the advice as a dict. The GIL is released during the runs.
/// A malformed scene raises `rapier_fvm.SceneError`; a 2D scene, one without probes, or one that
/// cannot be run or runs unstable as written, `rapier_fvm.Error`.
#[pyfunction]
#[pyo3(signature = (path, out, *, target = 0.05, duration = None, overrides = None))]
pub fn advise<'py>(
    py: Python<'py>,
    path: PathBuf,
    out: PathBuf,
    target: f64,
    duration: Option<f64>,
    overrides: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let text = scene_text(&path, overrides)?;
    let options = AdviseOptions {
        target,
        window: duration,
        out,
    };
    let advice = py.detach(|| -> PyResult<String> {
        let advice =
            advisor::advise_text((&path, text), &options, |_| {}).map_err(|e| match e {
                AdviseError::Target(_) => argument("target", e),
                AdviseError::Duration(_) => argument("duration", e),
                AdviseError::Scene(e) => scene_error(e),
                other => Error::new_err(other.to_string()),
            })?;
        serde_json::to_string(&advice)
            .map_err(|e| Error::new_err(format!("the advice could not be written: {e}")))
    })?;
    py.import("json")?.call_method1("loads", (advice,))
}

/// A run's error: a scene's as `rapier_fvm.SceneError`, an output file's or a duration's as
/// `rapier_fvm.Error`.
fn run_error(error: RunError) -> PyErr {
    match error {
        RunError::Scene(e) => scene_error(e),
        other => Error::new_err(other.to_string()),
    }
}
