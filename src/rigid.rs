//! The rigid bodies a soft body touches, as the soft step sees them: velocity, centre of mass and
//! inverse mass, updated by the contact impulses as they are applied, and the total impulse to
//! hand back to rapier when the step is accepted.
//!
//! An implicit step sees each body at its pose when the step began, carrying what it touches by
//! its velocity over the step. The explicit substeps move it as they move the nodes
//! (`x ← x + h v`, at the velocity the sweeps left): the proxy keeps the rigid motion since it
//! was made, a translation of the centre of mass `c₀ → c` and a turn `R`, and a material point
//! at `p₀` then is at `c + R (p₀ − c₀)` now. Colliders keep their pose at detection; a node is
//! taken back into that pose to be projected onto them, and its contact plane carried forward
//! (see [`RigidProxy::carry`]), so that a fast body sweeps through the nodes in its path within
//! the soft step instead of jumping over them in rapier's.

use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodyType};
use rapier3d::glamx::{DMat3, DQuat, DVec3};

/// The linear velocity of the centre of mass (m/s) and the angular velocity (rad/s) `body` will
/// have over the coming step of `dt` (s): its velocities, or, for a position-based kinematic
/// body, the motion to the pose it was told to reach (as rapier derives them in its step).
pub(crate) fn coming_velocity(body: &RigidBody, dt: f64) -> (DVec3, DVec3) {
    if body.body_type() != RigidBodyType::KinematicPositionBased {
        return (body.linvel().as_dvec3(), body.angvel().as_dvec3());
    }
    let (now, next) = (body.position(), body.next_position());
    let local_com = body.mass_properties().local_mprops.local_com;
    let travel = next.transform_point(local_com) - now.transform_point(local_com);
    let turn = (next.rotation * now.rotation.inverse()).to_scaled_axis();
    (travel.as_dvec3() / dt, turn.as_dvec3() / dt)
}

/// A material point of a dynamic rigid body that an implicit term acts against: the term
/// depends on its soft point's position relative to where the rigid body carries this point over
/// the step, and the body takes the opposite of the term's force there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RigidPoint {
    /// The body's index among the soft body's proxies.
    pub(crate) proxy: usize,
    /// The point (m), where it is at the start of the step.
    pub(crate) point: DVec3,
}

/// A rigid body in contact with a soft body during one soft step.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RigidProxy {
    /// The body in rapier's set.
    pub(crate) handle: RigidBodyHandle,
    /// Linear velocity (m/s) and angular velocity (rad/s), updated by the contact impulses.
    linvel: DVec3,
    angvel: DVec3,
    /// World centre of mass (m), carried along by the explicit substeps.
    com: DVec3,
    /// The centre of mass (m) when the proxy was made, and the turn since then.
    start_com: DVec3,
    turn: DQuat,
    /// The body's gravity scale if dynamic, zero otherwise.
    fall: f64,
    /// Whether rapier's own contacts hold the body (see [`RigidProxy::hold`]).
    held: bool,
    /// What rapier's last step did to a held body: linear (m/s²) and angular (rad/s²).
    pull: (DVec3, DVec3),
    /// Per-axis inverse mass (1/kg) and world inverse inertia (1/(kg m²)); zero unless dynamic.
    inv_mass: DVec3,
    inv_inertia: DMat3,
    /// Impulse (N s) and angular impulse (N m s) received so far, the latter about the centre of
    /// mass where the proxy was made: rapier applies them to the body there, and so taken the
    /// system's angular momentum is exchanged exactly.
    pub(crate) impulse: DVec3,
    pub(crate) angular_impulse: DVec3,
}

