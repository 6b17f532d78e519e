//! The data blocks of legacy `.vtk` files: keyword lines and the number lists after them.
//!
//! In ASCII files the numbers are whitespace-separated tokens spread over any number of lines;
//! in BINARY files they are big-endian values of the size their data type names (`float`,
//! `double`, `char` to `long`, `vtktypeint8` to `vtktypeuint64`, `vtkIdType`), errors in them
//! placed at their byte offset. A block holding more tokens than its count announces, an
//! unknown data type, a negative index or count, and a non-finite coordinate are errors.

use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{Source, finite, parse_token, shorten};
use std::str::{FromStr, SplitAsciiWhitespace};

/// A legacy VTK data type: its size in binary files and whether it is a float.
#[derive(Clone, Copy)]
pub(super) enum DataType {
    Float(usize),
    Signed(usize),
    Unsigned(usize),
}

impl DataType {
    /// The size of a binary value (bytes).
    fn size(self) -> usize {
        match self {
            Self::Float(s) | Self::Signed(s) | Self::Unsigned(s) => s,
        }
    }
}

/// The values of a data block, or the error that stops it.
type Values<T> = Result<Vec<T>, Error>;

/// The data type `name` (a keyword line's type field), or a syntax error.
pub(super) fn data_type(source: &Source<'_>, name: Option<&str>) -> Result<DataType, Error> {
    let name = name.unwrap_or("");
    Ok(match name {
        "float" => DataType::Float(4),
        "double" => DataType::Float(8),
        "char" | "vtktypeint8" => DataType::Signed(1),
        "unsigned_char" | "vtktypeuint8" => DataType::Unsigned(1),
        "short" | "vtktypeint16" => DataType::Signed(2),
        "unsigned_short" | "vtktypeuint16" => DataType::Unsigned(2),
        "int" | "vtktypeint32" => DataType::Signed(4),
        "unsigned_int" | "vtktypeuint32" => DataType::Unsigned(4),
        "long" | "vtktypeint64" | "vtkIdType" => DataType::Signed(8),
        "unsigned_long" | "vtktypeuint64" => DataType::Unsigned(8),
        _ => {
            return Err(source.error(
                ImportErrorKind::Syntax,
                format!("unknown data type `{}`", shorten(name)),
            ));
        }
    })
}

/// The legacy reader's state: the file, its encoding and the rest of the current line.
pub(super) struct Legacy<'a> {
    pub(super) source: Source<'a>,
    /// Whether the data blocks are binary.
    binary: bool,
    /// The tokens left on the current line of an ASCII data block.
    tokens: SplitAsciiWhitespace<'a>,
}

impl<'a> Legacy<'a> {
    /// The reader of the data of `source` (after its header), binary or not.
    pub(super) fn new(source: Source<'a>, binary: bool) -> Self {
        Self {
            source,
            binary,
            tokens: "".split_ascii_whitespace(),
        }
    }

