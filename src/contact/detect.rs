//! Contact detection against rapier colliders: each surface node is projected onto every
//! non-sensor collider within reach whose collision groups interact with the body's (parry's
//! point projection, so every shape), and keeps the nearest surface point and outward normal;
//! rigid vertices are tested against the boundary triangles. Also the exchange with rapier: the
//! impulses handed to rigid bodies and the force on any collider.

use super::{
    BodyPoint, Coefficients, ContactSettings, ContactTarget, NodeContact, Obstacle, RigidProxy,
    SurfaceCoefficients, coming_velocity, corner, surface_tree,
};
use crate::Error;
use crate::body::DeformableBody;
use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Collider, ColliderHandle, ColliderSet, Shape, SharedShape};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;

impl DeformableBody {
    /// Finds the contacts of the body's surface nodes with `colliders` for a frame of `frame_dt`
    /// (s) under `gravity` (m/s²), replacing the previous ones: a node gets a contact with each
    /// non-sensor collider its [`DeformableBody::collision_groups`] interact with and it is within
    /// `margin` of, plus twice the distance the body's fastest
    /// node can travel in the frame (`2 (|v|max + |g| dt) dt`), plus twice the collider's own
    /// travel (at most 1 m), except the colliders of a rigid body the node is attached to. The
    /// integrators enforce them until
    /// the next detection. It also places the attachments' anchors where their rigid bodies are
    /// now, ready for the step.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`], [`Error::NonFiniteInput`] or [`Error::InvalidSetting`] for a bad
    /// step, gravity or setting; the contacts are then left as they were.
    pub fn detect_contacts(
        &mut self,
        colliders: &ColliderSet,
        bodies: &RigidBodySet,
        frame_dt: f64,
        gravity: DVec3,
        settings: &ContactSettings,
    ) -> Result<&[NodeContact], Error> {
        Error::check_step(frame_dt, gravity)?;
        settings.check()?;
        let mut contacts = Vec::new();
        let mut proxies: Vec<RigidProxy> = Vec::new();
        // Elastic waves can speed a node up within the frame: reach as far as the body's fastest
        // node, twice over.
        let reach = settings.margin
            + 2.0 * (self.fastest_node_speed() + gravity.length() * frame_dt) * frame_dt;
        let bounds = self.position_bounds();
        let mut tree = None;
        let mut corners = Vec::new();
        let contact_points = self.contact_points();
        for (handle, collider) in colliders.iter() {
            if collider.is_sensor() || !self.collision_groups.test(collider.collision_groups()) {
                continue;
            }
            let near = self.near_collider(handle, collider, bodies, reach, frame_dt);
            let mut proxy = None;
            for &at in &contact_points {
                let Some(contact) = self.node_contact_with(&near, at) else {
                    continue;
                };
                if proxy.is_none() {
                    proxy = near.proxy_in(&mut proxies, frame_dt);
                }
                contacts.push(contact.with_proxy(proxy));
            }
            if near.overlaps(bounds) && corner::has_vertices(near.shape.as_ref()) {
                let tree = tree.get_or_insert_with(|| surface_tree::SurfaceTree::of(self));
                let mut found = self.find_corner_contacts(tree, &near);
                if !found.is_empty() {
                    let proxy = proxy.or_else(|| near.proxy_in(&mut proxies, frame_dt));
                    for contact in &mut found {
                        contact.proxy = proxy;
                    }
                }
                corners.extend(found);
            }
        }
        self.constraints.corner_contacts = corners;
        crate::attachment::ready(
            &mut self.constraints.attachments,
            &mut proxies,
            bodies,
            frame_dt,
        );
        self.constraints.contacts = contacts;
        self.constraints.rigid_proxies = proxies;
        if self.self_contact {
            self.detect_self_contacts(reach);
        }
        self.constraints.settings = *settings;
        Ok(&self.constraints.contacts)
    }

