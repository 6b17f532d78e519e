//! Scene files from Python: a world read from a scene (`World.from_scene`), with values
//! overridden at key paths (`{"soft_body[0].material.young": 2e6}`), its bodies found
//! by name and its probes read; and a whole run (`run_scene`) as `rapier-fvm run` does it,
//! returning the report.
//!
//! An override edits the scene's TOML before it is read, so every value is checked as the
//! scene's own are; the lines an error names are those of the scene as overridden.

use crate::arrays::rows_out;
use crate::errors::{argument, scene as scene_error};
use crate::handles::{RigidBody, SoftBody};
use crate::world::World;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use rapier_fvm_runner::planar::{self, PlanarScene};
use rapier_fvm_runner::scene::{Scene, dimension_of};
use rapier_fvm_runner::sim::{self, RunOptions, Simulation};
use std::path::{Path, PathBuf};

/// The text of the scene file `path` with `overrides` applied.
fn scene_text(path: &Path, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| scene_error(format!("{}: cannot read the scene: {e}", path.display())))?;
    let Some(overrides) = overrides.filter(|o| !o.is_empty()) else {
        return Ok(text);
    };
    let mut table: toml::Table = text
        .parse()
        .map_err(|e| scene_error(format!("{}: {e}", path.display())))?;
    for (key, value) in overrides.iter() {
        let key: String = key.extract()?;
        let value = toml_value(&key, &value)?;
        set_at(&mut table, &key, value)?;
    }
    toml::to_string(&table).map_err(|e| scene_error(format!("{}: {e}", path.display())))
}

/// A Python value (number, bool, string or list of them) as a TOML value, for the key `key`.
fn toml_value(key: &str, value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(value.extract()?))
    } else if value.is_instance_of::<PyInt>() {
        Ok(toml::Value::Integer(value.extract()?))
    } else if value.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(value.extract()?))
    } else if value.is_instance_of::<PyString>() {
        Ok(toml::Value::String(value.extract()?))
    } else if let Ok(list) = value.cast::<PyList>() {
        let items = list.iter().map(|item| toml_value(key, &item));
        Ok(toml::Value::Array(items.collect::<PyResult<_>>()?))
    } else {
        Err(argument(
            key,
            format!("an override must be a number, bool, string or list, got {value}"),
        ))
    }
}

/// One step of a key path: a table key or an array index.
enum Step {
    Key(String),
    Index(usize),
}

/// The steps of `path` (`soft_body[0].material.young`).
fn steps(path: &str) -> PyResult<Vec<Step>> {
    let mut steps = Vec::new();
    for part in path.split('.') {
        let (name, rest) = part.split_once('[').unwrap_or((part, ""));
        if name.is_empty() {
            return Err(argument(path, "an empty key in the override's path"));
        }
        steps.push(Step::Key(name.to_owned()));
        for index in rest.split('[').filter(|s| !s.is_empty()) {
            let index = (index.strip_suffix(']').and_then(|i| i.parse().ok()))
                .ok_or_else(|| argument(path, format!("not an index: [{index}")))?;
            steps.push(Step::Index(index));
        }
    }
    Ok(steps)
}

/// Sets `value` at the key path `path` in `table`; every step but the last must exist.
fn set_at(table: &mut toml::Table, path: &str, value: toml::Value) -> PyResult<()> {
    let steps = steps(path)?;
    let missing = |what: &str| argument(path, format!("the scene has no {what}"));
    let (last, within) = steps.split_last().ok_or_else(|| missing("such key"))?;
    let mut here = toml::Value::Table(std::mem::take(table));
    let mut slot = &mut here;
    for step in within {
        slot = match step {
            Step::Key(k) => (slot.as_table_mut().and_then(|t| t.get_mut(k)))
                .ok_or_else(|| missing(&format!("key {k:?}")))?,
            Step::Index(i) => (slot.as_array_mut().and_then(|a| a.get_mut(*i)))
                .ok_or_else(|| missing(&format!("element [{i}]")))?,
        };
    }
    match last {
        Step::Key(k) => {
            let t = slot
                .as_table_mut()
                .ok_or_else(|| missing(&format!("table for {k:?}")))?;
            t.insert(k.clone(), value);
        }
        Step::Index(i) => {
            let a = slot.as_array_mut().ok_or_else(|| missing("array there"))?;
            *a.get_mut(*i)
                .ok_or_else(|| missing(&format!("element [{i}]")))? = value;
        }
    }
    if let toml::Value::Table(t) = here {
        *table = t;
    }
    Ok(())
}

#[pymethods]
impl World {
    /// The world of the 3D scene file `path` (its `[world]` dt and gravity, bodies, contact and
    /// integrator settings, keyframes and probes), with `overrides` (a dict of key paths such as
    /// `"soft_body[0].material.young"` to values) applied first. Scene errors raise
    /// `rapier_fvm.SceneError` naming the file, line and key.
    #[staticmethod]
    #[pyo3(signature = (path, overrides = None))]
    fn from_scene(path: PathBuf, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
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
/// `out` (`report.json`, the `.vtu` series, pictures, plots), for `duration` (s) if given instead of
/// the scene's, with `overrides` applied; returns the report as a dict. The GIL is released
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
    let report = py.detach(|| -> Result<String, String> {
        let json = if dimension_of(&text) == Some(2) {
            let scene = PlanarScene::parse(&path, text).map_err(|e| e.to_string())?;
            let report = planar::run_planar(&scene, &options).map_err(|e| e.to_string())?;
            serde_json::to_string(&report)
        } else {
            let scene = Scene::parse(&path, text).map_err(|e| e.to_string())?;
            let report = sim::run(&scene, &options).map_err(|e| e.to_string())?;
            serde_json::to_string(&report)
        };
        json.map_err(|e| e.to_string())
    });
    let report = report.map_err(scene_error)?;
    py.import("json")?.call_method1("loads", (report,))
}
