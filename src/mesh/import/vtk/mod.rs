//! VTK unstructured grids: XML `.vtu` files and legacy `.vtk` files.
//!
//! Cells of type 10 (tetra), 24 (quadratic tetra: its corners, then its mid-edge nodes in
//! VTK's edge order, kept in [`RawMesh::mid_edge_nodes`]), 12 (hexahedron) and 29
//! (triquadratic hexahedron), the hexahedra split into tetrahedra ([`RawMesh::hexahedra`]), are
//! read, one kind per file. Lower-dimensional cells (vertices, lines, triangles, quads and
//! their higher-order forms: boundary elements written beside the volume) are skipped, as in
//! Gmsh files. Any other volume cell (wedge 13, pyramid 14, ...) is an
//! [`ImportErrorKind::UnsupportedElement`] error naming the cell: dropping it would silently
//! lose material.
//!
//! `.vtu` files are read by this crate (`xml`: the layout walked with `quick-xml` in
//! `xml_document`, the values decoded in `xml_data`, binary blocks in `xml_block`): ASCII,
//! base64 `binary` and appended raw or base64 data, uncompressed or zlib-compressed (inflated
//! within the sizes the file declares), every count checked against the data. Errors name the
//! line of the `<DataArray>` or `<Piece>` at fault, a token that is not a number at its own
//! line, appended binary data at its byte offset. No input makes the reader panic or allocate
//! beyond what its counts and data can fill (fuzzed in `tests/mesh_import`).
//!
//! Legacy `.vtk` files (versions 2.0 to 5.1, ASCII or big-endian BINARY, `DATASET
//! UNSTRUCTURED_GRID`) are read by hand too (`legacy`, its data blocks in `legacy_data`): the
//! format is a few keywords and number lists.
//!
//! This module turns the cells both readers collect into tetrahedra, and the cells a file tags
//! (its `gmsh:physical` or `CellEntityIds` cell data) into unnamed regions by
//! dimension and tag: a tetrahedron's into a volume, a triangle's or quadrangle's into a
//! surface, as a Gmsh file's physical groups are.

mod legacy;
mod legacy_attributes;
mod legacy_data;
mod xml;
mod xml_block;
mod xml_data;
mod xml_document;

pub use legacy::parse_legacy;
pub use xml::parse_vtu;

use super::hexahedra;
use super::text::Source;
use super::{Hexahedra, MeshRegion, RawMesh};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::hex_split::split_lattice;
use rapier3d::glamx::DVec3;

/// VTK's linear tetrahedron.
const VTK_TETRA: u64 = 10;
/// VTK's quadratic (10-node) tetrahedron.
const VTK_QUADRATIC_TETRA: u64 = 24;
/// VTK's linear hexahedron.
const VTK_HEXAHEDRON: u64 = 12;
/// VTK's triquadratic (27-node) hexahedron.
const VTK_TRIQUADRATIC_HEXAHEDRON: u64 = 29;

/// Whether VTK cell type `cell_type` is empty (0), a vertex, curve or surface cell, skipped on
/// import.
fn is_lower_dimensional(cell_type: u64) -> bool {
    matches!(
        cell_type,
        0..=9 | 21 | 22 | 23 | 28 | 30 | 34 | 35 | 36 | 68 | 69 | 70 | 75 | 76 | 77
    )
}

/// A region tag stored as a float (vmtk writes them so at times): a whole number from 0, below
/// 2^53 where floats still count every integer; `None` otherwise.
fn whole_tag(value: f64) -> Option<u64> {
    (value >= 0.0 && value.fract() == 0.0 && value < 9.0e15).then_some(value as u64)
}

/// Cells as offsets into `connectivity` and types, turned into a [`RawMesh`] by [`build`].
struct Cells<'c> {
    /// `offsets[i]..offsets[i + 1]` is cell `i`'s range in `connectivity`.
    offsets: &'c [u64],
    /// The cells' point indices, one after the other.
    connectivity: &'c [u64],
    /// VTK's cell type of each cell.
    types: &'c [u64],
    /// Each cell's region tag, if the file tags its cells (empty, or `None` for a cell, if not).
    tags: &'c [Option<u64>],
}

/// Which of a cell's data an error is about, for the location of its data array.
#[derive(Clone, Copy)]
enum CellData {
    Offsets,
    Connectivity,
    Types,
}

/// Gives the file location of the data of one kind of a cell.
type Locate<'l> = &'l dyn Fn(usize, CellData) -> FileLocation;

