//! What rapier's step did to each held rigid body, as an acceleration: `a = (v' − v)/h` and
//! `α = (ω' − ω)/h`, with `v`, `ω` the body's velocities when a soft substep of `h` handed its
//! impulses over and `v'`, `ω'` those it has when the next soft substep begins: rapier's step in
//! between (gravity, and rapier's own contacts and joints), whether
//! [`SoftCoupling::step`](super::SoftCoupling::step) ran it or the caller of
//! [`SoftCoupling::substep`](super::SoftCoupling::substep) did.
//!
//! A held body (one rapier's contacts hold up, see
//! [`RigidProxy::hold`](crate::rigid::RigidProxy::hold)) is moved in the next soft step by that
//! pull and the soft forces: the soft step then sees the body as rapier will move it, and a board
//! whose foot rapier's ground holds while its top leans on a soft block rests, instead of being
//! pushed away by the block alone and pulled back by rapier's step in turn.

use crate::rigid::RigidProxy;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::glamx::DVec3;

/// The pull of rapier's last step on each held rigid body, and the velocities handed to the
/// coming one.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct RapierPull {
    /// Per body: linear (m/s²) and angular (rad/s²) pull.
    pulls: Vec<(RigidBodyHandle, DVec3, DVec3)>,
    /// Per held body: its velocities (m/s, rad/s) when the last soft substep ended.
    handed: Vec<(RigidBodyHandle, DVec3, DVec3)>,
    /// That substep's length (s).
    h: f64,
}

impl RapierPull {
    /// The pull on `handle` (linear m/s², angular rad/s²), zero if not measured.
    pub(crate) fn on(&self, handle: RigidBodyHandle) -> (DVec3, DVec3) {
        (self.pulls.iter())
            .find(|(h, _, _)| *h == handle)
            .map_or((DVec3::ZERO, DVec3::ZERO), |&(_, a, alpha)| (a, alpha))
    }

    /// Notes, as a soft substep of `h` (s) ends, the velocities in `bodies` of the held dynamic
    /// bodies among `proxies`.
    pub(super) fn note_handed<'a>(
        &mut self,
        proxies: impl Iterator<Item = &'a RigidProxy>,
        bodies: &RigidBodySet,
        h: f64,
    ) {
        self.handed.clear();
        self.h = h;
        for proxy in proxies.filter(|p| p.is_dynamic() && p.is_held()) {
            if self.handed.iter().any(|(h, _, _)| *h == proxy.handle) {
                continue;
            }
            if let Some(body) = bodies.get(proxy.handle) {
                let (v, w) = (body.linvel().as_dvec3(), body.angvel().as_dvec3());
                self.handed.push((proxy.handle, v, w));
            }
        }
    }

    /// Measures, as a soft substep begins, the pull of the rapier step since the last one ended
    /// from the velocities in `bodies` (a body asleep or gone has none).
    pub(super) fn measure(&mut self, bodies: &RigidBodySet) {
        let h = self.h;
        self.pulls = (self.handed.drain(..))
            .filter_map(|(handle, v, w)| {
                let body = bodies.get(handle).filter(|b| !b.is_sleeping())?;
                let a = (body.linvel().as_dvec3() - v) / h;
                let alpha = (body.angvel().as_dvec3() - w) / h;
                Some((handle, a, alpha))
            })
            .collect();
    }
}
