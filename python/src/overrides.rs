//! Scene overrides: values set at key paths (`soft_body[0].material.young`) in a scene's TOML
//! before the scene is read, so that each is checked as the scene's own values are.
//!
//! The text is edited in place (`toml_edit` keeps the rest of the file as written), so the lines
//! an error names are the file's own. A path is keys joined by `.`, each followed by any number
//! of `[index]`; an index must name an existing element (of an array or of `[[…]]` tables), and
//! a key missing on the way is created (`contact.margin` in a scene without `[contact]`). A
//! value is a bool, an integer, a float (numpy scalars included), a string, or a list or tuple
//! of them.

use crate::errors::{argument, scene as scene_error};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple};
use std::path::Path;
use toml_edit::{Array, DocumentMut, Item, Table, Value};

/// One step of a key path.
#[derive(Debug)]
enum Step {
    /// A table's key.
    Key(String),
    /// An element of an array or of an array of tables.
    Index(usize),
}

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
    let mut document: DocumentMut = text
        .parse()
        .map_err(|e| scene_error(format!("{}: {e}", path.display())))?;
    for (key, value) in overrides.iter() {
        let key: String = key.extract()?;
        let value = toml_value(&key, &value)?;
        set_at(document.as_table_mut(), &key, value)?;
    }
    Ok(document.to_string())
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

/// The steps of the key path `path`.
fn steps(path: &str) -> PyResult<Vec<Step>> {
    let malformed = || {
        argument(
            path,
            "a key path is keys joined by '.', each with any [index]",
        )
    };
    let mut steps = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = part.split_once('[').map_or((part, ""), |(n, r)| (n, r));
        if name.is_empty() {
            return Err(malformed());
        }
        steps.push(Step::Key(name.to_owned()));
        while !rest.is_empty() {
            let (index, after) = rest.split_once(']').ok_or_else(malformed)?;
            steps.push(Step::Index(index.parse().map_err(|_| malformed())?));
            rest = match after {
                "" => "",
                _ => after.strip_prefix('[').ok_or_else(malformed)?,
            };
        }
        if part.ends_with('[') {
            return Err(malformed());
        }
    }
    Ok(steps)
}

/// Where a key path has led so far.
enum Cursor<'a> {
    Table(&'a mut Table),
    Item(&'a mut Item),
    Value(&'a mut Value),
}

/// Sets `value` at the key path `path` under `root`.
fn set_at(root: &mut Table, path: &str, value: Value) -> PyResult<()> {
    let steps = steps(path)?;
    let missing = |what: String| argument(path, format!("the scene has no {what}"));
    let mut cursor = Cursor::Table(root);
    for (i, step) in steps.iter().enumerate() {
        let last = i + 1 == steps.len();
        cursor = match (cursor, step) {
            (Cursor::Table(t), Step::Key(k)) => into_key(t, k, last.then(|| value.clone()))?,
            (Cursor::Item(Item::Table(t)), Step::Key(k)) => {
                into_key(t, k, last.then(|| value.clone()))?
            }
            (Cursor::Item(Item::Value(Value::InlineTable(t))), Step::Key(k))
            | (Cursor::Value(Value::InlineTable(t)), Step::Key(k)) => {
                if last {
                    t.insert(k, value.clone());
                    return Ok(());
                }
                let v = (t.get_mut(k)).ok_or_else(|| missing(format!("key {k:?}")))?;
                Cursor::Value(v)
            }
            (Cursor::Item(Item::ArrayOfTables(a)), Step::Index(n)) if !last => Cursor::Table(
                a.get_mut(*n)
                    .ok_or_else(|| missing(format!("element [{n}]")))?,
            ),
            (Cursor::Item(Item::Value(Value::Array(a))), Step::Index(n))
            | (Cursor::Value(Value::Array(a)), Step::Index(n)) => {
                let element = a
                    .get_mut(*n)
                    .ok_or_else(|| missing(format!("element [{n}]")))?;
                if last {
                    *element = value.clone();
                    return Ok(());
                }
                Cursor::Value(element)
            }
            (_, step) => return Err(missing(format!("{step:?} there"))),
        };
        if last {
            return Ok(());
        }
    }
    Ok(())
}

/// The key `key` of `table`: set to `value` if given (the path's end), else entered, made a
/// table if missing.
fn into_key<'a>(table: &'a mut Table, key: &str, value: Option<Value>) -> PyResult<Cursor<'a>> {
    if let Some(value) = value {
        table.insert(key, Item::Value(value));
    } else if !table.contains_key(key) {
        table.insert(key, Item::Table(Table::new()));
    }
    let item = table
        .get_mut(key)
        .ok_or_else(|| argument(key, "could not be set"))?;
    Ok(Cursor::Item(item))
}
