//! VTK XML unstructured grids (`.vtu`), parsed by `vtkio`.
//!
//! Reads every inline `<Piece>` of an `UnstructuredGrid` (ASCII, base64 or appended data; not
//! compressed), its points as numbers (three coordinates each, finite once scaled) and its
//! cells' offsets (a leading zero tolerated), connectivity and types; the pieces' points are
//! numbered one after the other. A file holding another data set, or pieces stored in other
//! files, is refused. Errors are placed at the line of the `<DataArray>` (or `<Piece>`) at
//! fault, found by scanning the file with `quick-xml`; `vtkio`'s own errors at the line where
//! the XML stops being well-formed or at the array they name, else [`FileLocation::Whole`].

use super::{CellData, Cells, build};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::locate::{self, PieceLines, VtuLines};
use crate::mesh::import::text::Source;
use crate::mesh::import::{RawMesh, check_scale, scaled_defect};
use rapier3d::glamx::DVec3;
use vtkio::model::{DataSet, IOBuffer, Piece, UnstructuredGridPiece, VertexNumbers};

/// Reads the `.vtu` file `data` (named `path` in errors) with `vtkio`, coordinates times
/// `scale` (m per file unit). All pieces of the grid are read.
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for malformed XML or
/// data, pieces in other files, cells that are not linear tetrahedra or lower-dimensional,
/// indices out of range, non-finite coordinates. Malformed XML is reported at the line where
/// it stops being well-formed, errors about a data array at the line of its `<DataArray>`,
/// count mismatches at the line of the `<Piece>`; `vtkio`'s errors that name no place carry
/// [`FileLocation::Whole`].
pub fn parse_vtu(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
    let vtk = vtkio::Vtk::parse_xml(data).map_err(|e| vtkio_error(&source, data, &e))?;
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        return Err(source.error_at(
            FileLocation::Whole,
            ImportErrorKind::Syntax,
            "the file holds no UnstructuredGrid",
        ));
    };
    let mut grid = Grid {
        source: &source,
        lines: VtuLines::scan(data),
        scale,
        positions: Vec::new(),
        offsets: vec![0u64],
        connectivity: Vec::new(),
        types: Vec::new(),
        first_cells: Vec::new(),
    };
    for (number, piece) in pieces.into_iter().enumerate() {
        let piece = match piece {
            Piece::Inline(piece) => piece,
            Piece::Source(..) | Piece::Loaded(_) => {
                return Err(source.error_at(
                    grid.at(number, piece_line),
                    ImportErrorKind::UnknownVersion,
                    format!("piece {number} is stored in another file: not supported"),
                ));
            }
        };
        grid.add_piece(number, *piece)?;
    }
    grid.build()
}

/// Chooses the line of one element of a piece.
type PieceElement = fn(&PieceLines) -> Option<usize>;

/// The line of the `<Piece>` element itself.
fn piece_line(p: &PieceLines) -> Option<usize> {
    Some(p.piece)
}

/// The pieces read so far, joined into one grid.
struct Grid<'s> {
    source: &'s Source<'s>,
    /// The lines of the file's elements, for error locations.
    lines: VtuLines,
    /// Metres per file unit.
    scale: f64,
    /// The points of all pieces (m).
    positions: Vec<DVec3>,
    /// The ends of all cells in `connectivity`, after a leading zero.
    offsets: Vec<u64>,
    /// The cells' point indices into `positions`.
    connectivity: Vec<u64>,
    /// The cells' VTK types.
    types: Vec<u64>,
    /// The first cell of each piece, to find a cell's piece.
    first_cells: Vec<usize>,
}

