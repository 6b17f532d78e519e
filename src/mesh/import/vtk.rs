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
//! mismatches); appended and binary data are placed at their element's line. Mutating valid files (tens of thousands of truncations, byte flips
//! and huge counts) made `vtkio` neither panic nor allocate beyond its input.
//!
//! Legacy `.vtk` files (versions 2.0 to 5.1, ASCII or big-endian BINARY, `DATASET
//! UNSTRUCTURED_GRID`) are read by hand: `vtkio`'s legacy parser reports only the nom error
//! kind (`Parse(Digit)`), with no line, while the format is a few keywords and number lists.

use super::locate::{self, PieceLines, VtuLines};
use super::text::{Source, finite, parse_token, scaled, shorten};
use super::{RawMesh, check_scale};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use rapier3d::glamx::DVec3;
use std::str::SplitAsciiWhitespace;

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

/// Points (as `x y z` triples, scaled) and cells (offsets into `connectivity`, types) turned
/// into a [`RawMesh`] by [`build`].
struct Cells<'c> {
    /// `offsets[i]..offsets[i + 1]` is cell `i`'s range in `connectivity`.
    offsets: &'c [u64],
    connectivity: &'c [u64],
    types: &'c [u64],
}

/// Which of a cell's data an error is about, for the location of its data array.
#[derive(Clone, Copy)]
enum CellData {
    Offsets,
    Connectivity,
    Types,
}