impl RigidProxy {
    /// The proxy of `body`, stored in rapier's set under `handle`, for a step of `dt` (s).
    pub(crate) fn new(handle: RigidBodyHandle, body: &RigidBody, dt: f64) -> Self {
        let props = body.mass_properties();
        let fall = if body.is_dynamic() {
            f64::from(body.gravity_scale())
        } else {
            0.0
        };
        let (inv_mass, inv_inertia) = if body.is_dynamic() {
            let i = props.effective_world_inv_inertia;
            let inertia = DMat3::from_cols_array(
                &[
                    i.m11, i.m12, i.m13, i.m12, i.m22, i.m23, i.m13, i.m23, i.m33,
                ]
                .map(f64::from),
            );
            (props.effective_inv_mass.as_dvec3(), inertia)
        } else {
            (DVec3::ZERO, DMat3::ZERO)
        };
        let (linvel, angvel) = coming_velocity(body, dt);
        Self {
            handle,
            linvel,
            angvel,
            com: props.world_com.as_dvec3(),
            start_com: props.world_com.as_dvec3(),
            turn: DQuat::IDENTITY,
            fall,
            held: false,
            pull: (DVec3::ZERO, DVec3::ZERO),
            inv_mass,
            inv_inertia,
            impulse: DVec3::ZERO,
            angular_impulse: DVec3::ZERO,
        }
    }

    /// Lets the body fall under `gravity` (m/s²) for `h` (s), as rapier will make it, or, if held
    /// (see [`RigidProxy::hold`]), moves it as rapier's last step did: the soft side then sees a
    /// body resting on it pressing on it rather than one that floats until rapier's step. Only
    /// the contact impulses are handed back.
    pub(crate) fn fall(&mut self, gravity: DVec3, h: f64) {
        self.linvel += gravity * (self.fall * h) + self.pull.0 * h;
        self.angvel += self.pull.1 * h;
    }

    /// The gravity scale the body falls by in the soft step: its own if dynamic and not held,
    /// zero otherwise.
    pub(crate) fn gravity_scale(&self) -> f64 {
        self.fall
    }

    /// Moves the body in the soft step by `pull`, what rapier's last step did to it (linear
    /// m/s², angular rad/s²: gravity and rapier's own contacts and joints, measured by the
    /// coupling's `RapierPull`), instead of gravity alone: for a body that
    /// rapier's own contacts hold (standing on rigid ground), whose weight rapier's step will
    /// carry. A soft step that saw the body moved by the soft forces alone pushed it away where
    /// rapier's step pulled it back, in turn: a 50 g board leaning on a soft block, its foot on
    /// the ground, stepped implicitly, still moved at 2.2 mm/s after 2 s (1.1e-6 m/s with the
    /// pull, `tests/rigid_on_faces.rs`).
    pub(crate) fn hold(&mut self, pull: (DVec3, DVec3)) {
        self.fall = 0.0;
        self.held = true;
        self.pull = pull;
    }

    /// Whether rapier's own contacts hold the body (see [`RigidProxy::hold`]).
    pub(crate) fn is_held(&self) -> bool {
        self.held
    }

    /// The change of linear velocity (m/s) the impulse received so far gives the body.
    pub(crate) fn impulse_velocity(&self) -> DVec3 {
        self.impulse * self.inv_mass
    }

    /// 1 along each world axis the body translates along (its inverse mass there not zero), 0
    /// along a locked one (and every one of a body that is not dynamic).
    pub(crate) fn free_axes(&self) -> DVec3 {
        self.inv_mass.map(|m| if m == 0.0 { 0.0 } else { 1.0 })
    }

    /// The index in `proxies` of the proxy of the rigid body `fresh` is the proxy of, added
    /// (a copy of `fresh`) if missing: one proxy per rigid body, whatever its number of
    /// colliders and attachments.
    pub(crate) fn index_in(proxies: &mut Vec<RigidProxy>, fresh: &RigidProxy) -> usize {
        match proxies.iter().position(|p| p.handle == fresh.handle) {
            Some(index) => index,
            None => {
                proxies.push(fresh.clone());
                proxies.len() - 1
            }
        }
    }

    /// Moves the body along its velocity for `h` (s), as an explicit substep moves the nodes once
    /// its sweeps are done: the centre of mass by `h v`, the orientation by the turn `h ω`. The
    /// inverse inertia stays the one of the starting pose (a coupling substep turns a body little).
    pub(crate) fn advance(&mut self, h: f64) {
        self.com += self.linvel * h;
        if self.angvel != DVec3::ZERO {
            self.turn = (DQuat::from_scaled_axis(self.angvel * h) * self.turn).normalize();
        }
    }

