//! The `$Nodes` and `$Elements` sections of MSH 4.0 files (ASCII; gmsh writes 4.0 in no other
//! form).
//!
//! Each section starts with `numEntityBlocks total` and holds entity blocks whose header is
//! `entity dim third count` (the entity tag first, unlike 4.1): a node block `entity dim
//! parametric count` followed by one `tag x y z` line per node (and `dim` parametric
//! coordinates when the flag is 1); an element block `entity dim type count` followed by one
//! `tag nodes...` line per element. Counts are checked as in 4.1 ([`BlockCount`]).

use super::Reader;
use super::v4::{BlockCount, ascii_node_coordinates_after};
use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{Source, parse_token};

impl Reader {
    /// Reads the body of a version 4.0 `$Nodes` section (after its first line).
    pub(super) fn nodes_v40(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = section_header(source, "node")?;
        let mut blocks_read = BlockCount::new("a node block", "node", total);
        for _ in 0..blocks {
            let location = source.location();
            let (dim, parametric, count) = block_header(source, "a node block", "parametric flag")?;
            if dim > 3 || parametric > 1 {
                return Err(source.error_at(
                    location,
                    ImportErrorKind::Syntax,
                    format!("entity dimension {dim} or parametric flag {parametric} is invalid"),
                ));
            }
            let count = blocks_read.take(source, location, count)?;
            let extra = if parametric == 1 { dim as usize } else { 0 };
            for _ in 0..count {
                let line = source.content_line(None, "a node line `tag x y z`")?;
                let mut tokens = line.split_ascii_whitespace();
                let tag: u64 = parse_token(source, tokens.next(), "node tag")?;
                let p = ascii_node_coordinates_after(source, tokens, extra)?;
                self.add_node(source, tag, p)?;
            }
        }
        blocks_read.finish(source)
    }

    /// Reads the body of a version 4.0 `$Elements` section (after its first line).
    pub(super) fn elements_v40(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = section_header(source, "element")?;
        let mut blocks_read = BlockCount::new("an element block", "element", total);
        for _ in 0..blocks {
            let location = source.location();
            let (_, element_type, count) =
                block_header(source, "an element block", "element type")?;
            // Version 4.0 entities are not read: no regions.
            self.regions.current.clear();
            let count = blocks_read.take(source, location, count)?;
            for _ in 0..count {
                let line = source.content_line(None, "an element line")?;
                let mut tokens = line.split_ascii_whitespace();
                let _: u64 = parse_token(source, tokens.next(), "element tag")?;
                self.element_line(source, element_type, tokens)?;
            }
        }
        blocks_read.finish(source)
    }
}

/// The `numEntityBlocks total` line of a 4.0 section counting `what`s: (blocks, total).
fn section_header(source: &mut Source<'_>, what: &str) -> Result<(usize, usize), Error> {
    let line = source.content_line(None, "a section header")?;
    let mut tokens = line.split_ascii_whitespace();
    let blocks: u64 = parse_token(source, tokens.next(), "entity block count")?;
    let total: u64 = parse_token(source, tokens.next(), &format!("{what} count"))?;
    let as_usize = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
    Ok((as_usize(blocks), as_usize(total)))
}

/// A 4.0 block header line `entity dim third count` (`block` names it, `third` its third
/// field): (dim, third, count).
fn block_header(
    source: &mut Source<'_>,
    block: &str,
    third: &str,
) -> Result<(u32, u32, u64), Error> {
    let line = source.content_line(None, &format!("{block} header"))?;
    let mut tokens = line.split_ascii_whitespace();
    let _: i64 = parse_token(source, tokens.next(), "entity tag")?;
    let dim: u32 = parse_token(source, tokens.next(), "entity dimension")?;
    let third: u32 = parse_token(source, tokens.next(), third)?;
    let count: u64 = parse_token(source, tokens.next(), &format!("{block} size"))?;
    Ok((dim, third, count))
}
