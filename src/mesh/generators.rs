//! Structured tetrahedral meshes of boxes, cylinders, tubes and spheres.
//!
//! Boxes are a lattice of cubes, each split into five tetrahedra (four corner tetrahedra around a
//! central one) with the split mirrored on alternate cubes, so neighbouring cubes share face
//! diagonals and no direction is preferred.
//!
//! Cylinders and spheres are block-structured: a straight core surrounded by blocks that blend
//! from the core's square (cube) boundary to the circle (sphere), the "O-grid" that keeps every
//! cell well shaped where a single mapped lattice would flatten its corner cells. Blocks meet with
//! different cell orientations, so each hexahedral cell is split around a node at its centre,
//! every face along the diagonal through its lowest-numbered node: neighbours then always agree.

use super::TetMesh;
use super::hex_mesher::HexMesher;
use crate::Error;
use rapier3d::glamx::{DVec2, DVec3};

/// Half-size of the cylinder's square core relative to the radius.
const CYLINDER_CORE: f64 = 0.5;
/// Half-size of the sphere's cubic core relative to the radius.
const SPHERE_CORE: f64 = 0.4;

/// A box centred at the origin with the given half extents (m), `cells[i]` cubes along axis `i`,
/// each split into five tetrahedra.
///
/// # Errors
/// [`Error::InvalidGeneratorParameter`] for a zero cell count, a non-positive, non-finite extent
/// or more nodes than 32-bit indices address; [`Error::AllocationFailed`] when the machine cannot
/// hold the mesh.
///
/// # Example
/// ```
/// use rapier_fvm::{glamx::DVec3, mesh};
/// let beam = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [20, 2, 2])?;
/// assert_eq!(beam.tet_count(), 20 * 2 * 2 * 5);
/// assert!((beam.volume() - 0.01).abs() < 1e-15);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
pub fn cuboid(half_extents: DVec3, cells: [usize; 3]) -> Result<TetMesh, Error> {
    for (name, value) in [
        ("half_extents.x", half_extents.x),
        ("half_extents.y", half_extents.y),
        ("half_extents.z", half_extents.z),
    ] {
        check_length(name, value)?;
    }
    lattice(cells, |u| u * half_extents)
}

/// A solid cylinder of the given radius and half height (m) centred at the origin with its axis
/// along +y (rapier's convention), about `cells_across` cells over the diameter and `cells_along`
/// over the height.
///
/// The cross-section is an O-grid: a square core (half-size `r/2`) and four blocks between the
/// square and the circle, so every cell is a well-shaped
/// hexahedron; each is split into twelve tetrahedra around its centre.
///
/// # Errors
/// [`Error::InvalidGeneratorParameter`] for fewer than 2 cells across, zero cells along, a
/// non-positive, non-finite size or more nodes than 32-bit indices address;
/// [`Error::AllocationFailed`] when the machine cannot hold the mesh.
pub fn cylinder(
    radius: f64,
    half_height: f64,
    cells_across: usize,
    cells_along: usize,
) -> Result<TetMesh, Error> {
    check_length("radius", radius)?;
    check_length("half_height", half_height)?;
    check_cells_across(cells_across)?;
    check_cells_along(cells_along)?;
    let core = (cells_across / 2).max(1);
    let layers = (cells_across / 4).max(1);
    let mut hexes = HexMesher::with_capacity(
        radius.max(half_height),
        &[
            (1, [core, cells_along, core]),
            (4, [core, cells_along, layers]),
        ],
    )?;
    let height = |t: f64| (2.0 * t - 1.0) * half_height;
    // The core: a straight box of half-size r/2 in x and z.
    hexes.add_block([core, cells_along, core], |u| {
        let half = CYLINDER_CORE * radius;
        DVec3::new(
            (2.0 * u.x - 1.0) * half,
            height(u.y),
            (2.0 * u.z - 1.0) * half,
        )
    });
    // Four blocks from the core's sides (direction d on the unit square's boundary) to the circle.
    for side in 0..4 {
        hexes.add_block([core, cells_along, layers], |u| {
            let s = 2.0 * u.x - 1.0;
            let side_direction = |s: f64| match side {
                0 => DVec2::new(1.0, s),
                1 => DVec2::new(-s, 1.0),
                2 => DVec2::new(-1.0, -s),
                _ => DVec2::new(s, -1.0),
            };
            let on_core = side_direction(s) * (CYLINDER_CORE * radius);
            let on_circle = side_direction(s).normalize() * radius;
            let q = on_core + (on_circle - on_core) * u.z;
            DVec3::new(q.x, height(u.y), q.y)
        });
    }
    hexes.finish()
}

