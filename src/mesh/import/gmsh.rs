//! Gmsh `.msh` files, versions 2.2 and 4.1, ASCII and binary.
//!
//! Linear tetrahedra (element type 4) and quadratic ones (type 11, `gmsh -order 2`; their
//! mid-edge nodes go to [`RawMesh::mid_edge_nodes`]) are read; points, lines, triangles and
//! quadrangles (boundary and geometry elements Gmsh saves beside the volume) are skipped; other
//! volume elements, and linear and quadratic tetrahedra mixed in one file, are an
//! [`ImportErrorKind::UnsupportedElement`] error, since dropping them would silently lose
//! material. Sections other than `$MeshFormat`, `$Nodes` and `$Elements` are skipped.
//!
//! Hand-written rather than built on the `mshio` crate (0.4.2, the only MSH crate): it reads
//! version 4.1 only, while 2.2, which many tools still write, needs this reader anyway; and it
//! panics on a malformed header, e.g. a data size of `0` (`4.1 0 0`: "not implemented: No
//! parser for input unsigned integer size of 0 bytes") or one that overflows (`4.1 0
//! 4000000000`: an `unwrap` on `ParseIntError`), found by mutating a valid file.

use super::text::{Source, finite, parse_finite, parse_token, scaled, shorten};
use super::{RawMesh, check_scale};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// Gmsh's linear tetrahedron.
const TETRAHEDRON: u32 = 4;
/// Gmsh's quadratic (10-node) tetrahedron.
const QUADRATIC_TETRAHEDRON: u32 = 11;

/// The node count of Gmsh's element type `element_type`, or
/// [`ImportErrorKind::UnsupportedElement`] at `location` for a type it does not define.
fn nodes_per_element(
    source: &Source<'_>,
    location: FileLocation,
    element_type: u32,
) -> Result<usize, Error> {
    element_shape(element_type)
        .map(|(nodes, _)| nodes)
        .ok_or_else(|| {
            source.error_at(
                location,
                ImportErrorKind::UnsupportedElement,
                format!("unknown element type {element_type}"),
            )
        })
}

/// Nodes per element and dimension of Gmsh's element types 1 to 31.
fn element_shape(element_type: u32) -> Option<(usize, u8)> {
    Some(match element_type {
        1 => (2, 1),
        2 => (3, 2),
        3 => (4, 2),
        4 => (4, 3),
        5 => (8, 3),
        6 => (6, 3),
        7 => (5, 3),
        8 => (3, 1),
        9 => (6, 2),
        10 => (9, 2),
        11 => (10, 3),
        12 => (27, 3),
        13 => (18, 3),
        14 => (14, 3),
        15 => (1, 0),
        16 => (8, 2),
        17 => (20, 3),
        18 => (15, 3),
        19 => (13, 3),
        20 => (9, 2),
        21 => (10, 2),
        22 => (12, 2),
        23 | 24 => (15, 2),
        25 => (21, 2),
        26 => (4, 1),
        27 => (5, 1),
        28 => (6, 1),
        29 => (20, 3),
        30 => (35, 3),
        31 => (56, 3),
        _ => return None,
    })
}

/// Reads the Gmsh file `data` (named `path` in errors), coordinates times `scale` (m per file
/// unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a malformed file, an
/// unknown version, an unsupported element type or a file without tetrahedra.
pub fn parse(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let mut source = Source::new(path, data);
    let header = source.content_line(None, "`$MeshFormat`")?;
    if header != "$MeshFormat" {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!(
                "a Gmsh file starts with `$MeshFormat`, not `{}`",
                shorten(header)
            ),
        ));
    }
    let format = read_format(&mut source)?;
    let mut reader = Reader {
        format,
        scale,
        node_index: HashMap::new(),
        positions: Vec::new(),
        tets: Vec::new(),
        mid_edge_tags: Vec::new(),
    };
    let mut saw_nodes = false;
    while let Some(line) = source.line()? {
        match line {
            "" => {}
            "$Nodes" => {
                if saw_nodes {
                    return Err(source.error(
                        ImportErrorKind::Syntax,
                        "a second `$Nodes` section: partitioned files are not supported",
                    ));
                }
                saw_nodes = true;
                if format.version == Version::V2 {
                    reader.nodes_v2(&mut source)?;
                } else {
                    reader.nodes_v4(&mut source)?;
                }
                expect_end(&mut source, "$EndNodes")?;
            }
            "$Elements" => {
                if format.version == Version::V2 {
                    reader.elements_v2(&mut source)?;
                } else {
                    reader.elements_v4(&mut source)?;
                }
                expect_end(&mut source, "$EndElements")?;
            }
            _ if line.starts_with('$') && !line.starts_with("$End") => {
                let end = format!("$End{}", &line[1..]);
                source.skip_past(end.as_bytes())?;
            }
            _ => {
                return Err(source.error(
                    ImportErrorKind::Syntax,
                    format!(
                        "expected a section such as `$Nodes`, found `{}`",
                        shorten(line)
                    ),
                ));
            }
        }
    }
    reader.finish(&source)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Version {
    /// 2.0, 2.1 or 2.2: one node or element per line (or record), tags of any value.
    V2,
    /// 4.1: nodes and elements in entity blocks.
    V4,
}

