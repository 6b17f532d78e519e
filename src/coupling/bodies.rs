//! What the coupling keeps of each deformable body beside the body, by handle ([`BodyMap`]): the
//! constraints acting on it (contacts, rigid corners, attachments, rigid proxies) and its solver
//! workspace. An entry is made the first time a body is attached or stepped, and dropped once its
//! body has left the set.

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
    /// The length (s) of the body's last step: a coupling substep, or the whole frame for a body
    /// that needed no coupling; zero before any.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    pub(super) last_step: f64,
    /// The wall-clock time (s) the body's last step took (its report's `seconds`; zero before
    /// any, or after a refused step): what its next one is expected to take, for the order in
    /// which groups start ([`step_groups`](super::groups::step_groups)). Measured, so not written.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub(super) last_seconds: f64,
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

/// A value per deformable body, by handle; written (feature `serde-serialize`) as a list of
/// pairs, as formats such as JSON take only strings as map keys.
#[derive(Debug, Clone)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        into = "Vec<(DeformableBodyHandle, T)>",
        from = "Vec<(DeformableBodyHandle, T)>"
    )
)]
pub(super) struct BodyMap<T: Clone> {
    map: BTreeMap<DeformableBodyHandle, T>,
}

impl<T: Clone> Default for BodyMap<T> {
    fn default() -> Self {
        Self {
            map: BTreeMap::new(),
        }
    }
}

impl<T: Clone> From<BodyMap<T>> for Vec<(DeformableBodyHandle, T)> {
    fn from(set: BodyMap<T>) -> Self {
        set.map.into_iter().collect()
    }
}

impl<T: Clone> From<Vec<(DeformableBodyHandle, T)>> for BodyMap<T> {
    fn from(pairs: Vec<(DeformableBodyHandle, T)>) -> Self {
        Self {
            map: pairs.into_iter().collect(),
        }
    }
}

/// The links of every deformable body.
pub(super) type LinkSet = BodyMap<BodyLinks>;

impl<T: Clone> BodyMap<T> {
    /// The value of `handle`, if it has one.
    pub(super) fn get(&self, handle: DeformableBodyHandle) -> Option<&T> {
        self.map.get(&handle)
    }

    /// The value of `handle`, mutably, if it has one.
    pub(super) fn get_mut(&mut self, handle: DeformableBodyHandle) -> Option<&mut T> {
        self.map.get_mut(&handle)
    }

    /// Sets the value of `handle`.
    pub(super) fn insert(&mut self, handle: DeformableBodyHandle, value: T) {
        self.map.insert(handle, value);
    }

    /// Every body's value, mutably.
    pub(super) fn values_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.map.values_mut()
    }

    /// Every body's value, by handle, mutably.
    pub(super) fn iter_mut(&mut self) -> impl Iterator<Item = (DeformableBodyHandle, &mut T)> {
        self.map.iter_mut().map(|(&handle, value)| (handle, value))
    }

    /// Forgets the value of `handle`.
    pub(super) fn remove(&mut self, handle: DeformableBodyHandle) {
        self.map.remove(&handle);
    }

    /// Every body's value, by handle.
    pub(super) fn iter(&self) -> impl Iterator<Item = (DeformableBodyHandle, &T)> {
        self.map.iter().map(|(&handle, value)| (handle, value))
    }

    /// Drops the values of bodies no longer in `bodies`.
    pub(super) fn prune(&mut self, bodies: &DeformableBodySet) {
        self.map.retain(|handle, _| bodies.contains(*handle));
    }
}

impl<T: Clone + Default> BodyMap<T> {
    /// The value of `handle`, made the default if it has none yet.
    pub(super) fn entry(&mut self, handle: DeformableBodyHandle) -> &mut T {
        self.map.entry(handle).or_default()
    }

    /// The values of distinct `handles`, made if missing, in the order given.
    pub(super) fn many_mut(&mut self, handles: &[DeformableBodyHandle]) -> Vec<&mut T> {
        for &handle in handles {
            self.entry(handle);
        }
        let mut found: Vec<Option<&mut T>> = handles.iter().map(|_| None).collect();
        for (handle, value) in &mut self.map {
            if let Some(i) = handles.iter().position(|h| h == handle) {
                found[i] = Some(value);
            }
        }
        found.into_iter().flatten().collect()
    }
}

impl LinkSet {
    /// Takes the links of distinct `handles` out of the set (made if missing), in the order
    /// given, for [`LinkSet::give_back`].
    pub(super) fn lend(
        &mut self,
        handles: &[DeformableBodyHandle],
    ) -> Vec<(DeformableBodyHandle, BodyLinks)> {
        (handles.iter())
            .map(|&handle| (handle, self.map.remove(&handle).unwrap_or_default()))
            .collect()
    }

    /// Puts links taken by [`LinkSet::lend`] back.
    pub(super) fn give_back(&mut self, lent: Vec<(DeformableBodyHandle, BodyLinks)>) {
        self.map.extend(lent);
    }

    /// Records that the bodies `stepped` (which have links) last stepped over `h` (s), in the
    /// wall-clock `seconds` each took.
    pub(super) fn set_last_step(
        &mut self,
        stepped: &[DeformableBodyHandle],
        h: f64,
        seconds: &[f64],
    ) {
        for (&handle, &seconds) in stepped.iter().zip(seconds) {
            if let Some(links) = self.get_mut(handle) {
                links.last_step = h;
                links.last_seconds = seconds;
            }
        }
    }

    /// What the last steps of `handles` took together (s, see [`BodyLinks::last_seconds`]).
    pub(super) fn last_seconds(
        &self,
        handles: impl IntoIterator<Item = DeformableBodyHandle>,
    ) -> f64 {
        (handles.into_iter())
            .filter_map(|handle| self.get(handle))
            .map(|links| links.last_seconds)
            .sum()
    }
}
