//! What the deformable bodies see of rapier's sets and hand back to them: every non-sensor
//! collider as a [`ColliderView`] (shape, pose, bounds, groups, coefficients, its rigid body's
//! proxy and travel over the step), the rigid bodies' poses and proxies for attachments, and the
//! impulses the soft step gave dynamic rigid bodies, applied at the end of the step. The
//! [`BodyConstraints`] methods that take rapier's sets live here.

use super::reach::turning_speed;
use crate::Error;
use crate::attachment;
use crate::body::DeformableBody;
use crate::constraint::BodyConstraints;
use crate::contact::{ColliderView, ContactSettings, NodeContact, SurfaceCoefficients};
use crate::rigid::{RigidProxy, coming_velocity};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::ColliderSet;
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;

/// Every non-sensor collider of `colliders`, with its rigid body of `bodies`, as the contacts of
/// a step of `dt` (s) see it.
pub(crate) fn collider_views(
    colliders: &ColliderSet,
    bodies: &RigidBodySet,
    dt: f64,
) -> Vec<ColliderView> {
    colliders
        .iter()
        .filter(|(_, collider)| !collider.is_sensor())
        .map(|(handle, collider)| {
            let aabb = collider.compute_aabb();
            let parent = collider
                .parent()
                .and_then(|handle| bodies.get(handle).map(|body| (handle, body)));
            // The collider's own travel in the step, at its fastest point.
            let travel = parent.map_or(0.0, |(_, body)| {
                let radius = f64::from(aabb.half_extents().length());
                let (linvel, angvel) = coming_velocity(body, dt);
                2.0 * (linvel.length() + turning_speed(angvel.length(), radius)) * dt
            });
            ColliderView {
                handle,
                shape: collider.shared_shape().clone(),
                pose: *collider.position(),
                bounds: (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3()),
                groups: collider.collision_groups(),
                coefficients: SurfaceCoefficients::of_collider(collider),
                parent: parent.map(|(handle, body)| RigidProxy::new(handle, body, dt)),
                travel,
            }
        })
        .collect()
}

/// The pose and fresh proxy, for a step of `dt` (s), of a rigid body of `bodies`.
pub(crate) fn rigid_lookup(
    bodies: &RigidBodySet,
    dt: f64,
) -> impl Fn(RigidBodyHandle) -> Option<(Pose, RigidProxy)> + '_ {
    move |handle| {
        bodies
            .get(handle)
            .map(|body| (*body.position(), RigidProxy::new(handle, body, dt)))
    }
}

impl BodyConstraints {
    /// Finds the contacts of `body`'s surface with `colliders` for a frame of `frame_dt` (s)
    /// under `gravity` (m/s²), replacing the previous ones: a surface point gets a contact with
    /// each non-sensor collider the body's
    /// [`collision_groups`](crate::body::DeformableBody::collision_groups) interact with and it
    /// is within `settings.margin` of, plus twice the distance the body's fastest node can
    /// travel in the frame (`2 (|v|max + |g| dt) dt`), plus twice the collider's own travel (at
    /// most 1 m) and twice that of the fastest collider that can meet the body (a collider
    /// striking it can drive its nodes into another), except the colliders of a rigid body the
    /// point is attached to; with
    /// [`self_contact`](crate::body::DeformableBody::self_contact) on, also with the body's own
    /// boundary. The integrators enforce them until the next detection. It also places the
    /// attachments' anchors where their rigid bodies of `bodies` are now (dropping attachments
    /// to bodies no longer there), ready for the step.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`], [`Error::NonFiniteInput`] or [`Error::InvalidSetting`] for a bad
    /// step, gravity or setting; the contacts are then left as they were.
    pub fn detect_contacts(
        &mut self,
        body: &DeformableBody,
        colliders: &ColliderSet,
        bodies: &RigidBodySet,
        frame_dt: f64,
        gravity: DVec3,
        settings: &ContactSettings,
    ) -> Result<&[NodeContact], Error> {
        let views = collider_views(colliders, bodies, frame_dt);
        let rigid = rigid_lookup(bodies, frame_dt);
        self.detect_among(body, (&views, 0.0), &rigid, frame_dt, gravity, settings)
    }

    /// Glues `nodes` of `body` to the rigid body `rigid` of `bodies` where they are now: each
    /// node keeps following the rigid body's material point it sits at, and the rigid body feels
    /// it (two-way when it is dynamic; a kinematic or fixed body drags the nodes along). The
    /// attachments act from the next [`BodyConstraints::detect_contacts`], which readies them
    /// for the coming step.
    ///
    /// # Errors
    /// [`Error::NodeOutOfRange`] for a node that does not exist, [`Error::UnknownRigidBody`] if
    /// `rigid` is not in `bodies`; nothing is attached then.
    pub fn attach(
        &mut self,
        body: &DeformableBody,
        nodes: impl IntoIterator<Item = u32>,
        rigid: RigidBodyHandle,
        bodies: &RigidBodySet,
    ) -> Result<(), Error> {
        let pose = bodies.get(rigid).ok_or(Error::UnknownRigidBody)?.position();
        let added = attachment::glue(body, nodes, rigid, pose)?;
        self.add_attachments(added);
        Ok(())
    }

    /// Hands the impulses the contacts and attachments of the last step gave dynamic rigid
    /// bodies to rapier's set (the opposite of what the soft body received), and forgets them.
    pub fn transfer_contact_impulses(&mut self, bodies: &mut RigidBodySet) {
        for proxy in self.rigid_proxies_mut() {
            if let Some(body) = bodies.get_mut(proxy.handle)
                && body.is_dynamic()
                && (proxy.impulse != DVec3::ZERO || proxy.angular_impulse != DVec3::ZERO)
            {
                body.apply_impulse(proxy.impulse.as_vec3(), true);
                body.apply_torque_impulse(proxy.angular_impulse.as_vec3(), true);
            }
            proxy.impulse = DVec3::ZERO;
            proxy.angular_impulse = DVec3::ZERO;
        }
    }
}