#[derive(Debug, Clone, Copy)]
struct MshFormat {
    version: Version,
    binary: bool,
    little_endian: bool,
    /// Size of the integers written as `size_t` in binary 4.1 files (4 or 8).
    size_t: usize,
}

/// Reads the rest of `$MeshFormat` (after its first line) up to `$EndMeshFormat`.
fn read_format(source: &mut Source<'_>) -> Result<MshFormat, Error> {
    let line = source.content_line(None, "the format line `version file-type data-size`")?;
    let mut tokens = line.split_ascii_whitespace();
    let version_text = tokens.next().unwrap_or("");
    let version = match version_text {
        "2" | "2.0" | "2.1" | "2.2" => Version::V2,
        "4.1" => Version::V4,
        _ => {
            return Err(source.error(
                ImportErrorKind::UnknownVersion,
                format!(
                    "MSH version `{}` is not supported (2.2 and 4.1 are)",
                    shorten(version_text)
                ),
            ));
        }
    };
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
    let size_ok = match version {
        Version::V2 => data_size == 8,
        Version::V4 => data_size == 4 || data_size == 8,
    };
    if !size_ok {
        return Err(source.error(
            ImportErrorKind::UnknownVersion,
            format!("data size {data_size} is not supported"),
        ));
    }
    let mut little_endian = true;
    if binary {
        // The integer 1 written in the file's byte order.
        let one = source.take(4, "the byte-order mark")?;
        let one = [one[0], one[1], one[2], one[3]];
        little_endian = if i32::from_le_bytes(one) == 1 {
            true
        } else if i32::from_be_bytes(one) == 1 {
            false
        } else {
            return Err(source.error(
                ImportErrorKind::Syntax,
                "the binary byte-order mark is not the integer 1",
            ));
        };
    }
    expect_end(source, "$EndMeshFormat")?;
    Ok(MshFormat {
        version,
        binary,
        little_endian,
        size_t: data_size,
    })
}

/// Skips whitespace and requires the line `marker`.
fn expect_end(source: &mut Source<'_>, marker: &str) -> Result<(), Error> {
    source.skip_whitespace();
    let line = source.content_line(None, marker)?;
    if line == marker {
        Ok(())
    } else {
        Err(source.error(
            ImportErrorKind::BadCount,
            format!(
                "expected `{marker}`, found `{}`: the section holds more or other data than its \
                 counts say",
                shorten(line)
            ),
        ))
    }
}

struct Reader {
    format: MshFormat,
    scale: f64,
    /// Node tag to index into `positions`.
    node_index: HashMap<u64, u32>,
    positions: Vec<DVec3>,
    /// Tetrahedra as node tags, with where they were read.
    tets: Vec<([u64; 4], FileLocation)>,
    /// The mid-edge node tags of quadratic tetrahedra, in Gmsh's order, one per tetrahedron.
    mid_edge_tags: Vec<[u64; 6]>,
}

impl Reader {
    fn add_node(&mut self, source: &Source<'_>, tag: u64, p: DVec3) -> Result<(), Error> {
        let p = scaled(source, p, self.scale)?;
        if self.positions.len() >= u32::MAX as usize {
            return Err(source.error(ImportErrorKind::BadCount, "more than 2^32 - 1 nodes"));
        }
        let index = self.positions.len() as u32;
        if self.node_index.insert(tag, index).is_some() {
            return Err(source.error(
                ImportErrorKind::DuplicateId,
                format!("node tag {tag} is defined twice"),
            ));
        }
        self.positions.push(p);
        Ok(())
    }

