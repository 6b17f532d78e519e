//! The implicit side of rigid corners against soft faces: the penalty `k/2 min(0, g)²` on the
//! gap `g = (v − p(x))·n` between the vertex `v`, carried over the step by its rigid body's
//! velocity, and the triangle's contact point `p(x) = Σ w_i x_i`, with `k` the penalty factor
//! times the point's effective `m/h²` (`h` the penalty step, see [`ImplicitStep`]) stiffened by its load (see [`super::super::stiffening`]),
//! and the lagged friction on the point's slip relative to the vertex; after the step their
//! forces' opposite goes to the rigid body at the vertex.

use super::super::node_contact::lagged_friction;
use super::super::penalty::effective_mass;
use super::super::stiffening::Penalty;
use super::super::{ContactSet, ContactSettings, ImplicitStep, penalty_tangent};
use super::CornerContact;
use crate::body::DeformableBody;
use crate::rigid::{RigidPoint, RigidProxy};
use crate::stencil::Stencil;
use rapier3d::glamx::{DMat3, DVec3};

/// A corner's sides at the body's current positions: the triangle's point as a stencil, its
/// position (m) and effective mass (kg), and the vertex's velocity (m/s).
type Sides<'a> = (Stencil<'a>, DVec3, f64, DVec3);

impl CornerContact {
    /// The contact's [`Sides`] with the body at `body` and the rigid proxies `proxies`: the
    /// mass is the triangle point's.
    fn sides(&self, body: &DeformableBody, proxies: &[RigidProxy]) -> Sides<'_> {
        let at = self.on_triangle.stencil();
        let point = at.interpolate(&body.positions);
        let mass = effective_mass(&at, &body.masses, &body.pinned);
        (at, point, mass, self.vertex_velocity(proxies))
    }

    /// The vertex's velocity (m/s), with its rigid body's proxy among `proxies`.
    fn vertex_velocity(&self, proxies: &[RigidProxy]) -> DVec3 {
        self.proxy
            .map_or(DVec3::ZERO, |p| proxies[p].velocity_at(self.vertex))
    }

    /// The gap (m) between the vertex moved at `vertex_velocity` (m/s) for `length` (s) and the
    /// triangle's point at `point` (m): negative with the vertex inside.
    fn gap(&self, point: DVec3, vertex_velocity: DVec3, length: f64) -> f64 {
        (self.vertex + vertex_velocity * length - point).dot(self.normal)
    }

    /// The penalty of the contact in an implicit step of `settings` and `step`, with the
    /// triangle's point at `point` (m) of effective mass `mass` (kg) and the vertex moving at
    /// `vertex_velocity` (m/s): the penalty factor times `m/h²` (`h` the step's penalty step), stiffened by its load (see
    /// [`super::stiffening`]); `None` while the vertex stays outside.
    fn penalty(
        &self,
        point: DVec3,
        mass: f64,
        vertex_velocity: DVec3,
        (settings, step): (&ContactSettings, &ImplicitStep),
    ) -> Option<Penalty> {
        let depth = -self.gap(point, vertex_velocity, step.length);
        (self.stiffening).penalty(settings.penalty_stiffness(mass, step.penalty_step), depth)
    }

    /// The lagged friction of the triangle's point at `point` (m) against the vertex moving at
    /// `vertex_velocity` (m/s) over an implicit step of `settings` and `step`: energy (J), force
    /// on the point (N), tangent (N/m).
    fn friction_term(
        &self,
        point: DVec3,
        vertex_velocity: DVec3,
        (settings, step): (&ContactSettings, &ImplicitStep),
    ) -> Option<(f64, DVec3, DMat3)> {
        lagged_friction(
            self.coefficients.friction * self.lagged_normal_force,
            self.normal,
            point - self.slip_origin - vertex_velocity * step.length,
            settings.stiction_speed * step.effective,
        )
    }

    /// The dynamic rigid body's vertex the corner's terms act against, if it has one.
    fn partner(&self, step: &ImplicitStep) -> Option<RigidPoint> {
        self.proxy
            .filter(|&p| step.rigid[p].is_dynamic())
            .map(|proxy| RigidPoint {
                proxy,
                point: self.vertex,
            })
    }

    /// The implicit force (N) on the triangle's point at `point` (m), of effective mass `mass`
    /// (kg), the vertex moving at `vertex_velocity` (m/s).
    fn implicit_force(
        &self,
        point: DVec3,
        mass: f64,
        vertex_velocity: DVec3,
        step: (&ContactSettings, &ImplicitStep),
    ) -> DVec3 {
        let penalty = self
            .penalty(point, mass, vertex_velocity, step)
            .map_or(DVec3::ZERO, |penalty| -self.normal * penalty.push);
        let friction = self
            .friction_term(point, vertex_velocity, step)
            .map_or(DVec3::ZERO, |(_, force, _)| force);
        penalty + friction
    }
}