    /// Where a plane fixed in the body, through `point` (m) with unit `normal`, is after `h` (s)
    /// at the body's velocity (as [`RigidProxy::advance`] moves the body).
    pub(crate) fn plane_after(&self, point: DVec3, normal: DVec3, h: f64) -> (DVec3, DVec3) {
        let normal = if self.angvel == DVec3::ZERO {
            normal
        } else {
            (DQuat::from_scaled_axis(self.angvel * h) * normal).normalize()
        };
        (point + self.velocity_at(point) * h, normal)
    }

    /// Whether the explicit substeps have moved the body since the proxy was made.
    pub(crate) fn has_moved(&self) -> bool {
        self.com != self.start_com || self.turn != DQuat::IDENTITY
    }

    /// Where the body's material point that was at `point` (m) when the proxy was made is now.
    pub(crate) fn carry(&self, point: DVec3) -> DVec3 {
        self.com + self.turn * (point - self.start_com)
    }

    /// Where the body's material point now at `point` (m) was when the proxy was made: the
    /// inverse of [`RigidProxy::carry`].
    pub(crate) fn carry_back(&self, point: DVec3) -> DVec3 {
        self.start_com + self.turn.inverse() * (point - self.com)
    }

    /// A direction fixed in the body, `direction` when the proxy was made, now.
    pub(crate) fn turn(&self, direction: DVec3) -> DVec3 {
        self.turn * direction
    }

    /// A direction fixed in the body, `direction` now, when the proxy was made.
    pub(crate) fn turn_back(&self, direction: DVec3) -> DVec3 {
        self.turn.inverse() * direction
    }

    /// Whether contact impulses move the body (it is dynamic).
    pub(crate) fn is_dynamic(&self) -> bool {
        self.inv_mass != DVec3::ZERO || self.inv_inertia != DMat3::ZERO
    }

    /// Velocity (m/s) of the body's material point at `point` (m).
    pub(crate) fn velocity_at(&self, point: DVec3) -> DVec3 {
        self.linvel + self.angvel.cross(point - self.com)
    }

    /// The inverse effective mass (1/kg) of the body at `point` along unit `direction`.
    pub(crate) fn inverse_mass_along(&self, point: DVec3, direction: DVec3) -> f64 {
        let arm = (point - self.com).cross(direction);
        direction.dot(self.inv_mass * direction) + arm.dot(self.inv_inertia * arm)
    }

    /// A lower bound (kg) of the body's effective mass at `point` (m) in every direction: one
    /// over the trace of its inverse effective mass there; infinite for a body contact impulses
    /// do not move.
    pub(crate) fn least_effective_mass(&self, point: DVec3) -> f64 {
        // tr(diag(1/m) − [r]× I⁻¹ [r]×) = Σ 1/m + |r|² tr(I⁻¹) − rᵀ I⁻¹ r.
        let r = point - self.com;
        let i = &self.inv_inertia;
        let trace = self.inv_mass.element_sum()
            + r.length_squared() * (i.x_axis.x + i.y_axis.y + i.z_axis.z)
            - r.dot(*i * r);
        trace.recip()
    }

    /// The 3 x 3 inverse effective mass (1/kg) of the body at `point` (m): the change of the
    /// point's velocity per unit impulse there, `diag(1/m) - [r]x I⁻¹ [r]x`.
    pub(crate) fn inverse_mass_matrix(&self, point: DVec3) -> DMat3 {
        let r = point - self.com;
        let cross = DMat3::from_cols(
            DVec3::new(0.0, r.z, -r.y),
            DVec3::new(-r.z, 0.0, r.x),
            DVec3::new(r.y, -r.x, 0.0),
        );
        DMat3::from_diagonal(self.inv_mass) - cross * self.inv_inertia * cross
    }

    /// The change of linear (m/s) and angular (rad/s) velocity an impulse `impulse` (N s) and
    /// angular impulse `angular` about the centre of mass (N m s) give the body.
    pub(crate) fn response(&self, [impulse, angular]: [DVec3; 2]) -> [DVec3; 2] {
        [self.inv_mass * impulse, self.inv_inertia * angular]
    }