    /// Handles an element of `element_type` with node tags `nodes`: keeps tetrahedra, skips
    /// lower-dimensional elements, rejects other volume elements.
    fn add_element(
        &mut self,
        source: &Source<'_>,
        location: FileLocation,
        element_type: u32,
        nodes: &[u64],
    ) -> Result<(), Error> {
        let quadratic = element_type == QUADRATIC_TETRAHEDRON;
        if matches!(element_type, TETRAHEDRON | QUADRATIC_TETRAHEDRON)
            && !self.tets.is_empty()
            && quadratic == self.mid_edge_tags.is_empty()
        {
            return Err(source.error_at(
                location,
                ImportErrorKind::UnsupportedElement,
                "linear (type 4) and quadratic (type 11) tetrahedra mixed in one mesh",
            ));
        }
        match element_type {
            TETRAHEDRON | QUADRATIC_TETRAHEDRON => {
                self.tets
                    .push(([nodes[0], nodes[1], nodes[2], nodes[3]], location));
                if quadratic {
                    // Gmsh numbers the edges (0,1) (1,2) (0,2) (0,3) (2,3) (1,3); the last two
                    // are swapped into VTK's order.
                    self.mid_edge_tags
                        .push([nodes[4], nodes[5], nodes[6], nodes[7], nodes[9], nodes[8]]);
                }
                Ok(())
            }
            _ => match element_shape(element_type) {
                Some((_, 3)) => Err(source.error_at(
                    location,
                    ImportErrorKind::UnsupportedElement,
                    format!(
                        "volume element type {element_type} mixed with the tetrahedra: only \
                         linear tetrahedra (type 4) can be used"
                    ),
                )),
                Some(_) => Ok(()),
                None => Err(source.error_at(
                    location,
                    ImportErrorKind::UnsupportedElement,
                    format!("unknown element type {element_type}"),
                )),
            },
        }
    }

    fn read_i32(&self, source: &mut Source<'_>, what: &str) -> Result<i32, Error> {
        if self.format.little_endian {
            source.binary(i32::from_le_bytes, what)
        } else {
            source.binary(i32::from_be_bytes, what)
        }
    }

    fn read_f64(&self, source: &mut Source<'_>, what: &str) -> Result<f64, Error> {
        let value = if self.format.little_endian {
            source.binary(f64::from_le_bytes, what)?
        } else {
            source.binary(f64::from_be_bytes, what)?
        };
        finite(source, value, what)
    }

    fn read_size(&self, source: &mut Source<'_>, what: &str) -> Result<u64, Error> {
        Ok(match (self.format.size_t, self.format.little_endian) {
            (4, true) => u64::from(source.binary(u32::from_le_bytes, what)?),
            (4, false) => u64::from(source.binary(u32::from_be_bytes, what)?),
            (_, true) => source.binary(u64::from_le_bytes, what)?,
            (_, false) => source.binary(u64::from_be_bytes, what)?,
        })
    }

    /// A non-negative binary `int` as a `u32`.
    fn read_u32(&self, source: &mut Source<'_>, what: &str) -> Result<u32, Error> {
        let value = self.read_i32(source, what)?;
        u32::try_from(value).map_err(|_| {
            source.error(
                ImportErrorKind::Syntax,
                format!("{what} is {value}, negative"),
            )
        })
    }

    fn read_point(&self, source: &mut Source<'_>) -> Result<DVec3, Error> {
        let x = self.read_f64(source, "a node's x coordinate")?;
        let y = self.read_f64(source, "a node's y coordinate")?;
        let z = self.read_f64(source, "a node's z coordinate")?;
        Ok(DVec3::new(x, y, z))
    }

    fn nodes_v2(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let line = source.content_line(None, "the node count")?;
        let count: usize = parse_token(source, Some(line), "node count")?;
        if self.format.binary {
            source.set_binary(true);
            // Each node: int tag, three doubles.
            self.positions.reserve(source.capacity(count, 28));
            for _ in 0..count {
                let tag = self.read_i32(source, "a node tag")?;
                let p = self.read_point(source)?;
                self.add_node(source, tag as u64, p)?;
            }
        } else {
            self.positions.reserve(source.capacity(count, 8));
            for _ in 0..count {
                let line = source.content_line(None, "a node line `tag x y z`")?;
                let mut tokens = line.split_ascii_whitespace();
                let tag: u64 = parse_token(source, tokens.next(), "node tag")?;
                let x = parse_finite(source, tokens.next(), "x coordinate")?;
                let y = parse_finite(source, tokens.next(), "y coordinate")?;
                let z = parse_finite(source, tokens.next(), "z coordinate")?;
                self.add_node(source, tag, DVec3::new(x, y, z))?;
            }
        }
        Ok(())
    }

