//! The values of a `.vtu` `<DataArray>`, whatever its format:
//! - `ascii`: numbers separated by whitespace;
//! - `binary` (base64 text inside the element) and `appended` (raw bytes or base64 text in
//!   `<AppendedData>`, from the array's offset to the next array's): one block, read by
//!   `xml_block`. Base64 text may be padded inside (VTK encodes a compressed array's header
//!   apart from its blocks): each padded group ends a part, decoded on its own.
//!
//! At most the values the piece can use (`max`) are read: more is an error, never a cut.

use super::xml_block::{BinaryBlock, unsigned};
use super::xml_document::{Appended, ArrayDecl, Format, Layout};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::{Source, shorten};
use base64::Engine;
use std::borrow::Cow;

/// A VTK number type: its width in bytes and kind.
#[derive(Debug, Clone, Copy, PartialEq)]
enum NumberType {
    Signed(usize),
    Unsigned(usize),
    Float(usize),
}

impl NumberType {
    /// The type of VTK's name `name` (`Int8` ... `UInt64`, `Float32`, `Float64`).
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "Int8" => Self::Signed(1),
            "UInt8" => Self::Unsigned(1),
            "Int16" => Self::Signed(2),
            "UInt16" => Self::Unsigned(2),
            "Int32" => Self::Signed(4),
            "UInt32" => Self::Unsigned(4),
            "Int64" => Self::Signed(8),
            "UInt64" => Self::Unsigned(8),
            "Float32" => Self::Float(4),
            "Float64" => Self::Float(8),
            _ => return None,
        })
    }

    /// Bytes per value.
    fn size(self) -> usize {
        match self {
            Self::Signed(n) | Self::Unsigned(n) | Self::Float(n) => n,
        }
    }
}

/// The number of `kind` in `bytes`, as `f64` (exact for integers below 2⁵³).
fn float(kind: NumberType, bytes: &[u8], big_endian: bool) -> f64 {
    let bits = unsigned(bytes, big_endian);
    match kind {
        NumberType::Float(4) => f64::from(f32::from_bits(bits as u32)),
        NumberType::Float(_) => f64::from_bits(bits),
        NumberType::Unsigned(_) => bits as f64,
        NumberType::Signed(n) => sign_extended(bits, n) as f64,
    }
}

/// The two's complement value of the `width`-byte integer `bits`.
fn sign_extended(bits: u64, width: usize) -> i64 {
    let unused = 64 - 8 * width as u32;
    ((bits << unused) as i64) >> unused
}

/// Decodes base64 `text`, whitespace ignored, padding allowed at the end of any 4-character
/// group (each padded group ends a separately encoded part).
fn decode_base64(text: &[u8]) -> Result<Vec<u8>, base64::DecodeError> {
    let compact: Vec<u8> = text
        .iter()
        .copied()
        .filter(|b| !b.is_ascii_whitespace())
        .collect();
    let mut bytes = Vec::with_capacity(compact.len() / 4 * 3);
    let mut rest = compact.as_slice();
    while !rest.is_empty() {
        let end = rest
            .iter()
            .position(|&b| b == b'=')
            .map_or(rest.len(), |pad| ((pad / 4 + 1) * 4).min(rest.len()));
        base64::engine::general_purpose::STANDARD.decode_vec(&rest[..end], &mut bytes)?;
        rest = &rest[end..];
    }
    Ok(bytes)
}

/// Reads the values of a file's arrays.
pub(super) struct Decoder<'a, 'd> {
    source: &'a Source<'a>,
    layout: &'a Layout,
    appended: Option<Appended<'d>>,
    /// The appended arrays' offsets, sorted: an array's data ends at the next one.
    appended_offsets: Vec<u64>,
}

