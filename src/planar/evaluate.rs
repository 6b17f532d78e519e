//! What a 2D body's elasticity gives at some positions: its energy, the nodal forces and the
//! tangent `K = −∂f/∂x`, with the volumetric term per triangle or averaged on node patches
//! ([`super::volumetric`]).
//!
//! Per triangle, with `F` its deformation gradient: the energy `t A Ψ(F)`, the forces
//! `f_i = t P b_i` ([`super::TriangleRest::forces`]) and the tangent block
//! `K_ij = −t dP(e ⊗ ∇N_j) b_i`; with nodal averaging `Ψ` becomes `Ψ_rest`, `P` the element stress
//! `P + K (θ̄ − m) ∂m/∂F`, and `dP` that stress's differential at fixed averages, the patch term
//! added by [`patch_tangent`].

use super::body::PlanarBody;
use super::plane::{PlanarLaw, PlanarStress, apply_tangent};
use super::volumetric::Averages;
use crate::material::VolumetricTerm;
use faer::sparse::Triplet;
use rapier3d::glamx::{DMat2, DVec2};

/// A [`PlanarLaw`] whatever its model, for the body's loops.
pub(super) trait PlanarLawDyn {
    /// See [`PlanarLaw::stress`].
    fn stress(&self, f: &DMat2) -> PlanarStress;
    /// See [`PlanarLaw::energy_density`].
    fn energy_density(&self, f: &DMat2) -> f64;
    /// See [`PlanarLaw::tangent`].
    fn tangent(&self, f: &DMat2) -> [DMat2; 4];
    /// See [`PlanarLaw::bulk_modulus`].
    fn bulk_modulus(&self) -> f64;
    /// See [`PlanarLaw::volume_measure`].
    fn volume_measure(&self, f: &DMat2) -> f64;
    /// See [`PlanarLaw::volume_gradient`].
    fn volume_gradient(&self, f: &DMat2) -> DMat2;
    /// See [`PlanarLaw::volume_differential`].
    fn volume_differential(&self, f: &DMat2, df: &DMat2) -> DMat2;
    /// See [`PlanarLaw::energy_without_volumetric`].
    fn energy_without_volumetric(&self, f: &DMat2) -> f64;
}

impl<M: VolumetricTerm> PlanarLawDyn for PlanarLaw<M> {
    fn stress(&self, f: &DMat2) -> PlanarStress {
        PlanarLaw::stress(self, f)
    }
    fn energy_density(&self, f: &DMat2) -> f64 {
        PlanarLaw::energy_density(self, f)
    }
    fn tangent(&self, f: &DMat2) -> [DMat2; 4] {
        PlanarLaw::tangent(self, f)
    }
    fn bulk_modulus(&self) -> f64 {
        PlanarLaw::bulk_modulus(self)
    }
    fn volume_measure(&self, f: &DMat2) -> f64 {
        PlanarLaw::volume_measure(self, f)
    }
    fn volume_gradient(&self, f: &DMat2) -> DMat2 {
        PlanarLaw::volume_gradient(self, f)
    }
    fn volume_differential(&self, f: &DMat2, df: &DMat2) -> DMat2 {
        PlanarLaw::volume_differential(self, f, df)
    }
    fn energy_without_volumetric(&self, f: &DMat2) -> f64 {
        PlanarLaw::energy_without_volumetric(self, f)
    }
}

/// The triangles' deformation gradients at some positions and, with nodal averaging, the
/// averages of their volume measures.
pub(super) struct Evaluation {
    pub(super) gradients: Vec<DMat2>,
    pub(super) averages: Option<Averages>,
}

impl PlanarBody {
    /// The evaluation of `positions` (m) under `law`.
    pub(super) fn evaluate(&self, law: &dyn PlanarLawDyn, positions: &[DVec2]) -> Evaluation {
        let gradients: Vec<DMat2> = (self.triangle_rest().iter().enumerate())
            .map(|(t, rest)| rest.gradient(&self.corners_in(t, positions)))
            .collect();
        let averages = self.patches.as_ref().map(|patches| {
            let measures = gradients.iter().map(|f| law.volume_measure(f)).collect();
            patches.averages(self.mesh(), self.triangle_rest(), measures)
        });
        Evaluation {
            gradients,
            averages,
        }
    }

    /// The elastic energy (J) of `evaluation`.
    pub(super) fn energy_of(&self, law: &dyn PlanarLawDyn, evaluation: &Evaluation) -> f64 {
        let per_area = |f: &DMat2| match evaluation.averages {
            Some(_) => law.energy_without_volumetric(f),
            None => law.energy_density(f),
        };
        let elements: f64 = (self.triangle_rest().iter().zip(&evaluation.gradients))
            .map(|(rest, f)| per_area(f) * rest.area())
            .sum();
        let patches = (self.patches.as_ref().zip(evaluation.averages.as_ref()))
            .map_or(0.0, |(p, a)| p.energy(a, law.bulk_modulus()));
        (elements + patches) * self.thickness()
    }

