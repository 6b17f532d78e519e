//! rapier's step made to carry each dynamic rigid body an implicit soft step moved along the
//! path that step assumed.
//!
//! An implicit soft step of `h` solves a dynamic rigid body's motion with the soft body's as one
//! backward Euler step: the body starts at `v₀ + g h` (gravity included, see
//! [`RigidProxy::fall`](crate::rigid::RigidProxy)), takes the impulse `ι` and ends at
//! `v = v₀ + g h + W ι`, and its points move by `h v`. rapier's TGS step then applies `ι` and
//! runs `n` solver iterations, each integrating over `h / n`: it ends at `v` too, but moves the
//! body by
//!
//! `Σₖ (h/n)(v − g h + k g h/n) = h v − g h² (n − 1)/(2n)`,
//!
//! `(n − 1)/(2n) |g| h²` less far down (1.0 mm at a 1/60 s substep and rapier's default four
//! iterations, nothing at one). A box resting on a soft block was then lifted that much every
//! substep and pushed back by the next soft step: it ended each frame moving down at
//! `(n − 1)/(2n) |g| h` (61 mm/s) while it stayed put, and turned slowly (0.39 rad/s after 2 s);
//! the energy of the lift (`m |g|² h² (n − 1)/(2n)` per substep, 4.3 mJ for a 0.43 kg box) was
//! left for backward Euler's damping to take away, and a box landing on the block gained
//! 0.19 mJ in a frame as it settled.
//!
//! [`RapierCarry`] removes the difference: before rapier's step each such body's velocity is
//! raised by `a = g h (n − 1)/(2n)` (times its gravity scale), so that rapier moves it by `h v`,
//! and after the step `a` is taken off again, so that it ends at `v`. The offset does not depend
//! on the impulses, so a body several soft bodies touch is carried right by all their impulses
//! together. A body that rapier's own contacts hold up moves in the soft step as rapier's last
//! step moved it (no gravity of its own there, see `pull.rs`) and is left to rapier, whose
//! contacts would answer the offset; so is a sleeping one.
//!
//! Explicit substeps carry a body along a path of their own (each substep falling and moving by
//! its share, the impulses coming in over the substeps) and are not matched here: rapier moves
//! such a body from the impulses' total, applied at its start.

use crate::rigid::RigidProxy;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::glamx::DVec3;

/// A dynamic rigid body an implicit soft step moved.
#[derive(Debug, Clone, Copy)]
pub(super) struct Carried {
    /// The body.
    handle: RigidBodyHandle,
    /// The gravity scale it fell by in the soft step (0 when rapier's contacts hold it up).
    gravity_scale: f64,
    /// Whether rapier's contacts hold it up (see [`RigidProxy::hold`]).
    held: bool,
    /// 1 along the axes it translates along, 0 along locked ones.
    free_axes: DVec3,
    /// The change of its linear velocity (m/s) the implicit steps' impulses made, summed over
    /// the soft bodies that moved it.
    impulse_velocity: DVec3,
}

impl Carried {
    /// Adds to `carried` each dynamic rigid body of `proxies`, those of a soft body an implicit
    /// step just moved, unless already there (its gravity scale is the same in every step), and
    /// the change of velocity their impulses made (before they are handed to rapier).
    pub(super) fn add(carried: &mut Vec<Carried>, proxies: &[RigidProxy]) {
        for proxy in proxies.iter().filter(|p| p.is_dynamic()) {
            let index =
                (carried.iter().position(|c| c.handle == proxy.handle)).unwrap_or_else(|| {
                    carried.push(Carried {
                        handle: proxy.handle,
                        gravity_scale: proxy.gravity_scale(),
                        held: proxy.is_held(),
                        free_axes: proxy.free_axes(),
                        impulse_velocity: DVec3::ZERO,
                    });
                    carried.len() - 1
                });
            carried[index].impulse_velocity += proxy.impulse_velocity();
        }
    }
}

