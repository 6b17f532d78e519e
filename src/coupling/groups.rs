//! Deformable bodies whose surfaces touch step together: the groups are the connected components
//! of the graph whose edges are the contacts between bodies (union–find with path halving).

use crate::contact::BetweenContact;

/// The groups of `count` bodies that the contacts `between` them link (directly or through
/// others), each with its contacts re-indexed to positions in the group: bodies that must step
/// together. A body touching no other is a group of its own.
pub(crate) fn touching_groups(
    count: usize,
    between: Vec<BetweenContact>,
) -> Vec<(Vec<usize>, Vec<BetweenContact>)> {
    let mut root: Vec<usize> = (0..count).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for contact in &between {
        let (a, b) = (
            find(&mut root, contact.node_body),
            find(&mut root, contact.triangle_body),
        );
        root[a.max(b)] = a.min(b);
    }
    let mut groups: Vec<(Vec<usize>, Vec<BetweenContact>)> = Vec::new();
    let mut group_of = vec![usize::MAX; count];
    let mut slot_of = vec![0; count];
    for (i, slot) in slot_of.iter_mut().enumerate() {
        let r = find(&mut root, i);
        if group_of[r] == usize::MAX {
            group_of[r] = groups.len();
            groups.push((Vec::new(), Vec::new()));
        }
        let group = &mut groups[group_of[r]].0;
        *slot = group.len();
        group.push(i);
    }
    for mut contact in between {
        let g = group_of[find(&mut root, contact.node_body)];
        contact.node_body = slot_of[contact.node_body];
        contact.triangle_body = slot_of[contact.triangle_body];
        groups[g].1.push(contact);
    }
    groups
}
