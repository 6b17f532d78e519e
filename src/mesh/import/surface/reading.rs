//! Reading surface files: Wavefront OBJ with `tobj`, STL (ASCII and binary) with `stl_io`.
//!
//! Both give a [`Surface`] of welded vertices (m) and triangles; OBJ polygons are triangulated,
//! its objects and groups joined, its material libraries never opened. A file the crate
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
use std::collections::HashMap;

/// Reads a Wavefront OBJ surface (all its objects and groups; polygons are triangulated) with
/// `tobj`, coordinates times `scale` (m per file unit). Material libraries are not opened.
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a file `tobj`
/// rejects, with the line of the first statement at fault (`tobj` gives none: the file is
/// scanned again to find it; [`FileLocation::Whole`] if that fails), indices out of range
/// ([`ImportErrorKind::IndexOutOfRange`]) or non-finite coordinates (at the vertex's line).
pub fn parse_obj(data: &[u8], path: &str, scale: f64) -> Result<Surface, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
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

/// Reads an STL surface, ASCII or binary, with `stl_io` (which merges vertices of identical
/// coordinates), coordinates times `scale` (m per file unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for a file `stl_io`
/// rejects or non-finite coordinates, at the line of the first statement at fault (ASCII) or
/// the byte offset of the incomplete or non-finite record (binary); `stl_io` gives no position,
/// so the file is scanned again to find it.
pub fn parse_stl(data: &[u8], path: &str, scale: f64) -> Result<Surface, Error> {
    check_scale(scale)?;
    let source = Source::new(path, data);
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(data)).map_err(|e| {
        let kind = if e.kind() == std::io::ErrorKind::UnexpectedEof {
            ImportErrorKind::Truncated
        } else {
            ImportErrorKind::Syntax
        };
        source.error_at(
            locate::stl_error_location(data).unwrap_or(FileLocation::Whole),
            kind,
            format!("invalid STL file: {e}"),
        )
    })?;
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| {
            let p = DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
            scaled_vertex(&source, p, scale, || {
                locate::stl_bad_vertex_location(data, scale).unwrap_or(FileLocation::Whole)
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut triangles = Vec::with_capacity(mesh.faces.len());
    for face in &mesh.faces {
        let mut triangle = [0u32; 3];
        for (corner, &i) in triangle.iter_mut().zip(&face.vertices) {
            if i >= vertices.len() {
                return Err(source.error_at(
                    FileLocation::Whole,
                    ImportErrorKind::IndexOutOfRange,
                    format!("a facet refers to vertex {i} of {}", vertices.len()),
                ));
            }
            *corner = i as u32;
        }
        triangles.push(triangle);
    }
    Ok(Surface {
        path: path.to_owned(),
        vertices,
        triangles,
    })
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
