//! Reading tetrahedral meshes written by other tools, and filling closed surfaces with
//! tetrahedra.
//!
//! | format | extension | reader |
//! |---|---|---|
//! | Gmsh MSH 2.2 and 4.1, ASCII and binary; 4.0 (ASCII) | `.msh` | [`gmsh`] |
//! | `TetGen` | `.node` + `.ele` | [`tetgen`] |
//! | VTK XML unstructured grid (ASCII, base64, appended raw or base64; uncompressed or zlib) | `.vtu` | [`vtk`] |
//! | VTK legacy unstructured grid (ASCII and binary, 2.0 to 5.1) | `.vtk` | [`vtk`] |
//! | surface: Wavefront OBJ, STL (ASCII and binary), Gmsh triangles only | `.obj`, `.stl`, `.msh` | [`surface`], [`gmsh::parse_surface`] |
//!
//! Gmsh's physical groups (and the cell tags of `.vtu` and legacy `.vtk` files, unnamed) are
//! kept as [`MeshRegion`]s of the raw mesh (the nodes of their elements, a volume group's
//! tetrahedra); [`RawMesh::regions_in_mesh`] numbers their nodes as the validated mesh's, [`MeshRegion::find`] picks one by name or tag ([`RegionId`]) and
//! [`RawMesh::keep_volume`] keeps one volume's tetrahedra (see the `region` module's example).
//!
//! Every reader takes a `scale` in metres per file unit (1 for files in metres, 0.001 for
//! millimetres) and first returns a [`RawMesh`]: positions and tetrahedra as the file has them,
//! lower-dimensional elements (points, lines, boundary triangles) skipped. Hexahedra (Gmsh and
//! VTK, linear and 27-node) are split into tetrahedra on their own nodes, conforming between
//! neighbours ([`Hexahedra`]); [`RawMesh::into_cage`] makes 27-node ones a
//! [`QuadraticHexMesh`](crate::mesh::QuadraticHexMesh) cage. [`check`] reports a raw
//! mesh's quality, defects included; [`RawMesh::into_mesh`] drops the nodes no tetrahedron uses
//! (geometry points of Gmsh files), fixes the orientation of inverted tetrahedra and validates
//! the result into a [`TetMesh`]. [`load`] does both, choosing the reader by extension.
//!
//! Malformed files give [`Error::MeshImport`] with the file, the line (text) or byte offset
//! (binary) and the [`ImportErrorKind`]; files that cannot be opened give [`Error::Io`]. Every
//! reader reports lines: the Gmsh, `TetGen`, VTU and legacy VTK readers as they read (VTU
//! errors at the `<DataArray>` or `<Piece>` at fault, appended binary data by byte offset); the
//! OBJ and STL readers, whose crates (`tobj`, `stl_io`) say what is wrong but not where, by
//! scanning the file again once it has failed (the first statement the crate rejects; binary STL
//! by the offset of the incomplete record). Only what no single place causes (no tetrahedra at
//! all, a surface that is not closed) carries [`FileLocation::Whole`]. No reader panics or allocates more than its input can
//! fill, whatever the bytes (fuzzed in `tests/mesh_import`).
//!
//! # Example
//! ```
//! use rapier_fvm::mesh::import;
//!
//! // A tetrahedron in TetGen's format, in millimetres.
//! let node = b"# corners\n4 3 0 0\n1 0 0 0\n2 10 0 0\n3 0 10 0\n4 0 0 10\n";
//! let ele = b"1 4 0\n1 1 2 3 4\n";
//! let raw = import::tetgen::parse(node, "tet.node", ele, "tet.ele", 0.001)?;
//! let mesh = raw.into_mesh()?;
//! assert_eq!(mesh.tet_count(), 1);
//! assert!((mesh.volume() - 1e-6 / 6.0).abs() < 1e-18); // (1 cm)^3 / 6
//! # Ok::<(), rapier_fvm::Error>(())
//! ```

pub mod gmsh;
mod hexahedra;
mod locate;
pub mod quality;
mod region;
pub mod surface;
pub mod tetgen;
mod text;
pub mod vtk;

pub use crate::error::{FileLocation, ImportErrorKind};
pub use hexahedra::{GMSH_TRIQUADRATIC, Hexahedra, VTK_TRIQUADRATIC};
pub use quality::{QualityReport, check, check_raw};
pub use region::{MeshRegion, RegionId};
pub use surface::SurfaceOptions;

use crate::Error;
use crate::mesh::{QuadraticTetMesh, TetMesh};
use rapier3d::glamx::DVec3;
use std::path::Path;

