//! Scene overrides: values set at key paths (`soft_body[0].material.young`) in a scene's TOML
//! before the scene is read, so that each is checked as the scene's own values are.
//!
//! The text is edited in place by the runner's [`rapier_fvm_runner::scene::edit`] (key paths
//! `keys.joined[0].by.dots`; the rest of the file kept as written, so the lines an error names are
//! the file's own). A value is a bool, an integer, a float (numpy scalars included), a string, or
//! a list or tuple of them.

use crate::errors::{argument, scene as scene_error};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple};
use rapier_fvm_runner::scene::edit;
use std::path::Path;
use toml_edit::{Array, Value};

/// The text of the scene file `path` with `overrides` applied.
///
/// # Errors
/// A `SceneError` if the file cannot be read or parsed; a `ValueError` naming the key path for
/// a malformed path, a missing element or a value of another kind.
pub fn scene_text(path: &Path, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| scene_error(format!("{}: cannot read the scene: {e}", path.display())))?;
    let Some(overrides) = overrides.filter(|o| !o.is_empty()) else {
        return Ok(text);
    };
    let mut edits = Vec::with_capacity(overrides.len());
    for (key, value) in overrides.iter() {
        let key: String = key.extract()?;
        let value = toml_value(&key, &value)?;
        edits.push((key, value));
    }
    edit::edited(&text, &edits).map_err(|e| match e.path.as_str() {
        "" => scene_error(format!("{}: {}", path.display(), e.message)),
        key => argument(key, e.message),
    })
}

/// A Python value as a TOML value, for the key path `key`.
fn toml_value(key: &str, value: &Bound<'_, PyAny>) -> PyResult<Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(Value::from(value.extract::<bool>()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(Value::from(value.extract::<String>()?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let mut array = Array::new();
        for item in value.try_iter()? {
            array.push_formatted(toml_value(key, &item?)?);
        }
        return Ok(Value::Array(array));
    }
    if value.hasattr("__index__")? {
        return Ok(Value::from(value.extract::<i64>()?));
    }
    match value.extract::<f64>() {
        Ok(number) => Ok(Value::from(number)),
        Err(_) => Err(argument(
            key,
            format!("an override must be a bool, number, string or list, got {value}"),
        )),
    }
}
