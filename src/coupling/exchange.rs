//! What the soft steps of a frame gave each dynamic rigid body, for the energy audit: the
//! kinetic energy their impulses gave it, whether rapier's own contacts held it meanwhile, and
//! the change of its linear velocity over the substeps in which implicit soft steps carried it.
//!
//! - **Energy given.** An impulse `ι` (N s) and angular impulse `τ` (N m s) applied to a body
//!   moving at `v`, `ω` give it `ι·v + ½ ι·M⁻¹ι + τ·ω + ½ τ·I⁻¹τ` of kinetic energy (J), exactly.
//!   A body rapier's contacts hold can gain energy from rapier's own contacts and position
//!   correction as well (a box tipping over its edge on the ground): the audit counts such a
//!   body's energy change at most as what the soft impulses gave it.
//! - **Carried change.** An implicit soft step of `h` moves a body it carries (not held, awake)
//!   with the soft body as one backward Euler step: its velocity changes by the impulses'
//!   `M⁻¹ι` and its fall `g h` (see `carry`). The audit measures such a change at the centre of
//!   mass, not half an integration step back.

use super::carry::Carried;
use crate::rigid::RigidProxy;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::glamx::DVec3;

/// What the frame's soft steps gave one dynamic rigid body.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct RigidExchange {
    /// The kinetic energy (J) the soft impulses gave it, summed as they were applied.
    pub(crate) energy_given: f64,
    /// Whether rapier's own contacts held it in a substep in which a soft body could touch it.
    pub(crate) held: bool,
    /// The change of its linear velocity (m/s) over the substeps in which implicit soft steps
    /// carried it.
    pub(crate) carried_velocity_change: DVec3,
}

/// Each dynamic rigid body's [`RigidExchange`] over the last frame.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(super) struct SoftExchange {
    bodies: Vec<(RigidBodyHandle, RigidExchange)>,
}

impl SoftExchange {
    /// Forgets the last frame's exchanges.
    pub(super) fn clear(&mut self) {
        self.bodies.clear();
    }

    /// The exchange of `handle` over the frame (nothing if no soft body reached it).
    pub(super) fn of(&self, handle: RigidBodyHandle) -> RigidExchange {
        (self.bodies.iter())
            .find(|(h, _)| *h == handle)
            .map_or_else(RigidExchange::default, |&(_, exchange)| exchange)
    }

    /// The exchange of `handle`, added empty if missing.
    fn entry(&mut self, handle: RigidBodyHandle) -> &mut RigidExchange {
        let index = (self.bodies.iter().position(|(h, _)| *h == handle)).unwrap_or_else(|| {
            self.bodies.push((handle, RigidExchange::default()));
            self.bodies.len() - 1
        });
        &mut self.bodies[index].1
    }

    /// Notes, before the impulses of `proxies` are applied to `bodies`, the kinetic energy they
    /// will give each dynamic body, and which bodies rapier's contacts hold.
    pub(super) fn note_impulses(&mut self, proxies: &[RigidProxy], bodies: &RigidBodySet) {
        for proxy in proxies.iter().filter(|p| p.is_dynamic()) {
            let Some(body) = bodies.get(proxy.handle).filter(|b| b.is_dynamic()) else {
                continue;
            };
            let given = proxy.impulse_energy(body.linvel().as_dvec3(), body.angvel().as_dvec3());
            let entry = self.entry(proxy.handle);
            entry.energy_given += given;
            entry.held |= proxy.is_held();
        }
    }

    /// Adds the velocity changes of a substep of `h` (s) under `gravity` (m/s²) of the bodies
    /// `carried` that rapier's contacts do not hold and that are awake in `bodies`.
    pub(super) fn note_carried(
        &mut self,
        carried: &[Carried],
        bodies: &RigidBodySet,
        (h, gravity): (f64, DVec3),
    ) {
        let awake = |c: &&Carried| bodies.get(c.handle).is_some_and(|b| !b.is_sleeping());
        for c in carried.iter().filter(|c| !c.held).filter(awake) {
            let change = c.impulse_velocity + gravity * (c.gravity_scale * h);
            self.entry(c.handle).carried_velocity_change += change;
        }
    }
}
