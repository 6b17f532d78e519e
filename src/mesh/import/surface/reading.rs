//! Reading surface files: Wavefront OBJ with `tobj`, STL (ASCII and binary) with `stl_io`.
//!
//! Both give a [`Surface`] of welded vertices (m) and triangles; OBJ polygons are triangulated,
//! its objects and groups joined, its material libraries never opened; every solid of an ASCII
//! STL file is read (gmsh writes one per surface), each by `stl_io`, their vertices welded. A
//! binary STL must hold the records its count announces, and no more. A file the crate
//! rejects, a face referring to a missing vertex and a coordinate that is not finite once scaled,
//! or beyond ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE) m, are errors; since neither crate
//! says where, the file is scanned again to find the line (or, in binary STL, the byte offset) at
//! fault.

use super::Surface;
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::locate;
use crate::mesh::import::text::Source;
use crate::mesh::import::{check_scale, scaled_defect};
use rapier3d::glamx::DVec3;
use std::borrow::Cow;
use std::collections::HashMap;

/// Reads a Wavefront OBJ surface (all its objects and groups; polygons are triangulated) with
/// `tobj`, coordinates times `scale` (m per file unit). Material libraries are not opened.
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a file `tobj`
/// rejects, with the line of the first statement at fault (`tobj` gives none: the file is
/// scanned again to find it; [`FileLocation::Whole`] if that fails), indices out of range
/// ([`ImportErrorKind::IndexOutOfRange`]), non-finite coordinates (at the vertex's line) and a
/// last statement without a line break ([`ImportErrorKind::Truncated`]: the file may be cut
/// inside a number).
pub fn parse_obj(data: &[u8], path: &str, scale: f64) -> Result<Surface, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
    check_last_statement_ended(&source, data)?;
    // tobj gives each object or group its own copy of the vertices it uses: vertices at the same
    // coordinates are welded back into one, so that a closed surface split into groups stays
    // closed.
    let mut vertices = Vec::new();
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut triangles = Vec::new();
    for model in obj_models(&source, data)? {
        let mut global = Vec::with_capacity(model.mesh.positions.len() / 3);
        for p in model.mesh.positions.chunks_exact(3) {
            let p = DVec3::new(p[0], p[1], p[2]);
            let vertex = scaled_vertex(&source, p, scale, || {
                locate::obj_bad_vertex_line(data, scale)
                    .map_or(FileLocation::Whole, FileLocation::Line)
            })?;
            let key = vertex.to_array().map(f64::to_bits);
            global.push(*welded.entry(key).or_insert_with(|| {
                vertices.push(vertex);
                (vertices.len() - 1) as u32
            }));
        }
        for t in model.mesh.indices.chunks_exact(3) {
            let mut triangle = [0u32; 3];
            for (corner, &i) in triangle.iter_mut().zip(t) {
                *corner = *global.get(i as usize).ok_or_else(|| {
                    source.error_at(
                        FileLocation::Whole,
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "object `{}` refers to vertex {i} of {}",
                            model.name,
                            global.len()
                        ),
                    )
                })?;
            }
            triangles.push(triangle);
        }
    }
    Ok(Surface {
        path: path.to_owned(),
        vertices,
        triangles,
    })
}

/// A [`ImportErrorKind::Truncated`] error at the OBJ file's last line if it holds a statement
/// (anything but a comment) and has no line break: a file cut inside a number reads as another
/// number, a vertex moved or a face on another vertex.
fn check_last_statement_ended(source: &Source<'_>, data: &[u8]) -> Result<(), Error> {
    if data.last().is_none_or(|&b| b == b'\n' || b == b'\r') {
        return Ok(());
    }
    let start = data.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let last = String::from_utf8_lossy(&data[start..]);
    let statement = last.trim();
    if statement.is_empty() || statement.starts_with('#') {
        return Ok(());
    }
    let line = data.iter().filter(|&&b| b == b'\n').count() + 1;
    Err(source.error_at(
        FileLocation::Line(line),
        ImportErrorKind::Truncated,
        "the file ends inside its last statement, without a line break: it may be cut short",
    ))
}

/// The objects and groups `tobj` reads from the OBJ file `data`, triangulated, or its error
/// placed at the line of the first statement at fault.
fn obj_models(source: &Source<'_>, data: &[u8]) -> Result<Vec<tobj::Model>, Error> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj_buf(&mut &data[..], &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| {
        use tobj::LoadError as E;
        let kind = match e {
            E::FaceVertexOutOfBounds
            | E::FaceTexCoordOutOfBounds
            | E::FaceNormalOutOfBounds
            | E::FaceColorOutOfBounds => ImportErrorKind::IndexOutOfRange,
            _ => ImportErrorKind::Syntax,
        };
        let line = locate::obj_error_line(data);
        source.error_at(
            line.map_or(FileLocation::Whole, FileLocation::Line),
            kind,
            format!("invalid OBJ file: {e}"),
        )
    })?;
    Ok(models)
}

