//! Contact of soft bodies with rapier colliders, with themselves (self-contact) and with each
//! other.
//!
//! Detection ([`DeformableBody::detect_contacts`]) projects every surface node onto every collider
//! (parry's point projection, which covers all of rapier's shapes) that the node can reach within
//! the coming frame, and keeps the nearest surface point and its outward normal as a
//! [`NodeContact`]: a plane the node must stay on the outer side of during the frame. The
//! integrators then enforce the planes:
//!
//! - [`SymplecticEuler`](crate::integrate::SymplecticEuler), at every substep, as velocity
//!   constraints: a node's normal velocity is raised so that it does not cross its plane within
//!   the substep (an inelastic, speculative contact), and its tangential velocity is reduced by a
//!   friction impulse of at most the collider's friction coefficient times the normal impulse
//!   (Coulomb friction). The impulses are accumulated and clamped over
//!   [`ContactSettings::velocity_iterations`] sweeps when dynamic rigid bodies couple the
//!   contacts (sequential impulses, as rapier's own solver).
//! - [`ImplicitIntegrator`](crate::integrate::ImplicitIntegrator), as a stiff penalty in the
//!   incremental potential, `k/2 min(0, g)²` per contact with `g` the signed distance to the plane
//!   and `k` [`ContactSettings::penalty_factor`] times the node's `m/h²`: the resting penetration
//!   under a load `w` is `w h²/(factor m)`, micrometres at game steps. Friction is the lagged
//!   dissipation potential of incremental potential contact (Li et al. 2020): the normal force
//!   is taken from the penalty at the start of the step, and the node's slip relative to the
//!   surface over the step, `u`, costs `μ λ f(|u|)`, with `f` quadratic below
//!   [`ContactSettings::stiction_speed`] times the step (static friction as a stiff spring) and
//!   linear above (sliding friction of exactly `μ λ`).
//!
//! A collider attached to a rigid body takes the body's motion into account (its velocity at the
//! contact point) and, when the body is dynamic, receives the opposite of every impulse the soft
//! body gets, at the node's position, so that linear and angular momentum are exchanged exactly.
//! Within a soft step the rigid bodies are frozen in pose and their velocities follow the
//! impulses; the total is handed to rapier when the step is accepted.

//!
//! A body with [`DeformableBody::self_contact`] on also gets contacts of its surface nodes with its own
//! boundary triangles away from their neighbourhood, and an [`FvmWorld`](crate::world::FvmWorld)
//! finds the contacts of each soft body's surface nodes with the boundary triangles of the
//! others. Both are solved by the explicit sweeps with the triangle's nodes taking their share of
//! the opposite impulse; soft bodies that touch are stepped together for that.

mod between;
mod corner;
mod rigid;
mod self_contact;
mod soft_point;
mod surface_tree;
mod velocity_constraint;

pub(crate) use between::{BetweenContact, detect_between, prepare_between, solve_between};
pub(crate) use corner::{CornerContact, advance_corners, prepare_corners, solve_corners};
pub(crate) use rigid::{RigidProxy, coming_velocity};
pub(crate) use soft_point::Stencil;
use soft_point::{SoftPoint, node_inverse_mass};
pub use velocity_constraint::RESTITUTION_THRESHOLD;
pub(crate) use velocity_constraint::{ContactSides, VelocityConstraint};

use crate::Error;
use crate::body::DeformableBody;
use crate::embedding::Embedding;
use rapier3d::dynamics::{CoefficientCombineRule, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderHandle, ColliderSet, Shape, SharedShape};
use rapier3d::glamx::{DMat3, DVec3};
use rapier3d::math::Pose;

