//! A material point of a soft body's boundary triangle, as one side of a contact: its velocity,
//! its inverse effective mass, and the impulse it takes, shared out among the triangle's nodes by
//! the point's barycentric weights.

use rapier3d::glamx::DVec3;

/// The inverse mass (1/kg) of a node of mass `mass` (kg): zero when `pinned`.
pub(crate) fn node_inverse_mass(mass: f64, pinned: bool) -> f64 {
    if pinned { 0.0 } else { 1.0 / mass }
}

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
    fn stencil(&self) -> Stencil<'_> {
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

/// A point of a body that moves with some of its nodes: a node itself (weight one), or a vertex
/// of an embedded mesh (its element's nodes, weighted by the shape functions at the vertex).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stencil<'a> {
    pub(crate) nodes: &'a [u32],
    pub(crate) weights: &'a [f64],
}

impl Stencil<'_> {
    /// The point's position (m) for node positions `x`; with velocities, its velocity (m/s).
    pub(crate) fn interpolate(&self, x: &[DVec3]) -> DVec3 {
        self.nodes
            .iter()
            .zip(self.weights)
            .map(|(&n, w)| x[n as usize] * *w)
            .sum()
    }

    /// The point's inverse effective mass (1/kg): `Σ w² / m` over the free nodes.
    pub(crate) fn inverse_mass(&self, masses: &[f64], pinned: &[bool]) -> f64 {
        self.nodes
            .iter()
            .zip(self.weights)
            .map(|(&n, w)| w * w * node_inverse_mass(masses[n as usize], pinned[n as usize]))
            .sum()
    }

    /// Gives the point `impulse` (N s): each free node its weight's share.
    pub(crate) fn apply(
        &self,
        impulse: DVec3,
        velocities: &mut [DVec3],
        masses: &[f64],
        pinned: &[bool],
    ) {
        for (&n, w) in self.nodes.iter().zip(self.weights) {
            let n = n as usize;
            velocities[n] += impulse * (w * node_inverse_mass(masses[n], pinned[n]));
        }
    }
}
