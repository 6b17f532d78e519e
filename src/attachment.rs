//! Nodes glued to rapier rigid bodies, two-way: the node follows the body's material point it was
//! attached at, and the body feels the node's pull.
//!
//! The explicit integrator enforces each attachment at every substep as a point constraint on
//! velocity (the node's velocity relative to the anchor's, with a fifth of the position drift
//! corrected per substep), solved with the 3 x 3 effective mass of node and body; the body gets
//! the opposite impulse at the node. The implicit integrator adds a stiff spring to the anchor's
//! position at the end of the step, `k = penalty_factor m/h²` (`h` the step's penalty step, see
//! `contact::ImplicitStep`), to its potential, the anchor
//! carried by its body at the velocity the step's solve gives it (a dynamic body's response to
//! the springs and contacts is part of the solve). In both, the body's velocity follows the
//! impulses, and the anchor moves with it, as for contacts.

use crate::Error;
use crate::body::DeformableBody;
use crate::contact::{ContactSettings, ImplicitStep};
use crate::rigid::{RigidPoint, RigidProxy};
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::glamx::{DMat3, DVec3};
use rapier3d::math::Pose;

/// Fraction of an attachment's position drift corrected per explicit substep.
const DRIFT_CORRECTION: f64 = 0.2;

/// A node glued to a point of a rigid body.
///
/// Written (feature `serde-serialize`) as its node, rigid body and local anchor: the rest is
/// readied again by the next contact detection.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct Attachment {
    /// The soft body's node.
    pub node: u32,
    /// The rigid body.
    pub body: RigidBodyHandle,
    /// The anchor point in the rigid body's local frame (m).
    pub local_anchor: DVec3,
    /// The anchor in the world (m), moved with the body during a soft step.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub(crate) anchor: DVec3,
    /// Index of the body among the soft body's rigid proxies.
    #[cfg_attr(feature = "serde-serialize", serde(skip, default = "unready"))]
    pub(crate) proxy: usize,
    /// Within an explicit substep: the velocity (m/s) of the node relative to the anchor that
    /// corrects part of the drift, and the inverse of the node's and body's joint inverse mass
    /// (kg).
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    drift_velocity: DVec3,
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    effective_mass: DMat3,
}

/// The proxy index of an attachment not readied for a step yet.
#[cfg(feature = "serde-serialize")]
fn unready() -> usize {
    usize::MAX
}

/// The attachments gluing `nodes` of `body` to the rigid body `rigid`, at `pose`, where they are
/// now (see [`BodyConstraints::attach`](crate::constraint::BodyConstraints::attach)).
///
/// # Errors
/// [`Error::NodeOutOfRange`] for a node that does not exist.
pub(crate) fn glue(
    body: &DeformableBody,
    nodes: impl IntoIterator<Item = u32>,
    rigid: RigidBodyHandle,
    pose: &Pose,
) -> Result<Vec<Attachment>, Error> {
    let node_count = body.node_count();
    let mut added = Vec::new();
    for node in nodes {
        let x = *body
            .positions()
            .get(node as usize)
            .ok_or(Error::NodeOutOfRange {
                node: node as usize,
                node_count,
            })?;
        let local_anchor = pose.inverse_transform_point(x.as_vec3()).as_dvec3();
        added.push(Attachment {
            node,
            body: rigid,
            local_anchor,
            anchor: x,
            proxy: usize::MAX,
            drift_velocity: DVec3::ZERO,
            effective_mass: DMat3::ZERO,
        });
    }
    Ok(added)
}