/// A tetrahedral mesh as read from a file, before validation: positions already scaled to
/// metres, tetrahedra as node indices into `positions` (in range, but possibly inverted,
/// degenerate, or leaving nodes unused).
#[derive(Debug, Clone, PartialEq)]
pub struct RawMesh {
    /// The file it was read from, as given (for error messages).
    pub path: String,
    /// Node positions (m).
    pub positions: Vec<DVec3>,
    /// Tetrahedra, four indices into `positions` each (the corners), in file order; a
    /// hexahedron's split follow one another ([`RawMesh::hexahedra`]).
    pub tets: Vec<[u32; 4]>,
    /// For a mesh of quadratic tetrahedra, the six mid-edge nodes of each (indices into
    /// `positions`, VTK's edge order `(0,1) (1,2) (0,2) (0,3) (1,3) (2,3)`); empty for linear
    /// ones.
    pub mid_edge_nodes: Vec<[u32; 6]>,
    /// Where each tetrahedron was defined in the file (same length as `tets`).
    pub tet_locations: Vec<FileLocation>,
    /// The file's named parts (Gmsh physical groups), in order of dimension and tag; empty for
    /// formats that keep none.
    pub regions: Vec<MeshRegion>,
    /// The hexahedra `tets` were split from, for a file of hexahedra.
    pub hexahedra: Hexahedra,
}

impl RawMesh {
    /// The validated mesh: nodes that no tetrahedron uses are dropped and the others renumbered
    /// in their order of first use, inverted tetrahedra are re-oriented. A mesh of quadratic
    /// tetrahedra becomes their [subdivision](QuadraticTetMesh::subdivided) into linear ones on
    /// all its nodes, which keeps every node and the curved shape; read it with
    /// [`RawMesh::into_quadratic_mesh`] to simulate the quadratic elements themselves.
    ///
    /// # Errors
    /// [`Error::MeshImport`] of kind [`ImportErrorKind::NoTetrahedra`] for a mesh without
    /// tetrahedra, [`ImportErrorKind::IndexOutOfRange`] for an index past `positions`,
    /// [`ImportErrorKind::NonFinite`] or [`ImportErrorKind::CoordinateOutOfRange`] at the first
    /// tetrahedron using a node that is not finite or beyond
    /// ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE) m (the readers refuse those at the node's
    /// own line), and [`ImportErrorKind::InvalidMesh`] naming the element's place in the file
    /// when [`TetMesh::new_reoriented`] rejects it (a degenerate, too small or repeated-node
    /// tetrahedron).
    pub fn into_mesh(self) -> Result<TetMesh, Error> {
        if !self.mid_edge_nodes.is_empty() {
            return Ok(self.into_quadratic_mesh()?.subdivided().clone());
        }
        if matches!(self.hexahedra, Hexahedra::Triquadratic(_)) {
            return Ok(self.into_cage()?.subdivided().clone());
        }
        let (positions, tets) = self.renumbered(&self.tets)?;
        match TetMesh::new_reoriented(positions, tets) {
            Ok((mesh, _flipped)) => Ok(mesh),
            Err(e) => Err(self.invalid(e)),
        }
    }

    /// The validated mesh of quadratic tetrahedra: the file's own for a quadratic mesh (nodes
    /// renumbered and inverted elements re-oriented as by [`RawMesh::into_mesh`]), or a linear
    /// mesh elevated by [`QuadraticTetMesh::from_linear`].
    ///
    /// # Errors
    /// Those of [`RawMesh::into_mesh`], and [`ImportErrorKind::InvalidMesh`] naming the
    /// element's place in the file when [`QuadraticTetMesh::new`] rejects it (a mid-edge node
    /// shared inconsistently, or an element folded by its mid-edge nodes).
    pub fn into_quadratic_mesh(self) -> Result<QuadraticTetMesh, Error> {
        if self.mid_edge_nodes.is_empty() {
            return QuadraticTetMesh::from_linear(&self.into_mesh()?);
        }
        let elements: Vec<[u32; 10]> = self
            .tets
            .iter()
            .zip(&self.mid_edge_nodes)
            .map(|(corners, mids)| {
                let mut element = [0; 10];
                element[..4].copy_from_slice(corners);
                element[4..].copy_from_slice(mids);
                element
            })
            .collect();
        let (positions, mut elements) = self.renumbered(&elements)?;
        for element in &mut elements {
            let corners = [element[0], element[1], element[2], element[3]];
            if crate::mesh::signed_volume(&positions, &corners) < 0.0 {
                // Swapping corners 2 and 3 exchanges the edges (1,2) <-> (1,3) and
                // (0,2) <-> (0,3).
                *element = [0, 1, 3, 2, 4, 8, 7, 6, 5, 9].map(|k| element[k]);
            }
        }
        QuadraticTetMesh::new(positions, elements).map_err(|e| self.invalid(e))
    }