/// How contacts are detected and enforced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSettings {
    /// Nodes within this distance (m) of a collider, beyond the distance they can travel in the
    /// frame, get a contact.
    pub margin: f64,
    /// The implicit penalty stiffness in units of a node's `m/h²` (dimensionless).
    pub penalty_factor: f64,
    /// The speed (m/s) at which explicit contacts push a node found inside a collider back out
    /// (it entered between detections, e.g. pushed by a rigid body that moved): an impulse, so
    /// that momentum stays exchanged exactly, rather than a jump of position.
    pub depenetration_speed: f64,
    /// Sweeps per explicit substep over the contacts and attachments of a body touching dynamic
    /// rigid bodies (at least 1): they are coupled through each rigid body's velocity, and a
    /// single sweep leaves it rocking on its supports. Contacts with fixed and kinematic bodies
    /// are independent and take one sweep.
    pub velocity_iterations: u32,
    /// Implicit friction: the slip speed (m/s) below which a contact sticks elastically rather
    /// than slides; a stuck node creeps at most at this speed, times the ratio of its friction
    /// force to its friction limit.
    pub stiction_speed: f64,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            margin: 1e-3,
            penalty_factor: 1e3,
            depenetration_speed: 0.1,
            velocity_iterations: 4,
            stiction_speed: 1e-4,
        }
    }
}

/// A surface's friction and restitution coefficients and how each combines with another's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SurfaceCoefficients {
    friction: f32,
    friction_rule: CoefficientCombineRule,
    restitution: f32,
    restitution_rule: CoefficientCombineRule,
}

impl SurfaceCoefficients {
    /// A soft body's.
    pub(crate) fn of_body(body: &DeformableBody) -> Self {
        Self {
            friction: body.friction as f32,
            friction_rule: body.friction_combine_rule,
            restitution: body.restitution as f32,
            restitution_rule: body.restitution_combine_rule,
        }
    }

    /// A collider's.
    pub(crate) fn of_collider(collider: &rapier3d::geometry::Collider) -> Self {
        Self {
            friction: collider.friction(),
            friction_rule: collider.friction_combine_rule(),
            restitution: collider.restitution(),
            restitution_rule: collider.restitution_combine_rule(),
        }
    }

    /// The coefficients of a contact between the two surfaces: each pair combined by the
    /// stronger of the two rules, as rapier combines two colliders'.
    pub(crate) fn combine(self, other: Self) -> Coefficients {
        let combine =
            |a, b, rule_a, rule_b| f64::from(CoefficientCombineRule::combine(a, b, rule_a, rule_b));
        Coefficients {
            friction: combine(
                self.friction,
                other.friction,
                self.friction_rule,
                other.friction_rule,
            ),
            restitution: combine(
                self.restitution,
                other.restitution,
                self.restitution_rule,
                other.restitution_rule,
            ),
        }
    }
}

/// A contact's Coulomb friction and restitution coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Coefficients {
    pub(crate) friction: f64,
    pub(crate) restitution: f64,
}

/// What a node's contact pushes against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactTarget {
    /// A rapier collider.
    Collider(ColliderHandle),
    /// A triangle of the body's own boundary, far from the node in the rest shape
    /// (self-contact; see [`DeformableBody::self_contact`]).
    OwnSurface {
        /// The triangle's nodes.
        triangle: [u32; 3],
    },
}

/// Where on a soft body a contact acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyPoint {
    /// A simulation node.
    Node(u32),
    /// A vertex of the body's embedded mesh ([`DeformableBody::embedding`]), which moves with the nodes
    /// of the element it lies in and shares its impulses among them by their weights.
    Embedded(u32),
}

impl BodyPoint {
    /// The nodes the point moves with and their weights; `embedding` is the body's, which every
    /// embedded point comes from.
    fn stencil<'a>(&'a self, embedding: Option<&'a Embedding>) -> Stencil<'a> {
        match self {
            Self::Node(node) => Stencil {
                nodes: std::slice::from_ref(node),
                weights: &[1.0],
            },
            Self::Embedded(vertex) => embedding
                .expect("embedded contact points are only made for a body with an embedding")
                .point_stencil(*vertex),
        }
    }
}