    /// The next whitespace-separated token of an ASCII data block, across lines.
    fn token(&mut self, what: &str) -> Result<&'a str, Error> {
        loop {
            if let Some(token) = self.tokens.next() {
                return Ok(token);
            }
            let Some(line) = self.source.line()? else {
                return Err(self.source.error(
                    ImportErrorKind::Truncated,
                    format!("the file ends where {what} was expected"),
                ));
            };
            self.tokens = line.split_ascii_whitespace();
        }
    }

    /// The next keyword line, after checking the previous data block left nothing over.
    pub(super) fn keyword_line(&mut self) -> Result<Option<&'a str>, Error> {
        if let Some(extra) = self.tokens.next() {
            return Err(self.source.error(
                ImportErrorKind::BadCount,
                format!(
                    "`{}` follows the data: more values than the count announces",
                    shorten(extra)
                ),
            ));
        }
        if self.binary {
            self.source.skip_whitespace();
        }
        loop {
            match self.source.line()? {
                None => return Ok(None),
                Some("") => {}
                Some(line) => return Ok(Some(line)),
            }
        }
    }

    /// `count` numbers of type `ty` as `f64`, each checked finite.
    pub(super) fn floats(&mut self, count: usize, ty: DataType, what: &str) -> Values<f64> {
        let decode = |_: &Source<'_>, bytes: &[u8]| Ok(binary_value(bytes, ty));
        self.values(count, ty.size(), what, decode, |source, value| {
            finite(source, value, what)
        })
    }

    /// `count` non-negative integers (indices, counts, cell types).
    pub(super) fn integers(&mut self, count: usize, ty: DataType, what: &str) -> Values<u64> {
        if let DataType::Float(_) = ty {
            return Err(self.source.error(
                ImportErrorKind::Syntax,
                format!("{what} must be integers, not floating point"),
            ));
        }
        let decode = |source: &Source<'_>, bytes: &[u8]| {
            let value = binary_integer(bytes, ty);
            u64::try_from(value).map_err(|_| {
                source.error(
                    ImportErrorKind::Syntax,
                    format!("{what}: {value} is negative"),
                )
            })
        };
        self.values(count, ty.size(), what, decode, |_, value| Ok(value))
    }

    /// Reads past `count` values of type `ty` (attribute data this crate does not use): binary
    /// ones by their size, ASCII ones each checked to be a number (NaN and infinities allowed).
    pub(super) fn skip(&mut self, count: usize, ty: DataType, what: &str) -> Result<(), Error> {
        if self.binary {
            self.source.set_binary(true);
            self.source.take(count.saturating_mul(ty.size()), what)?;
            self.source.set_binary(false);
            return Ok(());
        }
        for _ in 0..count {
            let token = self.token(what)?;
            parse_token::<f64>(&self.source, Some(token), what)?;
        }
        Ok(())
    }

    /// `count` region tags of type `ty`: non-negative integers, or whole numbers stored as
    /// floats.
    pub(super) fn tags(&mut self, count: usize, ty: DataType, what: &str) -> Values<u64> {
        let DataType::Float(_) = ty else {
            return self.integers(count, ty, what);
        };
        let whole = |source: &Source<'_>, v: f64| {
            super::whole_tag(v).map(|_| v).ok_or_else(|| {
                source.error(
                    ImportErrorKind::Syntax,
                    format!("{what}: {v} is not a whole number of 0 or more"),
                )
            })
        };
        let decode = |_: &Source<'_>, bytes: &[u8]| Ok(binary_value(bytes, ty));
        let values = self.values(count, ty.size(), what, decode, whole)?;
        Ok(values.into_iter().map(|v| v as u64).collect())
    }

    /// `count` values named `what`: binary ones of `size` bytes turned into a `T` by `decode`
    /// (its errors placed at the value's byte offset), ASCII tokens parsed as a `T`; each then
    /// passed through `check` (its errors placed at the line).
    fn values<T: FromStr>(
        &mut self,
        count: usize,
        size: usize,
        what: &str,
        decode: impl Fn(&Source<'_>, &[u8]) -> Result<T, Error>,
        check: impl Fn(&Source<'_>, T) -> Result<T, Error>,
    ) -> Values<T> {
        let min_bytes = if self.binary { size } else { 2 };
        let mut values = Vec::with_capacity(self.source.capacity(count, min_bytes));
        for _ in 0..count {
            let value = if self.binary {
                self.source.set_binary(true);
                let bytes = self.source.take(size, what)?;
                let value = decode(&self.source, bytes)?;
                self.source.set_binary(false);
                value
            } else {
                let token = self.token(what)?;
                parse_token(&self.source, Some(token), what)?
            };
            values.push(check(&self.source, value)?);
        }
        Ok(values)
    }
}

/// A big-endian binary value of type `ty` (`bytes.len()` is its size) as `f64`.
fn binary_value(bytes: &[u8], ty: DataType) -> f64 {
    match ty {
        DataType::Float(4) => {
            f64::from(f32::from_be_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
        }
        DataType::Float(_) => {
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[..8]);
            f64::from_be_bytes(b)
        }
        _ => binary_integer(bytes, ty) as f64,
    }
}

/// A big-endian binary integer of type `ty`.
fn binary_integer(bytes: &[u8], ty: DataType) -> i128 {
    let mut value: u128 = 0;
    for &b in bytes {
        value = (value << 8) | u128::from(b);
    }
    match ty {
        DataType::Signed(size) => {
            let shift = 128 - 8 * size as u32;
            ((value << shift) as i128) >> shift
        }
        _ => value as i128,
    }
}