/// A tube (hollow cylinder) along the y axis, centred at the origin, between the radii
/// `inner_radius` and `outer_radius` (m), of height `2 half_height` (m): `cells_around` cells
/// around, `cells_through` through the wall and `cells_along` along the axis, each hexahedral
/// cell split into twelve tetrahedra around its centre. Its inner surface is the boundary a
/// pneumatic chamber's or a pressure vessel's pressure acts on.
///
/// # Errors
/// [`Error::InvalidGeneratorParameter`] for an inner radius not below the outer one, fewer than
/// 3 cells around, zero cells through or along, a non-positive, non-finite size or more nodes
/// than 32-bit indices address; [`Error::AllocationFailed`] when the machine cannot hold the
/// mesh.
///
/// # Example
/// ```
/// use rapier_fvm::mesh;
/// let tube = mesh::tube(0.01, 0.02, 0.05, 24, 2, 10)?;
/// let exact = std::f64::consts::PI * (0.02f64.powi(2) - 0.01f64.powi(2)) * 0.1;
/// // The polygonal section is a little smaller than the round one.
/// assert!((tube.volume() / exact - 1.0).abs() < 0.012);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
pub fn tube(
    inner_radius: f64,
    outer_radius: f64,
    half_height: f64,
    cells_around: usize,
    cells_through: usize,
    cells_along: usize,
) -> Result<TetMesh, Error> {
    check_length("inner_radius", inner_radius)?;
    check_length("outer_radius", outer_radius)?;
    check_length("half_height", half_height)?;
    if inner_radius >= outer_radius {
        return Err(Error::InvalidGeneratorParameter {
            parameter: "inner_radius",
            value: inner_radius,
            reason: "must be below the outer radius",
        });
    }
    if cells_around < 3 {
        return Err(Error::InvalidGeneratorParameter {
            parameter: "cells_around",
            value: cells_around as f64,
            reason: "a tube needs at least 3 cells around",
        });
    }
    check_cells_along(cells_through)?;
    check_cells_along(cells_along)?;
    let cells = [cells_around, cells_along, cells_through];
    let mut hexes = HexMesher::with_capacity(outer_radius.max(half_height), &[(1, cells)])?;
    hexes.add_block(cells, |u| {
        let angle = std::f64::consts::TAU * u.x;
        let radius = inner_radius + (outer_radius - inner_radius) * u.z;
        DVec3::new(
            radius * angle.cos(),
            (2.0 * u.y - 1.0) * half_height,
            radius * angle.sin(),
        )
    });
    hexes.finish()
}

/// A solid ball of the given radius (m) centred at the origin, about `cells_across` cells over
/// the diameter.
///
/// The ball is a "cubed sphere": a cubic core (half-size `0.4 r`) and six blocks between the cube
/// and the sphere, every cell a well-shaped hexahedron split
/// into twelve tetrahedra around its centre.
///
/// # Errors
/// [`Error::InvalidGeneratorParameter`] for fewer than 2 cells across, a non-positive,
/// non-finite radius or more nodes than 32-bit indices address; [`Error::AllocationFailed`] when
/// the machine cannot hold the mesh.
pub fn sphere(radius: f64, cells_across: usize) -> Result<TetMesh, Error> {
    check_length("radius", radius)?;
    check_cells_across(cells_across)?;
    let core = ((cells_across as f64 * 0.4).round() as usize).max(1);
    let layers = ((core as f64 * 0.6).round() as usize).max(1);
    let mut hexes = HexMesher::with_capacity(radius, &[(1, [core; 3]), (6, [core, core, layers])])?;
    hexes.add_block([core; 3], |u| {
        (u * 2.0 - DVec3::ONE) * (SPHERE_CORE * radius)
    });
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            hexes.add_block([core, core, layers], |u| {
                let face_direction = |s: f64, t: f64| {
                    let mut d = DVec3::ZERO;
                    d[axis] = sign;
                    d[(axis + 1) % 3] = s;
                    d[(axis + 2) % 3] = t;
                    d
                };
                let (s, t) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
                let on_core = face_direction(s, t) * (SPHERE_CORE * radius);
                let on_sphere = face_direction(s, t).normalize() * radius;
                on_core + (on_sphere - on_core) * u.z
            });
        }
    }
    hexes.finish()
}

/// Refuses meshes whose node count would not fit the 32-bit node indices.
pub(super) fn check_node_budget(nodes: f64) -> Result<(), Error> {
    if nodes <= f64::from(u32::MAX) {
        Ok(())
    } else {
        Err(Error::InvalidGeneratorParameter {
            parameter: "cells",
            value: nodes,
            reason: "the mesh would have more nodes than 32-bit indices address",
        })
    }
}

