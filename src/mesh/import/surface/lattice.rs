//! Filling a closed surface with the tetrahedra of a body-centred cubic lattice (steps 1 and 2
//! of the module documentation), then conforming them to it (step 3, in `snap`).
//!
//! Refuses `cells_across` outside 2 to 128, a surface that is empty, open, non-manifold,
//! inconsistently oriented or encloses no volume, and a lattice of which no tetrahedron falls
//! inside. An inward-facing surface is turned outwards first.

use super::projector::Projector;
use super::{Surface, SurfaceOptions, snap};
use crate::Error;
use crate::error::{FileLocation, ImportErrorKind};
use crate::mesh::import::RawMesh;
use crate::mesh::signed_volume;
use rapier3d::glamx::DVec3;

/// Largest [`SurfaceOptions::cells_across`]: a lattice of 128³ cells is already about 25
/// million tetrahedra.
const MAX_CELLS_ACROSS: usize = 128;

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
    let triangles = surface.closed_triangles()?;
    let volume = surface.enclosed_volume();
    let (lo, hi) = surface.bounds();
    let extent = (hi - lo).max_element();
    if volume.abs().partial_cmp(&(1e-9 * extent.powi(3))) != Some(std::cmp::Ordering::Greater) {
        return Err(surface.error(format!("the surface encloses no volume ({volume:e} m^3)")));
    }
    let triangles: Vec<[u32; 3]> = if volume < 0.0 {
        triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
    } else {
        triangles
    };
    let projector = Projector::new(surface, triangles, (lo + hi) / 2.0)?;
    let lattice = Lattice::new(lo, hi, extent / options.cells_across as f64);
    let mut positions = lattice.positions();
    let tets = lattice.tets_inside(&positions, &projector);
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
    snap::conform(&mut positions, &tets, &projector);
    Ok(compacted(&surface.path, &positions, &tets))
}

/// A BCC lattice: the corners and centres of `cells` cubes of side `h` (m) from `origin` (m).
struct Lattice {
    origin: DVec3,
    /// The cube side (m).
    h: f64,
    /// Cubes along x, y and z.
    cells: [usize; 3],
}

/// The corners of a cube face normal to an axis, as steps along the two other axes, in order
/// around the face.
const FACE: [[usize; 2]; 4] = [[0, 0], [1, 0], [1, 1], [0, 1]];

impl Lattice {
    /// The lattice of spacing `h` (m) over the box from `lo` to `hi` (m) grown by one cell.
    fn new(lo: DVec3, hi: DVec3, h: f64) -> Self {
        let cells = ((hi - lo) / h)
            .ceil()
            .as_uvec3()
            .to_array()
            .map(|n| n as usize + 2);
        Self {
            origin: lo - DVec3::splat(h),
            h,
            cells,
        }
    }

    /// The node of the cube corner `[i, j, k]`.
    fn corner(&self, [i, j, k]: [usize; 3]) -> u32 {
        let [nx, ny, _] = self.cells;
        (i + (nx + 1) * (j + (ny + 1) * k)) as u32
    }

    /// The node of the centre of cube `[i, j, k]`, numbered after all corners.
    fn centre(&self, [i, j, k]: [usize; 3]) -> u32 {
        let [nx, ny, nz] = self.cells;
        let corner_count = (nx + 1) * (ny + 1) * (nz + 1);
        (corner_count + i + nx * (j + ny * k)) as u32
    }

    /// The nodes' positions (m): the cube corners, x fastest, then the cube centres.
    fn positions(&self) -> Vec<DVec3> {
        let [nx, ny, nz] = self.cells;
        let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1) + nx * ny * nz);
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    positions.push(self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.h);
                }
            }
        }
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let centre = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.h;
                    positions.push(self.origin + centre);
                }
            }
        }
        positions
    }

    /// The lattice's tetrahedra whose centroid lies inside the surface, positively oriented:
    /// for each cube and each of its neighbours towards +x, +y and +z, the four around the
    /// segment joining their centres.
    fn tets_inside(&self, positions: &[DVec3], projector: &Projector<'_>) -> Vec<[u32; 4]> {
        let mut tets = Vec::new();
        let [nx, ny, nz] = self.cells;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c0 = self.centre([i, j, k]);
                    for axis in 0..3 {
                        let mut next = [i, j, k];
                        next[axis] += 1;
                        if next[axis] >= self.cells[axis] {
                            continue;
                        }
                        let c1 = self.centre(next);
                        let face = self.face(next, axis);
                        for m in 0..4 {
                            let tet = [c0, c1, face[m], face[(m + 1) % 4]];
                            if let Some(tet) = inside(tet, positions, projector) {
                                tets.push(tet);
                            }
                        }
                    }
                }
            }
        }
        tets
    }

    /// The corners, in order around it, of the face normal to `axis` at the low side of cube
    /// `cube`.
    fn face(&self, cube: [usize; 3], axis: usize) -> [u32; 4] {
        let (b, c) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        FACE.map(|[db, dc]| {
            let mut corner = cube;
            corner[b] += db;
            corner[c] += dc;
            self.corner(corner)
        })
    }
}

/// `tet`, positively oriented, if its centroid lies inside the surface.
fn inside(mut tet: [u32; 4], positions: &[DVec3], projector: &Projector<'_>) -> Option<[u32; 4]> {
    let centroid = tet.iter().map(|&n| positions[n as usize]).sum::<DVec3>() / 4.0;
    if !projector.contains(centroid) {
        return None;
    }
    if signed_volume(positions, &tet) < 0.0 {
        tet.swap(2, 3);
    }
    Some(tet)
}

/// The mesh of `tets` on the nodes they use, renumbered in lattice order (read from `path`).
fn compacted(path: &str, positions: &[DVec3], tets: &[[u32; 4]]) -> RawMesh {
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut used = Vec::new();
    for tet in tets {
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
    RawMesh {
        path: path.to_owned(),
        positions: used,
        mid_edge_nodes: Vec::new(),
        hexahedra: crate::mesh::import::Hexahedra::None,
        tet_locations: vec![FileLocation::Whole; tets.len()],
        regions: Vec::new(),
        tets,
    }
}
