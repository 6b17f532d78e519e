//! One binary block of a `.vtu` array (inline base64 decoded, or appended): a header of the
//! byte count (`header_type` wide) and the bytes; compressed
//! (`compressor="vtkZLibDataCompressor"`), a header `[blocks, block size, last block size,
//! compressed size of each block]` and the blocks as zlib streams, inflated by `flate2`.
//!
//! Every count is checked against what the block holds and against the most values the piece
//! can use, before anything is allocated for it: a header announcing more, a block that
//! inflates to more or less than its header says, or data running past the file is an error.
//! Inflating stops one byte past each block's declared size, so a decompression bomb costs no
//! more memory than the counts the piece declares. Other compressors (LZ4, LZMA) are refused.

use super::xml_document::Layout;
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::{Source, shorten};
use std::borrow::Cow;
use std::io::Read;

/// The class VTK names its zlib compressor by, the one compressor read.
const ZLIB: &str = "vtkZLibDataCompressor";

/// The value of the `bytes` of one number (as many as its type is wide), in either byte order.
pub(super) fn unsigned(bytes: &[u8], big_endian: bool) -> u64 {
    let fold = |value: u64, &b: &u8| (value << 8) | u64::from(b);
    if big_endian {
        bytes.iter().fold(0, fold)
    } else {
        bytes.iter().rev().fold(0, fold)
    }
}

/// A block of values `size` bytes wide, at most `max` of them, in a file of `layout`; `at` and
/// `what` place and name it in errors.
pub(super) struct BinaryBlock<'a> {
    pub(super) source: &'a Source<'a>,
    pub(super) layout: &'a Layout,
    pub(super) size: usize,
    pub(super) max: u64,
    pub(super) at: FileLocation,
    pub(super) what: &'a str,
}

impl BinaryBlock<'_> {
    /// An error of `kind` at the block.
    fn error(&self, at: FileLocation, kind: ImportErrorKind, message: String) -> Error {
        self.source.error_at(at, kind, message)
    }

    /// The bytes of the values that `bytes` holds after its header, inflated if the file is
    /// compressed.
    pub(super) fn payload<'b>(&self, bytes: &'b [u8]) -> Result<Cow<'b, [u8]>, Error> {
        let (at, what) = (self.at, self.what);
        let mut block = Block {
            bytes,
            position: 0,
            width: self.layout.header_bytes,
            big_endian: self.layout.big_endian,
        };
        match self.layout.compressor.as_deref() {
            None => {
                let total = block.header().ok_or_else(|| self.truncated("header"))?;
                let total = self.check_total(Some(total))?;
                let data = block.take(total);
                Ok(Cow::Borrowed(data.ok_or_else(|| self.truncated("data"))?))
            }
            Some(ZLIB) => self.inflate(block).map(Cow::Owned),
            Some(other) => Err(self.error(
                at,
                ImportErrorKind::UnknownVersion,
                format!(
                    "the {what} are compressed by {}: only {ZLIB} (zlib) is read",
                    shorten(other)
                ),
            )),
        }
    }

    /// The inflated data of the zlib-compressed `block`, its header first.
    fn inflate(&self, mut block: Block<'_>) -> Result<Vec<u8>, Error> {
        let (at, what) = (self.at, self.what);
        let truncated = || self.truncated("compression header");
        let blocks = block.header().ok_or_else(truncated)?;
        let block_size = block.header().ok_or_else(truncated)?;
        let last = block.header().ok_or_else(truncated)?;
        if blocks > (block.bytes.len() / block.width) as u64 || last > block_size {
            return Err(self.error(
                at,
                ImportErrorKind::BadCount,
                format!(
                    "the {what}' compression header is inconsistent ({blocks} blocks of \
                     {block_size} bytes, the last {last})"
                ),
            ));
        }
        let sizes: Vec<u64> = (0..blocks)
            .map(|_| block.header())
            .collect::<Option<_>>()
            .ok_or_else(truncated)?;
        let full = if last == 0 { block_size } else { last };
        let total = match blocks {
            0 => Some(0),
            _ => block_size
                .checked_mul(blocks - 1)
                .and_then(|t| t.checked_add(full)),
        };
        let total = self.check_total(total)?;
        // At most what the compressed bytes can inflate to (deflate's ratio is below 1032).
        let mut inflated = Vec::with_capacity(total.min(block.bytes.len().saturating_mul(1032)));
        for (i, &compressed) in sizes.iter().enumerate() {
            let expected = if i as u64 + 1 == blocks {
                full
            } else {
                block_size
            };
            let stream = usize::try_from(compressed)
                .ok()
                .and_then(|n| block.take(n))
                .ok_or_else(|| self.truncated("compressed blocks"))?;
            let before = inflated.len();
            flate2::read::ZlibDecoder::new(stream)
                .take(expected.saturating_add(1))
                .read_to_end(&mut inflated)
                .map_err(|e| {
                    self.error(
                        at,
                        ImportErrorKind::Syntax,
                        format!("block {i} of the {what} is not a zlib stream: {e}"),
                    )
                })?;
            let got = inflated.len() - before;
            if got as u64 != expected {
                return Err(self.error(
                    at,
                    ImportErrorKind::BadCount,
                    format!("block {i} of the {what} inflates to {got} bytes, its header says {expected}"),
                ));
            }
        }
        Ok(inflated)
    }

    /// A [`ImportErrorKind::Truncated`] error: the data ends before their `needed` part.
    fn truncated(&self, needed: &str) -> Error {
        self.error(
            self.at,
            ImportErrorKind::Truncated,
            format!("the {} end before their {needed}", self.what),
        )
    }

    /// The byte count `total` of values, checked to be whole values and at most the limit.
    fn check_total(&self, total: Option<u64>) -> Result<usize, Error> {
        let (max, at, what) = (self.max, self.at, self.what);
        let size = self.size as u64;
        let total = total.filter(|t| t % size == 0).ok_or_else(|| {
            self.error(
                at,
                ImportErrorKind::BadCount,
                format!("the {what}' byte count is not a whole number of values"),
            )
        })?;
        if total / size > max {
            return Err(self.error(
                at,
                ImportErrorKind::BadCount,
                format!(
                    "the {what} hold {} values, more than the {max} the piece declares",
                    total / size
                ),
            ));
        }
        usize::try_from(total).map_err(|_| self.truncated("data"))
    }
}

/// A binary block being read: header integers of `width` bytes, then data.
struct Block<'b> {
    bytes: &'b [u8],
    position: usize,
    width: usize,
    big_endian: bool,
}

impl<'b> Block<'b> {
    /// The next `n` bytes, `None` past the end.
    fn take(&mut self, n: usize) -> Option<&'b [u8]> {
        let end = self
            .position
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())?;
        let taken = &self.bytes[self.position..end];
        self.position = end;
        Some(taken)
    }

    /// The next header integer, `None` past the end.
    fn header(&mut self) -> Option<u64> {
        let big_endian = self.big_endian;
        self.take(self.width).map(|b| unsigned(b, big_endian))
    }
}
