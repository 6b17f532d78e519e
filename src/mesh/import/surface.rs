//! Closed surface meshes (Wavefront OBJ, STL) filled with tetrahedra.
//!
//! The surface is read with the `tobj` or `stl_io` crate, checked closed and consistently
//! oriented, and filled by [`fill`]:
//!
//! 1. a body-centred cubic (BCC) lattice of spacing `h` (the surface's largest bounding-box
//!    extent over [`SurfaceOptions::cells_across`]) is laid over the surface: cube corners and
//!    cube centres, each pair of neighbouring centres with the four corners of their shared
//!    face making four tetrahedra whose dihedral angles are 60° and 90°;
//! 2. the tetrahedra whose centroid lies inside the surface are kept (point containment by
//!    `parry3d`'s triangle mesh with pseudo-normals, as re-exported by rapier);
//! 3. the nodes on the boundary of the kept set are moved to their closest point on the
//!    surface, each move shortened (3/4, 1/2, 1/4, none) when it would push an incident
//!    tetrahedron's shape quality below a threshold; then interior nodes next to the boundary
//!    are relaxed towards the mean of their neighbours when that improves their worst element.
//!
//! The result conforms to the surface only approximately: its boundary nodes lie on the
//! surface, but sharp edges and corners narrower than about `h` are rounded, so the volume
//! differs from the enclosed one by a fraction of a percent to a few percent (measured in
//! `tests/mesh_import.rs` on a 642-vertex icosphere: -2.2 % at 8 cells across, -0.41 % at 16,
//! -0.24 % at 32, with minimum dihedral angles of 10.0°, 9.0° and 8.7° and no inverted
//! element; boundary nodes whose full move would flatten an element stay up to 0.24 cell
//! outside the surface). Conforming tetrahedralizers (`TetGen` through `tritet`) are AGPL-licensed, and
//! `parry3d`'s own `volume_mesh` encloses the shape (1.26 times its volume on the same sphere),
//! hence this lattice approach.

use super::locate;
use super::text::Source;
use super::{RawMesh, check_scale};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::signed_volume;
use rapier3d::glamx::{DVec3, Vec3};
use rapier3d::parry::query::PointQueryWithLocation;
use rapier3d::parry::shape::{TriMesh, TriMeshFlags};
use std::collections::HashMap;

/// Largest [`SurfaceOptions::cells_across`]: a lattice of 128³ cells is already about 25
/// million tetrahedra.
const MAX_CELLS_ACROSS: usize = 128;
/// Shape quality ([`shape_quality`]) below which a boundary node's move is shortened.
const MIN_QUALITY: f64 = 0.2;

/// How [`fill`] tetrahedralizes a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceOptions {
    /// Lattice cells across the surface's largest bounding-box extent, 2 to 128 (default 16):
    /// the element size is about that extent over this number.
    pub cells_across: usize,
}

impl Default for SurfaceOptions {
    fn default() -> Self {
        Self { cells_across: 16 }
    }
}