    fn elements_v2(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let line = source.content_line(None, "the element count")?;
        let count: usize = parse_token(source, Some(line), "element count")?;
        if self.format.binary {
            source.set_binary(true);
            let mut read = 0;
            while read < count {
                let location = source.location();
                let element_type = self.read_u32(source, "an element type")?;
                let following = self.read_u32(source, "an element block size")? as usize;
                let tag_count = self.read_u32(source, "a tag count")? as usize;
                if following == 0 || following > count - read {
                    return Err(source.error_at(
                        location,
                        ImportErrorKind::BadCount,
                        format!(
                            "an element block of {following} elements, but {} of the {count} \
                             announced remain",
                            count - read
                        ),
                    ));
                }
                let node_count = nodes_per_element(source, location, element_type)?;
                let mut nodes = [0u64; 56];
                for _ in 0..following {
                    let location = source.location();
                    self.read_i32(source, "an element tag")?;
                    for _ in 0..tag_count {
                        self.read_i32(source, "an element's tag")?;
                    }
                    for node in nodes.iter_mut().take(node_count) {
                        *node = self.read_i32(source, "an element's node")? as u32 as u64;
                    }
                    self.add_element(source, location, element_type, &nodes[..node_count])?;
                }
                read += following;
            }
        } else {
            for _ in 0..count {
                let line = source.content_line(None, "an element line")?;
                let mut tokens = line.split_ascii_whitespace();
                let _tag: u64 = parse_token(source, tokens.next(), "element tag")?;
                let element_type: u32 = parse_token(source, tokens.next(), "element type")?;
                let tag_count: usize = parse_token(source, tokens.next(), "tag count")?;
                for _ in 0..tag_count {
                    let _: i64 = parse_token(source, tokens.next(), "element tag")?;
                }
                self.element_line(source, element_type, tokens)?;
            }
        }
        Ok(())
    }