/// The [`RawMesh`] of `positions` (m) and the tetrahedra of `cells`; `locate` gives the file
/// location of a cell's data (that of its connectivity is each tetrahedron's location).
fn build(
    source: &Source<'_>,
    positions: Vec<DVec3>,
    cells: &Cells<'_>,
    locate: Locate<'_>,
) -> Result<RawMesh, Error> {
    let cell_count = cells.types.len();
    if cells.offsets.len() != cell_count + 1 {
        return Err(source.error_at(
            locate(0, CellData::Offsets),
            ImportErrorKind::BadCount,
            format!(
                "{} cell types but {} cells",
                cell_count,
                cells.offsets.len().saturating_sub(1)
            ),
        ));
    }
    let mut volume = VolumeCells::default();
    let mut tagged = TaggedCells::default();
    for (cell, &cell_type) in cells.types.iter().enumerate() {
        let nodes = cells.nodes(source, cell, locate)?;
        let tag = cells.tags.get(cell).copied().flatten();
        let Some(nodes) = volume_nodes(source, cell, cell_type, nodes, positions.len(), locate)?
        else {
            if let Some(tag) = tag {
                let at = locate(cell, CellData::Connectivity);
                tagged.add_boundary(source, (cell, cell_type, tag), nodes, positions.len(), at)?;
            }
            continue;
        };
        if volume.cell_type.is_some_and(|first| first != cell_type) {
            return Err(source.error_at(
                locate(cell, CellData::Types),
                ImportErrorKind::UnsupportedElement,
                format!(
                    "cell {cell} has type {cell_type}, the cells before type {}: one kind of \
                     volume cell per mesh",
                    volume.cell_type.unwrap_or_default()
                ),
            ));
        }
        let first_tet = volume.tets.len();
        volume.add(cell_type, &nodes, locate(cell, CellData::Connectivity));
        if let Some(tag) = tag {
            tagged.add_tets(tag, first_tet..volume.tets.len(), &nodes);
        }
    }
    if volume.tets.is_empty() {
        return Err(source.error_at(
            FileLocation::Whole,
            ImportErrorKind::NoTetrahedra,
            "the file holds no tetrahedra or hexahedra (cell type 10, 24, 12 or 29)",
        ));
    }
    let hexahedra = match volume.cell_type {
        Some(VTK_HEXAHEDRON) => Hexahedra::Linear(volume.hexahedra),
        Some(VTK_TRIQUADRATIC_HEXAHEDRON) => Hexahedra::Triquadratic(volume.cage),
        _ => Hexahedra::None,
    };
    Ok(RawMesh {
        path: source.path().to_owned(),
        positions,
        tets: volume.tets,
        mid_edge_nodes: volume.mid_edge_nodes,
        tet_locations: volume.tet_locations,
        regions: tagged.regions(source)?,
        hexahedra,
    })
}

/// The volume cells read so far, as a [`RawMesh`] holds them.
#[derive(Default)]
struct VolumeCells {
    /// The type of the first volume cell (all must have it).
    cell_type: Option<u64>,
    tets: Vec<[u32; 4]>,
    mid_edge_nodes: Vec<[u32; 6]>,
    tet_locations: Vec<FileLocation>,
    /// Linear hexahedra's corners in file order.
    hexahedra: Vec<[u32; 8]>,
    /// 27-node hexahedra in lattice order.
    cage: Vec<[u32; 27]>,
}

impl VolumeCells {
    /// Adds the volume cell of `cell_type` on `nodes` (as many as the type has), defined at
    /// `at`: a tetrahedron as it is, a hexahedron split into tetrahedra.
    fn add(&mut self, cell_type: u64, nodes: &[u32], at: FileLocation) {
        self.cell_type = Some(cell_type);
        let first = self.tets.len();
        match cell_type {
            VTK_HEXAHEDRON => {
                self.tets.extend(hexahedra::split_linear(nodes));
                self.hexahedra
                    .push(std::array::from_fn(|corner| nodes[corner]));
            }
            VTK_TRIQUADRATIC_HEXAHEDRON => {
                let lattice = hexahedra::lattice(nodes, &hexahedra::VTK_TRIQUADRATIC);
                self.tets.extend(split_lattice(&lattice));
                self.cage.push(lattice);
            }
            _ => {
                self.tets.push([nodes[0], nodes[1], nodes[2], nodes[3]]);
                if cell_type == VTK_QUADRATIC_TETRA {
                    let mids = [nodes[4], nodes[5], nodes[6], nodes[7], nodes[8], nodes[9]];
                    self.mid_edge_nodes.push(mids);
                }
            }
        }
        let added = self.tets.len() - first;
        self.tet_locations.extend(std::iter::repeat_n(at, added));
    }
}

/// The tagged cells seen so far, by dimension and tag: their nodes and, for volumes, their
/// tetrahedra.
#[derive(Default)]
struct TaggedCells {
    groups: std::collections::BTreeMap<(u8, u64), (Vec<u32>, Vec<u32>)>,
}

