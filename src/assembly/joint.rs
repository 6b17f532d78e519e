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
        let dofs: usize = parts.iter().map(|part| part.dofs).sum();
        let mut union = pairs.to_vec();
        union.sort_unstable();
        union.dedup();
        let earlier = earlier.filter(|earlier| {
            earlier.dofs == dofs && earlier.extra_pairs.len() <= KEPT_PAIRS * union.len().max(1)
        });
        let Some(earlier) = earlier else {
            return Self::joint(parts, &union);
        };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::SymbolicFactor;

    /// A part of four nodes, all coupled (one tetrahedron's pattern).
    fn tetrahedron() -> Stiffness {
        Stiffness::with_neighbours((0..4u32).map(|b| (b..4).collect()).collect())
    }

    /// `joint` with its symbolic factorization made, as the first factorization makes it.
    fn analysed(mut joint: Stiffness) -> Stiffness {
        let pattern = joint.as_faer().symbolic();
        joint.symbolic = Some(SymbolicFactor::try_new(pattern).unwrap());
        joint
    }

    #[test]
    fn a_group_whose_contact_moves_between_triangles_keeps_one_pattern_and_its_analysis() {
        let part = tetrahedron();
        let parts = [&part, &part];
        // Node 4 (the second part's first) touches the first part's triangle 0-1-2, then 1-2-3,
        // then 0-1-2 again.
        let first = analysed(Stiffness::joint(&parts, &[[4, 0], [4, 1], [4, 2]]).unwrap());
        let second = Stiffness::joint_after(&parts, &[[4, 1], [4, 2], [4, 3]], Some(first));
        let second = second.unwrap();
        assert!(second.couples(4, 0) && second.couples(4, 3));
        assert!(
            second.symbolic.is_none(),
            "a wider pattern is analysed anew"
        );
        let second = analysed(second);
        let (col_ptr, row_idx) = (second.col_ptr.clone(), second.row_idx.clone());
        let third = Stiffness::joint_after(&parts, &[[4, 0], [4, 1], [4, 2]], Some(second));
        let third = third.unwrap();
        assert_eq!((&third.col_ptr, &third.row_idx), (&col_ptr, &row_idx));
        assert!(
            third.symbolic.is_some(),
            "the same pattern keeps its analysis"
        );
        // Far more pairs kept than coupled now: the pattern starts afresh.
        let fourth = Stiffness::joint_after(&parts, &[[5, 0]], Some(third)).unwrap();
        assert!(!fourth.couples(4, 0) && fourth.couples(5, 0) && fourth.symbolic.is_none());
        // Another group size: the earlier tangent is not used.
        let three = [&part, &part, &part];
        let other = Stiffness::joint_after(&three, &[[8, 0]], Some(analysed(fourth))).unwrap();
        assert!(!other.couples(5, 0) && other.symbolic.is_none());
    }
}