/// A surface point's contact for the coming frame: the plane through `point` with outward normal
/// `normal` that the point (a surface node, or a surface vertex of the body's embedded mesh) must
/// not cross. Against a collider, the explicit integrator re-projects
/// the node onto the collider's shape (at its pose when detected) every substep to update the
/// plane; against a triangle of the body's own surface the plane follows the triangle.
#[derive(Clone)]
pub struct NodeContact {
    /// The point of the soft body in contact.
    pub at: BodyPoint,
    /// What it touches.
    pub target: ContactTarget,
    /// The nearest point of the target's surface to the node when detected (m).
    pub point: DVec3,
    /// The target's outward unit normal there.
    pub normal: DVec3,
    /// Coulomb friction coefficient: the body's and the target's, combined by their rules.
    pub friction: f64,
    /// Restitution coefficient: the body's and the target's, combined by their rules (see
    /// [`RESTITUTION_THRESHOLD`]).
    pub restitution: f64,
    /// The impulse (N s) the contact gave the node over the last step.
    pub impulse: DVec3,
    /// The far side of the contact, as the velocity constraints see it.
    obstacle: Obstacle,
    /// Within an explicit substep: the velocity constraint.
    constraint: VelocityConstraint,
    /// Within an implicit step: the normal force (N) friction is limited by, and the node's
    /// position and the surface's velocity there at the start of the step (m, m/s).
    lagged_normal_force: f64,
    slip_origin: DVec3,
    surface_velocity: DVec3,
}

/// The far side of a contact.
#[derive(Clone)]
enum Obstacle {
    /// A collider's shape at its pose, and its rigid body's index among the body's proxies, if it
    /// has one.
    Collider {
        shape: SharedShape,
        pose: Pose,
        proxy: Option<usize>,
    },
    /// The contact point of a triangle of the body's own surface.
    OwnTriangle(SoftPoint),
}

impl std::fmt::Debug for NodeContact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NodeContact")
            .field("at", &self.at)
            .field("target", &self.target)
            .field("point", &self.point)
            .field("normal", &self.normal)
            .field("friction", &self.friction)
            .field("impulse", &self.impulse)
            .finish_non_exhaustive()
    }
}

impl NodeContact {
    /// A contact of `at` with `target` through the plane at `point` (m) with outward unit
    /// `normal`, with `coefficients`, enforced against `obstacle`.
    fn new(
        at: BodyPoint,
        target: ContactTarget,
        point: DVec3,
        normal: DVec3,
        coefficients: Coefficients,
        obstacle: Obstacle,
    ) -> Self {
        Self {
            at,
            target,
            point,
            normal,
            friction: coefficients.friction,
            restitution: coefficients.restitution,
            impulse: DVec3::ZERO,
            obstacle,
            constraint: VelocityConstraint::default(),
            lagged_normal_force: 0.0,
            slip_origin: DVec3::ZERO,
            surface_velocity: DVec3::ZERO,
        }
    }

    /// Whether the implicit integrator enforces the contact: those with colliders (it leaves
    /// self-contact to the explicit integrator).
    fn is_implicit(&self) -> bool {
        matches!(self.obstacle, Obstacle::Collider { .. })
    }

    /// Signed distance (m) of position `x` from the contact plane, negative inside.
    pub fn gap(&self, x: DVec3) -> f64 {
        (x - self.point).dot(self.normal)
    }

    /// The penalty stiffness (N/m) and gap (m) of the contact's node at `x` (m), of mass `mass`
    /// (kg), in an implicit step of effective length `h` (s); `None` outside its plane.
    fn penalty(
        &self,
        x: DVec3,
        mass: f64,
        settings: &ContactSettings,
        h: f64,
    ) -> Option<(f64, f64)> {
        let gap = self.gap(x);
        (gap < 0.0).then(|| (settings.penalty_stiffness(mass, h), gap))
    }

