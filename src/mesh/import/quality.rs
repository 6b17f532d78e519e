//! Quality of a tetrahedral mesh before validation: counts, volume, shape measures and
//! defects, for a `check` command to print.
//!
//! Measures the mesh alone, any positions and node indices (out of range, repeated, inverted,
//! flat), and never fails or panics. The explicit time step a mesh allows depends on its
//! material as well: the integrator layer computes it
//! ([`SymplecticEuler::mesh_time_steps`](crate::integrate::SymplecticEuler::mesh_time_steps)).

use super::{Hexahedra, RawMesh};
use crate::mesh::{DEGENERATE_RELATIVE_VOLUME, signed_volume};
use crate::shape::{hex27, tet10};
use rapier3d::glamx::DVec3;

/// What [`check`] finds in a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct QualityReport {
    /// Number of tetrahedra.
    pub tets: usize,
    /// Number of nodes given, used or not.
    pub nodes: usize,
    /// Nodes that no tetrahedron uses (dropped by [`RawMesh::into_mesh`](super::RawMesh::into_mesh)).
    pub unused_nodes: usize,
    /// Sum of the tetrahedra's signed volumes (m³); inverted elements count negatively.
    pub volume: f64,
    /// Smallest dihedral angle over all tetrahedra (degrees): 70.5° for a regular
    /// tetrahedron, 0° for a flat one. Below about 5° an element is a sliver.
    pub min_dihedral_angle: f64,
    /// Largest dihedral angle over all tetrahedra (degrees), 180° for a flat one.
    pub max_dihedral_angle: f64,
    /// Smallest radius ratio `3 r_in / r_circ` (dimensionless): 1 for a regular tetrahedron, 0
    /// for a flat one.
    pub min_radius_ratio: f64,
    /// Tetrahedra with negative volume (wrong node order; [`RawMesh::into_mesh`](super::RawMesh::into_mesh) fixes them).
    pub inverted: usize,
    /// Tetrahedra with (numerically) zero volume, `|V| <= 1e-12 l³` with `l` the longest edge,
    /// which no simulation can use.
    pub degenerate: usize,
    /// Tetrahedra referring to a node that does not exist or twice to the same node; they are
    /// left out of every other measure.
    pub invalid: usize,
    /// Quadratic tetrahedra or 27-node hexahedra whose rest map folds (see
    /// [`Error::FoldedElement`](crate::Error::FoldedElement)); 0 for linear elements.
    pub folded: usize,
    /// Hexahedra the tetrahedra were split from (see [`Hexahedra`]); 0 for a mesh of
    /// tetrahedra.
    pub hexahedra: usize,
}

/// Measures the mesh of `positions` (m) and `tets` without requiring it to be valid. Never
/// panics.
///
/// # Example
/// ```
/// use rapier_fvm::prelude::*;
/// use rapier_fvm::mesh::import;
///
/// let cube = mesh::cuboid(DVec3::splat(0.5), [2, 2, 2])?;
/// let report = import::check(cube.positions(), cube.tets());
/// assert_eq!(report.tets, 40);
/// assert!((report.volume - 1.0).abs() < 1e-12);
/// assert_eq!(report.inverted + report.degenerate, 0);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
pub fn check(positions: &[DVec3], tets: &[[u32; 4]]) -> QualityReport {
    let mut used = vec![false; positions.len()];
    let mut report = QualityReport {
        tets: tets.len(),
        nodes: positions.len(),
        unused_nodes: 0,
        volume: 0.0,
        min_dihedral_angle: f64::INFINITY,
        max_dihedral_angle: 0.0,
        min_radius_ratio: f64::INFINITY,
        inverted: 0,
        degenerate: 0,
        invalid: 0,
        folded: 0,
        hexahedra: 0,
    };
    for tet in tets {
        let in_range = tet.iter().all(|&n| (n as usize) < positions.len());
        let distinct = (0..4).all(|i| !tet[i + 1..].contains(&tet[i]));
        if !in_range || !distinct {
            report.invalid += 1;
            continue;
        }
        for &n in tet {
            used[n as usize] = true;
        }
        let p = tet.map(|n| positions[n as usize]);
        let volume = signed_volume(positions, tet);
        report.volume += volume;
        let longest = longest_edge(&p);
        // A NaN volume counts as degenerate.
        if volume
            .abs()
            .partial_cmp(&(DEGENERATE_RELATIVE_VOLUME * longest.powi(3)))
            != Some(std::cmp::Ordering::Greater)
        {
            report.degenerate += 1;
        } else if volume < 0.0 {
            report.inverted += 1;
        }
        let (min, max) = dihedral_angles(&p);
        report.min_dihedral_angle = report.min_dihedral_angle.min(min);
        report.max_dihedral_angle = report.max_dihedral_angle.max(max);
        report.min_radius_ratio = report.min_radius_ratio.min(radius_ratio(&p, volume));
    }
    report.unused_nodes = used.iter().filter(|&&u| !u).count();
    if report.min_dihedral_angle.is_infinite() {
        report.min_dihedral_angle = 0.0;
    }
    if report.min_radius_ratio.is_infinite() {
        report.min_radius_ratio = 0.0;
    }
    report
}

