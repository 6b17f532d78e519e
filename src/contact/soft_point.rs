//! A material point of a soft body's boundary triangle, as one side of a contact: its velocity,
//! its inverse effective mass, and the impulse it takes, shared out among the triangle's nodes by
//! the point's barycentric weights.

use crate::stencil::Stencil;
use rapier3d::glamx::DVec3;

/// A point of a boundary triangle: the triangle's nodes and the point's barycentric weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SoftPoint {
    pub(crate) nodes: [u32; 3],
    pub(crate) weights: [f64; 3],
}

impl SoftPoint {
    /// The point and the triangle's outward unit normal, with the nodes at `positions` (m);
    /// `None` for a flat triangle.
    pub(crate) fn plane(&self, positions: &[DVec3]) -> Option<(DVec3, DVec3)> {
        let [a, b, c] = self.nodes.map(|n| positions[n as usize]);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let [wa, wb, wc] = self.weights;
        (normal != DVec3::ZERO).then(|| (a * wa + b * wb + c * wc, normal))
    }

    /// The point's nodes and weights.
    pub(crate) fn stencil(&self) -> Stencil<'_> {
        Stencil {
            nodes: &self.nodes,
            weights: &self.weights,
        }
    }

    /// The point's velocity (m/s), with the nodes at `velocities`.
    pub(crate) fn velocity(&self, velocities: &[DVec3]) -> DVec3 {
        self.stencil().interpolate(velocities)
    }

    /// The point's inverse effective mass (1/kg): `Σ w² / m` over the free nodes.
    pub(crate) fn inverse_mass(&self, masses: &[f64], pinned: &[bool]) -> f64 {
        self.stencil().inverse_mass(masses, pinned)
    }

    /// Gives the point `impulse` (N s): each free node its weight's share.
    pub(crate) fn apply(
        &self,
        impulse: DVec3,
        velocities: &mut [DVec3],
        masses: &[f64],
        pinned: &[bool],
    ) {
        self.stencil().apply(impulse, velocities, masses, pinned);
    }
}