    /// What detection needs of `collider` (handle `handle`): its shape, pose, parent body,
    /// coefficients, the nodes glued to its body, and `reach` (m) widened by its own travel over
    /// the frame of `frame_dt` (s).
    fn near_collider<'a>(
        &self,
        handle: ColliderHandle,
        collider: &'a Collider,
        bodies: &'a RigidBodySet,
        reach: f64,
        frame_dt: f64,
    ) -> NearCollider<'a> {
        let aabb = collider.compute_aabb();
        let parent = collider
            .parent()
            .and_then(|handle| bodies.get(handle).map(|body| (handle, body)));
        // The collider's own travel in the frame, at its fastest point.
        let collider_reach = parent.map_or(0.0, |(_, body)| {
            let radius = f64::from(aabb.half_extents().length());
            let (linvel, angvel) = coming_velocity(body, frame_dt);
            2.0 * (linvel.length() + angvel.length() * radius) * frame_dt
        });
        NearCollider {
            handle,
            shape: collider.shared_shape(),
            pose: collider.position(),
            parent,
            reach: reach + collider_reach.min(MAX_COLLIDER_REACH),
            bounds: (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3()),
            glued: self
                .constraints
                .attachments
                .iter()
                .filter(|a| Some(a.body) == collider.parent())
                .map(|a| a.node)
                .collect(),
            coefficients: SurfaceCoefficients::of_body(self)
                .combine(SurfaceCoefficients::of_collider(collider)),
        }
    }

    /// The contact of the body's point `at` with `near`, if it lies within reach of its surface
    /// and can move apart from it (not pinned, not glued to the collider's body); its proxy is
    /// left for the caller to set.
    fn node_contact_with(&self, near: &NearCollider<'_>, at: BodyPoint) -> Option<NodeContact> {
        let stencil = at.stencil(self.embedding.as_ref());
        if stencil.nodes.iter().all(|&n| self.pinned[n as usize])
            || stencil.nodes.iter().any(|n| near.glued.contains(n))
        {
            return None;
        }
        let x = stencil.interpolate(&self.positions);
        let reach = DVec3::splat(near.reach);
        let (lo, hi) = near.bounds;
        if (x + reach).cmplt(lo).any() || (x - reach).cmpgt(hi).any() {
            return None;
        }
        let (point, normal, distance) = nearest_surface_point(near.shape.as_ref(), near.pose, x)?;
        (distance <= near.reach).then(|| {
            NodeContact::new(
                at,
                ContactTarget::Collider(near.handle),
                point,
                normal,
                near.coefficients,
                Obstacle::Collider {
                    shape: near.shape.clone(),
                    pose: *near.pose,
                    proxy: None,
                },
            )
        })
    }

    /// The points contacts with colliders are detected for: the surface vertices of the
    /// embedded mesh if the body has one, else its surface nodes.
    pub(super) fn contact_points(&self) -> Vec<BodyPoint> {
        match &self.embedding {
            Some(embedding) => embedding
                .surface_vertices()
                .iter()
                .map(|&v| BodyPoint::Embedded(v))
                .collect(),
            None => self
                .surface
                .nodes
                .iter()
                .map(|&n| BodyPoint::Node(n))
                .collect(),
        }
    }

    /// The contacts found by the last [`DeformableBody::detect_contacts`].
    pub fn contacts(&self) -> &[NodeContact] {
        &self.constraints.contacts
    }

    /// Removes every contact.
    pub fn clear_contacts(&mut self) {
        self.constraints.contacts.clear();
        self.constraints.corner_contacts.clear();
        self.constraints.rigid_proxies.clear();
    }

    /// The impulse (N s) and angular impulse about the centre of mass (N m s) the body gave each
    /// rigid body it touches or is attached to over the last step, not yet handed to rapier (see
    /// [`DeformableBody::transfer_contact_impulses`]).
    pub fn rigid_impulses(&self) -> impl Iterator<Item = (RigidBodyHandle, DVec3, DVec3)> + '_ {
        self.constraints
            .rigid_proxies
            .iter()
            .map(|proxy| (proxy.handle, proxy.impulse, proxy.angular_impulse))
    }

    /// Hands the impulses the contacts of the last step gave rigid bodies to rapier's set (the
    /// opposite of what the soft body received), and forgets them.
    pub fn transfer_contact_impulses(&mut self, bodies: &mut RigidBodySet) {
        for proxy in &mut self.constraints.rigid_proxies {
            proxy.transfer(bodies);
            proxy.impulse = DVec3::ZERO;
            proxy.angular_impulse = DVec3::ZERO;
        }
    }

    /// Each contact's collider, the point (m) it acts at, and the mean force (N) it exerted on
    /// the collider over the last step of `dt` (s): node contacts at their points' end-of-step
    /// positions, rigid vertices at the vertices; nodes first, then vertices, in order.
    fn forces_on_colliders(
        &self,
        dt: f64,
    ) -> impl Iterator<Item = (ColliderHandle, DVec3, DVec3)> + '_ {
        let from_nodes = self
            .constraints
            .contacts
            .iter()
            .filter_map(move |c| match c.target {
                ContactTarget::Collider(collider) => {
                    let at = c.at.stencil(self.embedding.as_ref());
                    Some((collider, at.interpolate(&self.positions), -c.impulse / dt))
                }
                ContactTarget::OwnSurface { .. } => None,
            });
        let from_corners = self.constraints.corner_contacts.iter().map(move |c| {
            let (at, force) = c.force_on_collider(dt);
            (c.collider, at, force)
        });
        from_nodes.chain(from_corners)
    }

    /// The impulse (N s) and angular impulse about the world origin (N m s) the body's contacts
    /// gave each collider they touch over the last step (see
    /// [`DeformableBody::contact_force_on`]), one entry per collider.
    pub(crate) fn collider_impulses(&self) -> Vec<(ColliderHandle, DVec3, DVec3)> {
        let mut totals: Vec<(ColliderHandle, DVec3, DVec3)> = Vec::new();
        for (collider, at, impulse) in self.forces_on_colliders(1.0) {
            let angular = at.cross(impulse);
            match totals.iter_mut().find(|(c, _, _)| *c == collider) {
                Some((_, total, total_angular)) => {
                    *total += impulse;
                    *total_angular += angular;
                }
                None => totals.push((collider, impulse, angular)),
            }
        }
        totals
    }

    /// The mean force (N) and torque about the world origin (N m) the soft body's contacts
    /// exerted on `collider` over the last step, of length `dt` (s): their impulses over `dt`
    /// (the torque taken at the nodes' end-of-step positions, and at the collider's vertices for
    /// its corners pressing on the surface). In an
    /// [`FvmWorld`](crate::world::FvmWorld) the last step is the frame's last coupling substep.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `dt`.
    pub fn contact_force_on(
        &self,
        collider: ColliderHandle,
        dt: f64,
    ) -> Result<(DVec3, DVec3), Error> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidTimeStep {
                dt,
                reason: "must be positive and finite",
            });
        }
        Ok(self
            .forces_on_colliders(dt)
            .filter(|(touched, _, _)| *touched == collider)
            .fold(
                (DVec3::ZERO, DVec3::ZERO),
                |(force, torque), (_, at, on_collider)| {
                    (force + on_collider, torque + at.cross(on_collider))
                },
            ))
    }
}

