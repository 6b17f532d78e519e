//! What a 2D body's elasticity gives at some positions: its energy, the nodal forces and the
//! tangent `K = −∂f/∂x`, with the volumetric term per point or averaged over groups of points
//! ([`super::volumetric`]).
//!
//! Per integration point `q` ([`super::points`]), with `F` its deformation gradient and `w` its
//! rest area: the energy `t w Ψ(F)`, the forces `f_a = −t w P ∇N_a` (for a linear triangle the
//! finite-volume `t P b_a`) and the tangent block `K_ab = t w dP(e ⊗ ∇N_b) ∇N_a`; with nodal
//! averaging `Ψ` becomes `Ψ_rest`, `P` the point's stress `P + K (θ̄ − m) ∂m/∂F`, and `dP` that
//! stress's differential at fixed averages, the patch term added by [`patch_tangent`].

use super::body::PlanarBody;
use super::plane::{PlanarLaw, PlanarStress, apply_tangent};
use super::volumetric::Averages;
use crate::material::VolumetricTerm;
use faer::sparse::Triplet;
use rapier3d::glamx::{DMat2, DMat3, DVec2};

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
    /// See [`PlanarLaw::volume_gradient_across`].
    fn volume_gradient_across(&self, f: &DMat2) -> f64;
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
    fn volume_gradient_across(&self, f: &DMat2) -> f64 {
        PlanarLaw::volume_gradient_across(self, f)
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
        let points = self.points();
        let gradients: Vec<DMat2> = (0..points.len())
            .map(|q| points.gradient(q, positions))
            .collect();
        let averages = self.averaging.as_ref().map(|averaging| {
            let measures = gradients.iter().map(|f| law.volume_measure(f)).collect();
            averaging.averages(points, measures)
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
        let points = self.points();
        let elements: f64 = (evaluation.gradients.iter().enumerate())
            .map(|(q, f)| per_area(f) * points.weight(q))
            .sum();
        let averaged = (self.averaging.as_ref().zip(evaluation.averages.as_ref()))
            .map_or(0.0, |(v, a)| v.energy(a, law.bulk_modulus()));
        (elements + averaged) * self.thickness()
    }

    /// Point `q`'s stress (Pa) in `evaluation`: the model's, plus the averaged volumetric
    /// term's correction `K (θ̄ − m) ∂m/∂F`.
    pub(super) fn point_stress(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        q: usize,
    ) -> DMat2 {
        let f = &evaluation.gradients[q];
        let p = law.stress(f).p;
        match &evaluation.averages {
            Some(a) => {
                p + law.volume_gradient(f) * (law.bulk_modulus() * (a.point[q] - a.measure[q]))
            }
            None => p,
        }
    }

    /// Point `q`'s stress in `evaluation` (see [`PlanarStress`]): the model's, with an averaged
    /// volumetric term's correction `K (θ̄ − m) ∂m/∂F₃` in both `P` and `P₃₃` (averaging is
    /// plane strain's, at unit stretch).
    pub(super) fn point_planar_stress(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        q: usize,
    ) -> PlanarStress {
        let f = &evaluation.gradients[q];
        let stress = law.stress(f);
        match &evaluation.averages {
            Some(a) => {
                let shift = law.bulk_modulus() * (a.point[q] - a.measure[q]);
                PlanarStress {
                    p: stress.p + law.volume_gradient(f) * shift,
                    p33: stress.p33 + law.volume_gradient_across(f) * shift,
                    ..stress
                }
            }
            None => stress,
        }
    }

    /// The Cauchy stress (Pa, 3×3 with `σ₃₃` across the plane) of each element where the body
    /// is: its integration point's for a linear triangle, the mean of its three points' for a
    /// quadratic one, with an averaged volumetric term as the forces take it.
    pub fn cauchy_stresses(&self) -> Vec<DMat3> {
        self.with_law(|law| {
            let evaluation = self.evaluate(law, self.positions());
            let per_element = self.points().per_element();
            let cauchy = |q: usize| {
                (self.point_planar_stress(law, &evaluation, q)).cauchy(&evaluation.gradients[q])
            };
            (0..self.points().len() / per_element)
                .map(|e| {
                    let sum: DMat3 = (0..per_element).map(|k| cauchy(e * per_element + k)).sum();
                    sum * (1.0 / per_element as f64)
                })
                .collect()
        })
    }

    /// The nodal forces (N) of `evaluation`.
    pub(super) fn forces_of(&self, law: &dyn PlanarLawDyn, evaluation: &Evaluation) -> Vec<DVec2> {
        let mut forces = vec![DVec2::ZERO; self.positions().len()];
        for q in 0..self.points().len() {
            let p = self.point_stress(law, evaluation, q);
            self.points()
                .add_forces(q, &p, self.thickness(), &mut forces);
        }
        forces
    }

    /// Point `q`'s stress differential for a change `df` of its `F`, the averages held.
    fn point_differential(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        q: usize,
        columns: &[DMat2; 4],
        df: &DMat2,
    ) -> DMat2 {
        let dp = apply_tangent(columns, df);
        let Some(a) = &evaluation.averages else {
            return dp;
        };
        let f = &evaluation.gradients[q];
        let (k, g) = (law.bulk_modulus(), law.volume_gradient(f));
        let dm = g.x_axis.dot(df.x_axis) + g.y_axis.dot(df.y_axis);
        dp - g * (k * dm) + law.volume_differential(f, df) * (k * (a.point[q] - a.measure[q]))
    }

    /// Adds the points' tangent blocks of `evaluation` to `triplets`, over the unknowns of
    /// `index` (per node and axis, `None` where held).
    pub(super) fn element_tangent(
        &self,
        law: &dyn PlanarLawDyn,
        evaluation: &Evaluation,
        index: &[[Option<usize>; 2]],
        triplets: &mut Vec<Triplet<usize, usize, f64>>,
    ) {
        let points = self.points();
        for q in 0..points.len() {
            let columns = law.tangent(&evaluation.gradients[q]);
            let nodes = points.nodes(q);
            for (j, &node_j) in nodes.iter().enumerate() {
                for (b, direction) in [DVec2::X, DVec2::Y].into_iter().enumerate() {
                    let Some(col) = index[node_j as usize][b] else {
                        continue;
                    };
                    let df = points.gradient_change(q, j, direction);
                    let dp = self.point_differential(law, evaluation, q, &columns, &df);
                    for (i, &node_i) in nodes.iter().enumerate() {
                        let k = (-points.force(q, i, &dp, self.thickness())).to_array();
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

/// Adds the averaging's term `Σ_g t W_g K g_g g_gᵀ` to `triplets` (nothing without
/// averaging).
pub(super) fn patch_tangent(
    body: &PlanarBody,
    law: &dyn PlanarLawDyn,
    evaluation: &Evaluation,
    index: &[[Option<usize>; 2]],
    triplets: &mut Vec<Triplet<usize, usize, f64>>,
) {
    let Some(averaging) = &body.averaging else {
        return;
    };
    let points = body.points();
    // ∂m_q/∂x_a = ∂m/∂F ∇N_a.
    let measure_gradients: Vec<Vec<DVec2>> = (evaluation.gradients.iter().enumerate())
        .map(|(q, f)| {
            let g = law.volume_gradient(f);
            points.gradients(q).iter().map(|n| g * *n).collect()
        })
        .collect();
    let gradients = averaging.average_gradients(points, &measure_gradients);
    let k = law.bulk_modulus() * body.thickness();
    for (a, entries) in gradients.iter().enumerate() {
        let weight = k * averaging.weight(a);
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