    /// The lagged friction dissipation of the node at `x` (m) over an implicit step of effective
    /// length `h` (s): its energy `μ λ f(|u|)` (J), force (N) and positive semi-definite tangent
    /// (N/m), where `u` is the slip relative to the surface in the contact plane and
    /// `f(s) = s²/2ε` below `ε = stiction_speed h`, `s - ε/2` above; `None` without a friction
    /// limit.
    fn friction_term(
        &self,
        x: DVec3,
        settings: &ContactSettings,
        h: f64,
    ) -> Option<(f64, DVec3, DMat3)> {
        let limit = self.friction * self.lagged_normal_force;
        if limit <= 0.0 {
            return None;
        }
        let plane = DMat3::IDENTITY - penalty_tangent(1.0, self.normal);
        let slip = plane * (x - self.slip_origin - self.surface_velocity * h);
        let (s, stick) = (slip.length(), settings.stiction_speed * h);
        Some(if s < stick {
            (
                limit * s * s / (2.0 * stick),
                -slip * (limit / stick),
                plane * (limit / stick),
            )
        } else {
            let direction = slip / s;
            (
                limit * (s - stick / 2.0),
                -direction * limit,
                (plane - penalty_tangent(1.0, direction)) * (limit / s),
            )
        })
    }

    /// Moves the plane to the collider's surface point nearest to `x` (m), if defined there, or
    /// to an own triangle's contact point where its nodes are now (`positions`, m).
    fn refresh(&mut self, x: DVec3, positions: &[DVec3]) {
        match &self.obstacle {
            Obstacle::Collider { shape, pose, .. } => {
                if let Some((point, normal, _)) = nearest_surface_point(&**shape, pose, x) {
                    self.point = point;
                    self.normal = normal;
                }
            }
            Obstacle::OwnTriangle(point) => {
                if let Some((point, normal)) = point.plane(positions) {
                    self.point = point;
                    self.normal = normal;
                }
            }
        }
    }
}

impl ContactSettings {
    /// The implicit penalty stiffness (N/m) on a node of mass `mass` (kg) for an effective step
    /// `h` (s): `penalty_factor m/h²`. Attachments' springs use it too.
    pub(crate) fn penalty_stiffness(&self, mass: f64, h: f64) -> f64 {
        self.penalty_factor * mass / (h * h)
    }

