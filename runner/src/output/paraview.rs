//! ParaView time series: one `.vtu` unstructured grid per soft body per saved frame, and one
//! `.pvd` collection that lists them with their simulated times, each body as its own part, so
//! that opening the `.pvd` shows every body moving over time.
//!
//! Each `.vtu` holds the world positions (m) as points, the tetrahedra (or a 2D body's
//! triangles, at z = 0) as cells, the point data
//! `displacement` (m) and `velocity` (m/s), and the cell data `cauchy_stress` (Pa, 9 components
//! in row-major order, symmetric) and `von_mises` (Pa). The `.pvd` is rewritten after every frame,
//! so a run stopped early still leaves a readable series.

use super::snapshot::{Snapshot, SoftBodySnapshot};
use super::{OutputError, file_stem};
use rapier_fvm::glamx::DVec3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version,
    VertexNumbers, Vtk,
};

/// A ParaView series being written into a folder.
#[derive(Debug, Clone)]
pub struct ParaViewSeries {
    folder: PathBuf,
    name: String,
    frames: usize,
    /// `(time (s), part, file name)` of every `.vtu` written so far.
    entries: Vec<(f64, usize, String)>,
}

impl ParaViewSeries {
    /// A series named `name` (its index is `<name>.pvd`) in `folder`, which is created if needed.
    ///
    /// # Errors
    /// [`OutputError::Io`] if the folder cannot be created.
    pub fn new(folder: impl Into<PathBuf>, name: &str) -> Result<Self, OutputError> {
        let folder = folder.into();
        std::fs::create_dir_all(&folder).map_err(OutputError::io(&folder))?;
        Ok(Self {
            folder,
            name: file_stem(name),
            frames: 0,
            entries: Vec::new(),
        })
    }

    /// The path of the `.pvd` index.
    pub fn pvd_path(&self) -> PathBuf {
        self.folder.join(format!("{}.pvd", self.name))
    }

    /// Writes one `.vtu` per soft body of `snapshot`, named `<body>_<frame>.vtu`, and rewrites
    /// the `.pvd` index; returns the paths of the `.vtu` files.
    ///
    /// # Errors
    /// [`OutputError::Vtk`] or [`OutputError::Io`] if a file cannot be written.
    pub fn write_frame(&mut self, snapshot: &Snapshot) -> Result<Vec<PathBuf>, OutputError> {
        let mut written = Vec::new();
        let mut stems: Vec<String> = Vec::new();
        for (part, body) in snapshot.soft_bodies.iter().enumerate() {
            let mut stem = file_stem(&body.name);
            if stems.contains(&stem) {
                stem = format!("{stem}_{part}");
            }
            let file = format!("{stem}_{:05}.vtu", self.frames);
            let path = self.folder.join(&file);
            write_vtu(&path, body)?;
            self.entries.push((snapshot.time, part, file));
            written.push(path);
            stems.push(stem);
        }
        self.frames += 1;
        let pvd = self.pvd_path();
        std::fs::write(&pvd, self.pvd_text()).map_err(OutputError::io(&pvd))?;
        Ok(written)
    }

    /// The `.pvd` collection of the entries so far.
    fn pvd_text(&self) -> String {
        let mut text = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (time, part, file) in &self.entries {
            let _ = writeln!(
                text,
                "    <DataSet timestep=\"{time}\" part=\"{part}\" file=\"{file}\"/>"
            );
        }
        text.push_str("  </Collection>\n</VTKFile>\n");
        text
    }
}

/// Writes `body` as an XML unstructured grid at `path`.
fn write_vtu(path: &Path, body: &SoftBodySnapshot) -> Result<(), OutputError> {
    let flat = |v: &[DVec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f64>>();
    let stress: Vec<f64> = body
        .cauchy_stress
        .iter()
        .flat_map(|s| s.transpose().to_cols_array())
        .collect();
    let (cell_type, per_cell) = match body.cells {
        super::Cells::Tetrahedra(_) => (CellType::Tetra, 4),
        super::Cells::Triangles(_) => (CellType::Triangle, 3),
    };
    let count = body.cells.len() as u64;
    let piece = UnstructuredGridPiece {
        points: flat(&body.positions).into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: body
                    .cells
                    .nodes()
                    .flatten()
                    .map(|&n| u64::from(n))
                    .collect(),
                offsets: (1..=count).map(|t| per_cell * t).collect(),
            },
            types: vec![cell_type; body.cells.len()],
        },
        data: Attributes {
            point: vec![
                Attribute::vectors("displacement").with_data(flat(&body.displacements())),
                Attribute::vectors("velocity").with_data(flat(&body.velocities)),
            ],
            cell: vec![
                Attribute::tensors("cauchy_stress").with_data(stress),
                Attribute::scalars("von_mises", 1).with_data(body.von_mises()),
            ],
        },
    };
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        byte_order: ByteOrder::LittleEndian,
        title: body.name.clone(),
        file_path: None,
        data: DataSet::inline(piece),
    };
    vtk.export(path).map_err(|error| OutputError::Vtk {
        path: path.to_path_buf(),
        message: error.to_string(),
    })
}