/// A closed triangulated surface as read from a file, positions in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The file it was read from (for error messages).
    pub path: String,
    /// Vertex positions (m).
    pub vertices: Vec<DVec3>,
    /// Triangles, three indices into `vertices` each.
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// The volume enclosed by the surface (m³), by the divergence theorem: positive when the
    /// triangles' normals `(b - a) x (c - a)` point outwards.
    pub fn enclosed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|i| self.vertices.get(i as usize).copied());
                Some(a?.dot(b?.cross(c?)) / 6.0)
            })
            .sum()
    }

    fn error(&self, message: impl Into<String>) -> Error {
        Error::MeshImport {
            path: self.path.clone(),
            location: FileLocation::Whole,
            kind: ImportErrorKind::InvalidSurface,
            message: message.into(),
        }
    }
}

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
    // tobj gives each object or group its own copy of the vertices it uses: vertices at the same
    // coordinates are welded back into one, so that a closed surface split into groups stays
    // closed.
    let mut vertices = Vec::new();
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut triangles = Vec::new();
    for model in models {
        let mut global = Vec::with_capacity(model.mesh.positions.len() / 3);
        for p in model.mesh.positions.chunks_exact(3) {
            let p = DVec3::new(p[0], p[1], p[2]);
            let vertex = scaled_vertex(&source, p, scale, || {
                locate::obj_non_finite_line(data, scale)
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
                locate::stl_non_finite_location(data, scale).unwrap_or(FileLocation::Whole)
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

/// `p * scale` if finite, else a [`ImportErrorKind::NonFinite`] error at the place `locate`
/// finds (called only then: it scans the file).
fn scaled_vertex(
    source: &Source<'_>,
    p: DVec3,
    scale: f64,
    locate: impl FnOnce() -> FileLocation,
) -> Result<DVec3, Error> {
    let scaled = p * scale;
    if scaled.is_finite() {
        Ok(scaled)
    } else {
        Err(source.error_at(
            locate(),
            ImportErrorKind::NonFinite,
            format!(
                "vertex [{:?}, {:?}, {:?}] times the scale {scale:?} is not finite",
                p.x, p.y, p.z
            ),
        ))
    }
}

/// Fills the closed surface with tetrahedra on a BCC lattice snapped to the surface (see the
/// module documentation). Inward-facing surfaces are accepted (their orientation is flipped).
///
/// # Errors
/// [`Error::InvalidSetting`] for `cells_across` outside 2 to 128; [`Error::MeshImport`] of kind
/// [`ImportErrorKind::InvalidSurface`] for an empty surface, one that is open, non-manifold or
/// inconsistently oriented, or one enclosing no volume; of kind
/// [`ImportErrorKind::NoTetrahedra`] when no lattice tetrahedron falls inside.
pub fn fill(surface: &Surface, options: &SurfaceOptions) -> Result<RawMesh, Error> {
    if !(2..=MAX_CELLS_ACROSS).contains(&options.cells_across) {
        return Err(Error::InvalidSetting {
            parameter: "cells_across",
            value: options.cells_across as f64,
            reason: "must be between 2 and 128",
        });
    }
    let triangles = checked_triangles(surface)?;
    let volume = surface.enclosed_volume();
    let (lo, hi) = surface
        .vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let extent = (hi - lo).max_element();
    if volume.abs().partial_cmp(&(1e-9 * extent.powi(3))) != Some(std::cmp::Ordering::Greater) {
        return Err(surface.error(format!("the surface encloses no volume ({volume:e} m^3)")));
    }
    let triangles: Vec<[u32; 3]> = if volume < 0.0 {
        triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
    } else {
        triangles
    };
    let centre = (lo + hi) / 2.0;
    let local: Vec<Vec3> = surface
        .vertices
        .iter()
        .map(|&p| (p - centre).as_vec3())
        .collect();
    let trimesh = TriMesh::with_flags(local, triangles.clone(), TriMeshFlags::ORIENTED)
        .map_err(|e| surface.error(format!("parry rejects the surface: {e}")))?;
    let projector = Projector {
        trimesh: &trimesh,
        vertices: &surface.vertices,
        triangles: &triangles,
        centre,
    };

    // 1. The BCC lattice over the bounding box grown by one cell.
    let h = extent / options.cells_across as f64;
    let origin = lo - DVec3::splat(h);
    let cells = ((hi - lo) / h)
        .ceil()
        .as_uvec3()
        .to_array()
        .map(|n| n as usize + 2);
    let [nx, ny, nz] = cells;
    let corner_count = (nx + 1) * (ny + 1) * (nz + 1);
    let corner = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let centre_node = |i: usize, j: usize, k: usize| (corner_count + i + nx * (j + ny * k)) as u32;
    let mut positions = Vec::with_capacity(corner_count + nx * ny * nz);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                positions.push(origin + DVec3::new(i as f64, j as f64, k as f64) * h);
            }
        }
    }
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                positions.push(origin + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * h);
            }
        }
    }
    // 2. Tetrahedra around each pair of neighbouring centres, kept when their centroid is inside.
    let mut tets = Vec::new();
    let mut keep = |tet: [u32; 4], positions: &[DVec3]| {
        let centroid = tet.iter().map(|&n| positions[n as usize]).sum::<DVec3>() / 4.0;
        if projector.contains(centroid) {
            let mut tet = tet;
            if signed_volume(positions, &tet) < 0.0 {
                tet.swap(2, 3);
            }
            tets.push(tet);
        }
    };
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let c0 = centre_node(i, j, k);
                if i + 1 < nx {
                    let c1 = centre_node(i + 1, j, k);
                    let face = [
                        corner(i + 1, j, k),
                        corner(i + 1, j + 1, k),
                        corner(i + 1, j + 1, k + 1),
                        corner(i + 1, j, k + 1),
                    ];
                    for m in 0..4 {
                        keep([c0, c1, face[m], face[(m + 1) % 4]], &positions);
                    }
                }
                if j + 1 < ny {
                    let c1 = centre_node(i, j + 1, k);
                    let face = [
                        corner(i, j + 1, k),
                        corner(i + 1, j + 1, k),
                        corner(i + 1, j + 1, k + 1),
                        corner(i, j + 1, k + 1),
                    ];
                    for m in 0..4 {
                        keep([c0, c1, face[m], face[(m + 1) % 4]], &positions);
                    }
                }
                if k + 1 < nz {
                    let c1 = centre_node(i, j, k + 1);
                    let face = [
                        corner(i, j, k + 1),
                        corner(i + 1, j, k + 1),
                        corner(i + 1, j + 1, k + 1),
                        corner(i, j + 1, k + 1),
                    ];
                    for m in 0..4 {
                        keep([c0, c1, face[m], face[(m + 1) % 4]], &positions);
                    }
                }
            }
        }
    }
    if tets.is_empty() {
        return Err(Error::MeshImport {
            path: surface.path.clone(),
            location: FileLocation::Whole,
            kind: ImportErrorKind::NoTetrahedra,
            message: format!(
                "no lattice tetrahedron falls inside the surface at {} cells across",
                options.cells_across
            ),
        });
    }
    // 3. Boundary nodes onto the surface, interior neighbours relaxed.
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (t, tet) in tets.iter().enumerate() {
        for &n in tet {
            incident[n as usize].push(t as u32);
        }
    }
    let mut on_boundary = vec![false; positions.len()];
    for face in crate::mesh::surface::boundary_faces(&tets) {
        for n in face {
            on_boundary[n as usize] = true;
        }
    }
    let boundary: Vec<usize> = (0..positions.len()).filter(|&n| on_boundary[n]).collect();
    for _sweep in 0..3 {
        for &n in &boundary {
            let target = projector.closest_point(positions[n]);
            move_node(
                &mut positions,
                &tets,
                &incident[n],
                n,
                target,
                &[1.0, 0.75, 0.5, 0.25],
            );
        }
    }
    let near_boundary: Vec<usize> = (0..positions.len())
        .filter(|&n| {
            !on_boundary[n]
                && incident[n]
                    .iter()
                    .any(|&t| tets[t as usize].iter().any(|&m| on_boundary[m as usize]))
        })
        .collect();
    for _sweep in 0..2 {
        for &n in &near_boundary {
            let mut sum = DVec3::ZERO;
            let mut count = 0.0;
            for &t in &incident[n] {
                for &m in &tets[t as usize] {
                    if m as usize != n {
                        sum += positions[m as usize];
                        count += 1.0;
                    }
                }
            }
            let target = sum / count;
            move_node(&mut positions, &tets, &incident[n], n, target, &[0.5]);
        }
    }
    // Keep only the nodes in use, in lattice order.
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut used = Vec::new();
    for tet in &tets {
        for &n in tet {
            new_index[n as usize] = 0;
        }
    }
    for (n, index) in new_index.iter_mut().enumerate() {
        if *index == 0 {
            *index = used.len() as u32;
            used.push(positions[n]);
        }
    }
    let tets: Vec<[u32; 4]> = tets
        .iter()
        .map(|t| t.map(|n| new_index[n as usize]))
        .collect();
    Ok(RawMesh {
        path: surface.path.clone(),
        positions: used,
        mid_edge_nodes: Vec::new(),
        tet_locations: vec![FileLocation::Whole; tets.len()],
        tets,
    })
}