impl Grid<'_> {
    /// The location of piece `number`'s element chosen by `element`.
    fn at(&self, number: usize, element: PieceElement) -> FileLocation {
        at(&self.lines, number, element)
    }

    /// Appends the points and cells of piece `number`, its point indices shifted past the
    /// points of the pieces before it.
    fn add_piece(&mut self, number: usize, piece: UnstructuredGridPiece) -> Result<(), Error> {
        let source = self.source;
        let first_point = self.positions.len() as u64;
        self.add_points(number, &piece.points)?;
        let (piece_offsets, piece_connectivity) =
            self.cell_vertices(number, piece.cells.cell_verts)?;
        // XML offsets are the cells' ends; some writers put a leading zero.
        let ends = match piece_offsets.first() {
            Some(0) if piece_offsets.len() == piece.cells.types.len() + 1 => &piece_offsets[1..],
            _ => &piece_offsets[..],
        };
        if ends.len() != piece.cells.types.len() {
            return Err(source.error_at(
                self.at(number, piece_line),
                ImportErrorKind::BadCount,
                format!(
                    "piece {number} has {} cell offsets but {} cell types",
                    ends.len(),
                    piece.cells.types.len()
                ),
            ));
        }
        self.first_cells.push(self.types.len());
        let base = self.connectivity.len() as u64;
        for &end in ends {
            if end > piece_connectivity.len() as u64 {
                return Err(source.error_at(
                    self.at(number, |p| p.offsets),
                    ImportErrorKind::BadCount,
                    format!(
                        "piece {number}: cell offset {end} is past the connectivity's {} entries",
                        piece_connectivity.len()
                    ),
                ));
            }
            self.offsets.push(base + end);
        }
        for &node in &piece_connectivity {
            let global = node.checked_add(first_point).ok_or_else(|| {
                source.error_at(
                    self.at(number, |p| p.connectivity),
                    ImportErrorKind::IndexOutOfRange,
                    format!("piece {number} refers to point {node}"),
                )
            })?;
            self.connectivity.push(global);
        }
        self.types
            .extend(piece.cells.types.iter().map(|&t| t as u64));
        Ok(())
    }

    /// Appends the points of piece `number`, scaled to m and checked finite.
    fn add_points(&mut self, number: usize, points_data: &IOBuffer) -> Result<(), Error> {
        let (source, scale) = (self.source, self.scale);
        let points = self.at(number, |p| p.points);
        let first_point = self.positions.len() as u64;
        let coordinates = points_data.cast_into::<f64>().ok_or_else(|| {
            source.error_at(
                points,
                ImportErrorKind::Syntax,
                format!("the points of piece {number} are not numbers"),
            )
        })?;
        if coordinates.len() % 3 != 0 {
            return Err(source.error_at(
                points,
                ImportErrorKind::BadCount,
                format!(
                    "piece {number} has {} point coordinates, not a multiple of 3",
                    coordinates.len()
                ),
            ));
        }
        for p in coordinates.chunks_exact(3) {
            let p = DVec3::new(p[0], p[1], p[2]);
            if let Some((kind, problem)) = scaled_defect(p, scale) {
                return Err(source.error_at(
                    points,
                    kind,
                    format!(
                        "point {} of piece {number} is {p}, which times the scale {scale} {problem}",
                        self.positions.len() as u64 - first_point
                    ),
                ));
            }
            self.positions.push(p * scale);
        }
        Ok(())
    }

    /// The cell offsets (cells' ends, maybe after a leading zero) and connectivity of piece
    /// `number`, converted from the legacy `n i_1 ... i_n` list when `vtkio` gives that.
    fn cell_vertices(
        &self,
        number: usize,
        cell_verts: VertexNumbers,
    ) -> Result<(Vec<u64>, Vec<u64>), Error> {
        match cell_verts {
            VertexNumbers::XML {
                connectivity,
                offsets,
            } => Ok((offsets, connectivity)),
            VertexNumbers::Legacy { vertices, .. } => {
                let mut offsets = Vec::new();
                let mut connectivity = Vec::new();
                let mut i = 0;
                while i < vertices.len() {
                    let n = vertices[i] as usize;
                    let cell = vertices.get(i + 1..i + 1 + n).ok_or_else(|| {
                        self.source.error_at(
                            self.at(number, |p| p.connectivity),
                            ImportErrorKind::Truncated,
                            "a cell list is cut short",
                        )
                    })?;
                    connectivity.extend(cell.iter().map(|&v| u64::from(v)));
                    offsets.push(connectivity.len() as u64);
                    i += 1 + n;
                }
                Ok((offsets, connectivity))
            }
        }
    }

    /// The mesh of all pieces' tetrahedra, errors placed at the data arrays of the cell's piece.
    fn build(self) -> Result<RawMesh, Error> {
        let Grid {
            source,
            lines,
            positions,
            offsets,
            connectivity,
            types,
            first_cells,
            ..
        } = self;
        let cells = Cells {
            offsets: &offsets,
            connectivity: &connectivity,
            types: &types,
        };
        let locate = |cell: usize, data: CellData| {
            let number = first_cells.partition_point(|&first| first <= cell).max(1) - 1;
            at(
                &lines,
                number,
                match data {
                    CellData::Offsets => |p| p.offsets,
                    CellData::Connectivity => |p| p.connectivity,
                    CellData::Types => |p| p.types,
                },
            )
        };
        build(source, positions, &cells, &locate)
    }
}

/// The location of piece `number`'s element chosen by `element`, in the file of `lines`.
fn at(lines: &VtuLines, number: usize, element: PieceElement) -> FileLocation {
    lines
        .pieces
        .get(number)
        .and_then(element)
        .map_or(FileLocation::Whole, FileLocation::Line)
}

/// `vtkio`'s error `e` on `data`, placed: at the line where the XML stops being well-formed,
/// else at the `<DataArray>` it names (a size mismatch, an unknown cell type), else nowhere.
fn vtkio_error(source: &Source<'_>, data: &[u8], e: &vtkio::Error) -> Error {
    use vtkio::xml::{Error as XmlError, ValidationError};
    if let Some((line, syntax)) = locate::xml_error(data) {
        return source.error_at(
            FileLocation::Line(line),
            ImportErrorKind::Syntax,
            format!("invalid VTU file: malformed XML: {syntax}"),
        );
    }
    let (kind, array) = match e {
        vtkio::Error::XML(XmlError::Validation(ValidationError::DataArraySizeMismatch {
            name,
            ..
        })) => (ImportErrorKind::BadCount, Some(name.as_str())),
        vtkio::Error::XML(XmlError::Validation(ValidationError::InvalidCellType(_))) => {
            (ImportErrorKind::UnsupportedElement, Some("types"))
        }
        _ => (ImportErrorKind::Syntax, None),
    };
    let line = array.and_then(|name| VtuLines::scan(data).array(name));
    source.error_at(
        line.map_or(FileLocation::Whole, FileLocation::Line),
        kind,
        format!("invalid VTU file: {e}"),
    )
}