/// The [`RawMesh`] of `positions` and the tetrahedra of `cells`; `locate` gives the file
/// location of a cell's data (that of its connectivity is each tetrahedron's location).
fn build(
    source: &Source<'_>,
    positions: Vec<DVec3>,
    cells: &Cells<'_>,
    locate: &dyn Fn(usize, CellData) -> FileLocation,
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
        let (start, end) = (cells.offsets[cell], cells.offsets[cell + 1]);
        if start > end || end > cells.connectivity.len() as u64 {
            return Err(source.error_at(
                locate(cell, CellData::Offsets),
                ImportErrorKind::BadCount,
                format!(
                    "cell {cell} spans entries {start}..{end} of a connectivity of {}",
                    cells.connectivity.len()
                ),
            ));
        }
        let nodes = &cells.connectivity[start as usize..end as usize];
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
                    if node >= positions.len() as u64 {
                        return Err(source.error_at(
                            locate(cell, CellData::Connectivity),
                            ImportErrorKind::IndexOutOfRange,
                            format!(
                                "cell {cell} refers to point {node}, but there are {} points",
                                positions.len()
                            ),
                        ));
                    }
                    *corner = node as u32;
                }
                tets.push(tet);
                tet_locations.push(locate(cell, CellData::Connectivity));
            }
            _ if is_lower_dimensional(cell_type) => {}
            VTK_QUADRATIC_TETRA => {
                return Err(source.error_at(
                    locate(cell, CellData::Types),
                    ImportErrorKind::UnsupportedElement,
                    format!(
                        "cell {cell} is a quadratic tetrahedron (type 24): only linear \
                         tetrahedra (type 10) are supported"
                    ),
                ));
            }
            _ => {
                return Err(source.error_at(
                    locate(cell, CellData::Types),
                    ImportErrorKind::UnsupportedElement,
                    format!(
                        "cell {cell} has type {cell_type}, a volume cell other than a linear \
                         tetrahedron (type 10): mixed element types cannot be used"
                    ),
                ));
            }
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
    use vtkio::model::{DataSet, Piece, VertexNumbers};
    check_scale(scale)?;
    let source = Source::new(path, data);
    let vtk = vtkio::Vtk::parse_xml(data).map_err(|e| vtkio_error(&source, data, &e))?;
    let lines = VtuLines::scan(data);
    // The location of piece `number`'s element chosen by `element`.
    let at = |number: usize, element: fn(&PieceLines) -> Option<usize>| {
        lines
            .pieces
            .get(number)
            .and_then(element)
            .map_or(FileLocation::Whole, FileLocation::Line)
    };
    let piece_line: fn(&PieceLines) -> Option<usize> = |p| Some(p.piece);
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        return Err(source.error_at(
            FileLocation::Whole,
            ImportErrorKind::Syntax,
            "the file holds no UnstructuredGrid",
        ));
    };
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    let mut connectivity = Vec::new();
    let mut types = Vec::new();
    // The first cell of each piece, to find a cell's piece.
    let mut first_cells = Vec::new();
    for (number, piece) in pieces.into_iter().enumerate() {
        let piece = match piece {
            Piece::Inline(piece) => piece,
            Piece::Source(..) | Piece::Loaded(_) => {
                return Err(source.error_at(
                    at(number, piece_line),
                    ImportErrorKind::UnknownVersion,
                    format!("piece {number} is stored in another file: not supported"),
                ));
            }
        };
        let points = at(number, |p| p.points);
        let first_point = positions.len() as u64;
        let coordinates = piece.points.cast_into::<f64>().ok_or_else(|| {
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
            let scaled = p * scale;
            if !scaled.is_finite() {
                return Err(source.error_at(
                    points,
                    ImportErrorKind::NonFinite,
                    format!(
                        "point {} of piece {number} is {p}, not finite times the scale {scale}",
                        positions.len() as u64 - first_point
                    ),
                ));
            }
            positions.push(scaled);
        }
        let (piece_offsets, piece_connectivity) = match piece.cells.cell_verts {
            VertexNumbers::XML {
                connectivity,
                offsets,
            } => (offsets, connectivity),
            VertexNumbers::Legacy { vertices, .. } => {
                let mut offsets = Vec::new();
                let mut connectivity = Vec::new();
                let mut i = 0;
                while i < vertices.len() {
                    let n = vertices[i] as usize;
                    let cell = vertices.get(i + 1..i + 1 + n).ok_or_else(|| {
                        source.error_at(
                            at(number, |p| p.connectivity),
                            ImportErrorKind::Truncated,
                            "a cell list is cut short",
                        )
                    })?;
                    connectivity.extend(cell.iter().map(|&v| u64::from(v)));
                    offsets.push(connectivity.len() as u64);
                    i += 1 + n;
                }
                (offsets, connectivity)
            }
        };
        // XML offsets are the cells' ends; some writers put a leading zero.
        let ends = match piece_offsets.first() {
            Some(0) if piece_offsets.len() == piece.cells.types.len() + 1 => &piece_offsets[1..],
            _ => &piece_offsets[..],
        };
        if ends.len() != piece.cells.types.len() {
            return Err(source.error_at(
                at(number, piece_line),
                ImportErrorKind::BadCount,
                format!(
                    "piece {number} has {} cell offsets but {} cell types",
                    ends.len(),
                    piece.cells.types.len()
                ),
            ));
        }
        first_cells.push(types.len());
        let base = connectivity.len() as u64;
        for &end in ends {
            if end > piece_connectivity.len() as u64 {
                return Err(source.error_at(
                    at(number, |p| p.offsets),
                    ImportErrorKind::BadCount,
                    format!(
                        "piece {number}: cell offset {end} is past the connectivity's {} entries",
                        piece_connectivity.len()
                    ),
                ));
            }
            offsets.push(base + end);
        }
        for &node in &piece_connectivity {
            let global = node.checked_add(first_point).ok_or_else(|| {
                source.error_at(
                    at(number, |p| p.connectivity),
                    ImportErrorKind::IndexOutOfRange,
                    format!("piece {number} refers to point {node}"),
                )
            })?;
            connectivity.push(global);
        }
        types.extend(piece.cells.types.iter().map(|&t| t as u64));
    }
    let cells = Cells {
        offsets: &offsets,
        connectivity: &connectivity,
        types: &types,
    };
    let locate = |cell: usize, data: CellData| {
        let number = first_cells.partition_point(|&first| first <= cell).max(1) - 1;
        at(
            number,
            match data {
                CellData::Offsets => |p| p.offsets,
                CellData::Connectivity => |p| p.connectivity,
                CellData::Types => |p| p.types,
            },
        )
    };
    build(&source, positions, &cells, &locate)
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

/// A legacy VTK data type: its size in binary files and whether it is a float.
#[derive(Clone, Copy)]
enum DataType {
    Float(usize),
    Signed(usize),
    Unsigned(usize),
}

fn data_type(source: &Source<'_>, name: Option<&str>) -> Result<DataType, Error> {
    let name = name.unwrap_or("");
    Ok(match name {
        "float" => DataType::Float(4),
        "double" => DataType::Float(8),
        "char" | "vtktypeint8" => DataType::Signed(1),
        "unsigned_char" | "vtktypeuint8" => DataType::Unsigned(1),
        "short" | "vtktypeint16" => DataType::Signed(2),
        "unsigned_short" | "vtktypeuint16" => DataType::Unsigned(2),
        "int" | "vtktypeint32" => DataType::Signed(4),
        "unsigned_int" | "vtktypeuint32" => DataType::Unsigned(4),
        "long" | "vtktypeint64" | "vtkIdType" => DataType::Signed(8),
        "unsigned_long" | "vtktypeuint64" => DataType::Unsigned(8),
        _ => {
            return Err(source.error(
                ImportErrorKind::Syntax,
                format!("unknown data type `{}`", shorten(name)),
            ));
        }
    })
}

/// The legacy reader's state: the file, its encoding and the rest of the current line.
struct Legacy<'a> {
    source: Source<'a>,
    binary: bool,
    tokens: SplitAsciiWhitespace<'a>,
}