/// Readies the corners' implicit friction for an implicit `step` from the body's positions:
/// each friction limit is the penalty force there, with the vertex where it is at the step's
/// start (as a node's contact takes it against its collider where that is), and slip is
/// measured from there.
pub(crate) fn lag_corner_friction(
    body: &DeformableBody,
    contacts: &mut ContactSet,
    step: ImplicitStep,
) {
    let settings = contacts.settings;
    for contact in &mut contacts.corners {
        let (_, point, mass, _) = contact.sides(body, step.rigid);
        contact.lagged_normal_force = contact
            .penalty(point, mass, DVec3::ZERO, (&settings, &step))
            .map_or(0.0, |penalty| penalty.push);
        contact.slip_origin = point;
    }
}

/// Calls `each(point, partner, energy (J), force (N), tangent (N/m))` for the implicit penalty
/// and friction of every corner in the implicit `step`, at the body's positions, on the
/// triangle's contact point: the penalty `k g²/2` with force `k g n` (into the body) and tangent
/// `k n nᵀ`, then the lagged friction; `partner` is the vertex when its rigid body is dynamic.
pub(crate) fn for_each_corner_term(
    body: &DeformableBody,
    contacts: &ContactSet,
    step: ImplicitStep,
    mut each: impl FnMut(Stencil, Option<RigidPoint>, f64, DVec3, DMat3),
) {
    let terms = (&contacts.settings, &step);
    for contact in &contacts.corners {
        let partner = contact.partner(&step);
        if step.skips(&partner) {
            continue;
        }
        let (at, point, mass, velocity) = contact.sides(body, step.rigid);
        if let Some(penalty) = contact.penalty(point, mass, velocity, terms) {
            let tangent = penalty_tangent(penalty.stiffness, contact.normal);
            each(
                at,
                partner,
                penalty.energy,
                -contact.normal * penalty.push,
                tangent,
            );
        }
        if let Some((energy, force, tangent)) = contact.friction_term(point, velocity, terms) {
            each(at, partner, energy, force, tangent);
        }
    }
}

/// Stiffens the penalty of every corner among `corners`, enforced with `settings`, whose vertex
/// the implicit `step` (its rigid bodies at the velocities the step's solve gave them) left
/// deeper behind the triangle's point than [`ContactSettings::resting_depth`], `body`'s nodes
/// having started the step at `start` (m) (see
/// [`Stiffening::stiffen`](super::super::stiffening::Stiffening::stiffen)). Returns whether any
/// was stiffened.
pub(in crate::contact) fn stiffen_deep_corners(
    (body, start): (&DeformableBody, &[DVec3]),
    (corners, settings): (&mut [CornerContact], &ContactSettings),
    step: ImplicitStep,
) -> bool {
    corners.iter_mut().fold(false, |stiffened, contact| {
        let (at, point, mass, velocity) = contact.sides(body, step.rigid);
        let started = contact.gap(at.interpolate(start), DVec3::ZERO, 0.0);
        let ended = contact.gap(point, velocity, step.length);
        let base = settings.penalty_stiffness(mass, step.penalty_step);
        let depths = (-started, -ended);
        (contact.stiffening).stiffen(base, depths, settings.resting_depth) | stiffened
    })
}

/// The energy (J) the corners' implicit penalties hold with the body and the vertices where
/// they are, at a penalty of an implicit step of penalty step `penalty_step` (s, see
/// [`ImplicitStep`]).
pub(crate) fn corner_penalty_energy(
    body: &DeformableBody,
    contacts: &ContactSet,
    penalty_step: f64,
) -> f64 {
    let settings = &contacts.settings;
    (contacts.corners.iter())
        .filter_map(|contact| {
            let at = contact.on_triangle.stencil();
            let depth = -contact.gap(at.interpolate(&body.positions), DVec3::ZERO, 0.0);
            let mass = effective_mass(&at, &body.masses, &body.pinned);
            let base = settings.penalty_stiffness(mass, penalty_step);
            contact.stiffening.penalty(base, depth)
        })
        .map(|penalty| penalty.energy)
        .sum()
}

/// Calls `each` with the stencil of every corner's triangle point.
pub(crate) fn for_each_corner_stencil(contacts: &ContactSet, mut each: impl FnMut(Stencil)) {
    for contact in &contacts.corners {
        each(contact.on_triangle.stencil());
    }
}

/// Records the impulses (N s) the implicit corner terms gave the triangles over the implicit
/// `step`, at the positions that ended it and the rigid velocities of `step`: the collider
/// receives their opposite at the vertex, its rigid body's proxy among `proxies` too, and the
/// vertex travels with its body.
pub(crate) fn record_corner_impulses(
    body: &DeformableBody,
    contacts: &mut ContactSet,
    step: ImplicitStep,
    proxies: &mut [RigidProxy],
) {
    let settings = contacts.settings;
    for contact in &mut contacts.corners {
        let (_, point, mass, velocity) = contact.sides(body, step.rigid);
        let force = contact.implicit_force(point, mass, velocity, (&settings, &step));
        let on_collider = -force * step.length;
        contact.impulse += on_collider;
        if let Some(p) = contact.proxy {
            proxies[p].apply(on_collider, contact.vertex);
        }
        contact.vertex += velocity * step.length;
    }
}
