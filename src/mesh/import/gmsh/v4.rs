//! The `$Nodes` and `$Elements` sections of MSH 4.1 files.
//!
//! Each section starts with `numEntityBlocks total minTag maxTag` and holds entity blocks: a
//! node block `dim entity parametric count` with the node tags first, then their coordinates
//! (and `dim` parametric coordinates when the flag is 1); an element block `dim entity type
//! count` with one `tag nodes...` per element. In binary files the integers are `int`s and
//! `size_t`s of the header's data size. Blocks announcing more than the section's total left,
//! or holding less in all, are an [`ImportErrorKind::BadCount`] error; an entity dimension above
//! 3 or a parametric flag other than 0 and 1 is a syntax error.

use super::Reader;
use super::elements::{MAX_NODES, nodes_per_element};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::{Source, end_of_line, parse_finite, parse_point, parse_token};
use rapier3d::glamx::DVec3;

/// A block header's numbers: entity dimension and tag, the third field (the parametric flag of
/// a node block, the element type of an element block) and the block's size.
type BlockHeader = (u32, i64, u32, u64);

impl Reader {
    /// Reads the body of a version 4.1 `$Nodes` section (after its first line).
    pub(super) fn nodes_v4(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = self.block_header(source, "node")?;
        let mut blocks_read = BlockCount::new("a node block", "node", total);
        for _ in 0..blocks {
            let location = source.location();
            let (dim, _, parametric, count) = if self.format.binary {
                let format = self.format;
                let dim = format.read_u32(source, "an entity dimension")?;
                format.read_i32(source, "an entity tag")?;
                let parametric = format.read_u32(source, "the parametric flag")?;
                let count = format.read_size(source, "a node block size")?;
                (dim, 0, parametric, count)
            } else {
                ascii_block_header(source, "a node block header", "parametric flag", "node")?
            };
            if dim > 3 || parametric > 1 {
                return Err(source.error_at(
                    location,
                    ImportErrorKind::Syntax,
                    format!("entity dimension {dim} or parametric flag {parametric} is invalid"),
                ));
            }
            let count = blocks_read.take(source, location, count)?;
            let extra = if parametric == 1 { dim as usize } else { 0 };
            self.node_block(source, count, extra)?;
        }
        blocks_read.finish(source)
    }

    /// Reads the `count` nodes of a node block: their tags, then their coordinates, each
    /// followed by `extra` parametric coordinates (ignored).
    fn node_block(
        &mut self,
        source: &mut Source<'_>,
        count: usize,
        extra: usize,
    ) -> Result<(), Error> {
        let format = self.format;
        let mut tags = Vec::with_capacity(source.capacity(count, 2));
        for _ in 0..count {
            let tag = if format.binary {
                format.read_size(source, "a node tag")?
            } else {
                let line = source.content_line(None, "a node tag")?;
                parse_token(source, Some(line), "node tag")?
            };
            tags.push(tag);
        }
        for tag in tags {
            let p = if format.binary {
                let p = format.read_point(source)?;
                for _ in 0..extra {
                    format.read_f64(source, "a parametric coordinate")?;
                }
                p
            } else {
                ascii_node_coordinates(source, extra)?
            };
            self.add_node(source, tag, p)?;
        }
        Ok(())
    }

    /// Reads the body of a version 4.1 `$Elements` section (after its first line).
    pub(super) fn elements_v4(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = self.block_header(source, "element")?;
        let mut blocks_read = BlockCount::new("an element block", "element", total);
        let format = self.format;
        for _ in 0..blocks {
            let location = source.location();
            let (dim, entity, element_type, count) = if format.binary {
                let dim = format.read_u32(source, "an entity dimension")?;
                let entity = i64::from(format.read_i32(source, "an entity tag")?);
                let element_type = format.read_u32(source, "an element type")?;
                let count = format.read_size(source, "an element block size")?;
                (dim, entity, element_type, count)
            } else {
                ascii_block_header(source, "an element block header", "element type", "element")?
            };
            self.regions
                .enter_entity(u8::try_from(dim).unwrap_or(u8::MAX), entity);
            let count = blocks_read.take(source, location, count)?;
            let node_count = nodes_per_element(source, location, element_type)?;
            let mut nodes = [0u64; MAX_NODES];
            for _ in 0..count {
                if format.binary {
                    let location = source.location();
                    format.read_size(source, "an element tag")?;
                    for node in nodes.iter_mut().take(node_count) {
                        *node = format.read_size(source, "an element's node")?;
                    }
                    self.add_element(source, location, element_type, &nodes[..node_count])?;
                } else {
                    let line = source.content_line(None, "an element line")?;
                    let mut tokens = line.split_ascii_whitespace();
                    let _: u64 = parse_token(source, tokens.next(), "element tag")?;
                    self.element_line(source, element_type, tokens)?;
                }
            }
        }
        blocks_read.finish(source)
    }