/// Reads an STL surface, ASCII (every solid of the file) or binary, with `stl_io` (which
/// merges vertices of identical coordinates within a solid; the solids' vertices are welded
/// here), coordinates times `scale` (m per file unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a file `stl_io`
/// rejects, text outside the solids of an ASCII file, a binary file holding more records than
/// its count, or non-finite coordinates, at the line of the first statement at fault (ASCII)
/// or the byte offset of the record (binary); `stl_io` gives no position, so the file is
/// scanned again to find it.
pub fn parse_stl(data: &[u8], path: &str, scale: f64) -> Result<Surface, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
    let parts = if locate::stl_is_ascii(data) {
        ascii_solids(&source, data)?
    } else {
        check_record_count(&source, data)?;
        vec![(0, Cow::Borrowed(data))]
    };
    let mut surface = Surface {
        path: path.to_owned(),
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    for (lines_before, part) in parts {
        let part: &[u8] = &part;
        let mesh = read_stl_part(&source, part, lines_before)?;
        let mut global = Vec::with_capacity(mesh.vertices.len());
        for v in &mesh.vertices {
            let p = DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
            let vertex = scaled_vertex(&source, p, scale, || {
                locate::stl_bad_vertex_location(part, scale)
                    .map_or(FileLocation::Whole, |at| shifted(at, lines_before))
            })?;
            let key = vertex.to_array().map(f64::to_bits);
            global.push(*welded.entry(key).or_insert_with(|| {
                surface.vertices.push(vertex);
                (surface.vertices.len() - 1) as u32
            }));
        }
        for face in &mesh.faces {
            let mut triangle = [0u32; 3];
            for (corner, &i) in triangle.iter_mut().zip(&face.vertices) {
                *corner = *global.get(i).ok_or_else(|| {
                    source.error_at(
                        FileLocation::Whole,
                        ImportErrorKind::IndexOutOfRange,
                        format!("a facet refers to vertex {i} of {}", global.len()),
                    )
                })?;
            }
            surface.triangles.push(triangle);
        }
    }
    Ok(surface)
}

/// `stl_io`'s mesh of `part`, a solid (or a whole binary file) after `lines_before` lines of
/// the file, its errors placed in the file.
fn read_stl_part(
    source: &Source<'_>,
    part: &[u8],
    lines_before: usize,
) -> Result<stl_io::IndexedMesh, Error> {
    stl_io::read_stl(&mut std::io::Cursor::new(part)).map_err(|e| {
        let kind = if e.kind() == std::io::ErrorKind::UnexpectedEof {
            ImportErrorKind::Truncated
        } else {
            ImportErrorKind::Syntax
        };
        source.error_at(
            locate::stl_error_location(part)
                .map_or(FileLocation::Whole, |at| shifted(at, lines_before)),
            kind,
            format!("invalid STL file: {e}"),
        )
    })
}

/// `at`, a place in a part of a file, as a place in the file when `lines_before` lines come
/// before the part (byte offsets are those of binary files, read whole).
fn shifted(at: FileLocation, lines_before: usize) -> FileLocation {
    match at {
        FileLocation::Line(line) => FileLocation::Line(line + lines_before),
        other => other,
    }
}

/// A part of an STL file read on its own: the lines before it and its bytes.
type SolidPart<'d> = (usize, Cow<'d, [u8]>);

/// The solids of the ASCII STL file `data`, each from its `solid` keyword to its `endsolid`
/// line (or to the end of the file, where `stl_io` will report the missing end), with the
/// number of lines before it. An unnamed `solid` gets a space after it, as `stl_io` needs to
/// read the part as text. Text other than blank lines between solids is an error at its line.
fn ascii_solids<'d>(source: &Source<'_>, data: &'d [u8]) -> Result<Vec<SolidPart<'d>>, Error> {
    let mut solids = Vec::new();
    // The open solid's first byte and line count before it.
    let mut open: Option<(usize, usize)> = None;
    let mut start = 0;
    for (index, line) in data.split_inclusive(|&b| b == b'\n').enumerate() {
        let end = start + line.len();
        let words = line.trim_ascii_start();
        match open {
            None if words.is_empty() => {}
            None if words.starts_with(b"solid") => {
                open = Some((end - words.len(), index));
            }
            None => {
                return Err(source.error_at(
                    FileLocation::Line(index + 1),
                    ImportErrorKind::Syntax,
                    "invalid STL file: text after `endsolid` that starts no new `solid`",
                ));
            }
            Some((first, lines_before)) if words.starts_with(b"endsolid") => {
                solids.push((lines_before, named(&data[first..end])));
                open = None;
            }
            Some(_) => {}
        }
        start = end;
    }
    if let Some((first, lines_before)) = open {
        solids.push((lines_before, named(&data[first..])));
    }
    Ok(solids)
}

/// `solid`, a part starting with the keyword `solid`, with a space after the keyword if it has
/// none (`stl_io` reads a part as text only if it starts with `solid `).
fn named(solid: &[u8]) -> Cow<'_, [u8]> {
    if solid.get(5) == Some(&b' ') {
        Cow::Borrowed(solid)
    } else {
        Cow::Owned([&solid[..5], b" ", &solid[5..]].concat())
    }
}

/// Checks that the binary STL file `data` holds no complete record past the count its header
/// announces (`stl_io` would ignore them); a short file is `stl_io`'s to report.
fn check_record_count(source: &Source<'_>, data: &[u8]) -> Result<(), Error> {
    let Some(count) = data.get(80..84) else {
        return Ok(());
    };
    let count = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as usize;
    let records = (data.len() - 84) / 50;
    if records > count {
        return Err(source.error_at(
            FileLocation::Byte(84 + count * 50),
            ImportErrorKind::BadCount,
            format!("the header announces {count} triangles, the file holds {records} records"),
        ));
    }
    Ok(())
}

/// `p * scale` if a mesh can use it, else an [`ImportErrorKind::NonFinite`] or
/// [`ImportErrorKind::CoordinateOutOfRange`] error at the place `locate` finds (called only
/// then: it scans the file).
fn scaled_vertex(
    source: &Source<'_>,
    p: DVec3,
    scale: f64,
    locate: impl FnOnce() -> FileLocation,
) -> Result<DVec3, Error> {
    match scaled_defect(p, scale) {
        None => Ok(p * scale),
        Some((kind, problem)) => Err(source.error_at(
            locate(),
            kind,
            format!(
                "vertex [{:?}, {:?}, {:?}] times the scale {scale:?} {problem}",
                p.x, p.y, p.z
            ),
        )),
    }
}