    /// The node tags of an ASCII element line (after its type and tags), checked against the
    /// type's node count.
    fn element_line<'t>(
        &mut self,
        source: &Source<'_>,
        element_type: u32,
        tokens: impl Iterator<Item = &'t str>,
    ) -> Result<(), Error> {
        let location = source.location();
        let node_count = nodes_per_element(source, location, element_type)?;
        let mut nodes = [0u64; 56];
        let mut n = 0;
        for token in tokens {
            if n == node_count {
                return Err(source.error(
                    ImportErrorKind::BadCount,
                    format!("more than the {node_count} nodes of element type {element_type}"),
                ));
            }
            nodes[n] = parse_token(source, Some(token), "node tag")?;
            n += 1;
        }
        if n < node_count {
            return Err(source.error(
                ImportErrorKind::BadCount,
                format!("{n} nodes, but element type {element_type} has {node_count}"),
            ));
        }
        self.add_element(source, location, element_type, &nodes[..node_count])
    }

    fn nodes_v4(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = self.block_header(source, "node")?;
        let mut blocks_read = BlockCount::new("a node block", "node", total);
        for _ in 0..blocks {
            let location = source.location();
            let (dim, parametric, count) = if self.format.binary {
                let dim = self.read_u32(source, "an entity dimension")?;
                self.read_i32(source, "an entity tag")?;
                let parametric = self.read_u32(source, "the parametric flag")?;
                let count = self.read_size(source, "a node block size")?;
                (dim, parametric, count)
            } else {
                let line = source.content_line(None, "a node block header")?;
                let mut tokens = line.split_ascii_whitespace();
                let dim: u32 = parse_token(source, tokens.next(), "entity dimension")?;
                let _: i64 = parse_token(source, tokens.next(), "entity tag")?;
                let parametric: u32 = parse_token(source, tokens.next(), "parametric flag")?;
                let count: u64 = parse_token(source, tokens.next(), "node block size")?;
                (dim, parametric, count)
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
            // Tags first, then coordinates.
            let mut tags = Vec::with_capacity(source.capacity(count, 2));
            for _ in 0..count {
                let tag = if self.format.binary {
                    self.read_size(source, "a node tag")?
                } else {
                    let line = source.content_line(None, "a node tag")?;
                    parse_token(source, Some(line), "node tag")?
                };
                tags.push(tag);
            }
            for tag in tags {
                let p = if self.format.binary {
                    let p = self.read_point(source)?;
                    for _ in 0..extra {
                        self.read_f64(source, "a parametric coordinate")?;
                    }
                    p
                } else {
                    let line = source.content_line(None, "a node's coordinates")?;
                    let mut tokens = line.split_ascii_whitespace();
                    let x = parse_finite(source, tokens.next(), "x coordinate")?;
                    let y = parse_finite(source, tokens.next(), "y coordinate")?;
                    let z = parse_finite(source, tokens.next(), "z coordinate")?;
                    for _ in 0..extra {
                        parse_finite(source, tokens.next(), "parametric coordinate")?;
                    }
                    if tokens.next().is_some() {
                        return Err(source.error(
                            ImportErrorKind::Syntax,
                            "more numbers than a node's coordinates",
                        ));
                    }
                    DVec3::new(x, y, z)
                };
                self.add_node(source, tag, p)?;
            }
        }
        blocks_read.finish(source)
    }

    fn elements_v4(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let (blocks, total) = self.block_header(source, "element")?;
        let mut blocks_read = BlockCount::new("an element block", "element", total);
        for _ in 0..blocks {
            let location = source.location();
            let (element_type, count) = if self.format.binary {
                self.read_i32(source, "an entity dimension")?;
                self.read_i32(source, "an entity tag")?;
                let element_type = self.read_u32(source, "an element type")?;
                let count = self.read_size(source, "an element block size")?;
                (element_type, count)
            } else {
                let line = source.content_line(None, "an element block header")?;
                let mut tokens = line.split_ascii_whitespace();
                let _: u32 = parse_token(source, tokens.next(), "entity dimension")?;
                let _: i64 = parse_token(source, tokens.next(), "entity tag")?;
                let element_type: u32 = parse_token(source, tokens.next(), "element type")?;
                let count: u64 = parse_token(source, tokens.next(), "element block size")?;
                (element_type, count)
            };
            let count = blocks_read.take(source, location, count)?;
            let node_count = nodes_per_element(source, location, element_type)?;
            let mut nodes = [0u64; 56];
            for _ in 0..count {
                if self.format.binary {
                    let location = source.location();
                    self.read_size(source, "an element tag")?;
                    for node in nodes.iter_mut().take(node_count) {
                        *node = self.read_size(source, "an element's node")?;
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
        let (blocks, total) = if self.format.binary {
            source.set_binary(true);
            let blocks = self.read_size(source, "the entity block count")?;
            let total = self.read_size(source, "the total count")?;
            self.read_size(source, "the minimum tag")?;
            self.read_size(source, "the maximum tag")?;
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

    fn finish(self, source: &Source<'_>) -> Result<RawMesh, Error> {
        if self.tets.is_empty() {
            return Err(source.error_at(
                FileLocation::Whole,
                ImportErrorKind::NoTetrahedra,
                "the file holds no tetrahedra (element type 4 or 11)",
            ));
        }
        let index = |tag: &u64, location: FileLocation| {
            self.node_index.get(tag).copied().ok_or_else(|| {
                source.error_at(
                    location,
                    ImportErrorKind::IndexOutOfRange,
                    format!("the tetrahedron refers to node {tag}, which is not defined"),
                )
            })
        };
        let mut tets = Vec::with_capacity(self.tets.len());
        let mut tet_locations = Vec::with_capacity(self.tets.len());
        for (tags, location) in &self.tets {
            let mut tet = [0u32; 4];
            for (corner, tag) in tags.iter().enumerate() {
                tet[corner] = index(tag, *location)?;
            }
            tets.push(tet);
            tet_locations.push(*location);
        }
        let mut mid_edge_nodes = Vec::with_capacity(self.mid_edge_tags.len());
        for (tags, (_, location)) in self.mid_edge_tags.iter().zip(&self.tets) {
            let mut mids = [0u32; 6];
            for (k, tag) in tags.iter().enumerate() {
                mids[k] = index(tag, *location)?;
            }
            mid_edge_nodes.push(mids);
        }
        Ok(RawMesh {
            path: source.path().to_owned(),
            positions: self.positions,
            tets,
            mid_edge_nodes,
            tet_locations,
        })
    }
}

/// The items a 4.1 section's blocks have announced so far, against the section's total.
struct BlockCount {
    /// "a node block" / "an element block", for messages.
    block: &'static str,
    /// "node" / "element".
    kind: &'static str,
    total: usize,
    read: usize,
}

impl BlockCount {
    fn new(block: &'static str, kind: &'static str, total: usize) -> Self {
        Self {
            block,
            kind,
            total,
            read: 0,
        }
    }

    /// Counts a block of `count` items, or [`ImportErrorKind::BadCount`] at `location` if it
    /// holds more than the section has left.
    fn take(
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
    fn finish(&self, source: &Source<'_>) -> Result<(), Error> {
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