/// Places the attachments' anchors where their bodies are now and gives each body a proxy
/// (shared with the contacts'): `rigid` tells a rigid body's pose and fresh proxy for the step,
/// `None` for a body no longer there, whose attachments are dropped.
pub(crate) fn ready(
    attachments: &mut Vec<Attachment>,
    proxies: &mut Vec<RigidProxy>,
    rigid: &dyn Fn(RigidBodyHandle) -> Option<(Pose, RigidProxy)>,
) {
    attachments.retain_mut(|attachment| {
        let Some((pose, fresh)) = rigid(attachment.body) else {
            return false;
        };
        attachment.anchor = pose
            .transform_point(attachment.local_anchor.as_vec3())
            .as_dvec3();
        attachment.proxy = RigidProxy::index_in(proxies, &fresh);
        true
    });
}

/// Readies the attachments' velocity constraints for an explicit substep of `h` (s), before the
/// sweeps of [`solve_velocities`].
pub(crate) fn prepare_velocities(
    body: &DeformableBody,
    attachments: &mut [Attachment],
    proxies: &[RigidProxy],
    h: f64,
) {
    for attachment in attachments {
        let n = attachment.node as usize;
        let x = body.positions[n];
        attachment.drift_velocity = (attachment.anchor - x) * (DRIFT_CORRECTION / h);
        let proxy = &proxies[attachment.proxy];
        let rigid = proxy.inverse_mass_matrix(x);
        attachment.effective_mass = if !body.pinned[n] {
            (DMat3::IDENTITY * (1.0 / body.masses[n]) + rigid).inverse()
        } else if proxy.is_dynamic() {
            rigid.inverse()
        } else {
            DMat3::ZERO
        };
    }
}

/// One sweep over the attachments' velocity constraints, after the contacts': each node's
/// velocity is set to its anchor's plus the drift correction by an impulse shared with the body.
/// A pinned node keeps its velocity and the body takes the whole correction: it is held there.
pub(crate) fn solve_velocities(
    body: &mut DeformableBody,
    attachments: &[Attachment],
    proxies: &mut [RigidProxy],
) {
    let DeformableBody {
        positions,
        velocities,
        masses,
        pinned,
        ..
    } = body;
    for attachment in attachments {
        let n = attachment.node as usize;
        let proxy = &mut proxies[attachment.proxy];
        let wanted = proxy.velocity_at(attachment.anchor) + attachment.drift_velocity;
        let impulse = attachment.effective_mass * (wanted - velocities[n]);
        if !pinned[n] {
            velocities[n] += impulse / masses[n];
        }
        proxy.apply(-impulse, positions[n]);
    }
}

/// Carries the anchors with their bodies over an explicit substep of `h` (s), after the sweeps.
pub(crate) fn advance_anchors(attachments: &mut [Attachment], proxies: &[RigidProxy], h: f64) {
    for attachment in attachments {
        let proxy = &proxies[attachment.proxy];
        attachment.anchor += proxy.velocity_at(attachment.anchor) * h;
    }
}

impl Attachment {
    /// Where the implicit spring pulls the node at the end of the implicit `step`: the anchor
    /// carried by its body's velocity there over the step's length (m).
    fn spring_target(&self, step: &ImplicitStep) -> DVec3 {
        self.anchor + step.rigid[self.proxy].velocity_at(self.anchor) * step.length
    }

    /// The implicit spring's stiffness (N/m) in `step`: the penalty factor times `m/h²` (`h` its
    /// penalty step), with
    /// `m` the node's mass plus, for a dynamic body, the least effective mass of the body at the
    /// anchor, so that the spring holds a heavy body as firmly as a light one.
    fn spring_stiffness(
        &self,
        body: &DeformableBody,
        settings: &ContactSettings,
        step: &ImplicitStep,
    ) -> f64 {
        self.stiffness_against(body, settings, (&step.rigid[self.proxy], step.penalty_step))
    }

    /// [`Attachment::spring_stiffness`] (N/m) against the body's `rigid` proxy in a step of
    /// penalty step `penalty_step` (s).
    fn stiffness_against(
        &self,
        body: &DeformableBody,
        settings: &ContactSettings,
        (rigid, penalty_step): (&RigidProxy, f64),
    ) -> f64 {
        let partner = if rigid.is_dynamic() {
            rigid.least_effective_mass(self.anchor)
        } else {
            0.0
        };
        settings.penalty_stiffness(body.masses[self.node as usize] + partner, penalty_step)
    }