/// The change of linear velocity (m/s) of each dynamic rigid body over the coupling substeps of
/// the last frame (or the last [`SoftCoupling::substep`](super::SoftCoupling::substep)) in which
/// implicit soft steps carried it: not held by rapier's contacts, awake, moved by the impulses'
/// `M⁻¹ι` and its fall `g h` along its free axes. The energy audit measures such changes at the
/// centre of mass: the step moves the body with the soft body as one backward Euler step, whose
/// energy measured there cannot rise (see the audit's `energy` module). Several soft bodies
/// stepped apart (not grouped) that carry one rigid body in a substep each solve their own step;
/// their impulses are summed here as if one step had moved it.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(super) struct CarriedMotion {
    /// Per body, its change (m/s) so far in the frame.
    changes: Vec<(RigidBodyHandle, DVec3)>,
    /// How many frames (or substeps run alone) have begun: the audit tells by it whether a step
    /// ran since it last looked.
    frames: u64,
}

impl CarriedMotion {
    /// Begins a frame (or a substep run alone): the last one's changes are forgotten.
    pub(super) fn begin_frame(&mut self) {
        self.changes.clear();
        self.frames += 1;
    }

    /// Adds the changes of a substep of `h` (s) under `gravity` (m/s²) of the bodies `carried`
    /// that rapier's contacts do not hold and that are awake in `bodies`.
    pub(super) fn add(
        &mut self,
        carried: &[Carried],
        bodies: &RigidBodySet,
        (h, gravity): (f64, DVec3),
    ) {
        let awake = |c: &&Carried| bodies.get(c.handle).is_some_and(|b| !b.is_sleeping());
        for c in carried.iter().filter(|c| !c.held).filter(awake) {
            let change = c.impulse_velocity + gravity * (c.gravity_scale * h) * c.free_axes;
            match self
                .changes
                .iter_mut()
                .find(|(handle, _)| *handle == c.handle)
            {
                Some((_, total)) => *total += change,
                None => self.changes.push((c.handle, change)),
            }
        }
    }

    /// The change (m/s) of `handle` over the frame's carried substeps.
    pub(super) fn of(&self, handle: RigidBodyHandle) -> DVec3 {
        (self.changes.iter())
            .find(|(h, _)| *h == handle)
            .map_or(DVec3::ZERO, |&(_, change)| change)
    }

    /// How many frames (or substeps run alone) have begun.
    pub(super) fn frames(&self) -> u64 {
        self.frames
    }
}

/// The velocity offsets that make rapier's coming step carry the rigid bodies an implicit soft
/// step moved along the paths that step assumed.
#[derive(Debug, Default)]
pub(super) struct RapierCarry {
    /// Per body, the velocity (m/s) added before rapier's step and taken off after it.
    offsets: Vec<(RigidBodyHandle, DVec3)>,
}

impl RapierCarry {
    /// Adds to the velocity of each body of `carried` in `bodies` the offset that makes a rapier
    /// step of `h` (s) in `iterations` solver iterations under `gravity` (m/s²) carry it by `h`
    /// times the velocity it ends with, and keeps the offsets to take off after the step.
    /// Bodies held by rapier's contacts, asleep or gone are left alone; with one iteration there
    /// is nothing to add.
    pub(super) fn lead(
        carried: &[Carried],
        bodies: &mut RigidBodySet,
        gravity: DVec3,
        (h, iterations): (f64, usize),
    ) -> Self {
        let n = iterations.max(1) as f64;
        let lag = gravity * (h * (n - 1.0) / (2.0 * n));
        let mut offsets = Vec::new();
        if lag == DVec3::ZERO {
            return Self { offsets };
        }
        for c in carried.iter().filter(|c| c.gravity_scale != 0.0) {
            let Some(body) = bodies.get_mut(c.handle).filter(|b| b.is_dynamic()) else {
                continue;
            };
            if body.is_sleeping() {
                continue;
            }
            let offset = lag * c.gravity_scale;
            body.set_linvel((body.linvel().as_dvec3() + offset).as_vec3(), false);
            offsets.push((c.handle, offset));
        }
        Self { offsets }
    }

    /// Takes each offset off its body's velocity again after rapier's step (a body rapier put
    /// to sleep in it, its velocity zeroed, is left alone).
    pub(super) fn settle(self, bodies: &mut RigidBodySet) {
        for (handle, offset) in self.offsets {
            if let Some(body) = bodies.get_mut(handle)
                && !body.is_sleeping()
            {
                let v = body.linvel().as_dvec3() - offset;
                body.set_linvel(v.as_vec3(), false);
            }
        }
    }
}