    /// Triangle `t`'s stress (Pa) in `evaluation`: the model's, plus the averaged volumetric
    /// term's correction `K (θ̄ − m) ∂m/∂F`.
    pub(super) fn element_stress(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        t: usize,
    ) -> DMat2 {
        let f = &evaluation.gradients[t];
        let p = law.stress(f).p;
        match &evaluation.averages {
            Some(a) => {
                p + law.volume_gradient(f) * (law.bulk_modulus() * (a.element[t] - a.measure[t]))
            }
            None => p,
        }
    }

    /// The nodal forces (N) of `evaluation`.
    pub(super) fn forces_of(&self, law: &dyn PlanarLawDyn, evaluation: &Evaluation) -> Vec<DVec2> {
        let mut forces = vec![DVec2::ZERO; self.positions().len()];
        for (t, rest) in self.triangle_rest().iter().enumerate() {
            let p = self.element_stress(law, evaluation, t);
            let nodes = self.mesh().triangles()[t];
            for (node, force) in nodes.iter().zip(rest.forces(&p, self.thickness())) {
                forces[*node as usize] += force;
            }
        }
        forces
    }

    /// Triangle `t`'s stress differential for a change `df` of its `F`, the averages held.
    fn element_differential(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        t: usize,
        columns: &[DMat2; 4],
        df: &DMat2,
    ) -> DMat2 {
        let dp = apply_tangent(columns, df);
        let Some(a) = &evaluation.averages else {
            return dp;
        };
        let f = &evaluation.gradients[t];
        let (k, g) = (law.bulk_modulus(), law.volume_gradient(f));
        let dm = g.x_axis.dot(df.x_axis) + g.y_axis.dot(df.y_axis);
        dp - g * (k * dm) + law.volume_differential(f, df) * (k * (a.element[t] - a.measure[t]))
    }

    /// Adds the elements' tangent blocks of `evaluation` to `triplets`, over the unknowns of
    /// `index` (per node and axis, `None` where held).
    pub(super) fn element_tangent(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        index: &[[Option<usize>; 2]],
        triplets: &mut Vec<Triplet<usize, usize, f64>>,
    ) {
        for (t, rest) in self.triangle_rest().iter().enumerate() {
            let columns = law.tangent(&evaluation.gradients[t]);
            let nodes = self.mesh().triangles()[t];
            for (j, &node_j) in nodes.iter().enumerate() {
                for (b, direction) in [DVec2::X, DVec2::Y].into_iter().enumerate() {
                    let Some(col) = index[node_j as usize][b] else {
                        continue;
                    };
                    let df = rest.gradient_change(j, direction);
                    let dp = self.element_differential(law, evaluation, t, &columns, &df);
                    for (i, &node_i) in nodes.iter().enumerate() {
                        let k = (-(dp * rest.normals()[i]) * self.thickness()).to_array();
                        for (a, row) in index[node_i as usize].iter().enumerate() {
                            if let Some(row) = row {
                                triplets.push(Triplet::new(*row, col, k[a]));
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Adds the patch term `Σ_a t W_a K g_a g_aᵀ` of nodal averaging to `triplets` (nothing
/// without it).
pub(super) fn patch_tangent(
    body: &PlanarBody,
    law: &dyn PlanarLawDyn,
    evaluation: &Evaluation,
    index: &[[Option<usize>; 2]],
    triplets: &mut Vec<Triplet<usize, usize, f64>>,
) {
    let Some(patches) = &body.patches else { return };
    // ∂m_e/∂x at corner i is ∂m/∂F ∇N_i = −∂m/∂F b_i / A.
    let measure_gradients: Vec<[DVec2; 3]> =
        (body.triangle_rest().iter().zip(&evaluation.gradients))
            .map(|(rest, f)| {
                let g = law.volume_gradient(f);
                rest.normals().map(|b| -(g * b) / rest.area())
            })
            .collect();
    let gradients =
        patches.average_gradients(body.mesh(), body.triangle_rest(), &measure_gradients);
    let k = law.bulk_modulus() * body.thickness();
    for (a, entries) in gradients.iter().enumerate() {
        let weight = k * patches.control_area(a);
        for &(col_node, g_col) in entries {
            for (b, col) in index[col_node as usize].iter().enumerate() {
                let Some(col) = col else { continue };
                for &(row_node, g_row) in entries {
                    for (c, row) in index[row_node as usize].iter().enumerate() {
                        if let Some(row) = row {
                            triplets.push(Triplet::new(*row, *col, weight * g_row[c] * g_col[b]));
                        }
                    }
                }
            }
        }
    }
}