impl<'a> Legacy<'a> {
    /// The next whitespace-separated token of an ASCII data block, across lines.
    fn token(&mut self, what: &str) -> Result<&'a str, Error> {
        loop {
            if let Some(token) = self.tokens.next() {
                return Ok(token);
            }
            let Some(line) = self.source.line()? else {
                return Err(self.source.error(
                    ImportErrorKind::Truncated,
                    format!("the file ends where {what} was expected"),
                ));
            };
            self.tokens = line.split_ascii_whitespace();
        }
    }

    /// The next keyword line, after checking the previous data block left nothing over.
    fn keyword_line(&mut self) -> Result<Option<&'a str>, Error> {
        if let Some(extra) = self.tokens.next() {
            return Err(self.source.error(
                ImportErrorKind::BadCount,
                format!(
                    "`{}` follows the data: more values than the count announces",
                    shorten(extra)
                ),
            ));
        }
        if self.binary {
            self.source.skip_whitespace();
        }
        loop {
            match self.source.line()? {
                None => return Ok(None),
                Some("") => {}
                Some(line) => return Ok(Some(line)),
            }
        }
    }

    /// `count` numbers of type `ty` as `f64`, each checked finite.
    fn floats(&mut self, count: usize, ty: DataType, what: &str) -> Result<Vec<f64>, Error> {
        let size = match ty {
            DataType::Float(s) | DataType::Signed(s) | DataType::Unsigned(s) => s,
        };
        let mut values = Vec::with_capacity(
            self.source
                .capacity(count, if self.binary { size } else { 2 }),
        );
        for _ in 0..count {
            let value = if self.binary {
                self.source.set_binary(true);
                let bytes = self.source.take(size, what)?;
                let value = binary_value(bytes, ty);
                self.source.set_binary(false);
                value
            } else {
                let token = self.token(what)?;
                parse_token(&self.source, Some(token), what)?
            };
            values.push(finite(&self.source, value, what)?);
        }
        Ok(values)
    }

    /// `count` non-negative integers (indices, counts, cell types).
    fn integers(&mut self, count: usize, ty: DataType, what: &str) -> Result<Vec<u64>, Error> {
        let size = match ty {
            DataType::Signed(s) | DataType::Unsigned(s) => s,
            DataType::Float(_) => {
                return Err(self.source.error(
                    ImportErrorKind::Syntax,
                    format!("{what} must be integers, not floating point"),
                ));
            }
        };
        let mut values = Vec::with_capacity(
            self.source
                .capacity(count, if self.binary { size } else { 2 }),
        );
        for _ in 0..count {
            let value = if self.binary {
                self.source.set_binary(true);
                let bytes = self.source.take(size, what)?;
                let value = binary_integer(bytes, ty);
                let value = u64::try_from(value).map_err(|_| {
                    self.source.error(
                        ImportErrorKind::Syntax,
                        format!("{what}: {value} is negative"),
                    )
                })?;
                self.source.set_binary(false);
                value
            } else {
                let token = self.token(what)?;
                parse_token(&self.source, Some(token), what)?
            };
            values.push(value);
        }
        Ok(values)
    }
}