/// A collider as one detection sees it.
pub(super) struct NearCollider<'a> {
    /// Its handle.
    pub(super) handle: ColliderHandle,
    /// Its shape and pose.
    pub(super) shape: &'a SharedShape,
    pub(super) pose: &'a Pose,
    /// Its rigid body, if it has one.
    parent: Option<(RigidBodyHandle, &'a RigidBody)>,
    /// How far (m) from its surface a point gets a contact.
    pub(super) reach: f64,
    /// Its bounding box (m).
    bounds: (DVec3, DVec3),
    /// The body's nodes glued to its rigid body, which do not touch it.
    pub(super) glued: Vec<u32>,
    /// The contact's combined coefficients.
    pub(super) coefficients: Coefficients,
}

impl NearCollider<'_> {
    /// The index in `proxies` of the proxy of its body (added if new), for a step of `dt` (s);
    /// `None` for a collider without a body.
    fn proxy_in(&self, proxies: &mut Vec<RigidProxy>, dt: f64) -> Option<usize> {
        self.parent
            .map(|(handle, body)| RigidProxy::index_in(proxies, handle, body, dt))
    }

    /// Whether its bounding box, widened by the reach, overlaps the box `(lo, hi)` (m).
    fn overlaps(&self, (lo, hi): (DVec3, DVec3)) -> bool {
        let reach = DVec3::splat(self.reach);
        let (own_lo, own_hi) = self.bounds;
        !((own_hi + reach).cmplt(lo).any() || (own_lo - reach).cmpgt(hi).any())
    }
}

/// The most (m) a rigid collider's own motion widens the detection reach (a body flung across
/// the world in one frame would otherwise make every node a candidate).
pub(super) const MAX_COLLIDER_REACH: f64 = 1.0;

/// Below this distance (m) from a surface, the offset of a node from its projection is f32
/// round-off and gives no direction.
pub(super) const ROUND_OFF_DISTANCE: f64 = 1e-6;
/// How far (m) outside a surface the normal of a node lying on it is probed.
pub(super) const PROBE_DISTANCE: f64 = 1e-4;

/// The point of a shape's surface (at `pose`) nearest to `x` (m), the outward normal there, and
/// the signed distance of `x` (negative inside); `None` where the normal is undefined.
pub(super) fn nearest_surface_point(
    shape: &dyn Shape,
    pose: &Pose,
    x: DVec3,
) -> Option<(DVec3, DVec3, f64)> {
    let (projection, feature) = shape.project_point_and_get_feature(pose, x.as_vec3());
    let point = projection.point.as_dvec3();
    let local = pose.inverse_transform_point(projection.point);
    let feature_normal = shape
        .feature_normal_at_point(projection.subshape, feature, local)
        .map(|n| (pose.rotation * n).as_dvec3());
    let offset = x - point;
    let sign = if projection.is_inside { -1.0 } else { 1.0 };
    // The feature's normal where parry has one (balls, cuboids, convex shapes, meshes), the
    // plane's for half-spaces, else the direction from the surface point to the node; a node
    // exactly on such a surface has no defined normal.
    let normal = match (feature_normal, shape.as_halfspace()) {
        (Some(n), _) if n.is_finite() && n.length() > 0.5 => n.normalize(),
        (_, Some(half_space)) => (pose.rotation * half_space.normal).as_dvec3().normalize(),
        _ if offset.length() > ROUND_OFF_DISTANCE => offset.normalize() * sign,
        _ => {
            // On the surface, where the offset is f32 round-off: probe a little outward from
            // the shape's origin (exact for convex shapes) and take the normal there.
            let outward = (x - pose.translation.as_dvec3()).normalize_or_zero();
            let probe = x + outward * PROBE_DISTANCE;
            let projected = shape.project_point(pose, probe.as_vec3(), false);
            let offset = probe - projected.point.as_dvec3();
            if projected.is_inside || offset.length() <= ROUND_OFF_DISTANCE {
                return None;
            }
            offset.normalize()
        }
    };
    Some((point, normal, sign * offset.length()))
}
