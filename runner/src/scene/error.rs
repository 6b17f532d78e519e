//! [`SceneError`]: what is wrong with a scene, where: the file, the line and the key path
//! (`soft_body[1].material.young`), so that the message alone leads to the mistake.

use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// A scene that cannot be read, parsed, or built.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// The scene file.
    pub file: PathBuf,
    /// The 1-based line of the offending key or value, when known.
    pub line: Option<usize>,
    /// The key path, e.g. `soft_body[1].material.young`, when the error has one.
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

/// The text of a scene file, to turn key paths and byte spans into line numbers.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SceneSource {
    /// The file (as given, for messages; relative mesh paths are resolved from its folder).
    pub path: PathBuf,
    /// Its content.
    pub text: String,
}

impl SceneSource {
    /// The 1-based line holding byte `offset` of the text.
    pub fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// An error about the value at `key` (a path such as `soft_body[1].material.young`),
    /// located at the line of the deepest part of the path present in the file (the table that
    /// should have held a missing key).
    pub fn error(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.path.clone(),
            line: self.line_of_key(key),
            key: Some(key.to_owned()),
            message: message.into(),
        }
    }

    /// The line of `key` in the text, or of its deepest present ancestor.
    fn line_of_key(&self, key: &str) -> Option<usize> {
        let root = DeTable::parse(&self.text).ok()?;
        let mut segments = parse_key_path(key).into_iter();
        let Some(Segment::Key(first)) = segments.next() else {
            return None;
        };
        let (name, value) = root
            .get_ref()
            .iter()
            .find(|(name, _)| name.get_ref().as_ref() == first)?;
        let mut span = span_of(name, value);
        let mut value: &Spanned<DeValue<'_>> = value;
        for segment in segments {
            let next = match segment {
                Segment::Key(key) => value.get_ref().get(key.as_str()),
                Segment::Index(index) => value.get_ref().get(index),
            };
            let Some(next) = next else { break };
            span = next.span().start;
            value = next;
        }
        Some(self.line_of(span))
    }

    /// `name`, or the file's stem (`scene` if it has none).
    pub fn name_or_stem(&self, name: Option<&str>) -> String {
        name.map_or_else(
            || {
                self.path
                    .file_stem()
                    .map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned())
            },
            str::to_owned,
        )
    }

    /// The path of the folder holding the scene, to resolve the files it names.
    pub fn folder(&self) -> &Path {
        self.path.parent().unwrap_or_else(|| Path::new(""))
    }
}

/// Where a key's entry starts: at the key for a `key = value` line, at the value (its header)
/// for a table or an array of tables.
fn span_of<T>(name: &Spanned<T>, value: &Spanned<DeValue<'_>>) -> usize {
    name.span().start.min(value.span().start)
}

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// Splits `soft_body[1].material.young` into its keys and indices.
fn parse_key_path(path: &str) -> Vec<Segment> {
    let mut segments = Vec::new();
    for part in path.split('.') {
        let mut rest = part;
        if let Some(open) = rest.find('[') {
            let key = &rest[..open];
            if !key.is_empty() {
                segments.push(Segment::Key(key.to_owned()));
            }
            rest = &rest[open..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let Some(close) = stripped.find(']') else {
                    break;
                };
                if let Ok(index) = stripped[..close].parse() {
                    segments.push(Segment::Index(index));
                }
                rest = &stripped[close + 1..];
            }
        } else if !rest.is_empty() {
            segments.push(Segment::Key(rest.to_owned()));
        }
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_paths_split_into_keys_and_indices() {
        assert_eq!(
            parse_key_path("soft_body[1].pinned[0].min"),
            vec![
                Segment::Key("soft_body".into()),
                Segment::Index(1),
                Segment::Key("pinned".into()),
                Segment::Index(0),
                Segment::Key("min".into()),
            ]
        );
    }

    #[test]
    fn a_key_path_is_found_on_its_line() {
        let source = SceneSource {
            path: "a.toml".into(),
            text: "[world]\nduration = 1\n\n[[soft_body]]\nname = \"a\"\n\n[[soft_body]]\nname = \"b\"\n[soft_body.material]\nyoung = -1\n".into(),
        };
        assert_eq!(source.line_of_key("world.duration"), Some(2));
        assert_eq!(source.line_of_key("soft_body[1].name"), Some(8));
        assert_eq!(source.line_of_key("soft_body[1].material.young"), Some(10));
        // A missing key: the line of the table that should hold it.
        assert_eq!(source.line_of_key("soft_body[1].material.poisson"), Some(9));
    }
}
