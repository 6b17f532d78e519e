//! The `$Nodes` (or `$ParametricNodes`) and `$Elements` sections of MSH 2.2 (and 2.0, 2.1)
//! files.
//!
//! ASCII: a count line, then one node `tag x y z` or one element `tag type tag-count tags...
//! nodes...` per line. Binary: after the count line, nodes as `int tag, double x y z` records,
//! and elements in blocks of one type, a header `int type, int count, int tag-count` followed by
//! `count` records `int tag, int tags..., int nodes...`. A block holding no element or more than
//! the count left is an [`ImportErrorKind::BadCount`] error.

use super::Reader;
use super::elements::{MAX_NODES, nodes_per_element};
use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{Source, end_of_line, parse_finite, parse_point, parse_token};

impl Reader {
    /// Reads the body of a version 2 `$Nodes` section (after its first line).
    pub(super) fn nodes_v2(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let line = source.content_line(None, "the node count")?;
        let count: usize = parse_token(source, Some(line), "node count")?;
        if self.format.binary {
            source.set_binary(true);
            // Each node: int tag, three doubles.
            self.positions.reserve(source.capacity(count, 28));
            for _ in 0..count {
                let tag = self.format.read_i32(source, "a node tag")?;
                let p = self.format.read_point(source)?;
                self.add_node(source, tag as u64, p)?;
            }
        } else {
            self.positions.reserve(source.capacity(count, 8));
            for _ in 0..count {
                let line = source.content_line(None, "a node line `tag x y z`")?;
                let mut tokens = line.split_ascii_whitespace();
                let tag: u64 = parse_token(source, tokens.next(), "node tag")?;
                let p = parse_point(source, &mut tokens)?;
                self.add_node(source, tag, p)?;
            }
        }
        Ok(())
    }

    /// Reads the body of a version 2 `$ParametricNodes` section (after its first line): ASCII
    /// lines `tag x y z dim entity` followed by the node's `dim` parametric coordinates on a
    /// curve (1) or a surface (2), none on a point or in a volume; `tag x y z` alone for a node
    /// on no geometric entity.
    pub(super) fn parametric_nodes_v2(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        if self.format.binary {
            return Err(source.error(
                ImportErrorKind::UnknownVersion,
                "binary `$ParametricNodes` are not read: save without parametric coordinates",
            ));
        }
        let line = source.content_line(None, "the node count")?;
        let count: usize = parse_token(source, Some(line), "node count")?;
        self.positions.reserve(source.capacity(count, 12));
        for _ in 0..count {
            let line = source.content_line(None, "a node line `tag x y z dim entity u v`")?;
            let mut tokens = line.split_ascii_whitespace();
            let tag: u64 = parse_token(source, tokens.next(), "node tag")?;
            let p = parse_point(source, &mut tokens)?;
            let mut tokens = tokens.peekable();
            if tokens.peek().is_none() {
                // A node on no geometric entity.
                self.add_node(source, tag, p)?;
                continue;
            }
            let dim: u32 = parse_token(source, tokens.next(), "geometric entity dimension")?;
            let _: i64 = parse_token(source, tokens.next(), "geometric entity tag")?;
            let parameters = match dim {
                0 | 3 => 0,
                1 | 2 => dim as usize,
                _ => {
                    return Err(source.error(
                        ImportErrorKind::Syntax,
                        format!("geometric entity dimension {dim} is not 0 to 3"),
                    ));
                }
            };
            for _ in 0..parameters {
                parse_finite(source, tokens.next(), "parametric coordinate")?;
            }
            end_of_line(
                source,
                tokens,
                ImportErrorKind::BadCount,
                "more numbers than a parametric node's",
            )?;
            self.add_node(source, tag, p)?;
        }
        Ok(())
    }

    /// Reads the body of a version 2 `$Elements` section (after its first line).
    pub(super) fn elements_v2(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let line = source.content_line(None, "the element count")?;
        let count: usize = parse_token(source, Some(line), "element count")?;
        if self.format.binary {
            source.set_binary(true);
            let mut read = 0;
            while read < count {
                read += self.binary_element_block_v2(source, count - read, count)?;
            }
        } else {
            for _ in 0..count {
                let line = source.content_line(None, "an element line")?;
                let mut tokens = line.split_ascii_whitespace();
                let _tag: u64 = parse_token(source, tokens.next(), "element tag")?;
                let element_type: u32 = parse_token(source, tokens.next(), "element type")?;
                let tag_count: usize = parse_token(source, tokens.next(), "tag count")?;
                self.regions.current.clear();
                for k in 0..tag_count {
                    let tag: i64 = parse_token(source, tokens.next(), "element tag")?;
                    // The first tag is the physical group (0: none).
                    if k == 0 && tag != 0 {
                        self.regions.current.push(tag);
                    }
                }
                self.element_line(source, element_type, tokens)?;
            }
        }
        Ok(())
    }

    /// Reads one block of elements of a binary version 2 `$Elements` section, of which `left`
    /// of the `count` announced remain; returns how many elements it held.
    fn binary_element_block_v2(
        &mut self,
        source: &mut Source<'_>,
        left: usize,
        count: usize,
    ) -> Result<usize, Error> {
        let format = self.format;
        let location = source.location();
        let element_type = format.read_u32(source, "an element type")?;
        let following = format.read_u32(source, "an element block size")? as usize;
        let tag_count = format.read_u32(source, "a tag count")? as usize;
        if following == 0 || following > left {
            return Err(source.error_at(
                location,
                ImportErrorKind::BadCount,
                format!(
                    "an element block of {following} elements, but {left} of the {count} \
                     announced remain"
                ),
            ));
        }
        let node_count = nodes_per_element(source, location, element_type)?;
        let mut nodes = [0u64; MAX_NODES];
        for _ in 0..following {
            let location = source.location();
            format.read_i32(source, "an element tag")?;
            self.regions.current.clear();
            for k in 0..tag_count {
                let tag = format.read_i32(source, "an element's tag")?;
                // The first tag is the physical group (0: none).
                if k == 0 && tag != 0 {
                    self.regions.current.push(i64::from(tag));
                }
            }
            for node in nodes.iter_mut().take(node_count) {
                *node = format.read_i32(source, "an element's node")? as u32 as u64;
            }
            self.add_element(source, location, element_type, &nodes[..node_count])?;
        }
        Ok(following)
    }
}