    /// The `numEntityBlocks numX minTag maxTag` header of a 4.1 section: (blocks, total).
    fn block_header(&self, source: &mut Source<'_>, what: &str) -> Result<(usize, usize), Error> {
        let format = self.format;
        let (blocks, total) = if format.binary {
            source.set_binary(true);
            let blocks = format.read_size(source, "the entity block count")?;
            let total = format.read_size(source, "the total count")?;
            format.read_size(source, "the minimum tag")?;
            format.read_size(source, "the maximum tag")?;
            (blocks, total)
        } else {
            let line = source.content_line(None, "a section header")?;
            let mut tokens = line.split_ascii_whitespace();
            let blocks: u64 = parse_token(source, tokens.next(), "entity block count")?;
            let total: u64 = parse_token(source, tokens.next(), &format!("{what} count"))?;
            let _: u64 = parse_token(source, tokens.next(), "minimum tag")?;
            let _: u64 = parse_token(source, tokens.next(), "maximum tag")?;
            (blocks, total)
        };
        let as_usize = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
        Ok((as_usize(blocks), as_usize(total)))
    }
}

/// An ASCII block header line `dim entity third size` (`header` names the line, `third` its
/// third field, `kind` the items it counts, in messages).
fn ascii_block_header(
    source: &mut Source<'_>,
    header: &str,
    third: &str,
    kind: &str,
) -> Result<BlockHeader, Error> {
    let line = source.content_line(None, header)?;
    let mut tokens = line.split_ascii_whitespace();
    let dim: u32 = parse_token(source, tokens.next(), "entity dimension")?;
    let entity: i64 = parse_token(source, tokens.next(), "entity tag")?;
    let third: u32 = parse_token(source, tokens.next(), third)?;
    let count: u64 = parse_token(source, tokens.next(), &format!("{kind} block size"))?;
    Ok((dim, entity, third, count))
}

/// An ASCII node line `x y z` (file units) followed by `extra` parametric coordinates, nothing
/// more.
fn ascii_node_coordinates(source: &mut Source<'_>, extra: usize) -> Result<DVec3, Error> {
    let line = source.content_line(None, "a node's coordinates")?;
    ascii_node_coordinates_after(source, line.split_ascii_whitespace(), extra)
}

/// The rest `tokens` of a node line: `x y z` (file units) followed by `extra` parametric
/// coordinates, nothing more.
pub(super) fn ascii_node_coordinates_after<'t>(
    source: &Source<'_>,
    mut tokens: impl Iterator<Item = &'t str>,
    extra: usize,
) -> Result<DVec3, Error> {
    let p = parse_point(source, &mut tokens)?;
    for _ in 0..extra {
        parse_finite(source, tokens.next(), "parametric coordinate")?;
    }
    end_of_line(
        source,
        tokens,
        ImportErrorKind::Syntax,
        "more numbers than a node's coordinates",
    )?;
    Ok(p)
}

/// The items a 4.1 section's blocks have announced so far, against the section's total.
pub(super) struct BlockCount {
    /// "a node block" / "an element block", for messages.
    block: &'static str,
    /// "node" / "element".
    kind: &'static str,
    /// The items the section header announces.
    total: usize,
    /// The items the blocks so far announce.
    read: usize,
}

impl BlockCount {
    /// No block counted yet of a section announcing `total` items.
    pub(super) fn new(block: &'static str, kind: &'static str, total: usize) -> Self {
        Self {
            block,
            kind,
            total,
            read: 0,
        }
    }

    /// Counts a block of `count` items, or [`ImportErrorKind::BadCount`] at `location` if it
    /// holds more than the section has left.
    pub(super) fn take(
        &mut self,
        source: &Source<'_>,
        location: FileLocation,
        count: u64,
    ) -> Result<usize, Error> {
        let count = usize::try_from(count).unwrap_or(usize::MAX);
        let left = self.total - self.read;
        if count > left {
            let (block, kind, total) = (self.block, self.kind, self.total);
            return Err(source.error_at(
                location,
                ImportErrorKind::BadCount,
                format!("{block} of {count} {kind}s, but {left} of the {total} announced remain"),
            ));
        }
        self.read += count;
        Ok(count)
    }

    /// [`ImportErrorKind::BadCount`] unless the blocks held the announced total.
    pub(super) fn finish(&self, source: &Source<'_>) -> Result<(), Error> {
        if self.read == self.total {
            return Ok(());
        }
        let (kind, read, total) = (self.kind, self.read, self.total);
        Err(source.error(
            ImportErrorKind::BadCount,
            format!("the {kind} blocks hold {read} {kind}s, the section header says {total}"),
        ))
    }
}