    fn check(&self) -> Result<(), Error> {
        if !(self.margin.is_finite() && self.margin >= 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "margin",
                value: self.margin,
                reason: "must be non-negative and finite (m)",
            });
        }
        if !(self.depenetration_speed.is_finite() && self.depenetration_speed >= 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "depenetration_speed",
                value: self.depenetration_speed,
                reason: "must be non-negative and finite (m/s)",
            });
        }
        if !(self.stiction_speed.is_finite() && self.stiction_speed > 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "stiction_speed",
                value: self.stiction_speed,
                reason: "must be positive and finite (m/s)",
            });
        }
        if !(self.penalty_factor.is_finite() && self.penalty_factor > 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "penalty_factor",
                value: self.penalty_factor,
                reason: "must be positive and finite",
            });
        }
        Ok(())
    }
}

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
        crate::integrate::check_step(frame_dt, gravity)?;
        settings.check()?;
        let mut contacts = Vec::new();
        let mut proxies: Vec<RigidProxy> = Vec::new();
        // Elastic waves can speed a node up within the frame: reach as far as the body's fastest
        // node, twice over.
        let reach = settings.margin
            + 2.0 * (self.fastest_node_speed() + gravity.length() * frame_dt) * frame_dt;
        let (body_lo, body_hi) = self.position_bounds();
        let mut tree = None;
        let mut corners = Vec::new();
        let contact_points = self.contact_points();
        for (handle, collider) in colliders.iter() {
            if collider.is_sensor() || !self.collision_groups.test(collider.collision_groups()) {
                continue;
            }
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
            let reach = reach + collider_reach.min(MAX_COLLIDER_REACH);
            let (lo, hi) = (aabb.mins.as_dvec3(), aabb.maxs.as_dvec3());
            let (shape, pose) = (collider.shared_shape(), collider.position());
            let glued: Vec<u32> = self
                .attachments
                .iter()
                .filter(|a| Some(a.body) == collider.parent())
                .map(|a| a.node)
                .collect();
            let coefficients = SurfaceCoefficients::of_body(self)
                .combine(SurfaceCoefficients::of_collider(collider));
            let mut proxy = None;
            for &at in &contact_points {
                let stencil = at.stencil(self.embedding.as_ref());
                // A point that cannot move, or moves with a node glued to the collider's body.
                if stencil.nodes.iter().all(|&n| self.pinned[n as usize])
                    || stencil.nodes.iter().any(|n| glued.contains(n))
                {
                    continue;
                }
                let x = stencil.interpolate(&self.positions);
                if (x + DVec3::splat(reach)).cmplt(lo).any()
                    || (x - DVec3::splat(reach)).cmpgt(hi).any()
                {
                    continue;
                }
                if let Some((point, normal, distance)) = nearest_surface_point(&**shape, pose, x)
                    && distance <= reach
                {
                    if proxy.is_none()
                        && let Some((handle, body)) = parent
                    {
                        proxy = Some(RigidProxy::index_in(&mut proxies, handle, body, frame_dt));
                    }
                    contacts.push(NodeContact::new(
                        at,
                        ContactTarget::Collider(handle),
                        point,
                        normal,
                        coefficients,
                        Obstacle::Collider {
                            shape: shape.clone(),
                            pose: *pose,
                            proxy,
                        },
                    ));
                }
            }
            let near_body = !((hi + DVec3::splat(reach)).cmplt(body_lo).any()
                || (lo - DVec3::splat(reach)).cmpgt(body_hi).any());
            if near_body && corner::has_vertices(&**shape) {
                let tree = tree.get_or_insert_with(|| surface_tree::SurfaceTree::of(self));
                let mut found = self.find_corner_contacts(
                    tree,
                    handle,
                    &**shape,
                    pose,
                    coefficients,
                    reach,
                    &glued,
                );
                if !found.is_empty()
                    && let Some((handle, body)) = parent
                {
                    let proxy = proxy.unwrap_or_else(|| {
                        RigidProxy::index_in(&mut proxies, handle, body, frame_dt)
                    });
                    for contact in &mut found {
                        contact.proxy = Some(proxy);
                    }
                }
                corners.extend(found);
            }
        }
        self.corner_contacts = corners;
        crate::attachment::ready(&mut self.attachments, &mut proxies, bodies, frame_dt);
        self.contacts = contacts;
        self.rigid_proxies = proxies;
        if self.self_contact {
            self.detect_self_contacts(reach);
        }
        self.contact_settings = *settings;
        Ok(&self.contacts)
    }

    /// The points contacts with colliders are detected for: the surface vertices of the
    /// embedded mesh if the body has one, else its surface nodes.
    fn contact_points(&self) -> Vec<BodyPoint> {
        match &self.embedding {
            Some(embedding) => embedding
                .surface_vertices()
                .iter()
                .map(|&v| BodyPoint::Embedded(v))
                .collect(),
            None => self
                .surface_nodes
                .iter()
                .map(|&n| BodyPoint::Node(n))
                .collect(),
        }
    }

    /// The contacts found by the last [`DeformableBody::detect_contacts`].
    pub fn contacts(&self) -> &[NodeContact] {
        &self.contacts
    }

    /// Removes every contact.
    pub fn clear_contacts(&mut self) {
        self.contacts.clear();
        self.corner_contacts.clear();
        self.rigid_proxies.clear();
    }

    /// The impulse (N s) and angular impulse about the centre of mass (N m s) the body gave each
    /// rigid body it touches or is attached to over the last step, not yet handed to rapier (see
    /// [`DeformableBody::transfer_contact_impulses`]).
    pub fn rigid_impulses(&self) -> impl Iterator<Item = (RigidBodyHandle, DVec3, DVec3)> + '_ {
        self.rigid_proxies
            .iter()
            .map(|proxy| (proxy.handle, proxy.impulse, proxy.angular_impulse))
    }

    /// Hands the impulses the contacts of the last step gave rigid bodies to rapier's set (the
    /// opposite of what the soft body received), and forgets them.
    pub fn transfer_contact_impulses(&mut self, bodies: &mut RigidBodySet) {
        for proxy in &mut self.rigid_proxies {
            proxy.transfer(bodies);
            proxy.impulse = DVec3::ZERO;
            proxy.angular_impulse = DVec3::ZERO;
        }
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
        let from_nodes = self
            .contacts
            .iter()
            .filter(|c| c.target == ContactTarget::Collider(collider))
            .map(|c| {
                let at = c.at.stencil(self.embedding.as_ref());
                (at.interpolate(&self.positions), -c.impulse / dt)
            });
        let from_corners = self
            .corner_contacts
            .iter()
            .filter(|c| c.collider == collider)
            .map(|c| c.force_on_collider(dt));
        Ok(from_nodes.chain(from_corners).fold(
            (DVec3::ZERO, DVec3::ZERO),
            |(force, torque), (at, on_collider)| {
                (force + on_collider, torque + at.cross(on_collider))
            },
        ))
    }
}

