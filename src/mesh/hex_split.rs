//! Conforming splits of hexahedra into tetrahedra on their own nodes.
//!
//! Every quadrilateral face is cut along its diagonal through its corner of least index, a rule
//! the two hexahedra sharing a face apply alike, so neighbours' splits conform without any new
//! node (the rule of Dompierre, Labbé, Vallet and Camarero, "How to subdivide pyramids, prisms
//! and hexahedra into tetrahedra", 1999). A hexahedron is then the union of the six tetrahedra
//! joining its least corner to the two triangles of each of the three faces it does not touch:
//! the three faces it does touch are cut through it, as the rule says. Valid for every convex
//! hexahedron (its least corner sees the opposite faces); a folded one gives inverted or
//! degenerate tetrahedra, which validation refuses.
//!
//! Corners are given by their place `i + 2j + 4k` on the unit cube (`i, j, k ∈ {0, 1}`), the
//! tetrahedra come out positively oriented when the hexahedron is (right-handed `i, j, k`).

/// Tetrahedra per split hexahedron.
pub const TETS_PER_HEXAHEDRON: usize = 6;

/// Tetrahedra per split 27-node hexahedron: its lattice's eight sub-cubes, split each.
pub const TETS_PER_LATTICE: usize = 8 * TETS_PER_HEXAHEDRON;

/// The corners of a hexahedron in the order of VTK and Gmsh (bottom face `0 1 2 3`
/// counter-clockwise seen from above, top face `4 5 6 7` above it) by their place
/// `i + 2j + 4k` on the unit cube.
#[cfg(feature = "import")]
pub const FILE_ORDER_CORNERS: [usize; 8] = [0, 1, 3, 2, 4, 5, 7, 6];

/// The position `(i, j, k)` of unit-cube corner `b`.
fn cube_corner(b: usize) -> [i64; 3] {
    [(b & 1) as i64, ((b >> 1) & 1) as i64, ((b >> 2) & 1) as i64]
}

/// The six tetrahedra of a hexahedron whose corner at unit-cube place `b` is `corners[b]`;
/// corners compare by their global index, so that shared faces are cut alike.
pub fn split_hexahedron<T: Ord + Copy>(corners: [T; 8]) -> [[T; 4]; TETS_PER_HEXAHEDRON] {
    let least = (0..8).min_by_key(|&b| corners[b]).unwrap_or(0);
    let apex = cube_corner(least);
    let mut tets = [[corners[0]; 4]; TETS_PER_HEXAHEDRON];
    for axis in 0..3 {
        // The face across from the least corner along `axis`, walked around: (0,0) (1,0) (1,1)
        // (0,1) in the other two axes.
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let far_bit = (1 - apex[axis]) as usize;
        let face = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(a, b)| far_bit << axis | a << u | b << v);
        let least_on_face = (0..4).min_by_key(|&q| corners[face[q]]).unwrap_or(0);
        // The diagonal from the face's least corner q to q + 2.
        let q = least_on_face % 2;
        let triangles = [
            [face[q], face[q + 1], face[(q + 2) % 4]],
            [face[q], face[(q + 2) % 4], face[(q + 3) % 4]],
        ];
        for (s, triangle) in triangles.into_iter().enumerate() {
            tets[2 * axis + s] =
                oriented([least, triangle[0], triangle[1], triangle[2]]).map(|b| corners[b]);
        }
    }
    tets
}

/// The unit-cube places of a tetrahedron, two swapped if needed for a positive volume on the
/// unit cube.
fn oriented(mut places: [usize; 4]) -> [usize; 4] {
    let [a, b, c, d] = places.map(cube_corner);
    let edge = |p: [i64; 3]| [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let (e1, e2, e3) = (edge(b), edge(c), edge(d));
    let determinant = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1])
        - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0])
        + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
    if determinant < 0 {
        places.swap(2, 3);
    }
    places
}

