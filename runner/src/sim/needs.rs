//! What a soft body's motion asked of its model, measured every frame for the report (the
//! first thing an advisor needs to choose a cheaper model): the largest principal Green strain
//! and the largest element rotation from the body's placement, and the frames in which a
//! collider pushed it (a contact of its last substep carried an impulse).
//!
//! Per tetrahedron, `F = D_x D_p⁻¹` (edge vectors now against those at the placement), its
//! singular values `F = U Σ Vᵀ` give the principal Green strains `(σᵢ² − 1)/2` and the rotation
//! of its polar decomposition `R = U Vᵀ` (a sign-fixed `U` when `det F < 0`), whose angle is
//! `θ = acos((tr R − 1)/2)`. A rotation `θ` gives the linear model the spurious strain
//! `ε = sym(R) − I` with principal values `cos θ − 1` (twice) and 0, so a spurious von Mises
//! stress `2μ (1 − cos θ) = E (1 − cos θ)/(1 + ν)`: the report gives
//! `(1 − cos θ)/(1 + ν)`, that stress over `E`, at the peak rotation (1e-3 at 2.9° and 1e-2 at
//! 9.2° for ν = 0.3), to weigh against the peak strain the body needed.

use rapier_fvm::body::DeformableBody;
use rapier_fvm::glamx::{DMat3, DVec3};
use rapier3d::na::Matrix3;
use rayon::prelude::*;
use serde::Serialize;

/// The peaks of a body's strain and rotation over a run, and its frames in contact.
#[derive(Debug, Clone, Default, Serialize)]
pub struct BodyNeeds {
    /// The largest principal Green strain in magnitude, `|(σᵢ² − 1)/2|`, over the elements and
    /// frames (dimensionless).
    pub peak_green_strain: f64,
    /// The largest rotation of an element from the body's placement (degrees, 0 to 180).
    pub peak_rotation_deg: f64,
    /// The linear model's spurious von Mises stress over Young's modulus at that rotation,
    /// `(1 − cos θ)/(1 + ν)`.
    pub linear_spurious_stress_over_e: f64,
    /// Frames whose last substep a collider's contact pushed the body in (an impulse, not a
    /// contact merely within reach).
    pub contact_frames: usize,
    /// Whether the body ended the last frame asleep (its nodes have not moved since).
    #[serde(skip)]
    was_asleep: bool,
}

/// An element's principal Green strain of largest magnitude and rotation angle (rad) for the
/// deformation gradient `f`.
pub fn strain_and_rotation(f: DMat3) -> (f64, f64) {
    let m = Matrix3::from_column_slice(&f.to_cols_array());
    let svd = m.svd(true, true);
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return (f64::NAN, f64::NAN);
    };
    if u.determinant() * v_t.determinant() < 0.0 {
        let mut last = u.column_mut(2);
        last *= -1.0;
    }
    let rotation = u * v_t;
    let cos = ((rotation.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let strain = (svd.singular_values.iter())
        .map(|s| ((s * s - 1.0) / 2.0).abs())
        .fold(0.0, f64::max);
    (strain, cos.acos())
}

impl BodyNeeds {
    /// Takes in the frame's state of `body`, placed at `placement` (the node positions before
    /// the first step, m), pushed by a collider in the frame if `touching`, ending it `asleep`
    /// or not (a body asleep at both ends of the frame has not moved: its elements are not
    /// measured again).
    pub fn record(
        &mut self,
        body: &DeformableBody,
        placement: &[DVec3],
        (touching, asleep): (bool, bool),
    ) {
        self.contact_frames += usize::from(touching);
        let unmoved = asleep && self.was_asleep;
        self.was_asleep = asleep;
        if unmoved {
            return;
        }
        let x = body.positions();
        let mut peak_rotation = self.peak_rotation_deg.to_radians();
        // On rayon's pool, as the step is: a serial pass left its threads asleep for the next
        // step to wake (6 % of the showcase's stepping time, measured).
        let (strain, rotation) = (body.mesh().tets().par_iter())
            .map(|tet| {
                let [a, b, c, d] = tet.map(|n| n as usize);
                let edges = |p: &[DVec3]| DMat3::from_cols(p[b] - p[a], p[c] - p[a], p[d] - p[a]);
                strain_and_rotation(edges(x) * edges(placement).inverse())
            })
            .reduce(|| (0.0, 0.0), |(s, r), (t, q)| (s.max(t), r.max(q)));
        self.peak_green_strain = self.peak_green_strain.max(strain);
        peak_rotation = peak_rotation.max(rotation);
        self.peak_rotation_deg = peak_rotation.to_degrees();
        let poisson = body.material().elasticity().poisson_ratio;
        self.linear_spurious_stress_over_e = (1.0 - peak_rotation.cos()) / (1.0 + poisson);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier_fvm::glamx::DQuat;

    #[test]
    fn a_stretch_and_a_rotation_are_read_back_to_round_off() {
        // Closed form: a stretch of 1.01 along x has the Green strain (1.01² − 1)/2 = 0.01005;
        // turned by 30° about an oblique axis, the rotation is 30°; an inverted element (a
        // reflection) keeps its rotation angle 0 and strain 0.
        let stretch = DMat3::from_diagonal(DVec3::new(1.01, 1.0, 1.0));
        let turn = DMat3::from_quat(DQuat::from_axis_angle(
            DVec3::new(1.0, 2.0, 3.0).normalize(),
            30f64.to_radians(),
        ));
        let (strain, rotation) = strain_and_rotation(turn * stretch);
        assert!((strain - 0.01005).abs() < 1e-12, "{strain}");
        assert!(
            (rotation.to_degrees() - 30.0).abs() < 1e-9,
            "{}",
            rotation.to_degrees()
        );
        let reflection = DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0));
        let (strain, rotation) = strain_and_rotation(reflection);
        assert!(
            strain.abs() < 1e-12 && rotation.abs() < 1e-9,
            "{strain} {rotation}"
        );
    }
}
