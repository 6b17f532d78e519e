//! Contact of soft bodies with rapier colliders, with themselves (self-contact) and with each
//! other.
//!
//! Detection ([`BodyConstraints::detect_contacts`](crate::constraint::BodyConstraints::detect_contacts)) projects every surface node onto every collider
//! (parry's point projection, which covers all of rapier's shapes) that the node can reach within
//! the coming frame (its body's fastest node, gravity, the collider's own motion, and the fastest
//! other collider or deformable body that can strike the body, which can drive its nodes towards
//! the others), and keeps the nearest surface point and its outward normal as a [`NodeContact`]:
//! a plane the node must stay on the outer side of during the frame. The integrators then enforce
//! the planes:
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
//!   and `k` at least [`ContactSettings::penalty_factor`] times the node's `m/h²` (`h` the effective
//!   step of the whole step the integrator takes, not of its substeps; the node's own mass,
//!   against a fixed collider as against a dynamic rigid body: the body's mass counted in would
//!   make each contact switching on or off a jump of curvature hundreds of times the node's
//!   inertia, and Newton wander between them), whose resting
//!   penetration under a load `w` is `w h²/(factor m)`: micrometres at game steps for a node
//!   carrying its own weight, millimetres for a light node under a heavy body. A step that
//!   leaves a point deeper than [`ContactSettings::resting_depth`] behind a collider's plane
//!   stiffens that contact beyond the depth it started the step at, so that its load holds it
//!   at half that depth, and is solved again; the contact keeps its stiffenings for as long as
//!   it is detected. Friction is the lagged
//!   dissipation potential of incremental potential contact (Li et al. 2020): the normal force
//!   is taken from the penalty at the start of the step, and the node's slip relative to the
//!   surface over the step, `u`, costs `μ λ f(|u|)`, with `f` quadratic below
//!   [`ContactSettings::stiction_speed`] times the step (static friction as a stiff spring) and
//!   linear above (sliding friction of exactly `μ λ`).
//!
//! A collider attached to a rigid body takes the body's motion into account (its velocity at the
//! contact point) and, when the body is dynamic, receives the opposite of every impulse the soft
//! body gets, at the node's position, so that linear and angular momentum are exchanged exactly.
//! Within a soft step the rigid bodies' velocities follow the impulses, and the explicit substeps
//! carry them along at those velocities as they move the nodes, so that a fast body sweeps
//! through the nodes in its path (it does not wait frozen for rapier's step to jump past them);
//! the total impulse is handed to rapier when the step is accepted. A point found inside a
//! collider (rapier's step ends a body where the sweep did not quite take it) is pushed out over
//! the step the contacts were detected for, not within one explicit substep.
//!
//! The vertices of a rigid polyhedral shape (cuboid, convex polyhedron, triangle mesh) and the
//! closest points of a rounded one (ball, capsule, cylinder, cone) also meet the body's boundary
//! triangles as corner contacts, so that a small rigid body cannot pass between the nodes of a
//! coarse mesh.
//!
//! A body with [`DeformableBody::self_contact`] on also gets contacts of its surface nodes with its own
//! boundary triangles away from their neighbourhood, and an [`FvmWorld`](crate::world::FvmWorld)
//! finds the contacts of each soft body's surface nodes with the boundary triangles of the
//! others. Both are solved by the explicit sweeps with the triangle's nodes taking their share of
//! the opposite impulse; soft bodies that touch are stepped together for that.

mod between;
mod corner;
mod detect;
mod entry;
mod joint;
mod node_contact;
mod penalty;
mod self_contact;
mod set;
mod soft_point;
mod stiffening;
mod support;
mod surface_tree;
mod sweep;
mod velocity_constraint;

