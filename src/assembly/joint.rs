//! The tangent of bodies stepped in one system: their matrices side by side on the diagonal,
//! node `n` of the body at `offset` being the system's node `offset + n`, and the blocks of the
//! node pairs a term between two bodies couples (a node and the corners of the triangle it
//! touches). Each body's tangent is assembled on its own pattern and added in by
//! [`Stiffness::add_part`].

use super::Stiffness;

/// How many times the pairs its contacts couple now a group's tangent may keep from earlier
/// frames (see [`Stiffness::joint_after`]).
const KEPT_PAIRS: usize = 2;

impl Stiffness {
    /// The pattern of `parts` side by side (part `k`'s nodes numbered from the sum of the node
    /// counts before it), widened by the node `pairs` (`[a, b]`, `a > b`, in that numbering),
    /// values zero. `None` for a pair naming a node past the last or not ordered.
    pub(crate) fn joint(parts: &[&Stiffness], pairs: &[[u32; 2]]) -> Option<Self> {
        let mut lower_neighbours: Vec<Vec<u32>> = Vec::new();
        for part in parts {
            let offset = lower_neighbours.len() as u32;
            lower_neighbours.extend(
                part.lower_neighbours
                    .iter()
                    .map(|list| list.iter().map(|&a| a + offset).collect()),
            );
        }
        let n = lower_neighbours.len();
        if pairs.iter().any(|&[a, b]| a <= b || a as usize >= n) {
            return None;
        }
        for &[a, b] in pairs {
            lower_neighbours[b as usize].push(a);
        }
        for list in &mut lower_neighbours {
            // Each node stays first in its own list (its neighbours are all greater).
            list.sort_unstable();
            list.dedup();
        }
        let mut extra_pairs = pairs.to_vec();
        extra_pairs.sort_unstable();
        extra_pairs.dedup();
        Some(Self {
            extra_pairs,
            ..Self::with_neighbours(lower_neighbours)
        })
    }

    /// [`Stiffness::joint`] for a group whose tangent was `earlier` the frame before: while the
    /// group has as many nodes, its pattern keeps `earlier`'s pairs as well (up to
    /// [`KEPT_PAIRS`] times the pairs of now), and takes over its symbolic factorization when
    /// that leaves the pattern as it was. Contacts that move among neighbouring nodes then
    /// keep one pattern, analysed once, at the cost of a few zero blocks.
    pub(crate) fn joint_after(
        parts: &[&Stiffness],
        pairs: &[[u32; 2]],
        earlier: Option<Stiffness>,
    ) -> Option<Self> {
        let joint = Self::joint(parts, pairs)?;
        let Some(earlier) = earlier.filter(|earlier| {
            earlier.dofs == joint.dofs
                && earlier.extra_pairs.len() <= KEPT_PAIRS * joint.extra_pairs.len().max(1)
        }) else {
            return Some(joint);
        };
        let mut union = joint.extra_pairs.clone();
        union.extend_from_slice(&earlier.extra_pairs);
        union.sort_unstable();
        union.dedup();
        let mut joint = Self::joint(parts, &union)?;
        if earlier.col_ptr == joint.col_ptr && earlier.row_idx == joint.row_idx {
            joint.symbolic = earlier.symbolic;
        }
        Some(joint)
    }

    /// Adds the values of `part`, one of the parts this joint pattern was made of, whose first
    /// node is the joint's node `offset`.
    ///
    /// In every column of the joint pattern the part's own rows come first, in the part's
    /// order: the pairs between parts couple a node only with greater nodes of later parts.
    pub(crate) fn add_part(&mut self, part: &Stiffness, offset: usize) {
        for column in 0..part.dofs {
            let (start, end) = (part.col_ptr[column], part.col_ptr[column + 1]);
            let joint_start = self.col_ptr[3 * offset + column];
            debug_assert!(
                (start..end)
                    .all(|k| self.row_idx[joint_start + k - start] == part.row_idx[k] + 3 * offset)
            );
            for (value, added) in self.values[joint_start..][..end - start]
                .iter_mut()
                .zip(&part.values[start..end])
            {
                *value += added;
            }
        }
    }
}
