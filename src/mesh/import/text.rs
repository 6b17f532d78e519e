//! A cursor over a file's bytes shared by the hand-written readers: lines with their numbers
//! for text, fixed-size little- or big-endian values with their offsets for binary blocks, and
//! typed errors that say where.

use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use rapier3d::glamx::DVec3;
use std::str::FromStr;

/// Reading position in a file, with the file's name for errors.
pub(super) struct Source<'a> {
    path: &'a str,
    data: &'a [u8],
    pos: usize,
    /// Number of the last line returned by [`Source::line`] (1-based; 0 before the first).
    line: usize,
    /// Whether errors give byte offsets (inside binary data) rather than lines.
    binary: bool,
    /// Whether the last line returned by [`Source::line`] ended with a line break.
    line_ended: bool,
}

impl<'a> Source<'a> {
    /// A cursor at the start of `data`, read from `path`.
    pub(super) fn new(path: &'a str, data: &'a [u8]) -> Self {
        Self {
            path,
            data,
            pos: 0,
            line: 0,
            binary: false,
            line_ended: true,
        }
    }

    /// Makes errors report byte offsets (`true`) or lines (`false`).
    pub(super) fn set_binary(&mut self, binary: bool) {
        self.binary = binary;
    }

    /// Where the cursor is, as errors report it.
    pub(super) fn location(&self) -> FileLocation {
        if self.binary {
            FileLocation::Byte(self.pos)
        } else {
            FileLocation::Line(self.line.max(1))
        }
    }

    /// An error of `kind` at the cursor.
    pub(super) fn error(&self, kind: ImportErrorKind, message: impl Into<String>) -> Error {
        self.error_at(self.location(), kind, message)
    }

    /// An error of `kind` at `location`.
    pub(super) fn error_at(
        &self,
        location: FileLocation,
        kind: ImportErrorKind,
        message: impl Into<String>,
    ) -> Error {
        Error::MeshImport {
            path: self.path.to_owned(),
            location,
            kind,
            message: printable(&message.into()),
        }
    }

    /// The file name errors carry.
    pub(super) fn path(&self) -> &'a str {
        self.path
    }

    /// Bytes left after the cursor.
    pub(super) fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// A capacity for `count` items announced by the file, bounded by what the remaining input
    /// can hold at `min_bytes` bytes per item at least.
    pub(super) fn capacity(&self, count: usize, min_bytes: usize) -> usize {
        count.min(self.remaining() / min_bytes.max(1))
    }

    /// The next line without its line ending and surrounding whitespace, or `None` at the end.
    pub(super) fn line(&mut self) -> Result<Option<&'a str>, Error> {
        if self.pos >= self.data.len() {
            return Ok(None);
        }
        let rest = &self.data[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        self.line += 1;
        self.line_ended = end < rest.len();
        match std::str::from_utf8(&rest[..end]) {
            Ok(text) => Ok(Some(text.trim())),
            Err(_) => {
                let was_binary = self.binary;
                self.binary = false;
                let e = self.error(ImportErrorKind::Syntax, "the line is not valid UTF-8 text");
                self.binary = was_binary;
                Err(e)
            }
        }
    }

    /// The next line that is neither empty nor (when `comment` is given) a comment starting with
    /// it, with trailing comments cut; a [`ImportErrorKind::Truncated`] error naming `what` was
    /// expected at the end of the file.
    pub(super) fn content_line(
        &mut self,
        comment: Option<char>,
        what: &str,
    ) -> Result<&'a str, Error> {
        loop {
            let Some(line) = self.line()? else {
                return Err(self.error(
                    ImportErrorKind::Truncated,
                    format!("the file ends where {what} was expected"),
                ));
            };
            let line = match comment {
                Some(c) => line.split(c).next().unwrap_or("").trim(),
                None => line,
            };
            if !line.is_empty() {
                return Ok(line);
            }
        }
    }

    /// A [`ImportErrorKind::Truncated`] error if the last line read, holding `what`, is the
    /// file's last and has no line break: a file cut inside a number reads as another number.
    pub(super) fn check_line_ended(&self, what: &str) -> Result<(), Error> {
        if self.line_ended {
            return Ok(());
        }
        Err(self.error(
            ImportErrorKind::Truncated,
            format!("the file ends inside {what}, without a line break: it may be cut short"),
        ))
    }

    /// A [`ImportErrorKind::BadCount`] error at the next line that is neither blank nor a
    /// comment (starting with `comment`), if there is one: the file holds more `what` than
    /// its header announces (`count`).
    pub(super) fn check_nothing_follows(
        &mut self,
        comment: char,
        what: &str,
        count: usize,
    ) -> Result<(), Error> {
        while let Some(line) = self.line()? {
            if !line.split(comment).next().unwrap_or("").trim().is_empty() {
                return Err(self.error(
                    ImportErrorKind::BadCount,
                    format!("more {what} than the {count} the header announces"),
                ));
            }
        }
        Ok(())
    }

    /// Skips whitespace (spaces, tabs, line endings) in binary mode, counting lines.
    pub(super) fn skip_whitespace(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next `n` raw bytes, or a [`ImportErrorKind::Truncated`] error naming `what`.
    pub(super) fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Error> {
        if n > self.remaining() {
            return Err(self.error(
                ImportErrorKind::Truncated,
                format!(
                    "the file ends inside {what}: {n} bytes needed, {} left",
                    self.remaining()
                ),
            ));
        }
        let bytes = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(bytes)
    }

    /// A fixed-size binary value: `N` bytes turned into `T` by `convert` (which picks the byte
    /// order).
    pub(super) fn binary<const N: usize, T>(
        &mut self,
        convert: impl Fn([u8; N]) -> T,
        what: &str,
    ) -> Result<T, Error> {
        let bytes = self.take(N, what)?;
        let mut array = [0u8; N];
        array.copy_from_slice(bytes);
        Ok(convert(array))
    }

    /// Moves the cursor past the next occurrence of `marker` (and the rest of its line), or
    /// gives a [`ImportErrorKind::Truncated`] error.
    pub(super) fn skip_past(&mut self, marker: &[u8]) -> Result<(), Error> {
        let rest = &self.data[self.pos..];
        let Some(at) = rest.windows(marker.len()).position(|w| w == marker) else {
            return Err(self.error(
                ImportErrorKind::Truncated,
                format!(
                    "`{}` is missing: the section never ends",
                    String::from_utf8_lossy(marker)
                ),
            ));
        };
        self.line += rest[..at].iter().filter(|&&b| b == b'\n').count();
        self.pos += at + marker.len();
        // Rest of the marker's line.
        let rest = &self.data[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        self.line += 1;
        Ok(())
    }
}

/// Parses `token` as a `T`, with errors naming `what` at `source`'s location.
pub(super) fn parse_token<T: FromStr>(
    source: &Source<'_>,
    token: Option<&str>,
    what: &str,
) -> Result<T, Error> {
    let Some(token) = token else {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!("{what} is missing from the line"),
        ));
    };
    token.parse().map_err(|_| {
        source.error(
            ImportErrorKind::Syntax,
            format!("`{}` is not a valid {what}", shorten(token)),
        )
    })
}

