//! Values set at key paths (`soft_body[0].material.young`) in a scene's TOML text, before the
//! scene is read, so that each is checked as the scene's own values are: the Python package's
//! overrides and the advisor's alternatives.
//!
//! The text is edited in place (`toml_edit` keeps the rest of the file as written, so the lines
//! an error names are the file's own). A path is keys joined by `.`, each followed by any number
//! of `[index]`; an index must name an existing element (of an array or of `[[…]]` tables), and
//! a key missing on the way is created (`contact.margin` in a scene without `[contact]`).

use toml_edit::{DocumentMut, Item, Table, Value};

/// A key path that cannot be set, or a text that is not TOML.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct EditError {
    /// The key path (empty for a text that does not parse).
    pub path: String,
    /// What is wrong.
    pub message: String,
}

/// `text` (a scene file's content) with each `(key path, value)` of `edits` set.
///
/// # Errors
/// An [`EditError`] for a text that is not TOML, a malformed key path, or a path through an
/// element or a key of another kind that the scene does not have.
pub fn edited(text: &str, edits: &[(String, Value)]) -> Result<String, EditError> {
    let mut document: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| EditError {
        path: String::new(),
        message: e.to_string().trim().to_owned(),
    })?;
    for (path, value) in edits {
        set_at(document.as_table_mut(), path, value.clone())?;
    }
    Ok(document.to_string())
}

/// One step of a key path.
#[derive(Debug)]
enum Step {
    /// A table's key.
    Key(String),
    /// An element of an array or of an array of tables.
    Index(usize),
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Key(key) => write!(f, "key {key:?}"),
            Self::Index(index) => write!(f, "element [{index}]"),
        }
    }
}

/// The steps of the key path `path`.
fn steps(path: &str) -> Result<Vec<Step>, EditError> {
    let malformed = || EditError {
        path: path.to_owned(),
        message: "a key path is keys joined by '.', each with any [index]".to_owned(),
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
///
/// # Errors
/// An [`EditError`] for a malformed path, or a path through an element or a key of another
/// kind that `root` does not have.
pub fn set_at(root: &mut Table, path: &str, value: Value) -> Result<(), EditError> {
    let steps = steps(path)?;
    let missing = |what: String| EditError {
        path: path.to_owned(),
        message: format!("the scene has no {what}"),
    };
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
            (_, step) => return Err(missing(format!("{step} there"))),
        };
        if last {
            return Ok(());
        }
    }
    Ok(())
}

/// The key `key` of `table`: set to `value` if given (the path's end), else entered, made a
/// table if missing.
fn into_key<'a>(
    table: &'a mut Table,
    key: &str,
    value: Option<Value>,
) -> Result<Cursor<'a>, EditError> {
    if let Some(value) = value {
        table.insert(key, Item::Value(value));
    } else if !table.contains_key(key) {
        table.insert(key, Item::Table(Table::new()));
    }
    let item = table.get_mut(key).ok_or_else(|| EditError {
        path: key.to_owned(),
        message: "could not be set".to_owned(),
    })?;
    Ok(Cursor::Item(item))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_is_set_in_place_and_the_rest_of_the_text_is_kept() {
        let text = "# a comment\n[[soft_body]]\nname = \"a\"\nmesh = { cuboid = { half_extents = [1, 1, 1], cells = [4, 4, 4] } }\n";
        let edits = [
            (
                "soft_body[0].mesh.cuboid.cells[1]".to_owned(),
                Value::from(2),
            ),
            ("integrator.kind".to_owned(), Value::from("implicit")),
        ];
        let out = edited(text, &edits).unwrap();
        assert!(out.starts_with("# a comment\n"), "{out}");
        assert!(out.contains("cells = [4, 2, 4]"), "{out}");
        assert!(out.contains("[integrator]\nkind = \"implicit\""), "{out}");
        let error = edited(text, &[("soft_body[1].name".to_owned(), Value::from("b"))]);
        assert_eq!(error.unwrap_err().message, "the scene has no element [1]");
        let error = edited(text, &[("soft_body[[0].name".to_owned(), Value::from("b"))]);
        assert!(error.unwrap_err().message.starts_with("a key path is"));
    }
}
