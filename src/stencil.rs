//! A point of a body that moves with some of its nodes, `x = Σ w_a x_a`: its position and
//! velocity, its inverse effective mass `Σ w_a²/m_a` over the free nodes, and an impulse shared
//! out by the weights. Contacts, attachments, embedded meshes and the tangent's assembly use it.

use rapier3d::glamx::DVec3;

/// The inverse mass (1/kg) of a node of mass `mass` (kg): zero when `pinned`.
pub(crate) fn node_inverse_mass(mass: f64, pinned: bool) -> f64 {
    if pinned { 0.0 } else { 1.0 / mass }
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
