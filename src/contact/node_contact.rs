//! A node's contact: the plane `n·(x − p) ≥ 0` through the nearest surface point `p` with
//! outward normal `n` that a surface node (or an embedded surface vertex) must stay on the outer
//! side of, what it pushes against (a collider, or the body's own boundary triangle), and the
//! implicit side's terms on it: the penalty `k/2 min(0, g)²` on the gap `g` and the lagged
//! friction dissipation `μ λ f(|u|)` on the slip `u` over the step.

use super::stiffening::{Penalty, Stiffening};
use super::{
    Coefficients, ContactSettings, SoftPoint, VelocityConstraint, nearest_surface_point,
    penalty_tangent,
};
use crate::embedding::Embedding;
use crate::rigid::RigidProxy;
use crate::stencil::Stencil;
use rapier3d::geometry::{ColliderHandle, Shape, SharedShape};
use rapier3d::glamx::{DMat3, DVec3};
use rapier3d::math::Pose;

/// What a node's contact pushes against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactTarget {
    /// A rapier collider.
    Collider(ColliderHandle),
    /// A triangle of the body's own boundary, far from the node in the rest shape
    /// (self-contact; see [`DeformableBody::self_contact`](crate::body::DeformableBody::self_contact)).
    OwnSurface {
        /// The triangle's nodes.
        triangle: [u32; 3],
    },
}

/// Where on a soft body a contact acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BodyPoint {
    /// A simulation node.
    Node(u32),
    /// A vertex of the body's embedded mesh ([`DeformableBody::embedding`](crate::body::DeformableBody::embedding)), which moves with the nodes
    /// of the element it lies in and shares its impulses among them by their weights.
    Embedded(u32),
}

