//! Conforming the lattice's tetrahedra to the surface (step 3 of the module documentation).
//!
//! Moves the boundary nodes of a set of positively oriented tetrahedra onto the surface (three
//! sweeps) and relaxes the interior nodes next to them towards their neighbours' mean (two
//! sweeps), never letting a move invert an incident tetrahedron or push its shape quality below
//! [`MIN_QUALITY`] (or below what it was, if it already was): a move that would is shortened,
//! or not made.

use super::projector::Projector;
use crate::mesh::signed_volume;
use rapier3d::glamx::DVec3;

/// Shape quality ([`shape_quality`]) below which a boundary node's move is shortened.
const MIN_QUALITY: f64 = 0.2;

/// Moves the boundary nodes of `tets` onto the surface of `projector` and relaxes the interior
/// nodes next to them; `positions` (m) are updated in place.
pub(super) fn conform(positions: &mut [DVec3], tets: &[[u32; 4]], projector: &Projector<'_>) {
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (t, tet) in tets.iter().enumerate() {
        for &n in tet {
            incident[n as usize].push(t as u32);
        }
    }
    let mut on_boundary = vec![false; positions.len()];
    for face in crate::mesh::surface::boundary_faces(tets) {
        for n in face {
            on_boundary[n as usize] = true;
        }
    }
    let boundary: Vec<usize> = (0..positions.len()).filter(|&n| on_boundary[n]).collect();
    for _sweep in 0..3 {
        for &n in &boundary {
            let target = projector.closest_point(positions[n]);
            let fractions = [1.0, 0.75, 0.5, 0.25];
            move_node(positions, tets, &incident[n], n, target, &fractions);
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
            let target = neighbour_mean(positions, tets, &incident[n], n);
            move_node(positions, tets, &incident[n], n, target, &[0.5]);
        }
    }
}

/// The mean position (m) of the nodes other than `n` of the tetrahedra `incident` to it, each
/// counted once per tetrahedron.
fn neighbour_mean(positions: &[DVec3], tets: &[[u32; 4]], incident: &[u32], n: usize) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let mut count = 0.0;
    for &t in incident {
        for &m in &tets[t as usize] {
            if m as usize != n {
                sum += positions[m as usize];
                count += 1.0;
            }
        }
    }
    sum / count
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