    /// The nodes `elements` use, in order of first use, and the elements renumbered to them.
    fn renumbered<const N: usize>(
        &self,
        elements: &[[u32; N]],
    ) -> Result<(Vec<DVec3>, Vec<[u32; N]>), Error> {
        if elements.is_empty() {
            return Err(self.error(
                FileLocation::Whole,
                ImportErrorKind::NoTetrahedra,
                "the file holds no tetrahedra".into(),
            ));
        }
        const UNUSED: u32 = u32::MAX;
        let mut new_index = vec![UNUSED; self.positions.len()];
        let mut positions = Vec::new();
        let mut renumbered = Vec::with_capacity(elements.len());
        for (t, element) in elements.iter().enumerate() {
            let mut nodes = [0; N];
            for (k, &node) in element.iter().enumerate() {
                let Some(slot) = new_index.get_mut(node as usize) else {
                    return Err(self.error(
                        self.location(t),
                        ImportErrorKind::IndexOutOfRange,
                        format!(
                            "tetrahedron {t} refers to node {node}, but there are {} nodes",
                            self.positions.len()
                        ),
                    ));
                };
                if *slot == UNUSED {
                    let position = self.positions[node as usize];
                    crate::mesh::check_position(node as usize, position)
                        .map_err(|e| self.coordinate_error(t, &e))?;
                    *slot = positions.len() as u32;
                    positions.push(position);
                }
                nodes[k] = *slot;
            }
            renumbered.push(nodes);
        }
        Ok((positions, renumbered))
    }

    /// Where tetrahedron `tet` was defined in the file.
    fn location(&self, tet: usize) -> FileLocation {
        self.tet_locations
            .get(tet)
            .copied()
            .unwrap_or(FileLocation::Whole)
    }

    fn error(&self, location: FileLocation, kind: ImportErrorKind, message: String) -> Error {
        Error::MeshImport {
            path: self.path.clone(),
            location,
            kind,
            message,
        }
    }

    /// [`ImportErrorKind::InvalidMesh`] for a validation error, at the element it names.
    fn invalid(&self, e: Error) -> Error {
        let at = match e {
            Error::DegenerateTet { tet, .. }
            | Error::TetTooSmall { tet, .. }
            | Error::RepeatedNode { tet, .. }
            | Error::InvertedTet { tet, .. }
            | Error::NonConformingEdge { tet, .. }
            | Error::FoldedElement { element: tet, .. } => self.location(tet),
            _ => FileLocation::Whole,
        };
        self.error(at, ImportErrorKind::InvalidMesh, e.to_string())
    }

    /// [`ImportErrorKind::NonFinite`] or [`ImportErrorKind::CoordinateOutOfRange`] for the
    /// coordinate error `e` of a node (numbered as in `positions`) that tetrahedron `tet` is the
    /// first to use, at that tetrahedron's place in the file.
    fn coordinate_error(&self, tet: usize, e: &Error) -> Error {
        let kind = match e {
            Error::NonFiniteCoordinate { .. } => ImportErrorKind::NonFinite,
            _ => ImportErrorKind::CoordinateOutOfRange,
        };
        self.error(
            self.location(tet),
            kind,
            format!("tetrahedron {tet} uses {e}"),
        )
    }
}

/// The file formats [`load`] recognises by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Gmsh `.msh`, versions 2.2 and 4.1, ASCII or binary.
    Gmsh,
    /// `TetGen` `.node` with its `.ele` beside it (either may be named).
    TetGen,
    /// VTK XML unstructured grid `.vtu`.
    Vtu,
    /// VTK legacy `.vtk` unstructured grid.
    LegacyVtk,
    /// Wavefront `.obj` surface, filled with tetrahedra.
    Obj,
    /// `.stl` surface (ASCII or binary), filled with tetrahedra.
    Stl,
}

impl Format {
    /// The format of `path` from its extension (case-insensitive), if known.
    pub fn from_path(path: &Path) -> Option<Self> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match extension.as_str() {
            "msh" => Self::Gmsh,
            "node" | "ele" => Self::TetGen,
            "vtu" => Self::Vtu,
            "vtk" => Self::LegacyVtk,
            "obj" => Self::Obj,
            "stl" => Self::Stl,
            _ => return None,
        })
    }
}