/// An empty vector with room for `count` items of `T`, or [`Error::AllocationFailed`] naming
/// `what` if the memory cannot be had (a mesh of more cells than the machine holds).
pub(super) fn reserve<T>(count: usize, what: &'static str) -> Result<Vec<T>, Error> {
    let mut items = Vec::new();
    items
        .try_reserve_exact(count)
        .map_err(|_| Error::AllocationFailed {
            what,
            bytes: (count as u64).saturating_mul(std::mem::size_of::<T>() as u64),
        })?;
    Ok(items)
}

fn check_length(parameter: &'static str, value: f64) -> Result<(), Error> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidGeneratorParameter {
            parameter,
            value,
            reason: "must be a positive, finite length in metres",
        })
    }
}

fn check_cells_along(cells: usize) -> Result<(), Error> {
    if cells >= 1 {
        Ok(())
    } else {
        Err(Error::InvalidGeneratorParameter {
            parameter: "cells_along",
            value: 0.0,
            reason: "at least one cell is needed along the axis",
        })
    }
}

fn check_cells_across(cells: usize) -> Result<(), Error> {
    if cells >= 2 {
        Ok(())
    } else {
        Err(Error::InvalidGeneratorParameter {
            parameter: "cells_across",
            value: cells as f64,
            reason: "a round cross-section needs at least 2 cells across",
        })
    }
}

/// The five-tetrahedron split of a unit cube whose corner `(i, j, k)` has local index
/// `i + 2 j + 4 k`, for cubes of even parity; odd cubes use the mirror image (corner `c ^ 1`).
/// Orientation is fixed when the lattice is built.
const FIVE_TET_SPLIT: [[usize; 4]; 5] = [
    [1, 0, 3, 5], // corner (1,0,0) with its three neighbours
    [2, 0, 3, 6], // corner (0,1,0)
    [4, 0, 5, 6], // corner (0,0,1)
    [7, 3, 5, 6], // corner (1,1,1)
    [0, 3, 5, 6], // the central tetrahedron
];

/// Builds the five-tet lattice over `[-1, 1]^3` with `cells` cubes per axis and maps every node
/// through `map`, which must preserve orientation.
fn lattice(cells: [usize; 3], map: impl Fn(DVec3) -> DVec3) -> Result<TetMesh, Error> {
    if let Some(&zero) = cells.iter().find(|&&c| c == 0) {
        return Err(Error::InvalidGeneratorParameter {
            parameter: "cells",
            value: zero as f64,
            reason: "every axis needs at least one cell",
        });
    }
    let [nx, ny, nz] = cells;
    check_node_budget(cells.iter().map(|&c| c as f64 + 1.0).product())?;
    // Within the node budget, the cell count fits (nx ny nz < (nx+1)(ny+1)(nz+1) <= u32::MAX);
    // five tetrahedra per cell may not, in a 32-bit usize.
    let tet_count = (nx * ny * nz).checked_mul(FIVE_TET_SPLIT.len()).ok_or(
        Error::InvalidGeneratorParameter {
            parameter: "cells",
            value: 5.0 * (nx * ny * nz) as f64,
            reason: "the mesh would have more tetrahedra than this platform can count",
        },
    )?;
    let node = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let lattice_point = |i: usize, j: usize, k: usize| {
        DVec3::new(
            2.0 * i as f64 / nx as f64 - 1.0,
            2.0 * j as f64 / ny as f64 - 1.0,
            2.0 * k as f64 / nz as f64 - 1.0,
        )
    };
    let mut lattice_points = reserve((nx + 1) * (ny + 1) * (nz + 1), "the mesh's nodes")?;
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                lattice_points.push(lattice_point(i, j, k));
            }
        }
    }
    let mut tets = reserve(tet_count, "the mesh's tetrahedra")?;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let mirror = (i + j + k) % 2;
                let corner = |c: usize| {
                    let c = c ^ mirror;
                    node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))
                };
                for split in FIVE_TET_SPLIT {
                    let mut tet = split.map(corner);
                    if super::signed_volume(&lattice_points, &tet) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    TetMesh::new(lattice_points.into_iter().map(map).collect(), tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reservation_no_allocator_can_serve_is_an_error_not_an_abort() {
        // 2^60 tetrahedra of 16 bytes: past `isize::MAX` bytes, refused before any allocation;
        // the 2^64 bytes asked for saturate the count.
        let error = reserve::<[u32; 4]>(1 << 60, "the mesh's tetrahedra").unwrap_err();
        assert_eq!(
            error,
            Error::AllocationFailed {
                what: "the mesh's tetrahedra",
                bytes: u64::MAX,
            }
        );
    }
}
