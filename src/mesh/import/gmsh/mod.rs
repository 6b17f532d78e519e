//! Gmsh `.msh` files, versions 2.2 and 4.1, ASCII and binary, and 4.0 (ASCII, as gmsh writes
//! it).
//!
//! Linear tetrahedra (element type 4) and quadratic ones (type 11, `gmsh -order 2`; their
//! mid-edge nodes go to [`RawMesh::mid_edge_nodes`]) are read, and hexahedra, linear (type 5)
//! and 27-node (type 12), split into tetrahedra ([`RawMesh::hexahedra`]); points, lines, triangles and
//! quadrangles (boundary and geometry elements Gmsh saves beside the volume) are skipped; other
//! volume elements, and two kinds of volume element mixed in one file, are an
//! [`ImportErrorKind::UnsupportedElement`] error, since dropping them would silently lose
//! material. A file holding triangles but no tetrahedra is a surface ([`parse_surface`]), which
//! [`load`](super::load) fills as an OBJ or STL surface. Sections other than `$MeshFormat`,
//! `$Nodes` (or, in version 2, `$ParametricNodes`: nodes with their place on the geometry,
//! ASCII), `$Elements`, `$PhysicalNames` and (in 4.1) `$Entities` are skipped; physical groups
//! become [`RawMesh::regions`] (`regions`); a second nodes section (a partitioned file) is refused.
//!
//! Hand-written rather than built on the `mshio` crate (0.4.2, the only MSH crate): it reads
//! version 4.1 only, while 2.2, which many tools still write, needs this reader anyway; and it
//! panics on a malformed header, e.g. a data size of `0` (`4.1 0 0`: "not implemented: No
//! parser for input unsigned integer size of 0 bytes") or one that overflows (`4.1 0
//! 4000000000`: an `unwrap` on `ParseIntError`), found by mutating a valid file.
//!
//! This module reads the file's sections in order and resolves the tetrahedra's node tags;
//! its submodules read the `$MeshFormat` header and binary values (`format`), the element
//! types (`elements`), and the `$Nodes` and `$Elements` sections of versions 2.2 (`v2`), 4.1
//! (`v4`) and 4.0 (`v40`).

mod elements;
mod format;
mod regions;
mod v2;
mod v4;
mod v40;

use super::surface::Surface;
use super::text::{Source, scaled, shorten};
use super::{Hexahedra, MeshRegion, RawMesh, check_scale};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::hex_split::{TETS_PER_HEXAHEDRON, TETS_PER_LATTICE};
use format::{MshFormat, Version};
use rapier3d::glamx::DVec3;
use std::collections::HashMap;

/// Reads the Gmsh file `data` (named `path` in errors), coordinates times `scale` (m per file
/// unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a malformed file, an
/// unknown version, an unsupported element type or a file without tetrahedra.
pub fn parse(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    let (reader, source) = read(data, path, scale)?;
    reader.finish(&source)
}

/// Reads the triangles of the Gmsh file `data` (named `path` in errors), a surface mesh
/// (gmsh's 2D mesh of a volume's boundary, as [`surface::fill`](super::surface::fill) takes),
/// coordinates times `scale` (m per file unit). [`load`](super::load) reads a `.msh` file
/// holding no tetrahedra so.
///
/// # Errors
/// Those of [`parse`], except that the file needs linear triangles (element type 2) instead of
/// tetrahedra: [`ImportErrorKind::NoTetrahedra`] for a file with neither,
/// [`ImportErrorKind::UnsupportedElement`] for other surface elements (quadrangles, curved
/// triangles) beside them.
pub fn parse_surface(data: &[u8], path: &str, scale: f64) -> Result<Surface, Error> {
    let (reader, source) = read(data, path, scale)?;
    reader.finish_surface(&source)
}

