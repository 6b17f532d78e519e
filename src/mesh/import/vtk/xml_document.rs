//! The layout of a VTK XML unstructured grid (`.vtu`), as `quick-xml` reads it: the file's
//! encoding attributes, each `<Piece>`'s counts and the `<DataArray>`s of its points and cells
//! (attributes, inline text, lines), and where the appended data lies. Nothing is decoded here
//! (see `xml_data`); every element and attribute this reader needs is checked, and any other is
//! ignored (point and cell data, `<InformationKey>`s, field data).
//!
//! The walk stops at `<AppendedData>`: raw appended data is bytes, not XML. Its region runs from
//! the byte after the `_` that opens it to the last `</AppendedData>` of the file (to the end of
//! the file if there is none).

use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::text::Source;
use quick_xml::events::{BytesStart, Event};

/// How the binary data of the file is laid out: `VTKFile`'s `byte_order`, `header_type` and
/// `compressor` attributes.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Layout {
    /// Whether numbers are stored most significant byte first (`byte_order="BigEndian"`).
    pub(super) big_endian: bool,
    /// Bytes of each integer of a binary block's header: 4 (`UInt32`, the default) or 8.
    pub(super) header_bytes: usize,
    /// The compressor's class name (`vtkZLibDataCompressor`, ...), if the data is compressed.
    pub(super) compressor: Option<String>,
}

impl Default for Layout {
    /// VTK's defaults: little-endian, 32-bit headers, no compression.
    fn default() -> Self {
        Self {
            big_endian: false,
            header_bytes: 4,
            compressor: None,
        }
    }
}

/// Where a `<DataArray>` keeps its values (its `format` attribute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Format {
    /// Numbers as text inside the element.
    Ascii,
    /// Base64 text inside the element.
    Binary,
    /// In `<AppendedData>`, at this offset (bytes of raw data, characters of base64 text).
    Appended(u64),
}

/// A `<DataArray>` element: its attributes, its inline text and where it is.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ArrayDecl {
    /// Its `Name` attribute (empty if none).
    pub(super) name: String,
    /// Its `type` attribute (`Float64`, `Int32`, ...).
    pub(super) value_type: String,
    /// Its `NumberOfComponents` attribute (1 if absent).
    pub(super) components: u64,
    /// Its `format` attribute and appended offset.
    pub(super) format: Format,
    /// Line of the `<DataArray>` tag.
    pub(super) line: usize,
    /// The element's own text (not that of child elements), text events joined by a space.
    pub(super) text: Vec<u8>,
    /// Line where the text starts.
    pub(super) text_line: usize,
}

/// A `<Piece>` element: its counts and the arrays this reader needs.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct PieceDecl {
    /// Line of the `<Piece>` tag.
    pub(super) line: usize,
    /// Its `NumberOfPoints` and `NumberOfCells` attributes.
    pub(super) point_count: u64,
    pub(super) cell_count: u64,
    /// The `<DataArray>` of `<Points>` and those of `<Cells>` named `connectivity`, `offsets`
    /// and `types`.
    pub(super) points: Option<ArrayDecl>,
    pub(super) connectivity: Option<ArrayDecl>,
    pub(super) offsets: Option<ArrayDecl>,
    pub(super) types: Option<ArrayDecl>,
    /// The `<CellData>` array of the cells' physical tags (see [`CELL_TAG_NAMES`]), if any.
    pub(super) cell_tags: Option<ArrayDecl>,
}

/// The names a `<CellData>` array of the cells' region tags goes by: Gmsh's physical groups as
/// meshio writes them, and vmtk's cell entity ids.
pub(super) const CELL_TAG_NAMES: [&str; 2] = ["gmsh:physical", "CellEntityIds"];

/// The `<AppendedData>` region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Appended<'d> {
    /// Whether the data is base64 text (`encoding="base64"`) rather than raw bytes.
    pub(super) base64: bool,
    /// The region, from the byte after its `_`.
    pub(super) data: &'d [u8],
    /// Byte offset of the region in the file.
    pub(super) start: usize,
}