/// Moves node `n` from its position towards `target` by the first of `fractions` that keeps
/// every incident tetrahedron positive with a shape quality of at least [`MIN_QUALITY`] (or no
/// worse than before, if it was already below); leaves it in place if none does.
fn move_node(
    positions: &mut [DVec3],
    tets: &[[u32; 4]],
    incident: &[u32],
    n: usize,
    target: DVec3,
    fractions: &[f64],
) {
    let start = positions[n];
    let worst = |positions: &[DVec3]| {
        incident
            .iter()
            .map(|&t| shape_quality(positions, &tets[t as usize]))
            .fold(f64::INFINITY, f64::min)
    };
    let before = worst(positions);
    let required = before.min(MIN_QUALITY);
    for &fraction in fractions {
        positions[n] = start + (target - start) * fraction;
        let after = worst(positions);
        if after >= required && after > 0.0 {
            return;
        }
    }
    positions[n] = start;
}

/// Shape quality of a tetrahedron (dimensionless): `6 sqrt(2) V / l_rms^3`, 1 for a regular
/// one, 0 for a flat one, negative for an inverted one.
fn shape_quality(positions: &[DVec3], tet: &[u32; 4]) -> f64 {
    let p = tet.map(|i| positions[i as usize]);
    let mut sum = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            sum += p[i].distance_squared(p[j]);
        }
    }
    let rms = (sum / 6.0).sqrt();
    6.0 * std::f64::consts::SQRT_2 * signed_volume(positions, tet) / rms.powi(3)
}

