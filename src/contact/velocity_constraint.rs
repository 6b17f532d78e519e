//! The explicit integrator's contact at the velocity level, shared by every kind of contact:
//! with a collider, with the body's own surface, and between two soft bodies.
//!
//! Over a substep of length `h` a node at signed distance `g` from its contact plane may approach
//! it at most at `g/h` (it arrives but does not cross: an inelastic, speculative contact), or,
//! found inside (`g < 0`), must leave at `-g/T`, the speed that takes it out over the step `T`
//! its contacts were detected for (a coupling substep), at most the depenetration speed
//! ([`Depenetration`]). Each sweep corrects the contact's
//! accumulated normal impulse toward the one that gives the node that lowest normal velocity
//! relative to the obstacle, kept pushing, then its friction impulse toward the one that stops the
//! sliding, kept within the friction coefficient times the normal impulse (Coulomb). The
//! obstacle takes the opposite impulses; repeated sweeps converge to the joint solution of
//! coupled contacts (sequential impulses, as rapier's solver).

use rapier3d::glamx::DVec3;

/// Approach speed (m/s) below which a contact does not bounce, whatever its restitution, so that
/// bodies can come to rest (as `Box2D`'s restitution threshold).
pub const RESTITUTION_THRESHOLD: f64 = 1.0;

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

