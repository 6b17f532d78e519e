//! The bodies that exchange energy within a frame, checked together: deformable bodies and the
//! dynamic rigid bodies they touched in any substep of the frame (those they handed a load to,
//! [`SoftCoupling::rigid_loads`](crate::coupling::SoftCoupling::rigid_loads)) or their last
//! substep touched or is glued to, joined with the deformable bodies whose bounding boxes,
//! widened by the contact margin, overlap. A ball that strikes a block and is gone by the
//! frame's last substep still took part in the frame's exchange.

use super::AuditInput;
use super::energy::Member;

/// The clusters of `input`'s deformable bodies: each a list of members, deformable bodies first.
pub(super) fn clusters(input: &AuditInput<'_>) -> Vec<Vec<Member>> {
    let margin = input.coupling.contact.margin;
    let mut clusters: Vec<Vec<Member>> = Vec::new();
    let soft: Vec<_> = input.soft_bodies.iter().collect();
    for (handle, body) in &soft {
        let mut members = vec![Member::Soft(*handle)];
        let loaded = (input.coupling.rigid_loads().iter())
            .filter(|load| load.soft_body == *handle)
            .map(|load| load.rigid_body);
        let linked = input
            .coupling
            .constraints(*handle)
            .into_iter()
            .flat_map(|c| {
                (c.rigid_proxies.iter().map(|p| p.handle))
                    .chain(c.attachments.iter().map(|a| a.body))
            });
        for rigid in loaded.chain(linked) {
            let dynamic = input.bodies.get(rigid).is_some_and(|b| b.is_dynamic());
            if dynamic && !members.contains(&Member::Rigid(rigid)) {
                members.push(Member::Rigid(rigid));
            }
        }
        let (lo, hi) = body.position_bounds();
        for (other, other_body) in &soft {
            let (other_lo, other_hi) = other_body.position_bounds();
            let apart = (lo - margin).cmpgt(other_hi).any() || (hi + margin).cmplt(other_lo).any();
            if other != handle && !apart {
                members.push(Member::Soft(*other));
            }
        }
        merge(&mut clusters, members);
    }
    clusters
}

/// Adds `members` to `clusters`, merging every cluster that shares one of them.
fn merge(clusters: &mut Vec<Vec<Member>>, mut members: Vec<Member>) {
    let mut i = 0;
    while i < clusters.len() {
        if clusters[i].iter().any(|m| members.contains(m)) {
            members.extend(clusters.swap_remove(i));
        } else {
            i += 1;
        }
    }
    let mut unique = Vec::with_capacity(members.len());
    for member in members {
        if !unique.contains(&member) {
            unique.push(member);
        }
    }
    clusters.push(unique);
}
