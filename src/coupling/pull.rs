//! What rapier's step did to each held rigid body, as an acceleration: `a = (v' − v)/h` and
//! `α = (ω' − ω)/h`, with `v`, `ω` the body's velocities handed to rapier (after the soft
//! impulses) and `v'`, `ω'` those rapier's step of `h` left: gravity, and rapier's own contacts
//! and joints.
//!
//! A held body (one rapier's contacts hold up, see
//! [`RigidProxy::hold`](crate::rigid::RigidProxy::hold)) is moved in the next soft step by
//! that pull and the soft forces: the soft step then sees the body as rapier will move
//! it, and a board whose foot rapier's ground holds while its top leans on a soft block rests,
//! instead of being pushed away by the block alone and pulled back by rapier's step in turn.

use crate::rigid::RigidProxy;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::glamx::DVec3;

/// The pull of rapier's step on each held rigid body: linear (m/s²) and angular (rad/s²).
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct RapierPull {
    pulls: Vec<(RigidBodyHandle, DVec3, DVec3)>,
}

/// The held bodies' velocities handed to a rapier step, to measure its pull with.
pub(super) struct BeforeRapier {
    velocities: Vec<(RigidBodyHandle, DVec3, DVec3)>,
}

impl RapierPull {
    /// The pull on `handle` (linear m/s², angular rad/s²), zero if not measured.
    pub(crate) fn on(&self, handle: RigidBodyHandle) -> (DVec3, DVec3) {
        (self.pulls.iter())
            .find(|(h, _, _)| *h == handle)
            .map_or((DVec3::ZERO, DVec3::ZERO), |&(_, a, alpha)| (a, alpha))
    }

    /// Notes the velocities in `bodies` of the held proxies of `proxies` before rapier's step.
    pub(super) fn before<'a>(
        proxies: impl Iterator<Item = &'a RigidProxy>,
        bodies: &RigidBodySet,
    ) -> BeforeRapier {
        let mut velocities = Vec::new();
        for proxy in proxies.filter(|p| p.is_dynamic() && p.is_held()) {
            if velocities.iter().any(|(h, _, _)| *h == proxy.handle) {
                continue;
            }
            if let Some(body) = bodies.get(proxy.handle) {
                let (v, w) = (body.linvel().as_dvec3(), body.angvel().as_dvec3());
                velocities.push((proxy.handle, v, w));
            }
        }
        BeforeRapier { velocities }
    }

    /// The pull of rapier's step of `h` (s) on the bodies noted `before`.
    pub(super) fn measure(before: BeforeRapier, bodies: &RigidBodySet, h: f64) -> Self {
        let pulls = (before.velocities.into_iter())
            .filter_map(|(handle, v, w)| {
                let body = bodies.get(handle).filter(|b| !b.is_sleeping())?;
                let a = (body.linvel().as_dvec3() - v) / h;
                let alpha = (body.angvel().as_dvec3() - w) / h;
                Some((handle, a, alpha))
            })
            .collect();
        Self { pulls }
    }
}