impl TaggedCells {
    /// Adds the tetrahedra `tets` (indices among the mesh's) of a volume cell of `nodes` to
    /// the volume tagged `tag`.
    fn add_tets(&mut self, tag: u64, tets: std::ops::Range<usize>, nodes: &[u32]) {
        let (group_nodes, group_tets) = self.groups.entry((3, tag)).or_default();
        group_nodes.extend_from_slice(nodes);
        // Saturated: a mesh cannot index more than u32::MAX tetrahedra.
        group_tets.extend(tets.map(|t| u32::try_from(t).unwrap_or(u32::MAX)));
    }

    /// Adds the lower-dimensional cell `cell` of `cell_type` tagged `tag`, of point indices
    /// `nodes` (of `point_count` points, checked; errors at `at`), to its group: a vertex, a
    /// curve or a surface by its type.
    fn add_boundary(
        &mut self,
        source: &Source<'_>,
        (cell, cell_type, tag): (usize, u64, u64),
        nodes: &[u64],
        point_count: usize,
        at: FileLocation,
    ) -> Result<(), Error> {
        let dimension = match cell_type {
            1 | 2 => 0,
            3 | 4 | 21 | 35 | 68 => 1,
            0 => return Ok(()),
            _ => 2,
        };
        let (group_nodes, _) = self.groups.entry((dimension, tag)).or_default();
        for &node in nodes {
            match u32::try_from(node)
                .ok()
                .filter(|&n| (n as usize) < point_count)
            {
                Some(n) => group_nodes.push(n),
                None => {
                    return Err(source.error_at(
                        at,
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "tagged cell {cell} refers to point {node}, but there are \
                             {point_count} points"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The groups as unnamed regions, nodes sorted and each once; a tag beyond `i64` is an
    /// error.
    fn regions(self, source: &Source<'_>) -> Result<Vec<MeshRegion>, Error> {
        (self.groups.into_iter())
            .map(|((dimension, tag), (mut nodes, tets))| {
                nodes.sort_unstable();
                nodes.dedup();
                let tag = i64::try_from(tag).map_err(|_| {
                    source.error_at(
                        FileLocation::Whole,
                        ImportErrorKind::BadCount,
                        format!("a cell tag of {tag} is beyond the tags a region can have"),
                    )
                })?;
                Ok(MeshRegion {
                    name: String::new(),
                    dimension,
                    tag,
                    nodes,
                    tets,
                })
            })
            .collect()
    }
}

impl Cells<'_> {
    /// The point indices of cell `cell`, or [`ImportErrorKind::BadCount`] if its offsets leave
    /// the connectivity.
    fn nodes(&self, source: &Source<'_>, cell: usize, locate: Locate<'_>) -> Result<&[u64], Error> {
        let (start, end) = (self.offsets[cell], self.offsets[cell + 1]);
        if start > end || end > self.connectivity.len() as u64 {
            return Err(source.error_at(
                locate(cell, CellData::Offsets),
                ImportErrorKind::BadCount,
                format!(
                    "cell {cell} spans entries {start}..{end} of a connectivity of {}",
                    self.connectivity.len()
                ),
            ));
        }
        Ok(&self.connectivity[start as usize..end as usize])
    }
}

/// The nodes of the volume cell `cell` of `cell_type` with point indices `nodes` (of
/// `point_count` points): a tetrahedron's (4 or 10) or a hexahedron's (8 or 27); `None` for a
/// lower-dimensional cell, an error for a cell with another number of points or one out of
/// range, and for any other volume cell.
fn volume_nodes(
    source: &Source<'_>,
    cell: usize,
    cell_type: u64,
    nodes: &[u64],
    point_count: usize,
    locate: Locate<'_>,
) -> Result<Option<Vec<u32>>, Error> {
    let expected = match cell_type {
        VTK_TETRA => 4,
        VTK_QUADRATIC_TETRA => 10,
        VTK_HEXAHEDRON => 8,
        VTK_TRIQUADRATIC_HEXAHEDRON => 27,
        _ if is_lower_dimensional(cell_type) => return Ok(None),
        _ => {
            return Err(source.error_at(
                locate(cell, CellData::Types),
                ImportErrorKind::UnsupportedElement,
                format!(
                    "cell {cell} has type {cell_type}, a volume cell other than a tetrahedron \
                     (type 10 or 24) or a hexahedron (type 12 or 29): it cannot be used"
                ),
            ));
        }
    };
    if nodes.len() != expected {
        return Err(source.error_at(
            locate(cell, CellData::Offsets),
            ImportErrorKind::BadCount,
            format!(
                "cell {cell} has type {cell_type} but {} nodes, not {expected}",
                nodes.len()
            ),
        ));
    }
    nodes
        .iter()
        .map(|&node| {
            u32::try_from(node)
                .ok()
                .filter(|&n| (n as usize) < point_count)
                .ok_or_else(|| {
                    source.error_at(
                        locate(cell, CellData::Connectivity),
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "cell {cell} refers to point {node}, but there are {point_count} \
                             points"
                        ),
                    )
                })
        })
        .collect::<Result<_, _>>()
        .map(Some)
}
