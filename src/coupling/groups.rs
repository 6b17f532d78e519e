//! Deformable bodies whose surfaces touch step together: the groups are the connected components
//! of the graph whose edges are the contacts between bodies (union–find with path halving).
//! Within a coupling substep the groups share nothing (each body's constraints hold their own
//! copies of the rigid bodies they touch; rapier's sets are only read), so they step at once, on
//! rayon's thread pool with the `parallel` feature: the same arithmetic body by body, in any
//! order, so the results do not depend on the threads.

use crate::Error;
use crate::contact::{BetweenContact, ContactSettings};
use crate::integrate::{AutomaticIntegrator, AutomaticReport, BodyInStep};
use rapier3d::glamx::DVec3;

/// A group of touching bodies ready to step: the bodies and the contacts between them (indices
/// into the bodies).
pub(super) struct GroupStep<'a> {
    pub(super) bodies: Vec<BodyInStep<'a>>,
    pub(super) between: Vec<BetweenContact>,
    /// What the bodies' last steps took (s, [`BodyLinks::last_seconds`](super::bodies::BodyLinks)):
    /// the dearest groups start first.
    pub(super) expected_seconds: f64,
}

/// Steps every group by `h` (s) under `gravity` (m/s²) with `integrator`, the contacts between
/// bodies enforced with `settings`: per group, a result per body, in order.
pub(super) fn step_groups(
    groups: &mut [GroupStep<'_>],
    integrator: &AutomaticIntegrator,
    settings: &ContactSettings,
    (h, gravity): (f64, DVec3),
) -> Vec<Vec<Result<AutomaticReport, Error>>> {
    let step = |group: &mut GroupStep<'_>| step_group(group, integrator, settings, (h, gravity));
    let expected = |group: &GroupStep<'_>| group.expected_seconds;
    // On the pool: a lone group would otherwise step on the calling thread.
    crate::parallel::on_pool(|| crate::parallel::map_dearest_first(groups, expected, step))
}

/// Steps one group: a lone body by itself, touching bodies together.
fn step_group(
    group: &mut GroupStep<'_>,
    integrator: &AutomaticIntegrator,
    settings: &ContactSettings,
    (h, gravity): (f64, DVec3),
) -> Vec<Result<AutomaticReport, Error>> {
    if let [step] = &mut group.bodies[..] {
        return vec![integrator.step(step.body, step.constraints, step.workspace, h, gravity)];
    }
    let between = (&mut group.between[..], settings);
    match integrator.step_together(&mut group.bodies, between, h, gravity) {
        Ok(reports) => reports.into_iter().map(Ok).collect(),
        Err(error) => vec![Err(error); group.bodies.len()],
    }
}

/// The groups of `count` bodies that the contacts `between` them link (directly or through
/// others), each with its contacts re-indexed to positions in the group: bodies that must step
/// together. A body touching no other is a group of its own.
pub(crate) fn touching_groups(
    count: usize,
    between: Vec<BetweenContact>,
) -> Vec<(Vec<usize>, Vec<BetweenContact>)> {
    let mut components = Components::new(count);
    for contact in &between {
        components.join(contact.node_body, contact.triangle_body);
    }
    let mut groups: Vec<(Vec<usize>, Vec<BetweenContact>)> = Vec::new();
    let mut group_of = vec![usize::MAX; count];
    let mut slot_of = vec![0; count];
    for (i, slot) in slot_of.iter_mut().enumerate() {
        let r = components.find(i);
        if group_of[r] == usize::MAX {
            group_of[r] = groups.len();
            groups.push((Vec::new(), Vec::new()));
        }
        let group = &mut groups[group_of[r]].0;
        *slot = group.len();
        group.push(i);
    }
    for mut contact in between {
        let g = group_of[components.find(contact.node_body)];
        contact.node_body = slot_of[contact.node_body];
        contact.triangle_body = slot_of[contact.triangle_body];
        groups[g].1.push(contact);
    }
    groups
}

/// The connected components of a graph on `0..n` built edge by edge (union–find with path
/// halving; each component's root is its smallest member).
pub(super) struct Components {
    root: Vec<usize>,
}

impl Components {
    /// `n` members, each its own component.
    pub(super) fn new(n: usize) -> Self {
        Self {
            root: (0..n).collect(),
        }
    }

    /// The root of `i`'s component.
    pub(super) fn find(&mut self, mut i: usize) -> usize {
        while self.root[i] != i {
            self.root[i] = self.root[self.root[i]];
            i = self.root[i];
        }
        i
    }

    /// Joins the components of `a` and `b`.
    pub(super) fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        self.root[a.max(b)] = a.min(b);
    }

    /// The components, each in increasing order, ordered by their smallest member.
    pub(super) fn groups(&mut self) -> Vec<Vec<usize>> {
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut group_of = vec![usize::MAX; self.root.len()];
        for i in 0..self.root.len() {
            let r = self.find(i);
            if group_of[r] == usize::MAX {
                group_of[r] = groups.len();
                groups.push(Vec::new());
            }
            groups[group_of[r]].push(i);
        }
        groups
    }
}