/// A `.vtu` file's layout, pieces and appended data.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Document<'d> {
    pub(super) layout: Layout,
    pub(super) pieces: Vec<PieceDecl>,
    pub(super) appended: Option<Appended<'d>>,
}

/// Reads the layout of the `.vtu` file `data`.
///
/// # Errors
/// [`ImportErrorKind::Syntax`] where the XML is malformed or an attribute this reader needs is
/// missing or invalid, [`ImportErrorKind::Truncated`] for a file ending inside an element,
/// [`ImportErrorKind::UnknownVersion`] for another data set or a piece stored in another file.
pub(super) fn read<'d>(source: &Source<'_>, data: &'d [u8]) -> Result<Document<'d>, Error> {
    let mut walk = Walk {
        source,
        data,
        line: 1,
        counted: 0,
    };
    let mut tree = Tree::default();
    let mut reader = quick_xml::Reader::from_reader(data);
    loop {
        let start = offset(reader.buffer_position()).min(data.len());
        let event = reader.read_event().map_err(|e| {
            let at = walk.line_at(offset(reader.error_position()));
            source.error_at(
                FileLocation::Line(at),
                ImportErrorKind::Syntax,
                format!("invalid VTU file: malformed XML: {e}"),
            )
        })?;
        let line = walk.line_at(start);
        let (tag, empty) = match event {
            Event::Start(tag) => (tag, false),
            Event::Empty(tag) => (tag, true),
            Event::Text(text) => {
                tree.gather(&text, line);
                continue;
            }
            Event::CData(text) => {
                tree.gather(&text, line);
                continue;
            }
            Event::End(_) => {
                tree.close();
                continue;
            }
            Event::Eof => return tree.finish(&walk, line),
            _ => continue,
        };
        if tag.local_name().as_ref() == b"AppendedData" && tree.seen_root {
            let appended = walk.appended(&tag, line, offset(reader.buffer_position()))?;
            tree.document.appended = Some(appended);
            tree.open.clear();
            return tree.finish(&walk, line);
        }
        tree.element(&walk, &tag, line, empty)?;
    }
}

/// The elements read so far: the document, the open elements (innermost last) and the array
/// whose text is being gathered, with the number of elements open inside it.
#[derive(Default)]
struct Tree<'d> {
    document: Document<'d>,
    open: Vec<Vec<u8>>,
    gathering: Option<(ArrayDecl, usize)>,
    seen_root: bool,
}

impl<'d> Tree<'d> {
    /// Reads the start tag `tag` at `line` of `walk`'s file (`empty`: one that closes itself).
    fn element(
        &mut self,
        walk: &Walk<'_, 'd>,
        tag: &BytesStart<'_>,
        line: usize,
        empty: bool,
    ) -> Result<(), Error> {
        if let Some(Err(e)) = tag.attributes().find(Result::is_err) {
            return Err(walk.syntax(line, format!("malformed XML: {e}")));
        }
        let name = tag.local_name().as_ref().to_vec();
        match (self.open.last().map(Vec::as_slice), name.as_slice()) {
            (None, b"VTKFile") => {
                self.document.layout = walk.root(tag, line)?;
                self.seen_root = true;
            }
            (None, _) => return Err(walk.syntax(line, "the root element is not <VTKFile>")),
            (Some(b"UnstructuredGrid"), b"Piece") => {
                let piece = walk.piece(tag, line, self.document.pieces.len())?;
                self.document.pieces.push(piece);
            }
            (Some(b"CellData"), b"DataArray")
                if !attribute(tag, b"Name")
                    .is_some_and(|n| CELL_TAG_NAMES.contains(&n.as_str())) => {}
            (Some(b"Points" | b"Cells" | b"CellData"), b"DataArray") => {
                let array = walk.array(tag, line)?;
                if empty {
                    self.keep(self.open.len(), array);
                } else {
                    self.gathering = Some((array, self.open.len() + 1));
                }
            }
            _ => {}
        }
        if !empty {
            self.open.push(name);
        }
        Ok(())
    }

