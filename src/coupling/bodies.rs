//! What the coupling keeps of each deformable body beside the body, by handle: the constraints
//! acting on it (contacts, rigid corners, attachments, rigid proxies) and its solver workspace.
//! An entry is made the first time a body is attached or stepped, and dropped once its body has
//! left the set.

use crate::body::{DeformableBody, DeformableBodyHandle, DeformableBodySet};
use crate::constraint::BodyConstraints;
use crate::integrate::{BodyInStep, SolverWorkspace};
use std::collections::BTreeMap;

/// One body's constraints and solver caches.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(super) struct BodyLinks {
    pub(super) constraints: BodyConstraints,
    pub(super) workspace: SolverWorkspace,
}

impl BodyLinks {
    /// `body` as a step sees it, with these constraints and caches.
    pub(super) fn with<'a>(&'a mut self, body: &'a mut DeformableBody) -> BodyInStep<'a> {
        BodyInStep {
            body,
            constraints: &mut self.constraints,
            workspace: &mut self.workspace,
        }
    }
}

/// The links of every deformable body, by handle.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        into = "Vec<(DeformableBodyHandle, BodyLinks)>",
        from = "Vec<(DeformableBodyHandle, BodyLinks)>"
    )
)]
pub(super) struct LinkSet {
    links: BTreeMap<DeformableBodyHandle, BodyLinks>,
}

/// Written as a list of pairs (formats such as JSON take only strings as map keys).
impl From<LinkSet> for Vec<(DeformableBodyHandle, BodyLinks)> {
    fn from(set: LinkSet) -> Self {
        set.links.into_iter().collect()
    }
}

impl From<Vec<(DeformableBodyHandle, BodyLinks)>> for LinkSet {
    fn from(pairs: Vec<(DeformableBodyHandle, BodyLinks)>) -> Self {
        Self {
            links: pairs.into_iter().collect(),
        }
    }
}

impl LinkSet {
    /// The links of `handle`, if it has some.
    pub(super) fn get(&self, handle: DeformableBodyHandle) -> Option<&BodyLinks> {
        self.links.get(&handle)
    }

    /// The links of `handle`, mutably, if it has some.
    pub(super) fn get_mut(&mut self, handle: DeformableBodyHandle) -> Option<&mut BodyLinks> {
        self.links.get_mut(&handle)
    }

    /// The links of `handle`, made empty if it has none yet.
    pub(super) fn entry(&mut self, handle: DeformableBodyHandle) -> &mut BodyLinks {
        self.links.entry(handle).or_default()
    }

    /// Drops the links of bodies no longer in `bodies`.
    pub(super) fn prune(&mut self, bodies: &DeformableBodySet) {
        self.links.retain(|handle, _| bodies.contains(*handle));
    }

    /// The links of distinct `handles`, made if missing, in the order given.
    pub(super) fn many_mut(&mut self, handles: &[DeformableBodyHandle]) -> Vec<&mut BodyLinks> {
        for &handle in handles {
            self.entry(handle);
        }
        let mut found: Vec<Option<&mut BodyLinks>> = handles.iter().map(|_| None).collect();
        for (handle, links) in &mut self.links {
            if let Some(i) = handles.iter().position(|h| h == handle) {
                found[i] = Some(links);
            }
        }
        found.into_iter().flatten().collect()
    }
}