/// The most (m) a rigid collider's own motion widens the detection reach (a body flung across
/// the world in one frame would otherwise make every node a candidate).
const MAX_COLLIDER_REACH: f64 = 1.0;

/// Below this distance (m) from a surface, the offset of a node from its projection is f32
/// round-off and gives no direction.
const ROUND_OFF_DISTANCE: f64 = 1e-6;
/// How far (m) outside a surface the normal of a node lying on it is probed.
const PROBE_DISTANCE: f64 = 1e-4;

/// The point of a shape's surface (at `pose`) nearest to `x` (m), the outward normal there, and
/// the signed distance of `x` (negative inside); `None` where the normal is undefined.
fn nearest_surface_point(shape: &dyn Shape, pose: &Pose, x: DVec3) -> Option<(DVec3, DVec3, f64)> {
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

/// What a body's contacts push against, as the sweeps see it: the rigid bodies' proxies and the
/// body's own nodes (the contacts' nodes and self-contact triangles).
struct Partners<'a> {
    rigid: &'a mut [RigidProxy],
    velocities: &'a mut [DVec3],
    masses: &'a [f64],
    pinned: &'a [bool],
}

impl Partners<'_> {
    /// Velocity (m/s) of the obstacle's material point at `x` (m): zero for a fixed collider.
    fn velocity_at(&self, obstacle: &Obstacle, x: DVec3) -> DVec3 {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                proxy.map_or(DVec3::ZERO, |p| self.rigid[p].velocity_at(x))
            }
            Obstacle::OwnTriangle(point) => point.velocity(self.velocities),
        }
    }

    /// The obstacle's inverse effective mass (1/kg) at `x` (m) along unit `direction`.
    fn inverse_mass_along(&self, obstacle: &Obstacle, x: DVec3, direction: DVec3) -> f64 {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                proxy.map_or(0.0, |p| self.rigid[p].inverse_mass_along(x, direction))
            }
            Obstacle::OwnTriangle(point) => point.inverse_mass(self.masses, self.pinned),
        }
    }

    /// Gives the obstacle `impulse` (N s) at `x` (m): the opposite of what its node received.
    fn apply(&mut self, obstacle: &Obstacle, impulse: DVec3, x: DVec3) {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                if let Some(p) = *proxy {
                    self.rigid[p].apply(impulse, x);
                }
            }
            Obstacle::OwnTriangle(point) => {
                point.apply(impulse, self.velocities, self.masses, self.pinned);
            }
        }
    }
}

/// Splits `body` into its contacts, its positions, its embedded mesh and what the contacts push
/// against.
fn contacts_and_partners(
    body: &mut DeformableBody,
) -> (
    &mut [NodeContact],
    &[DVec3],
    Option<&Embedding>,
    Partners<'_>,
) {
    let DeformableBody {
        contacts,
        rigid_proxies,
        positions,
        velocities,
        masses,
        pinned,
        embedding,
        ..
    } = body;
    (
        contacts,
        positions,
        embedding.as_ref(),
        Partners {
            rigid: rigid_proxies,
            velocities,
            masses,
            pinned,
        },
    )
}

