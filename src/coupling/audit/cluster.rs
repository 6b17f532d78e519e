//! The bodies that exchange energy within a frame, checked together: deformable bodies and the
//! dynamic rigid bodies they touched in any substep of the frame (those they handed a load to,
//! [`SoftCoupling::rigid_loads`](crate::coupling::SoftCoupling::rigid_loads)) or their last
//! substep touched or is glued to, joined with the deformable bodies whose bounding boxes,
//! widened by the contact margin, overlap. A ball that strikes a block and is gone by the
//! frame's last substep still took part in the frame's exchange. A cluster then takes in, one
//! contact after another, the dynamic rigid bodies rapier's own contacts held against its rigid
//! members in any rapier step of the frame
//! ([`SoftCoupling::rigid_touches`](crate::coupling::SoftCoupling::rigid_touches)): a box that
//! falls onto a ball resting against a soft block hands the ball its energy through rapier, and
//! the box's loss is counted beside the ball's gain. What rapier's contacts themselves create
//! is then counted too (its position correction lifting a box, a ball spinning at 20 rad/s
//! meeting a box, measured up to 1.7e-4 J in a frame of the game scene), so each cluster keeps
//! the list of its members without the bodies only those contacts joined: the audit checks
//! both (see the module's documentation). A deformable body standing in as a rigid body
//! counts as one: its rapier contacts are rapier's, and alone it is not checked.

use super::AuditInput;
use super::energy::Member;
use rapier3d::dynamics::RigidBodyHandle;

/// A cluster of bodies checked together.
pub(super) struct Cluster {
    /// Its members, deformable bodies first.
    pub(super) members: Vec<Member>,
    /// The members but those only rapier's contacts with other rigid bodies joined.
    pub(super) exchanging: Vec<Member>,
}

/// The clusters of `input`'s deformable bodies.
pub(super) fn clusters(input: &AuditInput<'_>) -> Vec<Cluster> {
    let margin = input.coupling.contact.margin;
    let mut clusters: Vec<Vec<Member>> = Vec::new();
    let soft: Vec<_> = input.soft_bodies.iter().collect();
    for (handle, body) in &soft {
        // A stand-in meets rigid bodies through rapier's contacts, as rigid bodies do; its
        // coupling's constraints are those of its last elastic step.
        let standing_in = input.coupling.rigid_stand_in_of(*handle).is_some();
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
        for rigid in loaded.chain(linked).filter(|_| !standing_in) {
            let dynamic = input.bodies.get(rigid).is_some_and(|b| b.is_dynamic());
            let member = rigid_member(input, rigid);
            if dynamic && !members.contains(&member) {
                members.push(member);
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
        if standing_in && members.len() == 1 {
            // Alone, it is rapier's to answer for, as a rigid body that met only rapier's
            // contacts.
            continue;
        }
        merge(&mut clusters, members);
    }
    let exchanging: Vec<Member> = clusters.iter().flatten().copied().collect();
    let touches: Vec<(Member, Member)> = (input.coupling.rigid_touches().iter())
        .map(|&(a, b)| (rigid_member(input, a), rigid_member(input, b)))
        .collect();
    join_touching(&mut clusters, &touches);
    (clusters.into_iter())
        .map(|mut members| {
            members.sort_by_key(|member| matches!(member, Member::Rigid(_)));
            Cluster {
                exchanging: (members.iter())
                    .filter(|m| exchanging.contains(m))
                    .copied()
                    .collect(),
                members,
            }
        })
        .collect()
}

/// The member a rigid body counts as: the deformable body it stands in for, if it is a
/// stand-in (its nodes carry its energy), or itself.
fn rigid_member(input: &AuditInput<'_>, rigid: RigidBodyHandle) -> Member {
    input
        .coupling
        .stand_in_for(rigid)
        .map_or(Member::Rigid(rigid), Member::Soft)
}

/// Adds to each of `clusters` the bodies `touches` holds against one of its members, until no
/// pair joins one more (two clusters a pair links become one).
fn join_touching(clusters: &mut Vec<Vec<Member>>, touches: &[(Member, Member)]) {
    let cluster_of =
        |clusters: &[Vec<Member>], member| clusters.iter().position(|c| c.contains(&member));
    let mut joined = true;
    while joined {
        joined = false;
        for &(a, b) in touches {
            let (of_a, of_b) = (cluster_of(clusters, a), cluster_of(clusters, b));
            if of_a != of_b {
                merge(clusters, vec![a, b]);
                joined = true;
            }
        }
    }
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