/// The 48 tetrahedra of a 27-node hexahedron whose lattice node `i + 3j + 9k`
/// (`i, j, k ∈ {0, 1, 2}`, the order of [`crate::shape::hex27`]) is `lattice[i + 3j + 9k]`:
/// each of its eight sub-cubes split by [`split_hexahedron`], sub-cube `s` giving tetrahedra
/// `6s..6s + 6`.
pub fn split_lattice<T: Ord + Copy>(lattice: &[T; 27]) -> [[T; 4]; TETS_PER_LATTICE] {
    let mut tets = [[lattice[0]; 4]; TETS_PER_LATTICE];
    for s in 0..8 {
        let [si, sj, sk] = cube_corner(s).map(|c| c as usize);
        let corners = std::array::from_fn(|b| {
            let [i, j, k] = cube_corner(b).map(|c| c as usize);
            lattice[(si + i) + 3 * (sj + j) + 9 * (sk + k)]
        });
        let sub = split_hexahedron(corners);
        tets[TETS_PER_HEXAHEDRON * s..TETS_PER_HEXAHEDRON * (s + 1)].copy_from_slice(&sub);
    }
    tets
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Six times the volume of the unit-cube tetrahedron on places given as lattice points.
    fn six_volume(points: [[i64; 3]; 4]) -> i64 {
        let [a, b, c, d] = points;
        let e = |p: [i64; 3]| [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
        let (e1, e2, e3) = (e(b), e(c), e(d));
        e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0])
            + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])
    }

    #[test]
    fn every_numbering_fills_the_cube_with_positive_tetrahedra() {
        // All 8! numberings would be slow to list; rotating the least corner through every
        // place with the others in several orders covers each least corner and face diagonal.
        for least in 0..8 {
            for seed in 0..64u64 {
                let mut order: Vec<u64> = (0..8).map(|b| (b * 7 + seed * 13) % 97 + 1).collect();
                order[least] = 0;
                let corners: [u64; 8] = std::array::from_fn(|b| order[b] * 8 + b as u64);
                let place_of: HashMap<u64, usize> =
                    corners.iter().enumerate().map(|(b, &c)| (c, b)).collect();
                let tets = split_hexahedron(corners);
                let volumes: Vec<i64> = tets
                    .iter()
                    .map(|t| six_volume(t.map(|c| cube_corner(place_of[&c]))))
                    .collect();
                assert!(
                    volumes.iter().all(|&v| v > 0),
                    "{least} {seed}: {volumes:?}"
                );
                // Six times the unit cube's volume: the tetrahedra fill it.
                assert_eq!(volumes.iter().sum::<i64>(), 6, "{least} {seed}");
            }
        }
    }

    #[test]
    fn neighbours_cut_their_shared_face_alike() {
        // Two unit cubes side by side along x on a 3 x 2 x 2 grid of points, numbered
        // arbitrarily: the triangles each puts on the face x = 1 are the same.
        const NUMBERS: [usize; 12] = [7, 2, 11, 0, 5, 9, 3, 10, 1, 6, 8, 4];
        let number = |i: usize, j: usize, k: usize| NUMBERS[i + 3 * j + 6 * k];
        let cube = |x: usize| -> [usize; 8] {
            std::array::from_fn(|b| {
                let [i, j, k] = cube_corner(b).map(|c| c as usize);
                number(x + i, j, k)
            })
        };
        let on_face = |tets: &[[usize; 4]]| {
            let face: Vec<usize> = (0..4).map(|q| number(1, q & 1, q >> 1)).collect();
            let mut triangles: Vec<[usize; 3]> = tets
                .iter()
                .flat_map(|t| {
                    (0..4).map(move |skip| {
                        let mut tri = [0; 3];
                        let mut n = 0;
                        for (m, &node) in t.iter().enumerate() {
                            if m != skip {
                                tri[n] = node;
                                n += 1;
                            }
                        }
                        tri.sort_unstable();
                        tri
                    })
                })
                .filter(|tri| tri.iter().all(|n| face.contains(n)))
                .collect();
            triangles.sort_unstable();
            triangles
        };
        let left = on_face(&split_hexahedron(cube(0)));
        let right = on_face(&split_hexahedron(cube(1)));
        assert_eq!(left.len(), 2);
        assert_eq!(left, right);
    }

    #[test]
    fn a_lattice_splits_into_forty_eight_positive_tetrahedra() {
        let lattice: [usize; 27] = std::array::from_fn(|n| (n * 10) % 27);
        let place = |node: usize| {
            let n = (0..27).find(|&m| lattice[m] == node).unwrap();
            [(n % 3) as i64, ((n / 3) % 3) as i64, (n / 9) as i64]
        };
        let tets = split_lattice(&lattice);
        let volumes: Vec<i64> = tets.iter().map(|t| six_volume(t.map(place))).collect();
        assert!(volumes.iter().all(|&v| v > 0));
        assert_eq!(volumes.iter().sum::<i64>(), 6 * 8);
    }
}
