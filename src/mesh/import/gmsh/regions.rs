//! Gmsh's physical groups, kept as the mesh's named regions.
//!
//! `$PhysicalNames` gives each group (dimension, tag) its name. An element belongs to the groups
//! of its physical tags: in version 2 the first of its tags (0 for none); in version 4.1 those of
//! the entity its block belongs to, listed in `$Entities` (ASCII or binary). A region holds the
//! nodes of its elements (and, for a volume group, its tetrahedra). Version 4.0 files keep no
//! regions (their `$Entities` are skipped).

use super::format::MshFormat;
use super::{FileLocation, MeshRegion};
use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{Source, parse_token};
use std::collections::{BTreeMap, HashMap};

/// A group: its dimension and physical tag.
type Group = (u8, i64);

/// The groups read so far.
#[derive(Default)]
pub(super) struct Regions {
    /// `$PhysicalNames`.
    names: HashMap<Group, String>,
    /// Version 4.1 entities (dimension, entity tag) and their physical tags.
    entities: HashMap<Group, Vec<i64>>,
    /// The physical tags of the elements being read (set per element or per block).
    pub(super) current: Vec<i64>,
    /// Each group's elements' node tags, and its tetrahedra (indices in file order).
    nodes: BTreeMap<Group, Vec<u64>>,
    tets: BTreeMap<Group, Vec<u32>>,
}

impl Regions {
    /// Sets the physical tags of the elements of a version 4.1 block of entity `(dim, tag)`.
    pub(super) fn enter_entity(&mut self, dim: u8, tag: i64) {
        self.current = self.entities.get(&(dim, tag)).cloned().unwrap_or_default();
    }

    /// Records an element of dimension `dim` with node tags `nodes` (the tetrahedra `tets` it
    /// became, none for a lower-dimensional element) in the groups of [`Regions::current`].
    pub(super) fn record(&mut self, dim: u8, nodes: &[u64], tets: std::ops::Range<u32>) {
        for &physical in &self.current {
            self.nodes
                .entry((dim, physical))
                .or_default()
                .extend_from_slice(nodes);
            if !tets.is_empty() {
                self.tets
                    .entry((dim, physical))
                    .or_default()
                    .extend(tets.clone());
            }
        }
    }

    /// Reads the body of `$PhysicalNames` (after its first line): a count, then `dim tag "name"`
    /// lines.
    pub(super) fn read_names(&mut self, source: &mut Source<'_>) -> Result<(), Error> {
        let line = source.content_line(None, "the physical name count")?;
        let count: usize = parse_token(source, Some(line), "physical name count")?;
        for _ in 0..count {
            let line = source.content_line(None, "a physical name `dim tag \"name\"`")?;
            let mut tokens = line.splitn(3, char::is_whitespace);
            let dim: u8 = parse_token(source, tokens.next(), "physical group dimension")?;
            let tag: i64 = parse_token(source, tokens.next(), "physical tag")?;
            let name = tokens.next().unwrap_or("").trim();
            let Some(name) = name.strip_prefix('"').and_then(|n| n.strip_suffix('"')) else {
                return Err(source.error(
                    ImportErrorKind::Syntax,
                    "a physical name is not in double quotes",
                ));
            };
            self.names.insert((dim, tag), name.to_owned());
        }
        Ok(())
    }

    /// Reads the body of a version 4.1 `$Entities` section (after its first line): the
    /// physical tags of every point, curve, surface and volume.
    pub(super) fn read_entities(
        &mut self,
        source: &mut Source<'_>,
        format: MshFormat,
    ) -> Result<(), Error> {
        let counts: [u64; 4] = if format.binary {
            source.set_binary(true);
            let mut counts = [0; 4];
            for count in &mut counts {
                *count = format.read_size(source, "an entity count")?;
            }
            counts
        } else {
            let line = source.content_line(None, "the entity counts")?;
            let mut tokens = line.split_ascii_whitespace();
            let mut counts = [0; 4];
            for count in &mut counts {
                *count = parse_token(source, tokens.next(), "entity count")?;
            }
            counts
        };
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let (tag, physicals) = if format.binary {
                    binary_entity(source, format, dim)?
                } else {
                    ascii_entity(source, dim)?
                };
                self.entities.insert((dim as u8, tag), physicals);
            }
        }
        source.set_binary(false);
        Ok(())
    }

    /// The regions, their node tags resolved by `index` (`None` for a tag no node has: an
    /// error at the file).
    pub(super) fn finish(
        self,
        source: &Source<'_>,
        index: impl Fn(u64) -> Option<u32>,
    ) -> Result<Vec<MeshRegion>, Error> {
        let mut regions = Vec::with_capacity(self.nodes.len());
        for ((dimension, tag), tags) in self.nodes {
            let mut nodes = Vec::with_capacity(tags.len());
            for node in tags {
                nodes.push(index(node).ok_or_else(|| {
                    source.error_at(
                        FileLocation::Whole,
                        ImportErrorKind::IndexOutOfRange,
                        format!("physical group {tag} refers to node {node}, which is not defined"),
                    )
                })?);
            }
            nodes.sort_unstable();
            nodes.dedup();
            regions.push(MeshRegion {
                name: self
                    .names
                    .get(&(dimension, tag))
                    .cloned()
                    .unwrap_or_default(),
                dimension,
                tag,
                nodes,
                tets: self
                    .tets
                    .get(&(dimension, tag))
                    .cloned()
                    .unwrap_or_default(),
            });
        }
        Ok(regions)
    }
}

/// One ASCII entity line of dimension `dim`: its tag and physical tags.
fn ascii_entity(source: &mut Source<'_>, dim: usize) -> Result<(i64, Vec<i64>), Error> {
    let line = source.content_line(None, "an entity line")?;
    let mut tokens = line.split_ascii_whitespace();
    let tag: i64 = parse_token(source, tokens.next(), "entity tag")?;
    // A point's coordinates, or a bounding box.
    let coordinates = if dim == 0 { 3 } else { 6 };
    for _ in 0..coordinates {
        let _: f64 = parse_token(source, tokens.next(), "entity coordinate")?;
    }
    let count: usize = parse_token(source, tokens.next(), "physical tag count")?;
    let mut physicals = Vec::with_capacity(count.min(line.len()));
    for _ in 0..count {
        physicals.push(parse_token(source, tokens.next(), "physical tag")?);
    }
    Ok((tag, physicals))
}

/// One binary entity of dimension `dim`: its tag and physical tags (its bounding entities read
/// past).
fn binary_entity(
    source: &mut Source<'_>,
    format: MshFormat,
    dim: usize,
) -> Result<(i64, Vec<i64>), Error> {
    let tag = i64::from(format.read_i32(source, "an entity tag")?);
    let coordinates = if dim == 0 { 3 } else { 6 };
    for _ in 0..coordinates {
        format.read_f64(source, "an entity coordinate")?;
    }
    let count = format.read_size(source, "a physical tag count")?;
    let mut physicals = Vec::with_capacity(source.capacity(count as usize, 4));
    for _ in 0..count {
        physicals.push(i64::from(format.read_i32(source, "a physical tag")?));
    }
    if dim > 0 {
        let bounding = format.read_size(source, "a bounding entity count")?;
        for _ in 0..bounding {
            format.read_i32(source, "a bounding entity tag")?;
        }
    }
    Ok((tag, physicals))
}
