//! An implicit step's internal forces and energy: the elastic ones and the damping's, whose
//! strain rate is the Green strain's change over the step, `Ġ = (G(F) − G_prev)/h` (see
//! [`RayleighDamping::step_potential`]); the forces are `−w (P(F) + F σ_damp(Ġ)) ∇N_a` and the
//! energy `Σ w (Ψ(F) + D(F))`, each integration point's `F` found once for both parts.
//!
//! [`RayleighDamping::step_potential`]: crate::damping::RayleighDamping::step_potential

use super::{Elements, deformation_gradient};
use crate::damping::StepDamping;
use crate::material::VolumetricTerm;
use rapier3d::glamx::{DMat3, DVec3};

impl Elements {
    /// Writes into `out` the internal force (N) on every node at positions `x` (m) in an
    /// implicit step: the elastic force and, with `damping`, the step's damping force (the
    /// gradient of its dissipation potential, its rate measured from each integration point's
    /// Green strain), each point's `F` found once.
    pub(crate) fn step_forces<M: VolumetricTerm>(
        &mut self,
        model: &M,
        damping: Option<StepDamping>,
        x: &[DVec3],
        out: &mut [DVec3],
    ) {
        if let Self::Linear {
            fvm,
            nodal_averaging,
        } = self
        {
            fvm.step_forces(model, damping, x, out);
            if let Some(averaging) = nodal_averaging {
                averaging.add_forces(model, fvm, x, out);
            }
            return;
        }
        self.point_forces(model, x, out, |point, _, _, f| {
            damping.map_or(DMat3::ZERO, |step| {
                (step.damping).step_first_piola(f, &step.green[point], step.h)
            })
        });
    }

    /// The elastic energy (J) at positions `x` (m) and, with `damping`, the step's dissipation
    /// potential (its rate measured from each integration point's Green strain); on linear
    /// tetrahedra without averaging in one pass that finds each `F` once.
    pub(crate) fn step_energy<M: VolumetricTerm>(
        &self,
        model: &M,
        damping: Option<StepDamping>,
        x: &[DVec3],
    ) -> f64 {
        if let Self::Linear {
            fvm,
            nodal_averaging: None,
        } = self
        {
            return fvm.step_energy(model, damping, x);
        }
        let dissipation = damping.map_or(0.0, |step| {
            self.sum_over_points(|point, nodes, gradients, weight| {
                let f = deformation_gradient(nodes, gradients, x);
                weight * (step.damping).step_potential(&f, &step.green[point], step.h)
            })
        });
        self.elastic_energy(model, x) + dissipation
    }
}
