//! Legacy VTK files (`.vtk`), read by hand.
//!
//! Accepts versions 2.0 to 5.1 (`# vtk DataFile Version x.y`, the major version 1 to 5
//! checked), a title line, `ASCII` or `BINARY` (big-endian) and `DATASET UNSTRUCTURED_GRID`,
//! followed by `POINTS`, `CELLS` and `CELL_TYPES` in any order: `CELLS` as one list of
//! `n i_1 ... i_n` before version 5, as `OFFSETS` and `CONNECTIVITY` arrays (the first offset 0)
//! from version 5 on. A `METADATA` block after an array (written by the VTK 9 library:
//! component names, information keys, up to a blank line) is skipped. The attribute data after
//! the grid is read by `legacy_attributes` (a cell array of region tags kept, the rest read
//! past). Any other keyword before all three are read, another data set or encoding, counts that disagree with the data, and an
//! ASCII file whose last data line has no line break (a file cut inside a number would read as
//! another number) are errors at the line (or, in binary data, the byte offset) at fault.

use super::legacy_attributes;
use super::legacy_data::{DataType, Legacy, data_type};
use super::{Cells, build};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::{Source, parse_token, scaled, shorten};
use crate::mesh::import::{RawMesh, check_scale};
use rapier3d::glamx::DVec3;
use std::str::SplitAsciiWhitespace;

/// Reads the legacy `.vtk` file `data` (named `path` in errors), coordinates times `scale` (m
/// per file unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] with the line (or byte
/// offset in binary data) for a malformed file, an unsupported version or dataset, cells that
/// are not tetrahedra (linear or quadratic) or lower-dimensional, indices out of range, non-finite
/// coordinates.
pub fn parse_legacy(data: &[u8], path: &str, scale: f64) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let mut source = Source::new(path, data);
    let (major, binary) = read_header(&mut source)?;
    let mut file = Legacy::new(source, binary);
    let mut sections = Sections::default();
    while sections.positions.is_none() || sections.cells.is_none() || sections.types.is_none() {
        let Some(line) = file.keyword_line()? else {
            return Err(file.source.error(
                ImportErrorKind::Truncated,
                "the file ends before its POINTS, CELLS and CELL_TYPES",
            ));
        };
        sections.read(&mut file, line, major, scale)?;
    }
    let Sections {
        positions: Some(positions),
        cells: Some((offsets, connectivity, location)),
        types: Some(types),
    } = sections
    else {
        return Err(file.source.error(
            ImportErrorKind::Truncated,
            "POINTS, CELLS or CELL_TYPES is missing",
        ));
    };
    let tags = legacy_attributes::read_cell_tags(&mut file, types.len(), positions.len())?;
    if !binary {
        // A file cut inside its last number would read as another number.
        file.source.check_line_ended("its last data line")?;
    }
    let tags: Vec<Option<u64>> = tags.into_iter().flatten().map(Some).collect();
    let cells = Cells {
        offsets: &offsets,
        connectivity: &connectivity,
        types: &types,
        tags: &tags,
    };
    build(&file.source, positions, &cells, &|_, _| location)
}

/// Reads the header up to `DATASET UNSTRUCTURED_GRID`: the file's major version and whether
/// its data is binary.
fn read_header(source: &mut Source<'_>) -> Result<(u32, bool), Error> {
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
    Ok((major, binary))
}

/// Cell offsets (starting at 0) and connectivity, with the line of their `CELLS` keyword.
type CellLists = (Vec<u64>, Vec<u64>, FileLocation);

/// The sections read so far.
#[derive(Default)]
struct Sections {
    /// `POINTS` (m).
    positions: Option<Vec<DVec3>>,
    /// `CELLS`.
    cells: Option<CellLists>,
    /// `CELL_TYPES`.
    types: Option<Vec<u64>>,
}

impl Sections {
    /// Reads the section that keyword line `line` opens, in a file of version `major` whose
    /// coordinates are `scale` m per unit.
    fn read(
        &mut self,
        file: &mut Legacy<'_>,
        line: &str,
        major: u32,
        scale: f64,
    ) -> Result<(), Error> {
        let mut words = line.split_ascii_whitespace();
        let keyword = words.next().unwrap_or("").to_ascii_uppercase();
        match keyword.as_str() {
            "POINTS" => self.positions = Some(read_points(file, words, scale)?),
            "CELLS" => self.cells = Some(read_cells(file, words, major)?),
            "CELL_TYPES" => {
                let count: usize = parse_token(&file.source, words.next(), "cell type count")?;
                self.types = Some(file.integers(count, DataType::Signed(4), "cell types")?);
            }
            // The VTK 9 library's description of the array before (its names, its range): text
            // lines up to a blank one.
            "METADATA" => while file.source.line()?.is_some_and(|l| !l.is_empty()) {},
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
        Ok(())
    }
}

/// The points of a `POINTS <count> <type>` section (`words` after the keyword), scaled to m.
fn read_points(
    file: &mut Legacy<'_>,
    mut words: SplitAsciiWhitespace<'_>,
    scale: f64,
) -> Result<Vec<DVec3>, Error> {
    let count: usize = parse_token(&file.source, words.next(), "point count")?;
    let ty = data_type(&file.source, words.next())?;
    let coordinates = file.floats(count.saturating_mul(3), ty, "point coordinates")?;
    let mut points = Vec::with_capacity(count.min(coordinates.len() / 3));
    for p in coordinates.chunks_exact(3) {
        points.push(scaled(&file.source, DVec3::new(p[0], p[1], p[2]), scale)?);
    }
    Ok(points)
}

/// The cells of a `CELLS <n> <m>` section (`words` after the keyword) in a file of version
/// `major`: from version 5 on, `n` offsets and `m` connectivity entries in `OFFSETS` and
/// `CONNECTIVITY` arrays; before, `n` cells in one list of `m` numbers.
fn read_cells(
    file: &mut Legacy<'_>,
    mut words: SplitAsciiWhitespace<'_>,
    major: u32,
) -> Result<CellLists, Error> {
    let location = file.source.location();
    let [first, second] = if major >= 5 {
        ["offset count", "connectivity size"]
    } else {
        ["cell count", "cell list size"]
    };
    let header = CellsHeader {
        location,
        first: parse_token(&file.source, words.next(), first)?,
        second: parse_token(&file.source, words.next(), second)?,
    };
    if major >= 5 {
        header.read_arrays(file)
    } else {
        header.read_list(file)
    }
}

/// A `CELLS <first> <second>` keyword line: its location and its two counts.
struct CellsHeader {
    location: FileLocation,
    first: usize,
    second: usize,
}

impl CellsHeader {
    /// The cells of a version 5 section: its `OFFSETS <type>` and `CONNECTIVITY <type>`
    /// arrays, of `first` and `second` entries.
    fn read_arrays(self, file: &mut Legacy<'_>) -> Result<CellLists, Error> {
        let (location, offset_count, connectivity_count) = (self.location, self.first, self.second);
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
        Ok((offsets, connectivity, location))
    }

    /// The `first` cells of a section before version 5: one list of `second` numbers
    /// `n i_1 ... i_n`, turned into offsets and connectivity.
    fn read_list(self, file: &mut Legacy<'_>) -> Result<CellLists, Error> {
        let (location, count, size) = (self.location, self.first, self.second);
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
        Ok((offsets, connectivity, location))
    }
}
