//! The explicit integrator's contact at the velocity level, shared by every kind of contact:
//! with a collider, with the body's own surface, and between two soft bodies.
//!
//! Over a substep of length `h` a node at signed distance `g` from its contact plane may approach
//! it at most at `g/h` (it arrives but does not cross: an inelastic, speculative contact), or,
//! found inside, must leave at up to the depenetration speed. Each sweep corrects the contact's
//! accumulated normal impulse toward the one that gives the node that lowest normal velocity
//! relative to the obstacle, kept pushing, then its friction impulse toward the one that stops the
//! sliding, kept within the friction coefficient times the normal impulse (Coulomb). The
//! obstacle takes the opposite impulses; repeated sweeps converge to the joint solution of
//! coupled contacts (sequential impulses, as rapier's solver).

use rapier3d::glamx::DVec3;

/// The two sides of a contact, as a sweep sees them.
pub(crate) trait ContactSides {
    /// Velocity (m/s) of the node relative to the obstacle's material point it touches.
    fn relative_velocity(&self) -> DVec3;
    /// Inverse effective mass (1/kg) of the pair along unit `direction`: the node's plus the
    /// obstacle's at the contact point.
    fn inverse_mass_along(&self, direction: DVec3) -> f64;
    /// Gives the node `impulse` (N s) and the obstacle its opposite.
    fn exchange(&mut self, impulse: DVec3);
}

/// A contact's velocity constraint over one explicit substep: the lowest normal velocity the node
/// may keep (m/s) and the normal and friction impulses accumulated so far (N s).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct VelocityConstraint {
    lowest_speed: f64,
    normal_impulse: f64,
    friction_impulse: DVec3,
}

impl VelocityConstraint {
    /// The constraint of a node at signed distance `gap` (m, negative inside) from its plane,
    /// for a substep of `h` (s), leaving an obstacle at most at `depenetration_speed` (m/s).
    pub(crate) fn new(gap: f64, h: f64, depenetration_speed: f64) -> Self {
        let lowest_speed = if gap >= 0.0 {
            -gap / h
        } else {
            (-gap / h).min(depenetration_speed)
        };
        Self {
            lowest_speed,
            ..Self::default()
        }
    }

    /// One sweep's correction along the plane's unit `normal` with Coulomb coefficient
    /// `friction`; returns the impulse (N s) it gave the node.
    pub(crate) fn correct(
        &mut self,
        normal: DVec3,
        friction: f64,
        sides: &mut impl ContactSides,
    ) -> DVec3 {
        let normal_speed = sides.relative_velocity().dot(normal);
        let normal_impulse = (self.normal_impulse
            + (self.lowest_speed - normal_speed) / sides.inverse_mass_along(normal))
        .max(0.0);
        let pushed = normal * (normal_impulse - self.normal_impulse);
        sides.exchange(pushed);
        self.normal_impulse = normal_impulse;

        let v = sides.relative_velocity();
        let sliding = v - normal * v.dot(normal);
        let slip = sliding.length();
        let mut friction_impulse = self.friction_impulse;
        if slip > 0.0 {
            friction_impulse -= sliding / sides.inverse_mass_along(sliding / slip);
        }
        let limit = friction * normal_impulse;
        if friction_impulse.length() > limit {
            friction_impulse *= limit / friction_impulse.length();
        }
        let rubbed = friction_impulse - self.friction_impulse;
        sides.exchange(rubbed);
        self.friction_impulse = friction_impulse;
        pushed + rubbed
    }
}