/// A big-endian binary value of type `ty` (`bytes.len()` is its size) as `f64`.
fn binary_value(bytes: &[u8], ty: DataType) -> f64 {
    match ty {
        DataType::Float(4) => {
            f64::from(f32::from_be_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
        }
        DataType::Float(_) => {
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[..8]);
            f64::from_be_bytes(b)
        }
        _ => binary_integer(bytes, ty) as f64,
    }
}

/// A big-endian binary integer of type `ty`.
fn binary_integer(bytes: &[u8], ty: DataType) -> i128 {
    let mut value: u128 = 0;
    for &b in bytes {
        value = (value << 8) | u128::from(b);
    }
    match ty {
        DataType::Signed(size) => {
            let shift = 128 - 8 * size as u32;
            ((value << shift) as i128) >> shift
        }
        _ => value as i128,
    }
}

/// Reads the legacy `.vtk` file `data` (named `path` in errors), coordinates times `scale` (m
/// per file unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] with the line (or byte
/// offset in binary data) for a malformed file, an unsupported version or dataset, cells that
/// are not linear tetrahedra or lower-dimensional, indices out of range, non-finite
/// coordinates.
pub fn parse_legacy(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let mut source = Source::new(path, data);
    let header = source.content_line(None, "the header `# vtk DataFile Version x.y`")?;
    let Some(version) = header.strip_prefix("# vtk DataFile Version ") else {
        return Err(source.error(
            ImportErrorKind::Syntax,
            "a legacy VTK file starts with `# vtk DataFile Version x.y`",
        ));
    };
    let major: u32 = match version.trim().split('.').next().map(str::parse) {
        Some(Ok(major @ 1..=5)) => major,
        _ => {
            return Err(source.error(
                ImportErrorKind::UnknownVersion,
                format!(
                    "version `{}` is not supported (2.0 to 5.1 are)",
                    shorten(version)
                ),
            ));
        }
    };
    // Title: any text, possibly empty.
    if source.line()?.is_none() {
        return Err(source.error(ImportErrorKind::Truncated, "the file ends after its header"));
    }
    let encoding = source.content_line(None, "`ASCII` or `BINARY`")?;
    let binary = match encoding.to_ascii_uppercase().as_str() {
        "ASCII" => false,
        "BINARY" => true,
        _ => {
            return Err(source.error(
                ImportErrorKind::Syntax,
                format!(
                    "expected `ASCII` or `BINARY`, found `{}`",
                    shorten(encoding)
                ),
            ));
        }
    };
    let dataset = source.content_line(None, "`DATASET UNSTRUCTURED_GRID`")?;
    if !dataset.eq_ignore_ascii_case("DATASET UNSTRUCTURED_GRID") {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!(
                "expected `DATASET UNSTRUCTURED_GRID`, found `{}`",
                shorten(dataset)
            ),
        ));
    }
    let mut file = Legacy {
        source,
        binary,
        tokens: "".split_ascii_whitespace(),
    };
    let mut positions: Option<Vec<DVec3>> = None;
    let mut cells: Option<(Vec<u64>, Vec<u64>, FileLocation)> = None;
    let mut types: Option<Vec<u64>> = None;
    while positions.is_none() || cells.is_none() || types.is_none() {
        let Some(line) = file.keyword_line()? else {
            return Err(file.source.error(
                ImportErrorKind::Truncated,
                "the file ends before its POINTS, CELLS and CELL_TYPES",
            ));
        };
        let mut words = line.split_ascii_whitespace();
        let keyword = words.next().unwrap_or("").to_ascii_uppercase();
        match keyword.as_str() {
            "POINTS" => {
                let count: usize = parse_token(&file.source, words.next(), "point count")?;
                let ty = data_type(&file.source, words.next())?;
                let coordinates = file.floats(count.saturating_mul(3), ty, "point coordinates")?;
                let mut points = Vec::with_capacity(count.min(coordinates.len() / 3));
                for p in coordinates.chunks_exact(3) {
                    points.push(scaled(&file.source, DVec3::new(p[0], p[1], p[2]), scale)?);
                }
                positions = Some(points);
            }
            "CELLS" if major >= 5 => {
                let location = file.source.location();
                let offset_count: usize = parse_token(&file.source, words.next(), "offset count")?;
                let connectivity_count: usize =
                    parse_token(&file.source, words.next(), "connectivity size")?;
                let mut arrays = [Vec::new(), Vec::new()];
                for (array, (name, count)) in arrays.iter_mut().zip([
                    ("OFFSETS", offset_count),
                    ("CONNECTIVITY", connectivity_count),
                ]) {
                    let line = file.keyword_line()?.unwrap_or("");
                    let mut words = line.split_ascii_whitespace();
                    if words.next() != Some(name) {
                        return Err(file.source.error(
                            ImportErrorKind::Syntax,
                            format!("expected `{name} <type>`, found `{}`", shorten(line)),
                        ));
                    }
                    let ty = data_type(&file.source, words.next())?;
                    *array = file.integers(count, ty, name)?;
                }
                let [offsets, connectivity] = arrays;
                if offsets.first().is_some_and(|&o| o != 0) {
                    return Err(file.source.error_at(
                        location,
                        ImportErrorKind::BadCount,
                        "the first cell offset is not 0",
                    ));
                }
                cells = Some((offsets, connectivity, location));
            }
            "CELLS" => {
                let location = file.source.location();
                let count: usize = parse_token(&file.source, words.next(), "cell count")?;
                let size: usize = parse_token(&file.source, words.next(), "cell list size")?;
                let list = file.integers(size, DataType::Signed(4), "cell list")?;
                let mut offsets = Vec::with_capacity(count.min(list.len()) + 1);
                offsets.push(0);
                let mut connectivity = Vec::with_capacity(list.len());
                let mut i = 0;
                while i < list.len() {
                    let n = usize::try_from(list[i]).unwrap_or(usize::MAX);
                    let Some(cell) = list.get(i + 1..).and_then(|rest| rest.get(..n)) else {
                        return Err(file.source.error_at(
                            location,
                            ImportErrorKind::BadCount,
                            format!(
                                "cell {} announces {n} points, past the list's {size} entries",
                                offsets.len() - 1
                            ),
                        ));
                    };
                    connectivity.extend_from_slice(cell);
                    offsets.push(connectivity.len() as u64);
                    i += 1 + n;
                }
                if offsets.len() - 1 != count {
                    return Err(file.source.error_at(
                        location,
                        ImportErrorKind::BadCount,
                        format!(
                            "the cell list holds {} cells, the header says {count}",
                            offsets.len() - 1
                        ),
                    ));
                }
                cells = Some((offsets, connectivity, location));
            }
            "CELL_TYPES" => {
                let count: usize = parse_token(&file.source, words.next(), "cell type count")?;
                types = Some(file.integers(count, DataType::Signed(4), "cell types")?);
            }
            _ => {
                return Err(file.source.error(
                    ImportErrorKind::Syntax,
                    format!(
                        "expected POINTS, CELLS or CELL_TYPES, found `{}`",
                        shorten(line)
                    ),
                ));
            }
        }
    }
    let (Some(positions), Some((offsets, connectivity, location)), Some(types)) =
        (positions, cells, types)
    else {
        return Err(file.source.error(
            ImportErrorKind::Truncated,
            "POINTS, CELLS or CELL_TYPES is missing",
        ));
    };
    let cells = Cells {
        offsets: &offsets,
        connectivity: &connectivity,
        types: &types,
    };
    build(&file.source, positions, &cells, &|_, _| location)
}
