//! VTK unstructured grids: XML `.vtu` files and legacy `.vtk` files.
//!
//! Cells of type 10 (tetra) are read. Lower-dimensional cells (vertices, lines, triangles,
//! quads and their higher-order forms: boundary elements written beside the volume) are
//! skipped, as in Gmsh files. Any other volume cell (quadratic tetra 24, hexahedron 12, wedge
//! 13, pyramid 14, ...) is an [`ImportErrorKind::UnsupportedElement`] error naming the cell:
//! dropping it would silently lose material.
//!
//! `.vtu` files are parsed by the `vtkio` crate (ASCII, base64 `binary` and appended data;
//! compressed data is an error since this crate builds `vtkio` without its decompressors,
//! which also rules out decompression bombs). `vtkio`'s errors do not say where in the file
//! they arise: on an error the file is scanned again with `quick-xml` (the version `vtkio`
//! uses) to report the line where the XML stops being well-formed, or the line of the
//! `<DataArray>` a size mismatch or an unknown cell type is about; other `vtkio` errors carry
//! [`FileLocation::Whole`]. The checks made here afterwards name the cell or the data array and
//! report the line of that array's `<DataArray>` element (of the `<Piece>` for count
//! mismatches); appended and binary data are placed at their element's line. Mutating valid
//! files (tens of thousands of truncations, byte flips and huge counts) made `vtkio` neither
//! panic nor allocate beyond its input.
//!
//! Legacy `.vtk` files (versions 2.0 to 5.1, ASCII or big-endian BINARY, `DATASET
//! UNSTRUCTURED_GRID`) are read by hand: `vtkio`'s legacy parser reports only the nom error
//! kind (`Parse(Digit)`), with no line, while the format is a few keywords and number lists.
//!
//! This module turns the cells both readers collect into tetrahedra; the submodules read the
//! XML files (`xml`) and the legacy ones (`legacy`, its data blocks in `legacy_data`).

mod legacy;
mod legacy_data;
mod xml;

pub use legacy::parse_legacy;
pub use xml::parse_vtu;

use super::RawMesh;
use super::text::Source;
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use rapier3d::glamx::DVec3;

/// VTK's linear tetrahedron.
const VTK_TETRA: u64 = 10;
/// VTK's quadratic (10-node) tetrahedron.
const VTK_QUADRATIC_TETRA: u64 = 24;

/// Whether VTK cell type `cell_type` is a vertex, curve or surface cell, skipped on import.
fn is_lower_dimensional(cell_type: u64) -> bool {
    matches!(
        cell_type,
        1..=9 | 21 | 22 | 23 | 28 | 30 | 34 | 35 | 36 | 68 | 69 | 70 | 75 | 76 | 77
    )
}

/// Cells as offsets into `connectivity` and types, turned into a [`RawMesh`] by [`build`].
struct Cells<'c> {
    /// `offsets[i]..offsets[i + 1]` is cell `i`'s range in `connectivity`.
    offsets: &'c [u64],
    /// The cells' point indices, one after the other.
    connectivity: &'c [u64],
    /// VTK's cell type of each cell.
    types: &'c [u64],
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
    let mut tets = Vec::new();
    let mut tet_locations = Vec::new();
    for (cell, &cell_type) in cells.types.iter().enumerate() {
        let nodes = cells.nodes(source, cell, locate)?;
        if let Some(tet) = tetrahedron(source, cell, cell_type, nodes, positions.len(), locate)? {
            tets.push(tet);
            tet_locations.push(locate(cell, CellData::Connectivity));
        }
    }
    if tets.is_empty() {
        return Err(source.error_at(
            FileLocation::Whole,
            ImportErrorKind::NoTetrahedra,
            "the file holds no tetrahedra (cell type 10)",
        ));
    }
    Ok(RawMesh {
        path: source.path().to_owned(),
        positions,
        tets,
        mid_edge_nodes: Vec::new(),
        tet_locations,
    })
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

/// The tetrahedron cell `cell` of `cell_type` with point indices `nodes` makes (of
/// `point_count` points): `None` for a lower-dimensional cell, an error for a tetrahedron
/// without four points in range and for any other volume cell.
fn tetrahedron(
    source: &Source<'_>,
    cell: usize,
    cell_type: u64,
    nodes: &[u64],
    point_count: usize,
    locate: Locate<'_>,
) -> Result<Option<[u32; 4]>, Error> {
    match cell_type {
        VTK_TETRA => {
            if nodes.len() != 4 {
                return Err(source.error_at(
                    locate(cell, CellData::Offsets),
                    ImportErrorKind::BadCount,
                    format!("cell {cell} is a tetrahedron with {} nodes", nodes.len()),
                ));
            }
            let mut tet = [0u32; 4];
            for (corner, &node) in tet.iter_mut().zip(nodes) {
                if node >= point_count as u64 {
                    return Err(source.error_at(
                        locate(cell, CellData::Connectivity),
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "cell {cell} refers to point {node}, but there are {point_count} \
                             points"
                        ),
                    ));
                }
                *corner = node as u32;
            }
            Ok(Some(tet))
        }
        _ if is_lower_dimensional(cell_type) => Ok(None),
        VTK_QUADRATIC_TETRA => Err(source.error_at(
            locate(cell, CellData::Types),
            ImportErrorKind::UnsupportedElement,
            format!(
                "cell {cell} is a quadratic tetrahedron (type 24): only linear tetrahedra \
                 (type 10) are supported"
            ),
        )),
        _ => Err(source.error_at(
            locate(cell, CellData::Types),
            ImportErrorKind::UnsupportedElement,
            format!(
                "cell {cell} has type {cell_type}, a volume cell other than a linear \
                 tetrahedron (type 10): mixed element types cannot be used"
            ),
        )),
    }
}