impl<'a, 'd> Decoder<'a, 'd> {
    /// A decoder for the arrays of `arrays`, in a file of `layout` with `appended` data.
    pub(super) fn new<'x>(
        source: &'a Source<'a>,
        layout: &'a Layout,
        appended: Option<Appended<'d>>,
        arrays: impl Iterator<Item = &'x ArrayDecl>,
    ) -> Self {
        let mut appended_offsets: Vec<u64> = arrays
            .filter_map(|a| match a.format {
                Format::Appended(offset) => Some(offset),
                _ => None,
            })
            .collect();
        appended_offsets.sort_unstable();
        Self {
            source,
            layout,
            appended,
            appended_offsets,
        }
    }

    /// An error of `kind` at `location`.
    fn error(&self, location: FileLocation, kind: ImportErrorKind, message: String) -> Error {
        self.source.error_at(location, kind, message)
    }

    /// The values of `array` (`what`, for errors) as numbers, at most `max` of them.
    pub(super) fn floats(
        &self,
        array: &ArrayDecl,
        max: u64,
        what: &str,
    ) -> Result<Vec<f64>, Error> {
        let kind = self.number_type(array, what)?;
        let big_endian = self.layout.big_endian;
        self.values(
            array,
            kind,
            max,
            what,
            "a number",
            |token| token.parse().ok(),
            |b| Some(float(kind, b, big_endian)),
        )
    }

    /// The values of `array` (`what`, for errors) as indices (non-negative integers of an
    /// integer type), at most `max` of them.
    pub(super) fn indices(
        &self,
        array: &ArrayDecl,
        max: u64,
        what: &str,
    ) -> Result<Vec<u64>, Error> {
        let kind = self.number_type(array, what)?;
        if let NumberType::Float(_) = kind {
            return Err(self.error(
                FileLocation::Line(array.line),
                ImportErrorKind::Syntax,
                format!("the {what} are {}, not integers", array.value_type),
            ));
        }
        let big_endian = self.layout.big_endian;
        let index = |bytes: &[u8]| {
            let bits = unsigned(bytes, big_endian);
            match kind {
                NumberType::Signed(n) => u64::try_from(sign_extended(bits, n)).ok(),
                _ => Some(bits),
            }
        };
        self.values(
            array,
            kind,
            max,
            what,
            "an index",
            |token| token.parse().ok(),
            index,
        )
    }

    /// The type of `array`'s values.
    fn number_type(&self, array: &ArrayDecl, what: &str) -> Result<NumberType, Error> {
        NumberType::parse(&array.value_type).ok_or_else(|| {
            self.error(
                FileLocation::Line(array.line),
                ImportErrorKind::Syntax,
                format!(
                    "the {what} have type {:?}, not a VTK number type",
                    shorten(&array.value_type)
                ),
            )
        })
    }

    /// At most `max` values of `array`, of type `kind`: tokens read by `from_text` (each
    /// `expected`, for errors), binary values by `from_bytes`.
    #[allow(clippy::too_many_arguments)]
    fn values<T>(
        &self,
        array: &ArrayDecl,
        kind: NumberType,
        max: u64,
        what: &str,
        expected: &str,
        from_text: impl Fn(&str) -> Option<T>,
        from_bytes: impl Fn(&[u8]) -> Option<T>,
    ) -> Result<Vec<T>, Error> {
        if array.format == Format::Ascii {
            return self.ascii(array, max, what, expected, from_text);
        }
        let (bytes, at) = self.binary_bytes(array, what)?;
        let block = BinaryBlock {
            source: self.source,
            layout: self.layout,
            size: kind.size(),
            max,
            at,
            what,
        };
        let payload = block.payload(&bytes)?;
        payload
            .chunks_exact(kind.size())
            .enumerate()
            .map(|(i, value)| {
                from_bytes(value).ok_or_else(|| {
                    self.error(
                        at,
                        ImportErrorKind::IndexOutOfRange,
                        format!("value {i} of the {what} is negative"),
                    )
                })
            })
            .collect()
    }

    /// The whitespace-separated tokens of `array`'s text read by `parse`, at most `max`; a
    /// token that does not parse is reported at its own line.
    fn ascii<T>(
        &self,
        array: &ArrayDecl,
        max: u64,
        what: &str,
        expected: &str,
        parse: impl Fn(&str) -> Option<T>,
    ) -> Result<Vec<T>, Error> {
        let text = &array.text;
        let mut values = Vec::with_capacity((text.len() / 2).min(max as usize));
        let (mut line, mut i) = (array.text_line, 0);
        while i < text.len() {
            if text[i].is_ascii_whitespace() {
                line += usize::from(text[i] == b'\n');
                i += 1;
                continue;
            }
            let end = text[i..]
                .iter()
                .position(u8::is_ascii_whitespace)
                .map_or(text.len(), |n| i + n);
            let token = String::from_utf8_lossy(&text[i..end]);
            if values.len() as u64 >= max {
                return Err(self.error(
                    FileLocation::Line(line),
                    ImportErrorKind::BadCount,
                    format!("the {what} hold more than the {max} values the piece declares"),
                ));
            }
            let value = parse(&token).ok_or_else(|| {
                self.error(
                    FileLocation::Line(line),
                    ImportErrorKind::Syntax,
                    format!("{:?} in the {what} is not {expected}", shorten(&token)),
                )
            })?;
            values.push(value);
            i = end;
        }
        Ok(values)
    }

    /// The binary bytes of `array` (base64 decoded) and where they are in the file.
    fn binary_bytes(
        &self,
        array: &ArrayDecl,
        what: &str,
    ) -> Result<(Cow<'d, [u8]>, FileLocation), Error> {
        let syntax = |at, e: base64::DecodeError| {
            self.error(
                at,
                ImportErrorKind::Syntax,
                format!("the {what} are not valid base64: {e}"),
            )
        };
        let Format::Appended(offset) = array.format else {
            let at = FileLocation::Line(array.line);
            return Ok((
                Cow::Owned(decode_base64(&array.text).map_err(|e| syntax(at, e))?),
                at,
            ));
        };
        let Some(appended) = self.appended else {
            return Err(self.error(
                FileLocation::Line(array.line),
                ImportErrorKind::Truncated,
                format!("the {what} are appended, but the file has no <AppendedData>"),
            ));
        };
        let region = appended.data;
        let start = usize::try_from(offset)
            .ok()
            .filter(|&o| o <= region.len())
            .ok_or_else(|| {
                self.error(
                    FileLocation::Line(array.line),
                    ImportErrorKind::Truncated,
                    format!(
                        "the {what} start at offset {offset}, past the {} bytes of appended data",
                        region.len()
                    ),
                )
            })?;
        let end = self
            .appended_offsets
            .iter()
            .find(|&&o| o > offset)
            .map_or(region.len(), |&o| (o as usize).min(region.len()));
        let at = FileLocation::Byte(appended.start + start);
        let data = &region[start..end];
        if appended.base64 {
            Ok((
                Cow::Owned(decode_base64(data).map_err(|e| syntax(at, e))?),
                at,
            ))
        } else {
            Ok((Cow::Borrowed(data), at))
        }
    }
}
