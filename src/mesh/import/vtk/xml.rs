//! VTK XML unstructured grids (`.vtu`), read by this crate (the layout with `quick-xml` in
//! `xml_document`, the values in `xml_data`).
//!
//! Reads every inline `<Piece>` of an `UnstructuredGrid`: ASCII, base64 `binary` and appended
//! (raw or base64) data, uncompressed or zlib-compressed, either byte order, 32- or 64-bit
//! headers; its points as numbers (three coordinates each, finite once scaled) and its cells'
//! offsets (a leading zero tolerated), connectivity and types. Every array must hold exactly
//! what its piece's `NumberOfPoints` and `NumberOfCells` declare (nothing for a count of 0), and
//! each cell's points must be its own piece's; the pieces' points are numbered one after the
//! other. A `<CellData>` array of the cells' physical tags (`gmsh:physical`, as meshio writes a
//! Gmsh file's, or vmtk's `CellEntityIds`, whole numbers of any type) makes the tagged cells
//! regions, as a Gmsh file's physical
//! groups are (unnamed: a VTU file has no names for them). Errors are placed at the line of the
//! `<DataArray>` at fault (a token that is not a
//! number at its own line; appended data at its byte offset), a missing array at its
//! `<Piece>`.

use super::xml_data::Decoder;
use super::xml_document::{self, ArrayDecl, PieceDecl};
use super::{CellData, Cells, build, whole_tag};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::Source;
use crate::mesh::import::{RawMesh, check_scale, scaled_defect};
use rapier3d::glamx::DVec3;

/// Reads the `.vtu` file `data` (named `path` in errors), coordinates times `scale` (m per file
/// unit). All pieces of the grid are read.
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for malformed XML or
/// data, a count that disagrees with the data, pieces in other files, compressors other than
/// zlib, cells that are not tetrahedra (linear or quadratic) or lower-dimensional, indices out
/// of range, non-finite coordinates. Malformed XML is reported at the line where it stops being
/// well-formed, errors about a data array at the line of its `<DataArray>` (appended data at
/// its byte offset), a missing array at the line of its `<Piece>`.
pub fn parse_vtu(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
    let document = xml_document::read(&source, data)?;
    let arrays = document.pieces.iter().flat_map(|p| {
        [
            &p.points,
            &p.connectivity,
            &p.offsets,
            &p.types,
            &p.cell_tags,
        ]
        .into_iter()
        .flatten()
    });
    let decoder = Decoder::new(&source, &document.layout, document.appended, arrays);
    let mut grid = Grid {
        source: &source,
        scale,
        positions: Vec::new(),
        offsets: vec![0u64],
        connectivity: Vec::new(),
        types: Vec::new(),
        tags: Vec::new(),
        pieces: Vec::new(),
    };
    for (number, piece) in document.pieces.iter().enumerate() {
        grid.add_piece(&decoder, number, piece)?;
    }
    grid.build()
}

/// The cells of one piece, read and checked, with the line of its connectivity.
struct PieceCells {
    types: Vec<u64>,
    ends: Vec<u64>,
    connectivity: Vec<u64>,
    at: FileLocation,
}

/// Where a piece's data lies, for errors about its cells.
struct PieceLines {
    /// The piece's first cell in the joined grid.
    first_cell: usize,
    /// The lines of its offsets, connectivity and types arrays.
    offsets: FileLocation,
    connectivity: FileLocation,
    types: FileLocation,
}

/// The pieces read so far, joined into one grid.
struct Grid<'s> {
    source: &'s Source<'s>,
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
    /// The cells' region tags, `None` for the cells of a piece without a tag array.
    tags: Vec<Option<u64>>,
    /// Where each piece's cells start and its arrays are.
    pieces: Vec<PieceLines>,
}

/// The line of `array`, or of its piece if it is missing.
fn line_of(array: Option<&ArrayDecl>, piece: &PieceDecl) -> FileLocation {
    FileLocation::Line(array.map_or(piece.line, |a| a.line))
}