/// Measures `raw` as [`check`] does its corner tetrahedra; for a mesh of quadratic tetrahedra
/// the mid-edge nodes count as used, the volume is that of the curved elements (exact: see
/// [`tet10::volume`]) and the elements whose rest map folds are counted; for a mesh of
/// hexahedra their number is given, and for 27-node ones the volume of the curved elements
/// (exact: [`hex27::volume`]) and the folded ones. Never panics.
pub fn check_raw(raw: &RawMesh) -> QualityReport {
    let mut report = check(&raw.positions, &raw.tets);
    report.hexahedra = match &raw.hexahedra {
        Hexahedra::None => 0,
        hexahedra => raw.tets.len() / hexahedra.tets_per_element(),
    };
    if let Hexahedra::Triquadratic(elements) = &raw.hexahedra {
        measure_cage(raw, elements, &mut report);
    }
    if raw.mid_edge_nodes.is_empty() {
        return report;
    }
    let count = raw.positions.len();
    let mut used = vec![false; count];
    let mut volume = 0.0;
    for (corners, mids) in raw.tets.iter().zip(&raw.mid_edge_nodes) {
        let mut element = [0u32; tet10::NODES];
        element[..4].copy_from_slice(corners);
        element[4..].copy_from_slice(mids);
        let corners_valid = corners.iter().all(|&n| (n as usize) < count)
            && (0..4).all(|i| !corners[i + 1..].contains(&corners[i]));
        if !corners_valid {
            // Counted invalid by `check`, left out here too.
            continue;
        }
        if mids.iter().any(|&n| n as usize >= count) {
            report.invalid += 1;
            continue;
        }
        for &n in &element {
            used[n as usize] = true;
        }
        let p = element.map(|n| raw.positions[n as usize]);
        volume += tet10::volume(&p);
        // Clockwise or flat corners are `check`'s inverted or degenerate elements.
        if signed_volume(&raw.positions, corners) > 0.0 {
            let determinant = tet10::smallest_jacobian_determinant(&p);
            report.folded += usize::from(!tet10::unfolded(determinant));
        }
    }
    report.volume = volume;
    report.unused_nodes = used.iter().filter(|&&u| !u).count();
    report
}

/// The curved volume and the folded elements of a raw mesh's 27-node hexahedra `elements`;
/// an element naming a node past the positions is left out (its tetrahedra count invalid).
fn measure_cage(raw: &RawMesh, elements: &[[u32; hex27::NODES]], report: &mut QualityReport) {
    let mut volume = 0.0;
    let mut folded = 0;
    for element in elements {
        let Some(p) = element
            .iter()
            .map(|&n| raw.positions.get(n as usize).copied())
            .collect::<Option<Vec<DVec3>>>()
        else {
            continue;
        };
        let mut p: [DVec3; hex27::NODES] = std::array::from_fn(|a| p[a]);
        let element_volume = hex27::volume(&p);
        if element_volume < 0.0 {
            // A left-handed element, mirrored as the cage mirrors it (lattice i to 2 − i).
            p = hex27::mirrored(&p);
        }
        volume += element_volume.abs();
        let smallest = hex27::smallest_jacobian_determinant(&p);
        folded += usize::from(smallest.is_nan() || smallest <= 0.0);
    }
    report.volume = volume;
    report.folded = folded;
}

fn longest_edge(p: &[DVec3; 4]) -> f64 {
    let mut longest: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            longest = longest.max(p[i].distance(p[j]));
        }
    }
    longest
}

/// The smallest and largest of the six dihedral angles (degrees); a flat tetrahedron has 0°
/// and 180°.
fn dihedral_angles(p: &[DVec3; 4]) -> (f64, f64) {
    let mut min = f64::INFINITY;
    let mut max: f64 = 0.0;
    for (i, j, k, l) in [
        (0, 1, 2, 3),
        (0, 2, 1, 3),
        (0, 3, 1, 2),
        (1, 2, 0, 3),
        (1, 3, 0, 2),
        (2, 3, 0, 1),
    ] {
        // The angle at edge ij between the faces towards k and towards l.
        let edge = (p[j] - p[i]).normalize_or_zero();
        let u = p[k] - p[i];
        let w = p[l] - p[i];
        let u = u - edge * u.dot(edge);
        let w = w - edge * w.dot(edge);
        let cos = u.dot(w) / (u.length() * w.length());
        let angle = if cos.is_finite() {
            cos.clamp(-1.0, 1.0).acos().to_degrees()
        } else {
            0.0
        };
        // A flat tetrahedron's angles are 0° or 180°: both count as worst.
        min = min.min(angle);
        max = max.max(angle);
    }
    (min, max)
}

/// `3 r_in / r_circ` (1 for a regular tetrahedron), 0 if flat.
fn radius_ratio(p: &[DVec3; 4], volume: f64) -> f64 {
    let [a, b, c] = [p[1] - p[0], p[2] - p[0], p[3] - p[0]];
    let area: f64 = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
        .iter()
        .map(|&[i, j, k]| 0.5 * (p[j] - p[i]).cross(p[k] - p[i]).length())
        .sum();
    let inradius = 3.0 * volume.abs() / area;
    let offset = (a.length_squared() * b.cross(c)
        + b.length_squared() * c.cross(a)
        + c.length_squared() * a.cross(b))
        / (2.0 * a.dot(b.cross(c)));
    let ratio = 3.0 * inradius / offset.length();
    if ratio.is_finite() { ratio } else { 0.0 }
}