/// Whether the body's contact constraints are coupled to each other (through a dynamic rigid
/// body's velocity or the nodes of a self-contact triangle), so that one sweep does not solve
/// them.
pub(crate) fn constraints_coupled(body: &DeformableBody) -> bool {
    body.rigid_proxies.iter().any(RigidProxy::is_dynamic) || body.needs_explicit_contacts()
}

impl DeformableBody {
    /// Whether the last detection found self-contacts or rigid corners against the surface,
    /// which only the explicit integrator solves.
    pub(crate) fn needs_explicit_contacts(&self) -> bool {
        !self.corner_contacts.is_empty()
            || self
                .contacts
                .iter()
                .any(|c| matches!(c.obstacle, Obstacle::OwnTriangle(_)))
    }
}

/// Readies the contacts' velocity constraints for an explicit substep of `h` (s), before the
/// sweeps of [`solve_velocities`]: each plane moves to the collider's surface point nearest to its
/// node, and the lowest normal velocity is set so that the node arrives at the plane but does not
/// cross it within the substep, or, found inside, leaves at most at the depenetration speed.
pub(crate) fn prepare_velocities(body: &mut DeformableBody, h: f64) {
    let depenetration_speed = body.contact_settings.depenetration_speed;
    let (contacts, positions, embedding, mut partners) = contacts_and_partners(body);
    for contact in contacts.iter_mut() {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        contact.refresh(x, positions);
        let gap = contact.gap(x);
        let sides = WithinBody {
            partners: &mut partners,
            obstacle: &contact.obstacle,
            at,
            x,
        };
        let normal = contact.normal;
        contact.constraint = VelocityConstraint::new(gap, h, depenetration_speed).bounce(
            gap,
            h,
            || sides.relative_velocity().dot(normal),
            contact.restitution,
        );
    }
}

/// One sweep over the contacts' velocity constraints (called after the velocity update, before
/// positions move; see [`VelocityConstraint`]). Against a rigid body or an own triangle the
/// velocities are relative, the obstacle's effective mass counts, and the obstacle receives the
/// opposite impulse.
pub(crate) fn solve_velocities(body: &mut DeformableBody) {
    let (contacts, positions, embedding, mut partners) = contacts_and_partners(body);
    for contact in contacts.iter_mut() {
        let point = contact.at;
        let at = point.stencil(embedding);
        let mut sides = WithinBody {
            partners: &mut partners,
            obstacle: &contact.obstacle,
            at,
            x: at.interpolate(positions),
        };
        contact.impulse += contact
            .constraint
            .correct(contact.normal, contact.friction, &mut sides);
    }
}

/// A contact's point and obstacle within one body's sweep.
struct WithinBody<'a, 'b> {
    partners: &'a mut Partners<'b>,
    obstacle: &'a Obstacle,
    at: Stencil<'a>,
    x: DVec3,
}

impl ContactSides for WithinBody<'_, '_> {
    fn relative_velocity(&self) -> DVec3 {
        self.at.interpolate(self.partners.velocities)
            - self.partners.velocity_at(self.obstacle, self.x)
    }

    fn inverse_mass_along(&self, direction: DVec3) -> f64 {
        self.at
            .inverse_mass(self.partners.masses, self.partners.pinned)
            + self
                .partners
                .inverse_mass_along(self.obstacle, self.x, direction)
    }

    fn exchange(&mut self, impulse: DVec3) {
        self.at.apply(
            impulse,
            self.partners.velocities,
            self.partners.masses,
            self.partners.pinned,
        );
        self.partners.apply(self.obstacle, -impulse, self.x);
    }
}

/// The contacts the implicit integrator enforces: those with colliders (it leaves self-contact
/// to the explicit integrator).
fn implicit_contacts(contacts: &mut [NodeContact]) -> impl Iterator<Item = &mut NodeContact> {
    contacts.iter_mut().filter(|c| c.is_implicit())
}

