//! The explicit side of contacts: velocity constraints solved by sequential impulses at each
//! substep. A contact's normal velocity is raised so that its node does not cross its plane
//! within the substep, and its tangential velocity is reduced by at most `μ` times the normal
//! impulse (Coulomb), with the opposite impulse on the partner (a rigid proxy or the body's own
//! nodes), so that momentum is exchanged exactly.

use super::{ContactSet, ContactSides, Obstacle, VelocityConstraint};
use crate::body::DeformableBody;
use crate::embedding::Embedding;
use crate::rigid::RigidProxy;
use crate::stencil::Stencil;
use rapier3d::glamx::DVec3;

/// What a body's contacts push against, as the sweeps see it: the rigid bodies' proxies and the
/// body's own nodes (the contacts' nodes and self-contact triangles).
pub(super) struct Partners<'a> {
    pub(super) rigid: &'a mut [RigidProxy],
    pub(super) velocities: &'a mut [DVec3],
    pub(super) masses: &'a [f64],
    pub(super) pinned: &'a [bool],
}

impl Partners<'_> {
    /// Velocity (m/s) of the obstacle's material point at `x` (m): zero for a fixed collider.
    pub(super) fn velocity_at(&self, obstacle: &Obstacle, x: DVec3) -> DVec3 {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                proxy.map_or(DVec3::ZERO, |p| self.rigid[p].velocity_at(x))
            }
            Obstacle::OwnTriangle(point) => point.velocity(self.velocities),
        }
    }

    /// The obstacle's inverse effective mass (1/kg) at `x` (m) along unit `direction`.
    pub(super) fn inverse_mass_along(
        &self,
        obstacle: &Obstacle,
        x: DVec3,
        direction: DVec3,
    ) -> f64 {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                proxy.map_or(0.0, |p| self.rigid[p].inverse_mass_along(x, direction))
            }
            Obstacle::OwnTriangle(point) => point.inverse_mass(self.masses, self.pinned),
        }
    }

    /// Gives the obstacle `impulse` (N s) at `x` (m): the opposite of what its node received.
    pub(super) fn apply(&mut self, obstacle: &Obstacle, impulse: DVec3, x: DVec3) {
        match obstacle {
            Obstacle::Collider { proxy, .. } => {
                if let Some(p) = *proxy {
                    self.rigid[p].apply(impulse, x);
                }
            }
            Obstacle::OwnTriangle(point) => {
                point.apply(impulse, self.velocities, self.masses, self.pinned);
            }
        }
    }
}

/// Splits `body` into its positions, its embedded mesh and what its contacts push against (the
/// rigid `proxies` and its own nodes).
pub(super) fn partners<'a>(
    body: &'a mut DeformableBody,
    proxies: &'a mut [RigidProxy],
) -> (&'a [DVec3], Option<&'a Embedding>, Partners<'a>) {
    let DeformableBody {
        positions,
        velocities,
        masses,
        pinned,
        embedding,
        ..
    } = body;
    (
        positions,
        embedding.as_ref(),
        Partners {
            rigid: proxies,
            velocities,
            masses,
            pinned,
        },
    )
}

/// Readies the contacts' velocity constraints for an explicit substep of `h` (s), before the
/// sweeps of [`solve_velocities`]: each plane moves to the collider's surface point nearest to its
/// node, and the lowest normal velocity is set so that the node arrives at the plane but does not
/// cross it within the substep, or, found inside, leaves over the detection's step (see
/// [`super::Depenetration`]).
pub(crate) fn prepare_velocities(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    proxies: &mut [RigidProxy],
    h: f64,
) {
    let depenetration = contacts.depenetration();
    let (positions, embedding, mut partners) = partners(body, proxies);
    for contact in &mut contacts.nodes {
        let point = contact.at;
        let at = point.stencil(embedding);
        let x = at.interpolate(positions);
        contact.refresh(x, positions, partners.rigid);
        let gap = contact.gap(x);
        let sides = WithinBody {
            partners: &mut partners,
            obstacle: &contact.obstacle,
            at,
            x,
        };
        let normal = contact.normal;
        contact.constraint = VelocityConstraint::new(gap, h, depenetration).bounce(
            gap,
            h,
            || sides.relative_velocity().dot(normal),
            contact.restitution,
        );
    }
}

/// Carries the contact planes of colliders on rigid bodies along with the bodies over the
/// explicit substep of `h` (s), before the proxies move (see [`RigidProxy::advance`]): a plane
/// the next substep keeps (a point behind a thin collider) is then where its collider is.
pub(crate) fn advance_planes(contacts: &mut ContactSet, proxies: &[RigidProxy], h: f64) {
    for contact in &mut contacts.nodes {
        if let Obstacle::Collider { proxy: Some(p), .. } = contact.obstacle {
            (contact.point, contact.normal) =
                proxies[p].plane_after(contact.point, contact.normal, h);
        }
    }
}

/// One sweep over the contacts' velocity constraints (called after the velocity update, before
/// positions move; see [`VelocityConstraint`]). Against a rigid body or an own triangle the
/// velocities are relative, the obstacle's effective mass counts, and the obstacle receives the
/// opposite impulse.
pub(crate) fn solve_velocities(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    proxies: &mut [RigidProxy],
) {
    let (positions, embedding, mut partners) = partners(body, proxies);
    for contact in &mut contacts.nodes {
        let point = contact.at;
        let at = point.stencil(embedding);
        let mut sides = WithinBody {
            partners: &mut partners,
            obstacle: &contact.obstacle,
            at,
            x: at.interpolate(positions),
        };
        contact.impulse += contact
            .constraint
            .correct(contact.normal, contact.friction, &mut sides);
    }
}

/// A contact's point and obstacle within one body's sweep.
pub(super) struct WithinBody<'a, 'b> {
    partners: &'a mut Partners<'b>,
    obstacle: &'a Obstacle,
    at: Stencil<'a>,
    x: DVec3,
}

impl ContactSides for WithinBody<'_, '_> {
    fn relative_velocity(&self) -> DVec3 {
        self.at.interpolate(self.partners.velocities)
            - self.partners.velocity_at(self.obstacle, self.x)
    }

    fn inverse_mass_along(&self, direction: DVec3) -> f64 {
        self.at
            .inverse_mass(self.partners.masses, self.partners.pinned)
            + self
                .partners
                .inverse_mass_along(self.obstacle, self.x, direction)
    }

    fn exchange(&mut self, impulse: DVec3) {
        self.at.apply(
            impulse,
            self.partners.velocities,
            self.partners.masses,
            self.partners.pinned,
        );
        self.partners.apply(self.obstacle, -impulse, self.x);
    }
}