    /// Adds `text` (at `line`) to the array being gathered when it is the element's own text.
    fn gather(&mut self, text: &[u8], line: usize) {
        let depth = self.open.len();
        if let Some((array, array_depth)) = &mut self.gathering
            && *array_depth == depth
        {
            if array.text.is_empty() {
                array.text_line = line;
            } else {
                array.text.push(b' ');
            }
            array.text.extend_from_slice(text);
        }
    }

    /// Closes the innermost element, keeping the array it ends.
    fn close(&mut self) {
        let depth = self.open.len();
        if let Some((array, _)) = self.gathering.take_if(|(_, d)| *d == depth) {
            self.keep(depth - 1, array);
        }
        self.open.pop();
    }

    /// Keeps `array`, read with `depth` elements open around it, in the last piece if this
    /// reader needs it (the `<Points>` array, the `<Cells>` arrays it names, the first cell tag
    /// array of `<CellData>`).
    fn keep(&mut self, depth: usize, array: ArrayDecl) {
        let parent = depth.checked_sub(1).map(|i| self.open[i].as_slice());
        let Some(piece) = self.document.pieces.last_mut() else {
            return;
        };
        let slot = match (parent, array.name.as_str()) {
            (Some(b"Points"), _) => &mut piece.points,
            (Some(b"Cells"), "connectivity") => &mut piece.connectivity,
            (Some(b"Cells"), "offsets") => &mut piece.offsets,
            (Some(b"Cells"), "types") => &mut piece.types,
            (Some(b"CellData"), name) if CELL_TAG_NAMES.contains(&name) => &mut piece.cell_tags,
            _ => return,
        };
        slot.get_or_insert(array);
    }

    /// The document, once the walk of `walk`'s file has ended at `line`.
    fn finish(self, walk: &Walk<'_, 'd>, line: usize) -> Result<Document<'d>, Error> {
        if let Some(element) = self.open.last() {
            return Err(walk.source.error_at(
                FileLocation::Line(line),
                ImportErrorKind::Truncated,
                format!(
                    "the file ends inside <{}>",
                    String::from_utf8_lossy(element)
                ),
            ));
        }
        if !self.seen_root {
            return Err(walk.syntax(1, "the file has no <VTKFile> element"));
        }
        Ok(self.document)
    }
}

/// The file being walked, with a line counter that only moves forward.
struct Walk<'s, 'd> {
    source: &'s Source<'s>,
    data: &'d [u8],
    /// The line of byte `counted`.
    line: usize,
    counted: usize,
}