/// Parses `token` as a finite `f64`, with errors naming `what`.
pub(super) fn parse_finite(
    source: &Source<'_>,
    token: Option<&str>,
    what: &str,
) -> Result<f64, Error> {
    let value: f64 = parse_token(source, token, what)?;
    finite(source, value, what)
}

/// The point of the next three tokens, finite coordinates `x y z` (file units), with errors
/// naming the coordinate.
pub(super) fn parse_point<'t>(
    source: &Source<'_>,
    tokens: &mut impl Iterator<Item = &'t str>,
) -> Result<DVec3, Error> {
    let x = parse_finite(source, tokens.next(), "x coordinate")?;
    let y = parse_finite(source, tokens.next(), "y coordinate")?;
    let z = parse_finite(source, tokens.next(), "z coordinate")?;
    Ok(DVec3::new(x, y, z))
}

/// `Ok` if `tokens` holds nothing more, else an error of `kind` saying `message`.
pub(super) fn end_of_line<'t>(
    source: &Source<'_>,
    mut tokens: impl Iterator<Item = &'t str>,
    kind: ImportErrorKind,
    message: &str,
) -> Result<(), Error> {
    match tokens.next() {
        Some(_) => Err(source.error(kind, message)),
        None => Ok(()),
    }
}

/// `value` if finite, else a [`ImportErrorKind::NonFinite`] error naming `what`.
pub(super) fn finite(source: &Source<'_>, value: f64, what: &str) -> Result<f64, Error> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(source.error(
            ImportErrorKind::NonFinite,
            format!("{what} is {value}, not a finite number"),
        ))
    }
}

/// `p * scale` if a mesh can use it, else an [`ImportErrorKind::NonFinite`] or
/// [`ImportErrorKind::CoordinateOutOfRange`] error at the cursor.
pub(super) fn scaled(source: &Source<'_>, p: DVec3, scale: f64) -> Result<DVec3, Error> {
    match super::scaled_defect(p, scale) {
        None => Ok(p * scale),
        Some((kind, problem)) => Err(source.error(
            kind,
            format!("the node at {p} times the scale {scale} {problem}"),
        )),
    }
}

/// `message` on one line of printable text: control characters (line breaks, escapes, bytes
/// of a binary file shown as text) written as Rust escapes (`\n`, `\u{1b}`).
fn printable(message: &str) -> String {
    if !message.chars().any(char::is_control) {
        return message.to_owned();
    }
    message
        .chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// At most 40 characters of `token`, for messages.
pub(super) fn shorten(token: &str) -> String {
    let mut short: String = token.chars().take(40).collect();
    if short.len() < token.len() {
        short.push('…');
    }
    short
}
