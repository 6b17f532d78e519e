//! A deformable body seen as a rigid body, and how far from rigid it is.
//!
//! The rigid body has the nodes' mass `M = Σ mᵢ`, centre `c = Σ mᵢ xᵢ / M` and inertia tensor
//! `I = Σ mᵢ (|rᵢ|² 𝟙 − rᵢ rᵢᵀ)` about it (`rᵢ = xᵢ − c`), and the nodes' momentum: `V = P / M`
//! with `P = Σ mᵢ vᵢ`, `ω = I⁻¹ L` with `L = Σ mᵢ rᵢ × vᵢ`. Carried back, `vᵢ = V + ω × rᵢ` gives
//! `Σ mᵢ vᵢ = M V = P` and `Σ mᵢ rᵢ × vᵢ = I ω = L`: both switches keep the momentum, and the
//! kinetic energy of the rigid motion; the switch to rigid drops the vibration's (`vᵢ` minus
//! the rigid motion), which it allows only when small.
//!
//! Strain: the largest Frobenius norm of the Green strain `G = (FᵀF − 𝟙)/2` over the
//! integration points (at least the largest principal strain), plus the largest vibration speed
//! over the slowest dilatational wave speed, `|vᵢ − V − ω × rᵢ| / c`: a wave of particle speed
//! `v` carries the strain `v / c`.

use crate::body::{DeformableBody, spin_of};
use crate::element::deformation_gradient;
use rapier3d::glamx::{DMat3, DVec3};

/// A body's rigid motion: its mass (kg), centre of mass (m), inertia tensor about it (kg m²),
/// velocity (m/s) and angular velocity (rad/s), and each node's offset from the centre (m).
pub(super) struct RigidMotion {
    pub(super) mass: f64,
    pub(super) center: DVec3,
    pub(super) inertia: DMat3,
    pub(super) linvel: DVec3,
    pub(super) angvel: DVec3,
    pub(super) offsets: Vec<DVec3>,
}

impl RigidMotion {
    /// `body`'s rigid motion; `None` for an inertia tensor that cannot be inverted (nodes on a
    /// line).
    pub(super) fn of(body: &DeformableBody) -> Option<Self> {
        let mass = body.total_mass();
        let center = body.center_of_mass();
        let inertia = body.inertia_about(center);
        Some(Self {
            mass,
            center,
            inertia,
            linvel: body.linear_momentum() / mass,
            angvel: spin_of(inertia, body.angular_momentum())?,
            offsets: body.positions().iter().map(|&x| x - center).collect(),
        })
    }

    /// The largest speed (m/s) of a node of `body` relative to this rigid motion.
    pub(super) fn vibration_speed(&self, body: &DeformableBody) -> f64 {
        (body.velocities().iter().zip(&self.offsets))
            .map(|(&v, &r)| (v - self.linvel - self.angvel.cross(r)).length())
            .fold(0.0, f64::max)
    }
}

/// The largest Frobenius norm (dimensionless) of the Green strain over `body`'s integration
/// points.
pub(super) fn peak_green_strain(body: &DeformableBody) -> f64 {
    let mut peak = 0.0_f64;
    let x = body.positions();
    body.elements.for_each_point(|_, nodes, gradients, _| {
        let f = deformation_gradient(nodes, gradients, x);
        let green = (f.transpose() * f - DMat3::IDENTITY) * 0.5;
        let norm = (green.x_axis.length_squared()
            + green.y_axis.length_squared()
            + green.z_axis.length_squared())
        .sqrt();
        peak = peak.max(norm);
    });
    peak
}

/// The smallest Young's modulus (Pa) and dilatational wave speed (m/s) over `body`'s
/// elements.
pub(super) fn softest(body: &DeformableBody) -> (f64, f64) {
    let materials = (0..body.element_count()).filter_map(|e| body.element_material(e));
    let materials: Vec<_> = if body.has_region_materials() {
        materials.collect()
    } else {
        vec![*body.material()]
    };
    materials
        .iter()
        .fold((f64::INFINITY, f64::INFINITY), |(e, c), m| {
            (
                e.min(m.elasticity().young_modulus),
                c.min(m.dilatational_wave_speed()),
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::DeformableBodyBuilder;
    use crate::material::{Material, MaterialModel};
    use crate::mesh;

    #[test]
    fn the_rigid_motion_carries_the_nodes_momentum() {
        // Closed form: vᵢ = V + ω × rᵢ with V = P / M, ω = I⁻¹ L gives Σ mᵢ vᵢ = P and
        // Σ mᵢ rᵢ × vᵢ = L exactly; in f64, to 1e-12 of their size.
        let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
        let mut body = DeformableBodyBuilder::new(
            mesh::cuboid(DVec3::new(0.2, 0.1, 0.05), [3, 2, 1]).unwrap(),
            material,
        )
        .translation(DVec3::new(0.3, 1.0, -0.2))
        .build()
        .unwrap();
        for (i, v) in body.velocities_mut().iter_mut().enumerate() {
            let t = i as f64;
            *v = DVec3::new((t * 0.7).sin(), (t * 1.3).cos(), (t * 0.4).sin() - 0.2);
        }
        let (p, l) = (body.linear_momentum(), body.angular_momentum());
        let motion = RigidMotion::of(&body).unwrap();
        for (v, r) in body.velocities_mut().iter_mut().zip(&motion.offsets) {
            *v = motion.linvel + motion.angvel.cross(*r);
        }
        assert!((body.linear_momentum() - p).length() < 1e-12 * p.length());
        assert!((body.angular_momentum() - l).length() < 1e-12 * l.length());
        assert!(motion.vibration_speed(&body) < 1e-12);
    }
}
