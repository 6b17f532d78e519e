//! The tangent of bodies stepped in one system: their matrices side by side on the diagonal,
//! node `n` of the body at `offset` being the system's node `offset + n`, and the blocks of the
//! node pairs a term between two bodies couples (a node and the corners of the triangle it
//! touches). Each body's tangent is assembled on its own pattern and added in by
//! [`Stiffness::add_part`].

use super::Stiffness;

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
        Some(Self::with_neighbours(lower_neighbours))
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