/// Reads every section of the Gmsh file `data`.
fn read<'d>(data: &'d [u8], path: &'d str, scale: f64) -> Result<(Reader, Source<'d>), Error> {
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
    let mut reader = Reader {
        format: format::read_format(&mut source)?,
        scale,
        saw_nodes: false,
        node_index: HashMap::new(),
        positions: Vec::new(),
        tets: Vec::new(),
        mid_edge_tags: Vec::new(),
        volume_type: None,
        hexahedron_tags: Vec::new(),
        cage_tags: Vec::new(),
        triangles: Vec::new(),
        other_surface_element: None,
        regions: regions::Regions::default(),
    };
    while let Some(line) = source.line()? {
        reader.section(&mut source, line)?;
    }
    Ok((reader, source))
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

/// What the sections read so far hold: nodes by tag, tetrahedra by node tag.
struct Reader {
    format: MshFormat,
    /// Metres per file unit.
    scale: f64,
    /// Whether a `$Nodes` section has been read (a second one is refused).
    saw_nodes: bool,
    /// Node tag to index into `positions`.
    node_index: HashMap<u64, u32>,
    /// Node positions (m).
    positions: Vec<DVec3>,
    /// Tetrahedra as node tags, with where they were read.
    tets: Vec<([u64; 4], FileLocation)>,
    /// The mid-edge node tags of quadratic tetrahedra, in VTK's order, one per tetrahedron.
    mid_edge_tags: Vec<[u64; 6]>,
    /// The element type of the first volume element (all must have it).
    volume_type: Option<u32>,
    /// The corner tags of linear hexahedra in file order, one per element (whose tetrahedra
    /// are in `tets`).
    hexahedron_tags: Vec<[u64; 8]>,
    /// The node tags of 27-node hexahedra in lattice order, one per element (whose
    /// tetrahedra are in `tets`).
    cage_tags: Vec<[u64; 27]>,
    /// Linear triangles as node tags, with where they were read (a surface-only file's mesh).
    triangles: Vec<([u64; 3], FileLocation)>,
    /// The type and place of the first surface element other than a linear triangle.
    other_surface_element: Option<(u32, FileLocation)>,
    /// The physical groups.
    regions: regions::Regions,
}

impl Reader {
    /// Reads the section that `line` (just read, outside any section) opens, up to and with its
    /// end marker: `$Nodes` and `$Elements` of the file's version, any other `$Name` skipped to
    /// its `$EndName`; blank lines pass, anything else is a syntax error.
    fn section(&mut self, source: &mut Source<'_>, line: &str) -> Result<(), Error> {
        match line {
            "" => Ok(()),
            "$Nodes" | "$ParametricNodes" => {
                if self.saw_nodes {
                    return Err(source.error(
                        ImportErrorKind::Syntax,
                        "a second nodes section: partitioned files are not supported",
                    ));
                }
                self.saw_nodes = true;
                let parametric = line == "$ParametricNodes";
                match self.format.version {
                    Version::V2 if parametric => self.parametric_nodes_v2(source)?,
                    Version::V2 => self.nodes_v2(source)?,
                    _ if parametric => {
                        return Err(source.error(
                            ImportErrorKind::UnknownVersion,
                            "`$ParametricNodes` belongs to version 2 files",
                        ));
                    }
                    Version::V4 => self.nodes_v4(source)?,
                    Version::V40 => self.nodes_v40(source)?,
                }
                expect_end(
                    source,
                    if parametric {
                        "$EndParametricNodes"
                    } else {
                        "$EndNodes"
                    },
                )
            }
            "$PhysicalNames" => {
                self.regions.read_names(source)?;
                expect_end(source, "$EndPhysicalNames")
            }
            "$Entities" if self.format.version == Version::V4 => {
                self.regions.read_entities(source, self.format)?;
                expect_end(source, "$EndEntities")
            }
            "$Elements" => {
                match self.format.version {
                    Version::V2 => self.elements_v2(source)?,
                    Version::V4 => self.elements_v4(source)?,
                    Version::V40 => self.elements_v40(source)?,
                }
                expect_end(source, "$EndElements")
            }
            _ if line.starts_with('$') && !line.starts_with("$End") => {
                let end = format!("$End{}", &line[1..]);
                source.skip_past(end.as_bytes())
            }
            _ => Err(source.error(
                ImportErrorKind::Syntax,
                format!(
                    "expected a section such as `$Nodes`, found `{}`",
                    shorten(line)
                ),
            )),
        }
    }

    /// Adds node `tag` at `p` (file units, scaled to m here), refusing a tag defined twice.
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

    /// The [`RawMesh`] of the nodes and tetrahedra read, their node tags resolved to indices;
    /// [`ImportErrorKind::NoTetrahedra`] for a file without any, and
    /// [`ImportErrorKind::IndexOutOfRange`] at the tetrahedron for a tag no node has.
    fn finish(mut self, source: &Source<'_>) -> Result<RawMesh, Error> {
        if self.tets.is_empty() {
            return Err(source.error_at(
                FileLocation::Whole,
                ImportErrorKind::NoTetrahedra,
                "the file holds no tetrahedra or hexahedra (element type 4, 11, 5 or 12); a \
                 surface of triangles is filled by `load`",
            ));
        }
        let mut tets = Vec::with_capacity(self.tets.len());
        let mut tet_locations = Vec::with_capacity(self.tets.len());
        for (tags, location) in &self.tets {
            tets.push(self.indices(source, tags, *location)?);
            tet_locations.push(*location);
        }
        let mut mid_edge_nodes = Vec::with_capacity(self.mid_edge_tags.len());
        for (tags, (_, location)) in self.mid_edge_tags.iter().zip(&self.tets) {
            mid_edge_nodes.push(self.indices(source, tags, *location)?);
        }
        let hexahedra = self.hexahedra(source)?;
        // Split again by node index (the file's order of nodes), as the cage is: tags need not
        // follow that order.
        hexahedra.split_into(&mut tets);
        let node_index = &self.node_index;
        let regions = std::mem::take(&mut self.regions)
            .finish(source, |tag| node_index.get(&tag).copied())?;
        Ok(RawMesh {
            path: source.path().to_owned(),
            positions: self.positions,
            tets,
            mid_edge_nodes,
            tet_locations,
            regions,
            hexahedra,
        })
    }

    /// The hexahedra read, their node tags resolved to indices.
    fn hexahedra(&self, source: &Source<'_>) -> Result<Hexahedra, Error> {
        Ok(match self.volume_type {
            Some(elements::HEXAHEDRON) => Hexahedra::Linear(self.resolved(
                source,
                &self.hexahedron_tags,
                TETS_PER_HEXAHEDRON,
            )?),
            Some(elements::TRIQUADRATIC_HEXAHEDRON) => {
                Hexahedra::Triquadratic(self.resolved(source, &self.cage_tags, TETS_PER_LATTICE)?)
            }
            _ => Hexahedra::None,
        })
    }

    /// The elements of node tags `elements` as node indices, element `e`'s errors at the place
    /// of its first tetrahedron (`e * tets_per_element`).
    fn resolved<const N: usize>(
        &self,
        source: &Source<'_>,
        elements: &[[u64; N]],
        tets_per_element: usize,
    ) -> Result<Vec<[u32; N]>, Error> {
        (elements.iter().enumerate())
            .map(|(e, tags)| self.indices(source, tags, self.tets[e * tets_per_element].1))
            .collect()
    }

    /// The [`Surface`] of the triangles read: the nodes they use (in order of first use) and
    /// the triangles on them.
    fn finish_surface(self, source: &Source<'_>) -> Result<Surface, Error> {
        if let Some((element_type, location)) = self.other_surface_element {
            return Err(source.error_at(
                location,
                ImportErrorKind::UnsupportedElement,
                format!(
                    "element type {element_type} in a surface: only linear triangles (type 2) \
                     can be filled"
                ),
            ));
        }
        if self.triangles.is_empty() {
            return Err(source.error_at(
                FileLocation::Whole,
                ImportErrorKind::NoTetrahedra,
                "the file holds neither tetrahedra (element type 4 or 11) nor triangles (type 2)",
            ));
        }
        let mut vertex_of: HashMap<u32, u32> = HashMap::new();
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(self.triangles.len());
        for (tags, location) in &self.triangles {
            let nodes = self.indices(source, tags, *location)?;
            triangles.push(nodes.map(|node| {
                *vertex_of.entry(node).or_insert_with(|| {
                    vertices.push(self.positions[node as usize]);
                    (vertices.len() - 1) as u32
                })
            }));
        }
        Ok(Surface {
            path: source.path().to_owned(),
            vertices,
            triangles,
        })
    }

    /// The node indices of the node `tags` of the element at `location`.
    fn indices<const N: usize>(
        &self,
        source: &Source<'_>,
        tags: &[u64; N],
        location: FileLocation,
    ) -> Result<[u32; N], Error> {
        let mut indices = [0u32; N];
        for (index, tag) in indices.iter_mut().zip(tags) {
            *index = self.node_index.get(tag).copied().ok_or_else(|| {
                source.error_at(
                    location,
                    ImportErrorKind::IndexOutOfRange,
                    format!("the element refers to node {tag}, which is not defined"),
                )
            })?;
        }
        Ok(indices)
    }
}