impl Grid<'_> {
    /// A [`ImportErrorKind::BadCount`] error at `at`.
    fn bad_count(&self, at: FileLocation, message: String) -> Error {
        self.source.error_at(at, ImportErrorKind::BadCount, message)
    }

    /// `array` (the `what` array of `piece`), or an error at the piece if it is missing.
    fn required<'p>(
        &self,
        array: Option<&'p ArrayDecl>,
        piece: &PieceDecl,
        what: &str,
    ) -> Result<&'p ArrayDecl, Error> {
        array.ok_or_else(|| {
            self.bad_count(
                FileLocation::Line(piece.line),
                format!("the piece declares cells or points but has no {what} <DataArray>"),
            )
        })
    }

    /// Appends the points and cells of piece `number`, its point indices shifted past the
    /// points of the pieces before it.
    fn add_piece(
        &mut self,
        decoder: &Decoder<'_, '_>,
        number: usize,
        piece: &PieceDecl,
    ) -> Result<(), Error> {
        let first_point = self.positions.len() as u64;
        self.add_points(decoder, number, piece)?;
        self.pieces.push(PieceLines {
            first_cell: self.types.len(),
            offsets: line_of(piece.offsets.as_ref(), piece),
            connectivity: line_of(piece.connectivity.as_ref(), piece),
            types: line_of(piece.types.as_ref(), piece),
        });
        let Some(cells) = self.read_cells(decoder, number, piece)? else {
            return Ok(());
        };
        let base = self.connectivity.len() as u64;
        // Every end is at most the connectivity's length (checked): no overflow.
        self.offsets
            .extend(cells.ends.iter().map(|&end| base + end));
        for &node in &cells.connectivity {
            if node >= piece.point_count {
                return Err(self.source.error_at(
                    cells.at,
                    ImportErrorKind::IndexOutOfRange,
                    format!(
                        "piece {number} refers to point {node}, but has {} points",
                        piece.point_count
                    ),
                ));
            }
            self.connectivity.push(first_point + node);
        }
        let tags = self.read_cell_tags(decoder, number, piece)?;
        match tags {
            Some(tags) => self.tags.extend(tags.into_iter().map(Some)),
            None => self.tags.extend(cells.types.iter().map(|_| None)),
        }
        self.types.extend(cells.types);
        Ok(())
    }

    /// The region tags of piece `number`'s cells (see
    /// [`CELL_TAG_NAMES`](xml_document::CELL_TAG_NAMES)), one per cell, or `None` if the piece
    /// has no tag array.
    fn read_cell_tags(
        &self,
        decoder: &Decoder<'_, '_>,
        number: usize,
        piece: &PieceDecl,
    ) -> Result<Option<Vec<u64>>, Error> {
        let Some(array) = &piece.cell_tags else {
            return Ok(None);
        };
        let cells = piece.cell_count;
        let what = format!("cell tags ({}) of piece {number}", array.name);
        let tags = if array.value_type.starts_with("Float") {
            // Some writers store the tags as floats (vmtk's, at times): whole numbers only.
            let values = decoder.floats(array, cells, &what)?;
            values
                .iter()
                .map(|&v| {
                    whole_tag(v).ok_or_else(|| {
                        self.source.error_at(
                            FileLocation::Line(array.line),
                            ImportErrorKind::Syntax,
                            format!("the {what} hold {v}, not a tag (a whole number from 0)"),
                        )
                    })
                })
                .collect::<Result<Vec<u64>, Error>>()?
        } else {
            decoder.indices(array, cells, &what)?
        };
        if tags.len() as u64 != cells || array.components != 1 {
            return Err(self.bad_count(
                FileLocation::Line(array.line),
                format!(
                    "piece {number} has {} values of {} in {} components for {cells} cells",
                    tags.len(),
                    array.name,
                    array.components
                ),
            ));
        }
        Ok(Some(tags))
    }

    /// The cells of piece `number`: its types, the ends of its cells in its connectivity (a
    /// leading zero dropped) and the connectivity, each array holding exactly what the piece
    /// declares; `None` for a piece of no cells, whose arrays (if any) must then be empty.
    fn read_cells(
        &self,
        decoder: &Decoder<'_, '_>,
        number: usize,
        piece: &PieceDecl,
    ) -> Result<Option<PieceCells>, Error> {
        let cells = piece.cell_count;
        let what = |name: &str| format!("{name} of piece {number}");
        if cells == 0 {
            for (array, name) in [
                (&piece.types, "cell types"),
                (&piece.offsets, "cell offsets"),
                (&piece.connectivity, "connectivity"),
            ] {
                if let Some(array) = array {
                    decoder.indices(array, 0, &what(name))?;
                }
            }
            return Ok(None);
        }
        let types_array = self.required(piece.types.as_ref(), piece, "types")?;
        let types = decoder.indices(types_array, cells, &what("cell types"))?;
        if types.len() as u64 != cells {
            return Err(self.bad_count(
                FileLocation::Line(types_array.line),
                format!(
                    "piece {number} has {} cell types for {cells} cells",
                    types.len()
                ),
            ));
        }
        let offsets_array = self.required(piece.offsets.as_ref(), piece, "offsets")?;
        let mut ends = decoder.indices(
            offsets_array,
            cells.saturating_add(1),
            &what("cell offsets"),
        )?;
        // XML offsets are the cells' ends; some writers put a leading zero.
        if ends.first() == Some(&0) && ends.len() as u64 == cells + 1 {
            ends.remove(0);
        }
        if ends.len() as u64 != cells {
            return Err(self.bad_count(
                FileLocation::Line(offsets_array.line),
                format!(
                    "piece {number} has {} cell offsets for {cells} cells",
                    ends.len()
                ),
            ));
        }
        let used = ends.last().copied().unwrap_or(0);
        let connectivity_array =
            self.required(piece.connectivity.as_ref(), piece, "connectivity")?;
        let connectivity = decoder.indices(connectivity_array, used, &what("connectivity"))?;
        let at = FileLocation::Line(connectivity_array.line);
        if connectivity.len() as u64 != used || ends.iter().any(|&end| end > used) {
            return Err(self.bad_count(
                at,
                format!(
                    "piece {number}'s connectivity has {} entries, its cells end at up to {}",
                    connectivity.len(),
                    ends.iter().max().copied().unwrap_or(0)
                ),
            ));
        }
        Ok(Some(PieceCells {
            types,
            ends,
            connectivity,
            at,
        }))
    }

    /// Appends the points of piece `number`, scaled to m and checked finite; a piece of no
    /// points may have no `<Points>` array, or an empty one.
    fn add_points(
        &mut self,
        decoder: &Decoder<'_, '_>,
        number: usize,
        piece: &PieceDecl,
    ) -> Result<(), Error> {
        let points = match (&piece.points, piece.point_count) {
            (None, 0) => return Ok(()),
            (points, _) => self.required(points.as_ref(), piece, "Points")?,
        };
        let (source, scale) = (self.source, self.scale);
        let at = FileLocation::Line(points.line);
        if points.components != 3 {
            return Err(self.bad_count(
                at,
                format!(
                    "the points of piece {number} have {} components, not 3",
                    points.components
                ),
            ));
        }
        let expected = piece.point_count.saturating_mul(3);
        let coordinates = decoder.floats(points, expected, &format!("points of piece {number}"))?;
        if coordinates.len() as u64 != expected {
            return Err(self.bad_count(
                at,
                format!(
                    "piece {number} has {} point coordinates for its {} points",
                    coordinates.len(),
                    piece.point_count
                ),
            ));
        }
        for (i, p) in coordinates.chunks_exact(3).enumerate() {
            let p = DVec3::new(p[0], p[1], p[2]);
            if let Some((kind, problem)) = scaled_defect(p, scale) {
                return Err(source.error_at(
                    at,
                    kind,
                    format!("point {i} of piece {number} is {p}, which times the scale {scale} {problem}"),
                ));
            }
            self.positions.push(p * scale);
        }
        Ok(())
    }

    /// The mesh of all pieces' tetrahedra, errors placed at the data arrays of the cell's piece.
    fn build(self) -> Result<RawMesh, Error> {
        let Grid {
            source,
            positions,
            offsets,
            connectivity,
            types,
            tags,
            pieces,
            ..
        } = self;
        let cells = Cells {
            offsets: &offsets,
            connectivity: &connectivity,
            types: &types,
            tags: &tags,
        };
        let locate = |cell: usize, data: CellData| {
            let number = pieces.partition_point(|p| p.first_cell <= cell).max(1) - 1;
            pieces
                .get(number)
                .map_or(FileLocation::Whole, |p| match data {
                    CellData::Offsets => p.offsets,
                    CellData::Connectivity => p.connectivity,
                    CellData::Types => p.types,
                })
        };
        build(source, positions, &cells, &locate)
    }
}
