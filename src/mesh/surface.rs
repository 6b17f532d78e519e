//! Boundary extraction: a face of a tetrahedral mesh lies on the boundary when exactly one
//! tetrahedron owns it.

use std::collections::HashMap;

/// The four faces of a positively oriented tetrahedron `[0, 1, 2, 3]`, as local indices ordered
/// so that each face normal points out of the tetrahedron.
const OUTWARD_FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

/// Faces owned by exactly one tetrahedron, outward-oriented, in order of first appearance.
pub(super) fn boundary_faces(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut owners: HashMap<[u32; 3], (usize, [u32; 3])> = HashMap::with_capacity(tets.len() * 2);
    let mut order = Vec::with_capacity(tets.len() * 2);
    for tet in tets {
        for local in OUTWARD_FACES {
            let face = local.map(|i| tet[i]);
            let mut key = face;
            key.sort_unstable();
            let entry = owners.entry(key).or_insert_with(|| {
                order.push(key);
                (0, face)
            });
            entry.0 += 1;
        }
    }
    order
        .into_iter()
        .filter_map(|key| {
            let (count, face) = owners[&key];
            (count == 1).then_some(face)
        })
        .collect()
}