/// Records the impulses (N s) the implicit penalty and friction gave the nodes over a substep of
/// length `h` (s), at the positions that ended it, and hands their opposite to the rigid bodies.
pub(crate) fn record_penalty_impulses(body: &mut DeformableBody, effective_h: f64, h: f64) {
    let settings = body.contact_settings;
    let (contacts, positions, embedding, mut partners) = contacts_and_partners(body);
    for contact in implicit_contacts(contacts) {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        let mut force = contact
            .friction_term(x, &settings, effective_h)
            .map_or(DVec3::ZERO, |(_, force, _)| force);
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        if let Some((stiffness, gap)) = contact.penalty(x, mass, &settings, effective_h) {
            force -= contact.normal * (stiffness * gap);
        }
        let impulse = force * h;
        contact.impulse += impulse;
        partners.apply(&contact.obstacle, -impulse, x);
    }
}

/// Readies implicit friction for a step of effective length `h` (s) from the body's positions:
/// each contact's friction limit is its penalty force there, and slip is measured from there.
pub(crate) fn lag_friction(body: &mut DeformableBody, h: f64) {
    let settings = body.contact_settings;
    let (contacts, positions, embedding, partners) = contacts_and_partners(body);
    for contact in implicit_contacts(contacts) {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        let mass = effective_mass(&at, partners.masses, partners.pinned);
        contact.lagged_normal_force = contact
            .penalty(x, mass, &settings, h)
            .map_or(0.0, |(stiffness, gap)| -stiffness * gap);
        contact.slip_origin = x;
        contact.surface_velocity = partners.velocity_at(&contact.obstacle, x);
    }
}

/// The effective mass (kg) of a contact point: `1 / Σ w² / m` over its free nodes, the node's
/// own mass for a node.
fn effective_mass(at: &Stencil, masses: &[f64], pinned: &[bool]) -> f64 {
    at.inverse_mass(masses, pinned).recip()
}

/// The implicit friction of the contacts for an effective step `h` (s), at the body's positions:
/// calls `each(point, energy (J), force (N), tangent (N/m))` for every contact with a friction
/// limit (see [`lag_friction`]); the force acts on the contact point, so node `a` of its stencil
/// takes `w_a f` and the tangent couples nodes `a, b` by `w_a w_b T`.
pub(crate) fn for_each_friction(
    body: &DeformableBody,
    h: f64,
    mut each: impl FnMut(Stencil, f64, DVec3, DMat3),
) {
    for contact in body.contacts.iter().filter(|c| c.is_implicit()) {
        let at = contact.at.stencil(body.embedding.as_ref());
        if let Some((energy, force, tangent)) =
            contact.friction_term(at.interpolate(&body.positions), &body.contact_settings, h)
        {
            each(at, energy, force, tangent);
        }
    }
}

/// The implicit penalty of the contacts for an effective step `h` (s), at the body's positions:
/// calls `each(point, stiffness k (N/m), gap g (m), normal)` for every contact whose point is
/// inside its plane (`g < 0`); the penalty energy is `Σ k g²/2`, its force on the point `-k g n`
/// (on node `a` of its stencil, `w_a` of it) and its tangent `w_a w_b k n nᵀ`.
pub(crate) fn for_each_active_penalty(
    body: &DeformableBody,
    h: f64,
    mut each: impl FnMut(Stencil, f64, f64, DVec3),
) {
    for contact in body.contacts.iter().filter(|c| c.is_implicit()) {
        let at = contact.at.stencil(body.embedding.as_ref());
        let mass = effective_mass(&at, &body.masses, &body.pinned);
        if let Some((stiffness, gap)) = contact.penalty(
            at.interpolate(&body.positions),
            mass,
            &body.contact_settings,
            h,
        ) {
            each(at, stiffness, gap, contact.normal);
        }
    }
}

/// `k n nᵀ` (N/m).
pub(crate) fn penalty_tangent(stiffness: f64, normal: DVec3) -> DMat3 {
    DMat3::from_cols(normal * normal.x, normal * normal.y, normal * normal.z) * stiffness
}