impl BodyPoint {
    /// The nodes the point moves with and their weights; `embedding` is the body's, which every
    /// embedded point comes from.
    pub(super) fn stencil<'a>(&'a self, embedding: Option<&'a Embedding>) -> Stencil<'a> {
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
/// not cross. Against a collider, the explicit integrator re-projects the node onto the
/// collider's shape every substep to update the plane, the shape where its rigid body has carried
/// it since detection; against a triangle of the body's own surface the plane follows the
/// triangle.
#[derive(Clone, PartialEq)]
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
    /// [`RESTITUTION_THRESHOLD`](super::RESTITUTION_THRESHOLD)).
    pub restitution: f64,
    /// The impulse (N s) the contact gave the node over the last step.
    pub impulse: DVec3,
    /// The far side of the contact, as the velocity constraints see it.
    pub(super) obstacle: Obstacle,
    /// Within an explicit substep: the velocity constraint.
    pub(super) constraint: VelocityConstraint,
    /// Within an implicit step: the normal force (N) friction is limited by, and the node's
    /// position at the start of the step (m).
    pub(super) lagged_normal_force: f64,
    pub(super) slip_origin: DVec3,
    /// Where the point was when the contact was found (m): the next detection's path starts
    /// there (see [`super::entry`]).
    pub(super) detected_at: DVec3,
    /// How deep (m) the point may go behind its plane before it is past the middle of the
    /// collider: half the collider's thickness along the normal there (infinite for a
    /// half-space or an own triangle).
    pub(super) depth_limit: f64,
    /// The stiffenings of the implicit penalty the contact's load has called for (see
    /// [`ContactSettings::resting_depth`]); none until a load presses the point that deep.
    pub(super) stiffening: Stiffening,
}

/// The far side of a contact.
#[derive(Clone)]
pub(super) enum Obstacle {
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

/// Equal obstacles: the same shape (the same shared allocation: a collider whose shape was
/// replaced is another obstacle) at the same pose, or the same triangle point.
impl PartialEq for Obstacle {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Self::Collider { shape, pose, proxy },
                Self::Collider {
                    shape: other_shape,
                    pose: other_pose,
                    proxy: other_proxy,
                },
            ) => {
                std::sync::Arc::ptr_eq(&shape.0, &other_shape.0)
                    && pose == other_pose
                    && proxy == other_proxy
            }
            (Self::OwnTriangle(a), Self::OwnTriangle(b)) => a == b,
            _ => false,
        }
    }
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
    pub(super) fn new(
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
            detected_at: point,
            depth_limit: f64::INFINITY,
            stiffening: Stiffening::default(),
        }
    }

    /// The contact with its collider's rigid body at `proxy` (an index into the body's rigid
    /// proxies), if any.
    pub(super) fn with_proxy(mut self, proxy: Option<usize>) -> Self {
        if let Obstacle::Collider { proxy: slot, .. } = &mut self.obstacle {
            *slot = proxy;
        }
        self
    }

    /// Whether the point, at `x` (m), is further behind its plane than half the collider's
    /// thickness: past the middle of a thin wall, so that a step which ends so is too long for
    /// the penalty to resolve.
    pub(super) fn past_middle(&self, x: DVec3) -> bool {
        -self.gap(x) > self.depth_limit
    }

    /// Signed distance (m) of position `x` from the contact plane, negative inside.
    pub fn gap(&self, x: DVec3) -> f64 {
        (x - self.point).dot(self.normal)
    }

    /// The implicit penalty of the contact's point at `x` (m), of effective mass `mass` (kg), in
    /// an implicit step of effective length `h` (s): the penalty factor times `m/h²`, stiffened
    /// by its load (see [`super::stiffening`]); `None` outside its plane.
    pub(crate) fn penalty(
        &self,
        x: DVec3,
        mass: f64,
        settings: &ContactSettings,
        h: f64,
    ) -> Option<Penalty> {
        (self.stiffening).penalty(settings.penalty_stiffness(mass, h), -self.gap(x))
    }

    /// What the Newton system must add at the point's position `from` (m) for its penalty to be
    /// the quadratic piece that holds at `to` (m), where a Newton step would take it, when that
    /// piece is stiffer than the one at `from` (a point reaching its plane, or passing the depth
    /// of a stiffening): the force (N) and the tangent (N/m) of the difference; effective mass
    /// `mass` (kg), effective step `h` (s).
    pub(crate) fn penalty_towards(
        &self,
        (from, to): (DVec3, DVec3),
        mass: f64,
        settings: &ContactSettings,
        h: f64,
    ) -> Option<(DVec3, DMat3)> {
        let base = settings.penalty_stiffness(mass, h);
        let depths = (-self.gap(from), -self.gap(to));
        let (push, stiffness) = self.stiffening.piece_towards(base, depths)?;
        let here =
            (self.stiffening.penalty(base, depths.0)).map_or((0.0, 0.0), |p| (p.push, p.stiffness));
        (stiffness > here.1).then(|| {
            let tangent = penalty_tangent(stiffness - here.1, self.normal);
            (self.normal * (push - here.0), tangent)
        })
    }

    /// Stiffens the penalty of the point an implicit step of effective length `h` (s) took from
    /// `start` to `end` (m), of effective mass `mass` (kg), when it left it deeper than
    /// [`ContactSettings::resting_depth`] (see [`Stiffening::stiffen`]). Returns whether it
    /// did.
    pub(super) fn stiffen_if_deep(
        &mut self,
        (start, end): (DVec3, DVec3),
        mass: f64,
        settings: &ContactSettings,
        h: f64,
    ) -> bool {
        let depths = (-self.gap(start), -self.gap(end));
        (self.stiffening).stiffen(
            settings.penalty_stiffness(mass, h),
            depths,
            settings.resting_depth,
        )
    }

    /// The lagged friction dissipation of the node at `x` (m) relative to the surface (its
    /// position less the surface's travel over the step) in an implicit step of effective length
    /// `h` (s): its energy `μ λ f(|u|)` (J), force (N) and positive semi-definite tangent (N/m),
    /// where `u` is the slip in the contact plane and `f(s) = s²/2ε` below
    /// `ε = stiction_speed h`, `s - ε/2` above; `None` without a friction limit.
    pub(super) fn friction_term(
        &self,
        x: DVec3,
        settings: &ContactSettings,
        h: f64,
    ) -> Option<(f64, DVec3, DMat3)> {
        let travel = x - self.slip_origin;
        lagged_friction(
            self.friction * self.lagged_normal_force,
            self.normal,
            travel,
            settings.stiction_speed * h,
        )
    }

    /// What the Newton system must add at the point's position `from` (m) for its lagged
    /// friction to be the sticking piece when a Newton step to `to` (m) would carry its slip
    /// through the stick zone (see [`stick_towards`]); the step's effective length `h` (s).
    pub(crate) fn friction_towards(
        &self,
        (from, to): (DVec3, DVec3),
        settings: &ContactSettings,
        h: f64,
    ) -> Option<(DVec3, DMat3)> {
        stick_towards(
            self.friction * self.lagged_normal_force,
            self.normal,
            (from - self.slip_origin, to - self.slip_origin),
            settings.stiction_speed * h,
        )
    }

    /// Moves the plane to the collider's surface point nearest to `x` (m), if defined there and
    /// facing the side the point entered from, or to an own triangle's contact point where its
    /// nodes are now (`positions`, m). A collider is where its rigid body's proxy among `rigid`
    /// has carried it since detection (see [`RigidProxy::carry`]).
    pub(super) fn refresh(&mut self, x: DVec3, positions: &[DVec3], rigid: &[RigidProxy]) {
        match &self.obstacle {
            Obstacle::Collider { shape, pose, proxy } => {
                let motion = proxy.map(|p| &rigid[p]);
                if let Some((point, normal)) = nearest_on_carried(&**shape, pose, motion, x) {
                    // Behind its plane with the nearest face looking the other way: past the
                    // middle of a thin wall, or through it; the plane it entered by stays (see
                    // `super::entry`).
                    let behind = (x - self.point).dot(self.normal) < 0.0;
                    if !(behind && normal.dot(self.normal) < 0.0) {
                        self.point = point;
                        self.normal = normal;
                    }
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

/// The surface point of `shape`, at `pose` when detected and carried since then by `motion` (its
/// rigid body's proxy, if any), nearest to `x` (m), and the outward unit normal there; `None`
/// where the normal is undefined. The point is projected in the collider's pose at detection,
/// which keeps the plane as steady as the node (a pose moved in f32 would jitter the gap by its
/// rounding).
fn nearest_on_carried(
    shape: &dyn Shape,
    pose: &Pose,
    motion: Option<&RigidProxy>,
    x: DVec3,
) -> Option<(DVec3, DVec3)> {
    match motion.filter(|m| m.has_moved()) {
        None => nearest_surface_point(shape, pose, x).map(|(point, normal, _)| (point, normal)),
        Some(motion) => nearest_surface_point(shape, pose, motion.carry_back(x))
            .map(|(point, normal, _)| (motion.carry(point), motion.turn(normal))),
    }
}

/// What a Newton system must add, for a point whose travel relative to the surface over the step
/// is `from` (m), to take its lagged friction (limit `μ λ`, N; see [`lagged_friction`]) as the
/// sticking quadratic `μ λ |u|²/2ε` when the point slides (`|u| ≥ ε = stick`, m) and a Newton
/// step to the travel `to` (m) would carry its slip `u` through the stick zone `|u| < ε`, to rest
/// there or to slide the other way: the difference of the forces (N) and of the tangents (N/m,
/// positive semi-definite: the sticking piece is the stiffer in every direction of the plane of
/// unit `normal`); `None` otherwise.
pub(super) fn stick_towards(
    limit: f64,
    normal: DVec3,
    (from, to): (DVec3, DVec3),
    stick: f64,
) -> Option<(DVec3, DMat3)> {
    let plane = DMat3::IDENTITY - penalty_tangent(1.0, normal);
    let (slip, along) = (plane * from, plane * (to - from));
    let s = slip.length();
    // The point of the slip's path nearest to no slip.
    let nearest =
        (-slip.dot(along) / along.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    if limit <= 0.0 || s < stick || (slip + along * nearest).length() >= stick {
        return None;
    }
    let direction = slip / s;
    let force = direction * (limit * (1.0 - s / stick));
    let sliding = (plane - penalty_tangent(1.0, direction)) * (limit / s);
    Some((force, plane * (limit / stick) - sliding))
}

/// The lagged friction dissipation `μ λ f(|u|)` of a point whose travel relative to the surface
/// over the step is `travel` (m), for the friction limit `μ λ` (N): its energy (J), its force on
/// the point (N) and its positive semi-definite tangent (N/m), with `u` the travel's part in the
/// plane of unit `normal` and `f(s) = s²/2ε` below `ε = stick` (m), `s - ε/2` above; `None`
/// without a positive limit.
pub(super) fn lagged_friction(
    limit: f64,
    normal: DVec3,
    travel: DVec3,
    stick: f64,
) -> Option<(f64, DVec3, DMat3)> {
    if limit <= 0.0 {
        return None;
    }
    let plane = DMat3::IDENTITY - penalty_tangent(1.0, normal);
    let slip = plane * travel;
    let s = slip.length();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slip_carried_through_the_stick_zone_takes_the_sticking_piece() {
        let (limit, stick, normal) = (2.0, 1e-3, DVec3::Y);
        let from = DVec3::new(3e-3, 0.0, 1e-3);
        let (_, force, tangent) = lagged_friction(limit, normal, from, stick).unwrap();
        // A step to the other side, past no slip: the sliding term plus the difference is the
        // sticking quadratic's force and tangent at the start, to round-off.
        let to = DVec3::new(-2e-3, 5e-4, -1e-3);
        let (extra_force, extra_tangent) = stick_towards(limit, normal, (from, to), stick).unwrap();
        let slip = DVec3::new(from.x, 0.0, from.z);
        let plane = DMat3::IDENTITY - penalty_tangent(1.0, normal);
        assert!((force + extra_force + slip * (limit / stick)).length() < 1e-12);
        let difference = tangent + extra_tangent - plane * (limit / stick);
        assert!(difference.to_cols_array().iter().all(|c| c.abs() < 1e-9));
        // The difference is positive semi-definite (every direction of the plane, none across).
        for d in [DVec3::X, DVec3::Z, DVec3::new(1.0, 0.0, -3.0), DVec3::Y] {
            assert!(d.dot(extra_tangent * d) >= -1e-12);
        }
        // A step that keeps sliding away from no slip, or a point already sticking: nothing.
        assert!(stick_towards(limit, normal, (from, from * 2.0), stick).is_none());
        assert!(stick_towards(limit, normal, (from * 0.1, -from), stick).is_none());
        // No friction limit: nothing.
        assert!(stick_towards(0.0, normal, (from, to), stick).is_none());
    }
}