impl<'d> Walk<'_, 'd> {
    /// The 1-based line of byte `at` (at or after the last one asked for).
    fn line_at(&mut self, at: usize) -> usize {
        let at = at.min(self.data.len());
        if at > self.counted {
            self.line += self.data[self.counted..at]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            self.counted = at;
        }
        self.line
    }

    /// A syntax error at `line`.
    fn syntax(&self, line: usize, message: impl Into<String>) -> Error {
        self.source.error_at(
            FileLocation::Line(line),
            ImportErrorKind::Syntax,
            format!("invalid VTU file: {}", message.into()),
        )
    }

    /// The layout `<VTKFile>`'s attributes give.
    fn root(&self, tag: &BytesStart<'_>, line: usize) -> Result<Layout, Error> {
        let kind = attribute(tag, b"type").unwrap_or_default();
        if kind != "UnstructuredGrid" {
            return Err(self.source.error_at(
                FileLocation::Line(line),
                ImportErrorKind::UnknownVersion,
                format!(
                    "the file holds a {}, not an UnstructuredGrid",
                    super::super::text::shorten(&kind)
                ),
            ));
        }
        let big_endian = match attribute(tag, b"byte_order").as_deref() {
            None | Some("LittleEndian") => false,
            Some("BigEndian") => true,
            Some(other) => return Err(self.syntax(line, format!("unknown byte_order {other:?}"))),
        };
        let header_bytes = match attribute(tag, b"header_type").as_deref() {
            None | Some("UInt32") => 4,
            Some("UInt64") => 8,
            Some(other) => return Err(self.syntax(line, format!("unknown header_type {other:?}"))),
        };
        Ok(Layout {
            big_endian,
            header_bytes,
            compressor: attribute(tag, b"compressor").filter(|c| !c.is_empty()),
        })
    }

    /// The `<Piece>` numbered `number`, at `line`.
    fn piece(&self, tag: &BytesStart<'_>, line: usize, number: usize) -> Result<PieceDecl, Error> {
        if attribute(tag, b"Source").is_some() {
            return Err(self.source.error_at(
                FileLocation::Line(line),
                ImportErrorKind::UnknownVersion,
                format!("piece {number} is stored in another file: not supported"),
            ));
        }
        let count = |name: &[u8]| {
            let text = attribute(tag, name).unwrap_or_default();
            text.trim().parse::<u64>().map_err(|_| {
                self.syntax(
                    line,
                    format!(
                        "piece {number}'s {} is {:?}, not a count",
                        String::from_utf8_lossy(name),
                        super::super::text::shorten(&text)
                    ),
                )
            })
        };
        Ok(PieceDecl {
            line,
            point_count: count(b"NumberOfPoints")?,
            cell_count: count(b"NumberOfCells")?,
            ..PieceDecl::default()
        })
    }

    /// The `<DataArray>` at `line`, its text not yet gathered.
    fn array(&self, tag: &BytesStart<'_>, line: usize) -> Result<ArrayDecl, Error> {
        let format = match attribute(tag, b"format").as_deref() {
            Some("ascii") => Format::Ascii,
            Some("binary") => Format::Binary,
            Some("appended") => {
                let offset = attribute(tag, b"offset").unwrap_or_default();
                Format::Appended(offset.trim().parse().map_err(|_| {
                    self.syntax(line, "an appended <DataArray> has no valid offset")
                })?)
            }
            other => {
                return Err(self.syntax(line, format!("a <DataArray> has format {other:?}")));
            }
        };
        let components = match attribute(tag, b"NumberOfComponents") {
            None => 1,
            Some(text) => text.trim().parse().map_err(|_| {
                self.syntax(line, "a <DataArray>'s NumberOfComponents is not a count")
            })?,
        };
        Ok(ArrayDecl {
            name: attribute(tag, b"Name").unwrap_or_default(),
            value_type: attribute(tag, b"type").unwrap_or_default(),
            components,
            format,
            line,
            text: Vec::new(),
            text_line: line,
        })
    }

    /// The `<AppendedData>` whose tag at `line` ends at byte `after_tag`.
    fn appended(
        &self,
        tag: &BytesStart<'_>,
        line: usize,
        after_tag: usize,
    ) -> Result<Appended<'d>, Error> {
        let base64 = match attribute(tag, b"encoding").as_deref() {
            Some("raw") => false,
            Some("base64") => true,
            other => {
                return Err(self.syntax(line, format!("<AppendedData> has encoding {other:?}")));
            }
        };
        let rest = &self.data[after_tag.min(self.data.len())..];
        let Some(underscore) = rest.iter().position(|&b| !b.is_ascii_whitespace()) else {
            return Err(self.source.error_at(
                FileLocation::Line(line),
                ImportErrorKind::Truncated,
                "the file ends at <AppendedData>",
            ));
        };
        if rest[underscore] != b'_' {
            return Err(self.syntax(line, "<AppendedData> does not start with '_'"));
        }
        let start = after_tag + underscore + 1;
        let region = &self.data[start..];
        let end = region
            .windows(b"</AppendedData>".len())
            .rposition(|w| w == b"</AppendedData>")
            .unwrap_or(region.len());
        Ok(Appended {
            base64,
            data: &region[..end],
            start,
        })
    }
}

/// The value of `tag`'s attribute `name` (its local name), as text; `None` if absent.
fn attribute(tag: &BytesStart<'_>, name: &[u8]) -> Option<String> {
    tag.attributes()
        .flatten()
        .find(|a| a.key.local_name().as_ref() == name)
        .map(|a| String::from_utf8_lossy(&a.value).into_owned())
}

/// A byte position of `quick-xml` as an index into the input.
fn offset(position: u64) -> usize {
    usize::try_from(position).unwrap_or(usize::MAX)
}
