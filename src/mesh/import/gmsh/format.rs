//! The `$MeshFormat` section of a Gmsh file and the binary values it announces.
//!
//! Reads `version file-type data-size` (versions 2.0 to 2.2 and 4.0 (ASCII) with a data size of
//! 8, and 4.1 with 4 or 8; file type 0 for ASCII, 1 for binary) and, in binary files, the byte-order mark (the
//! integer 1); refuses any other version ([`ImportErrorKind::UnknownVersion`]), data size or
//! byte-order mark. The binary readers here take `int`s, `double`s and `size_t`s in the byte
//! order and size the header gave, each checked (non-negative, finite) where the format needs it.

use super::expect_end;
use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{Source, finite, parse_token, shorten};
use rapier3d::glamx::DVec3;

/// The MSH versions read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Version {
    /// 2.0, 2.1 or 2.2: one node or element per line (or record), tags of any value.
    V2,
    /// 4.1: nodes and elements in entity blocks.
    V4,
    /// 4.0 (ASCII only, as gmsh writes it): entity blocks whose headers give the entity tag
    /// before its dimension, each node's tag on its coordinates' line.
    V40,
}

/// What `$MeshFormat` says about the rest of the file.
#[derive(Debug, Clone, Copy)]
pub(super) struct MshFormat {
    pub(super) version: Version,
    /// Whether `$Nodes` and `$Elements` are binary.
    pub(super) binary: bool,
    /// The byte order of binary data.
    little_endian: bool,
    /// Size of the integers written as `size_t` in binary 4.1 files (4 or 8).
    size_t: usize,
}

/// Reads the rest of `$MeshFormat` (after its first line) up to `$EndMeshFormat`.
pub(super) fn read_format(source: &mut Source<'_>) -> Result<MshFormat, Error> {
    let line = source.content_line(None, "the format line `version file-type data-size`")?;
    let mut tokens = line.split_ascii_whitespace();
    let version = read_version(source, tokens.next().unwrap_or(""))?;
    let file_type: u32 = parse_token(source, tokens.next(), "file type (0 or 1)")?;
    let data_size: usize = parse_token(source, tokens.next(), "data size")?;
    let binary = match file_type {
        0 => false,
        1 => true,
        _ => {
            return Err(source.error(
                ImportErrorKind::Syntax,
                format!("file type {file_type} is neither 0 (ASCII) nor 1 (binary)"),
            ));
        }
    };
    if version == Version::V40 && binary {
        return Err(source.error(
            ImportErrorKind::UnknownVersion,
            "binary MSH 4.0 is not read (gmsh writes 4.0 in ASCII only): save as 4.1",
        ));
    }
    let size_ok = match version {
        Version::V2 | Version::V40 => data_size == 8,
        Version::V4 => data_size == 4 || data_size == 8,
    };
    if !size_ok {
        return Err(source.error(
            ImportErrorKind::UnknownVersion,
            format!("data size {data_size} is not supported"),
        ));
    }
    let little_endian = !binary || read_byte_order(source)?;
    expect_end(source, "$EndMeshFormat")?;
    Ok(MshFormat {
        version,
        binary,
        little_endian,
        size_t: data_size,
    })
}

/// The version the format line's first token names, or [`ImportErrorKind::UnknownVersion`].
fn read_version(source: &Source<'_>, version_text: &str) -> Result<Version, Error> {
    match version_text {
        "2" | "2.0" | "2.1" | "2.2" => Ok(Version::V2),
        "4.1" => Ok(Version::V4),
        "4" | "4.0" => Ok(Version::V40),
        _ => Err(source.error(
            ImportErrorKind::UnknownVersion,
            format!(
                "MSH version `{}` is not supported (2.0 to 2.2, 4.0 and 4.1 are)",
                shorten(version_text)
            ),
        )),
    }
}

/// Whether the binary byte-order mark (the integer 1 written in the file's byte order) is
/// little-endian.
fn read_byte_order(source: &mut Source<'_>) -> Result<bool, Error> {
    let one = source.take(4, "the byte-order mark")?;
    let one = [one[0], one[1], one[2], one[3]];
    if i32::from_le_bytes(one) == 1 {
        Ok(true)
    } else if i32::from_be_bytes(one) == 1 {
        Ok(false)
    } else {
        Err(source.error(
            ImportErrorKind::Syntax,
            "the binary byte-order mark is not the integer 1",
        ))
    }
}

impl MshFormat {
    /// A binary `int`.
    pub(super) fn read_i32(&self, source: &mut Source<'_>, what: &str) -> Result<i32, Error> {
        if self.little_endian {
            source.binary(i32::from_le_bytes, what)
        } else {
            source.binary(i32::from_be_bytes, what)
        }
    }

    /// A binary `double`, checked finite.
    pub(super) fn read_f64(&self, source: &mut Source<'_>, what: &str) -> Result<f64, Error> {
        let value = if self.little_endian {
            source.binary(f64::from_le_bytes, what)?
        } else {
            source.binary(f64::from_be_bytes, what)?
        };
        finite(source, value, what)
    }

    /// A binary `size_t` of the header's data size.
    pub(super) fn read_size(&self, source: &mut Source<'_>, what: &str) -> Result<u64, Error> {
        Ok(match (self.size_t, self.little_endian) {
            (4, true) => u64::from(source.binary(u32::from_le_bytes, what)?),
            (4, false) => u64::from(source.binary(u32::from_be_bytes, what)?),
            (_, true) => source.binary(u64::from_le_bytes, what)?,
            (_, false) => source.binary(u64::from_be_bytes, what)?,
        })
    }

    /// A non-negative binary `int` as a `u32`.
    pub(super) fn read_u32(&self, source: &mut Source<'_>, what: &str) -> Result<u32, Error> {
        let value = self.read_i32(source, what)?;
        u32::try_from(value).map_err(|_| {
            source.error(
                ImportErrorKind::Syntax,
                format!("{what} is {value}, negative"),
            )
        })
    }

    /// A node's three binary coordinates (file units).
    pub(super) fn read_point(&self, source: &mut Source<'_>) -> Result<DVec3, Error> {
        let x = self.read_f64(source, "a node's x coordinate")?;
        let y = self.read_f64(source, "a node's y coordinate")?;
        let z = self.read_f64(source, "a node's z coordinate")?;
        Ok(DVec3::new(x, y, z))
    }
}