    /// The kinetic energy (J) the velocity change of an impulse and angular impulse (N s, N m s)
    /// carries, `½ ιᵀ W ι` with `W` the body's inverse mass and inertia.
    pub(crate) fn kinetic_energy_of(&self, impulses: [DVec3; 2]) -> f64 {
        let [dv, dw] = self.response(impulses);
        0.5 * (impulses[0].dot(dv) + impulses[1].dot(dw))
    }

    /// A copy of `base` moving with the velocity change of `impulses` (linear, N s; angular
    /// about the centre of mass, N m s) added, its received impulses unchanged.
    pub(crate) fn nudge_from(&mut self, base: &RigidProxy, impulses: [DVec3; 2]) {
        let [dv, dw] = base.response(impulses);
        self.linvel = base.linvel + dv;
        self.angvel = base.angvel + dw;
    }

    /// The world centre of mass (m), where the explicit substeps carried it.
    pub(crate) fn center_of_mass(&self) -> DVec3 {
        self.com
    }

    /// The per-axis inverse mass (1/kg) and the world inverse inertia (1/(kg m²)).
    pub(crate) fn inverse_mass_and_inertia(&self) -> (DVec3, DMat3) {
        (self.inv_mass, self.inv_inertia)
    }

    /// Applies `impulse` (N s) at `point` (m): the body's velocities change by its response about
    /// the centre of mass where the explicit substeps carried it, and the impulse is recorded
    /// with its moment about the starting centre of mass. The two differ by
    /// `(c − c₀) × impulse`, which rapier's step, applying the impulses where the body started,
    /// turns into a spin the proxy did not have (nothing for a body struck along its path).
    pub(crate) fn apply(&mut self, impulse: DVec3, point: DVec3) {
        let angular = (point - self.com).cross(impulse);
        self.linvel += self.inv_mass * impulse;
        self.angvel += self.inv_inertia * angular;
        self.impulse += impulse;
        self.angular_impulse += (point - self.start_com).cross(impulse);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::dynamics::{RigidBodyBuilder, RigidBodySet};
    use rapier3d::geometry::{ColliderBuilder, ColliderSet};
    use rapier3d::math::Vector;

    #[test]
    fn a_proxy_carries_the_body_s_points_along_its_velocity() {
        // A 20 cm cube at (1, 2, 3) m moving at (2, -1, 0.5) m/s and turning at 3 rad/s about z,
        // no impulse: after 10 substeps of 1 ms its centre of mass has moved by 10 ms of its
        // velocity, and a point fixed in it by that translation and a turn of 0.03 rad about
        // the centre of mass; taking the point back gives where it started.
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let handle = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(1.0, 2.0, 3.0))
                .linvel(Vector::new(2.0, -1.0, 0.5))
                .angvel(Vector::new(0.0, 0.0, 3.0)),
        );
        colliders.insert_with_parent(ColliderBuilder::cuboid(0.1, 0.1, 0.1), handle, &mut bodies);
        let mut proxy = RigidProxy::new(handle, &bodies[handle], 1e-2);
        let start = proxy.center_of_mass();
        assert!(!proxy.has_moved());
        for _ in 0..10 {
            proxy.advance(1e-3);
        }
        let point = start + DVec3::new(0.1, -0.05, 0.02);
        let turn = DQuat::from_rotation_z(0.03);
        let travel = DVec3::new(2.0, -1.0, 0.5) * 1e-2;
        let expected = start + travel + turn * (point - start);
        assert!(proxy.has_moved());
        assert!((proxy.carry(point) - expected).length() < 1e-12);
        assert!((proxy.carry_back(proxy.carry(point)) - point).length() < 1e-12);
        assert!((proxy.turn(DVec3::X) - turn * DVec3::X).length() < 1e-12);
        assert!((proxy.turn_back(proxy.turn(DVec3::Y)) - DVec3::Y).length() < 1e-12);
    }
}