/// The triangles without degenerate ones, or an error if the surface is empty, open,
/// non-manifold or inconsistently oriented.
fn checked_triangles(surface: &Surface) -> Result<Vec<[u32; 3]>, Error> {
    let n = surface.vertices.len();
    let triangles: Vec<[u32; 3]> = surface
        .triangles
        .iter()
        .copied()
        .filter(|&[a, b, c]| a != b && b != c && a != c)
        .collect();
    if triangles.is_empty() {
        return Err(surface.error("the surface has no triangles"));
    }
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
    for &[a, b, c] in &triangles {
        for edge in [(a, b), (b, c), (c, a)] {
            if edge.0 as usize >= n || edge.1 as usize >= n {
                return Err(surface.error(format!(
                    "a triangle refers to vertex {}, but there are {n}",
                    edge.0.max(edge.1)
                )));
            }
            *directed.entry(edge).or_insert(0) += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        if count != 1 || directed.get(&(b, a)) != Some(&1) {
            return Err(surface.error(format!(
                "the surface is not closed and consistently oriented: edge {a}-{b} is used \
                 {count} time(s) in this direction and {} in the other",
                directed.get(&(b, a)).copied().unwrap_or(0)
            )));
        }
    }
    Ok(triangles)
}

/// Point queries against the surface: containment by parry (f32, pseudo-normals), closest
/// points recomputed in f64 on the triangle parry finds.
struct Projector<'s> {
    trimesh: &'s TriMesh,
    vertices: &'s [DVec3],
    triangles: &'s [[u32; 3]],
    centre: DVec3,
}

impl Projector<'_> {
    fn contains(&self, p: DVec3) -> bool {
        self.trimesh
            .project_local_point_and_get_location((p - self.centre).as_vec3(), true)
            .0
            .is_inside
    }

    fn closest_point(&self, p: DVec3) -> DVec3 {
        let (_, (triangle, _)) = self
            .trimesh
            .project_local_point_and_get_location((p - self.centre).as_vec3(), false);
        match self.triangles.get(triangle as usize) {
            Some(t) => {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                closest_on_triangle(p, a, b, c)
            }
            None => p,
        }
    }
}

/// The point of triangle `abc` closest to `p` (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f64::MIN_POSITIVE {
        return a;
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}