/// Reads the mesh file at `path` (format by extension, see [`Format`]) into a [`RawMesh`] with
/// positions in metres: `scale` metres per file unit. Surfaces (OBJ, STL, a `.msh` file holding
/// triangles but no tetrahedra) are filled with tetrahedra following `surface_options`.
///
/// # Errors
/// [`Error::InvalidSetting`] for a `scale` that is not finite and positive, [`Error::Io`] when
/// a file cannot be read, and [`Error::MeshImport`] for an unknown extension or malformed
/// content.
pub fn load_raw(
    path: impl AsRef<Path>,
    scale: f64,
    surface_options: &SurfaceOptions,
) -> Result<RawMesh, Error> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let Some(format) = Format::from_path(path) else {
        return Err(Error::MeshImport {
            path: name,
            location: FileLocation::Whole,
            kind: ImportErrorKind::UnknownFormat,
            message: "unknown mesh file extension (expected .msh, .node, .ele, .vtu, .vtk, \
                      .obj or .stl)"
                .into(),
        });
    };
    match format {
        Format::Gmsh => {
            let data = read_file(path)?;
            match gmsh::parse(&data, &name, scale) {
                Err(Error::MeshImport {
                    kind: ImportErrorKind::NoTetrahedra,
                    ..
                }) => surface::fill(&gmsh::parse_surface(&data, &name, scale)?, surface_options),
                other => other,
            }
        }
        Format::TetGen => {
            let node = path.with_extension("node");
            let ele = path.with_extension("ele");
            tetgen::parse(
                &read_file(&node)?,
                &node.display().to_string(),
                &read_file(&ele)?,
                &ele.display().to_string(),
                scale,
            )
        }
        Format::Vtu => vtk::parse_vtu(&read_file(path)?, &name, scale),
        Format::LegacyVtk => vtk::parse_legacy(&read_file(path)?, &name, scale),
        Format::Obj => surface::fill(
            &surface::parse_obj(&read_file(path)?, &name, scale)?,
            surface_options,
        ),
        Format::Stl => surface::fill(
            &surface::parse_stl(&read_file(path)?, &name, scale)?,
            surface_options,
        ),
    }
}

/// Reads and validates the mesh file at `path`: [`load_raw`] then [`RawMesh::into_mesh`].
///
/// # Errors
/// Those of [`load_raw`] and [`RawMesh::into_mesh`].
///
/// # Example
/// ```no_run
/// use rapier_fvm::mesh::import::{self, SurfaceOptions};
/// // A part drawn in millimetres.
/// let mesh = import::load("part.msh", 0.001, &SurfaceOptions::default())?;
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
pub fn load(
    path: impl AsRef<Path>,
    scale: f64,
    surface_options: &SurfaceOptions,
) -> Result<TetMesh, Error> {
    load_raw(path, scale, surface_options)?.into_mesh()
}

/// Reads the mesh file at `path` as quadratic tetrahedra: [`load_raw`] then
/// [`RawMesh::into_quadratic_mesh`] (a Gmsh file of second-order tetrahedra keeps its own
/// mid-edge nodes; a linear mesh gets them at its edges' midpoints).
///
/// # Errors
/// Those of [`load_raw`] and [`RawMesh::into_quadratic_mesh`].
pub fn load_quadratic(
    path: impl AsRef<Path>,
    scale: f64,
    surface_options: &SurfaceOptions,
) -> Result<QuadraticTetMesh, Error> {
    load_raw(path, scale, surface_options)?.into_quadratic_mesh()
}

/// The whole file at `path`, or [`Error::Io`].
fn read_file(path: &Path) -> Result<Vec<u8>, Error> {
    std::fs::read(path).map_err(|e| Error::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// What is wrong with a node read as `p` (file units) once times `scale` (m per file unit), if
/// anything: the kind, and the words that follow "... times the scale" in a message. A node
/// must be finite and within ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE) m, as a
/// [`TetMesh`] requires; the readers say so at the node's line.
fn scaled_defect(p: DVec3, scale: f64) -> Option<(ImportErrorKind, String)> {
    let scaled = p * scale;
    if !scaled.is_finite() {
        Some((ImportErrorKind::NonFinite, "is not finite".into()))
    } else if !coordinate_usable(scaled.abs().max_element()) {
        Some((
            ImportErrorKind::CoordinateOutOfRange,
            format!(
                "lies beyond ±{:e} m, where the element computations overflow",
                crate::mesh::MAX_COORDINATE
            ),
        ))
    } else {
        None
    }
}

/// Whether a scaled coordinate (m) is finite and within
/// ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE).
fn coordinate_usable(x: f64) -> bool {
    x.abs() <= crate::mesh::MAX_COORDINATE
}

/// [`Error::InvalidSetting`] unless `scale` (m per file unit) is finite and positive.
fn check_scale(scale: f64) -> Result<(), Error> {
    if scale.is_finite() && scale > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidSetting {
            parameter: "scale",
            value: scale,
            reason: "must be finite and positive (m per file unit)",
        })
    }
}