pub(crate) use between::{BetweenContact, detect_between, prepare_between, solve_between};
pub(crate) use corner::{
    CornerContact, CornerPlace, advance_corners, corner_penalty_energy, for_each_corner_stencil,
    for_each_corner_term, lag_corner_friction, prepare_corners, record_corner_impulses,
    solve_corners,
};
use detect::nearest_surface_point;
pub(crate) use detect::{
    ColliderView, collider_impulses, contact_point_positions, detect, force_on_collider,
};
pub(crate) use joint::JointContacts;
use node_contact::Obstacle;
pub use node_contact::{BodyPoint, ContactTarget, NodeContact};
pub(crate) use penalty::{
    NodeSlices, for_each_contact_stencil, for_each_contact_term, for_each_engaged_term,
    lag_friction, penalty_tangent, record_penalty_impulses, stiffen_deep_contacts,
};
pub(crate) use self_contact::detect_self_contacts;
pub(crate) use set::ContactSet;
use soft_point::SoftPoint;
pub(crate) use surface_tree::{KeptTree, nearest_point_on_triangle};
use sweep::partners;
pub(crate) use sweep::{advance_planes, prepare_velocities, solve_velocities};
pub use velocity_constraint::RESTITUTION_THRESHOLD;
pub(crate) use velocity_constraint::{ContactSides, Depenetration, VelocityConstraint};

use crate::Error;
use crate::body::DeformableBody;
use crate::rigid::RigidProxy;
use rapier3d::dynamics::CoefficientCombineRule;

/// An implicit step as the contact and attachment terms see it.
#[derive(Clone, Copy)]
pub(crate) struct ImplicitStep<'a> {
    /// The effective step `ĥ` (s): friction's stick length uses it.
    pub(crate) effective: f64,
    /// The step (s) whose `m/h²` the penalties and the attachments' springs take: the effective
    /// step's share of the whole step the integrator was given (a coupling substep, or the
    /// frame), whatever number of substeps it cuts that into. A stiffness that followed the
    /// substeps would jump when their number changes (a body's spin, a refined frame), and a
    /// spring holding a load releases `½ (1/k₁ − 1/k₂) f²` at each jump (a rope glued to a
    /// swinging ball gained 1.8e-3 J in a frame so).
    pub(crate) penalty_step: f64,
    /// The step's length `h` (s): rigid bodies carry their colliders, vertices and anchors over
    /// it at their velocity.
    pub(crate) length: f64,
    /// The rigid bodies the body touches, at the velocities the step's solve gives them.
    pub(crate) rigid: &'a [RigidProxy],
    /// Whether only the terms acting against a dynamic rigid body are wanted (the rigid bodies'
    /// response, solved many times per step, needs no others): the rest are skipped unevaluated.
    pub(crate) partners_only: bool,
}

impl ImplicitStep<'_> {
    /// Whether a term whose rigid partner is `partner` is skipped (see
    /// [`ImplicitStep::partners_only`]).
    pub(crate) fn skips<T>(&self, partner: &Option<T>) -> bool {
        self.partners_only && partner.is_none()
    }
}

/// How contacts are detected and enforced.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct ContactSettings {
    /// Nodes within this distance (m) of a collider, beyond the distance they can travel in the
    /// frame, get a contact.
    pub margin: f64,
    /// The implicit penalty stiffness in units of a node's `m/h²` (dimensionless): the least
    /// stiffness of a contact, which its load raises (see [`ContactSettings::resting_depth`]).
    pub penalty_factor: f64,
    /// The deepest (m) an implicit step leaves a point behind its contact plane with a collider
    /// (or a collider's corner behind a soft face) before the contact's penalty stiffens: a
    /// contact whose load presses it deeper is stiffened beyond the depth the step started it
    /// at, so that the load is held at half this depth (a point that started deeper is held
    /// short of where it ended), and the step is solved again; the contact keeps its
    /// stiffenings while it is detected in later frames. A stiffening acts only beyond the
    /// step's start, so it never changes the energy a point holds there (see
    /// `contact::stiffening`).
    pub resting_depth: f64,
    /// The most speed (m/s) at which explicit contacts push a node found inside a collider back
    /// out (it entered between detections, e.g. pushed by a rigid body that moved): an impulse,
    /// so that momentum stays exchanged exactly, rather than a jump of position. A node leaves at
    /// the speed that takes it out over the step the contacts were detected for (a coupling
    /// substep in [`SoftCoupling`](crate::coupling::SoftCoupling)), up to this one.
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
            resting_depth: 1e-3,
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
        if !(self.resting_depth.is_finite() && self.resting_depth > 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "resting_depth",
                value: self.resting_depth,
                reason: "must be positive and finite (m)",
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