/// How a point found inside its obstacle is pushed back out: at the speed that takes it out over
/// `time`, at most `speed`. Pushed out within one explicit substep instead, a point and a light
/// partner would part at the full speed however shallow the penetration, which is kinetic energy
/// out of nothing: a micrometre found inside at 65 000 substeps per frame (rapier's step leaves
/// a spinning 1 g box's corner that deep in a stiff block) kicked the box off at 0.1 m/s.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Depenetration {
    /// The most (m/s) a point leaves at: [`ContactSettings::depenetration_speed`](super::ContactSettings::depenetration_speed).
    pub(crate) speed: f64,
    /// The time (s) a penetration is undone over: the step the contacts were detected for (an
    /// explicit substep, if longer).
    pub(crate) time: f64,
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
    /// for a substep of `h` (s), leaving an obstacle as `depenetration` says.
    pub(crate) fn new(gap: f64, h: f64, depenetration: Depenetration) -> Self {
        let lowest_speed = if gap >= 0.0 {
            -gap / h
        } else {
            (-gap / depenetration.time.max(h)).min(depenetration.speed)
        };
        Self {
            lowest_speed,
            ..Self::default()
        }
    }

    /// Makes the contact bounce: a node that approaches the plane at normal velocity
    /// `normal_speed()` (m/s, negative toward it, asked for only when `restitution > 0`) faster
    /// than [`RESTITUTION_THRESHOLD`] and reaches it within the substep of `h` (s) from `gap` (m)
    /// leaves it at `restitution` times its approach speed (a new contact, as rapier bounces only
    /// those).
    pub(crate) fn bounce(
        mut self,
        gap: f64,
        h: f64,
        normal_speed: impl FnOnce() -> f64,
        restitution: f64,
    ) -> Self {
        if restitution > 0.0 && gap >= 0.0 {
            let normal_speed = normal_speed();
            if normal_speed < -RESTITUTION_THRESHOLD && normal_speed * h <= -gap {
                self.lowest_speed = self.lowest_speed.max(-restitution * normal_speed);
            }
        }
        self
    }

    /// One sweep's correction along the plane's unit `normal` with Coulomb coefficient
    /// `friction`; returns the impulse (N s) it gave the node. Nothing when no impulse moves
    /// either side (both held: a pinned node, or a held body's node, against a fixed obstacle),
    /// nor for a contact that has pushed nothing yet and whose node keeps clear of the plane
    /// (most of a sweep's contacts: the reach takes nodes that may meet the obstacle): its
    /// normal impulse would stay zero, and with it the friction's limit.
    pub(crate) fn correct(
        &mut self,
        normal: DVec3,
        friction: f64,
        sides: &mut impl ContactSides,
    ) -> DVec3 {
        let normal_speed = sides.relative_velocity().dot(normal);
        let untouched = self.normal_impulse == 0.0 && self.friction_impulse == DVec3::ZERO;
        if untouched && normal_speed >= self.lowest_speed {
            return DVec3::ZERO;
        }
        let inverse_mass = sides.inverse_mass_along(normal);
        if inverse_mass <= 0.0 {
            return DVec3::ZERO;
        }
        let normal_impulse =
            (self.normal_impulse + (self.lowest_speed - normal_speed) / inverse_mass).max(0.0);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Found inside: out at up to 0.1 m/s over a step of 1/240 s.
    const DEPENETRATION: Depenetration = Depenetration {
        speed: 0.1,
        time: 1.0 / 240.0,
    };

    /// A node of mass `m` against a fixed plane of normal +y.
    struct AgainstFixedPlane {
        velocity: DVec3,
        mass: f64,
    }

    impl ContactSides for AgainstFixedPlane {
        fn relative_velocity(&self) -> DVec3 {
            self.velocity
        }

        fn inverse_mass_along(&self, _direction: DVec3) -> f64 {
            1.0 / self.mass
        }

        fn exchange(&mut self, impulse: DVec3) {
            self.velocity += impulse / self.mass;
        }
    }

    #[test]
    fn a_node_hitting_a_fixed_plane_leaves_at_restitution_times_its_approach_speed() {
        // A 0.1 kg node 1 mm above the plane at -3 m/s (it reaches the plane within a substep
        // of 1 ms), frictionless: one sweep against a fixed plane is exact, so the normal
        // velocity after is e times 3 m/s to round-off, and the tangential one is untouched.
        for restitution in [0.0, 0.5, 1.0] {
            let (gap, h) = (1e-3, 1e-3);
            let mut node = AgainstFixedPlane {
                velocity: DVec3::new(0.2, -3.0, 0.0),
                mass: 0.1,
            };
            let mut constraint =
                VelocityConstraint::new(gap, h, DEPENETRATION).bounce(gap, h, || -3.0, restitution);
            constraint.correct(DVec3::Y, 0.0, &mut node);
            let expected = if restitution > 0.0 {
                3.0 * restitution
            } else {
                // Inelastic: it arrives at the plane by the end of the substep.
                -gap / h
            };
            assert!(
                (node.velocity.y - expected).abs() < 1e-12,
                "{restitution}: {node:?}",
                node = node.velocity
            );
            assert!((node.velocity.x - 0.2).abs() < 1e-15);
        }
    }

    #[test]
    fn a_node_found_inside_leaves_over_the_detection_step_at_most_at_the_depenetration_speed() {
        // A 0.1 kg node at rest against a fixed plane, substeps of 1e-7 s within a step of
        // 1/240 s: found 1 µm inside it leaves at 1 µm / (1/240 s) = 2.4e-4 m/s (not at
        // 0.1 m/s, what 1 µm per substep asks); 1 mm inside, at the 0.1 m/s cap.
        for (gap, expected) in [(-1e-6, 2.4e-4), (-1e-3, 0.1)] {
            let mut node = AgainstFixedPlane {
                velocity: DVec3::ZERO,
                mass: 0.1,
            };
            let mut constraint = VelocityConstraint::new(gap, 1e-7, DEPENETRATION);
            constraint.correct(DVec3::Y, 0.0, &mut node);
            assert!((node.velocity.y - expected).abs() < 1e-12 * expected.max(1.0));
        }
    }

    #[test]
    fn slow_or_resting_contacts_do_not_bounce() {
        // Below the threshold (resting nodes pressed by gravity), or not reaching the plane
        // within the substep, the constraint is the inelastic one.
        let inelastic = VelocityConstraint::new(1e-3, 1e-3, DEPENETRATION);
        assert_eq!(inelastic.bounce(1e-3, 1e-3, || -0.5, 1.0), inelastic);
        let far = VelocityConstraint::new(1e-2, 1e-3, DEPENETRATION);
        assert_eq!(far.bounce(1e-2, 1e-3, || -3.0, 1.0), far);
    }
}