    /// The dynamic rigid body's point the spring pulls against, if the body is dynamic.
    pub(crate) fn partner(&self, step: &ImplicitStep) -> Option<RigidPoint> {
        step.rigid[self.proxy].is_dynamic().then_some(RigidPoint {
            proxy: self.proxy,
            point: self.anchor,
        })
    }
}

/// Calls `each(attachment, stiffness k (N/m), target (m))` for every attachment of a free node
/// in the implicit `step`: the node is pulled toward the anchor's end position with the energy
/// `k/2 |x - target|²` (see [`Attachment::spring_stiffness`]); only those to a dynamic rigid body
/// if the step wants [`partners_only`](ImplicitStep::partners_only).
pub(crate) fn for_each_spring<'a>(
    body: &DeformableBody,
    attachments: &'a [Attachment],
    settings: &ContactSettings,
    step: &ImplicitStep,
    mut each: impl FnMut(&'a Attachment, f64, DVec3),
) {
    for attachment in attachments {
        let n = attachment.node as usize;
        if !body.pinned[n] && !step.skips(&attachment.partner(step)) {
            let stiffness = attachment.spring_stiffness(body, settings, step);
            each(attachment, stiffness, attachment.spring_target(step));
        }
    }
}

/// The anchors (m) of the `attachments` of the free nodes of `body` whose rigid bodies, among
/// `proxies`, do not move (fixed, or kinematic at rest): points the body turns about as about
/// pinned nodes.
pub(crate) fn still_anchors(
    body: &DeformableBody,
    attachments: &[Attachment],
    proxies: &[RigidProxy],
) -> Vec<DVec3> {
    (attachments.iter())
        .filter(|a| !body.pinned[a.node as usize])
        .filter_map(|a| {
            let rigid = proxies.get(a.proxy)?;
            (!rigid.is_dynamic() && rigid.velocity_at(a.anchor) == DVec3::ZERO).then_some(a.anchor)
        })
        .collect()
}

/// The energy (J) the implicit springs of `attachments` hold, `Σ k/2 |x − anchor|²`, with the
/// nodes of `body` where they are and each anchor where the last implicit step, of penalty step
/// `penalty_step` (s, see `contact::ImplicitStep`), left it, against the rigid bodies' `proxies`
/// of that step.
pub(crate) fn spring_energy(
    body: &DeformableBody,
    attachments: &[Attachment],
    (proxies, settings): (&[RigidProxy], &ContactSettings),
    penalty_step: f64,
) -> f64 {
    (attachments.iter())
        .filter(|a| !body.pinned[a.node as usize])
        .filter_map(|a| {
            let rigid = proxies.get(a.proxy)?;
            let stiffness = a.stiffness_against(body, settings, (rigid, penalty_step));
            let stretch = body.positions[a.node as usize] - a.anchor;
            Some(0.5 * stiffness * stretch.length_squared())
        })
        .sum()
}

/// Records the impulses (N s) the implicit springs gave the nodes over the implicit `step`, at
/// the rigid velocities of `step`, hands their opposite to the bodies' `proxies` at the anchors,
/// and carries the anchors with them.
pub(crate) fn record_spring_impulses(
    body: &DeformableBody,
    attachments: &mut [Attachment],
    settings: &ContactSettings,
    step: &ImplicitStep,
    proxies: &mut [RigidProxy],
) {
    for attachment in attachments.iter_mut() {
        let n = attachment.node as usize;
        if body.pinned[n] {
            continue;
        }
        let stiffness = attachment.spring_stiffness(body, settings, step);
        let target = attachment.spring_target(step);
        let impulse = (target - body.positions[n]) * (stiffness * step.length);
        proxies[attachment.proxy].apply(-impulse, attachment.anchor);
        attachment.anchor = target;
    }
}
