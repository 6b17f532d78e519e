//! The Newton direction of an implicit step: the exact tangent's solution for the
//! out-of-balance force, solved again where it would carry contact points onto stiffer pieces
//! of their penalty or friction.
//!
//! A contact's penalty `k/2 min(0, g)²` (with its stiffenings beyond given depths) and its
//! lagged friction (quadratic within the stick zone, linear beyond) are piecewise quadratic:
//! the tangent at a point in front of its plane has no penalty in it, and at a sliding point no
//! stiffness along the slip. A direction computed there carries the points it moves through
//! their planes deep into the obstacle, or through the stick zone, where the stiff piece sends
//! the line search back to a sliver of the step; each iteration then brings only the next few
//! points onto their new piece (the showcase's gel ball, landing at 2.2 m/s, took 47 and 79
//! iterations a frame, then gave the frame up to 0.36 s of explicit substeps). So the system is
//! solved again with the pieces the direction lands on
//! ([`contact::for_each_engaged_term`](crate::contact::for_each_engaged_term)), as a primal–dual
//! active-set method does, up to [`ENGAGING_ROUNDS`] times, as long as the new direction still
//! descends the true potential: the line search judges every step on it, so the minimizer is
//! the one it was (the gel ball's impact frame: 12 iterations, no explicit frame). The rounds
//! solve at the same positions, so they add their pieces to a kept copy of the iteration's
//! tangent ([`UnengagedTangent`]) instead of assembling every element again.

use super::potential::{Engaged, Potential};
use super::report::Outcome;
use super::{ImplicitIntegrator, Solver};
use crate::Error;
use crate::assembly::{Factor, Stiffness};
use crate::body::DeformableBody;
use crate::linear_solver::{Method, solve_newton_system};
use crate::newton::dot;
use rapier3d::glamx::DVec3;

/// A Newton system is solved again, with the pieces its direction lands on, at most this many
/// times.
const ENGAGING_ROUNDS: usize = 3;

impl ImplicitIntegrator {
    /// The Newton direction (m per node) for `residual` (N) with the exact tangent (`inertia` its
    /// `m/ĥ²` per node), solved again with the contact pieces it lands on (see the module's
    /// documentation); the chord keeps the factorization of the direction taken, when one was
    /// made.
    pub(super) fn exact_direction(
        &self,
        body: &DeformableBody,
        solver: &mut Solver,
        incremental: &Potential,
        inertia: &[f64],
        residual: &[DVec3],
        outcome: &mut Outcome,
    ) -> Result<Vec<DVec3>, Error> {
        let mut tangent = UnengagedTangent::default();
        let solve = |rhs: &[DVec3], engaged: Option<&Engaged>| {
            let system = (inertia, rhs, engaged);
            let tangent = &mut tangent;
            self.solve_direction(body, (&mut *solver, incremental, tangent), system, outcome)
        };
        let (direction, factor) = engaging(residual, solve, |d| incremental.engaged(body, d))?;
        if let Some(factor) = factor.flatten()
            && self.reuse_factorization
        {
            let correction = incremental.kept_correction(body);
            solver.chord.keep(factor, incremental.start.h, correction);
            #[cfg(feature = "serde-serialize")]
            solver.chord.remember(&solver.stiffness);
        }
        Ok(direction)
    }

    /// The solution (m per node) of the Newton system for the right-hand side `rhs` (N), with the
    /// exact tangent (`inertia` its `m/ĥ²` per node; assembled once per projection into
    /// `tangent`) and the `engaged` contacts' tangents, and its factorization if a direct solve
    /// made one.
    fn solve_direction(
        &self,
        body: &DeformableBody,
        (solver, incremental, tangent): (&mut Solver, &Potential, &mut UnengagedTangent),
        (inertia, rhs, engaged): (&[f64], &[DVec3], Option<&Engaged>),
        outcome: &mut Outcome,
    ) -> Result<(Vec<DVec3>, Option<Factor>), Error> {
        // The exact Hessian converges fastest; where it is indefinite (compressed elements)
        // the per-element projection restores a descent direction.
        let solution = solve_newton_system(
            solver.method,
            self.tolerance / outcome.residual,
            &mut solver.stiffness,
            rhs,
            outcome.iterations,
            |stiffness, project| {
                tangent.fill(stiffness, project, (engaged, &body.pinned), |stiffness| {
                    incremental.assemble(body, stiffness, inertia, project);
                });
            },
        )?;
        outcome.linear_iterations += solution.cg_iterations;
        outcome.factorizations += solution.factorizations;
        outcome.projected_tangents += usize::from(solution.projected);
        if solution.fell_back {
            solver.method = Method::Direct;
        }
        let mut direction = solution.direction;
        if let Some(factor) = &solution.factor {
            direction = incremental.take_in_unassembled(body, (factor, false), rhs, direction);
        }
        Ok((direction, solution.factor))
    }
}

/// A Newton iteration's tangent without the engaged contact pieces, assembled once per
/// projection: every solve of the iteration is at the same positions, so the engaging rounds
/// add their pieces to a kept copy of its values (the same values to the bit) instead of
/// assembling every element again. In the game scene a third of the assemblies were such rounds.
#[derive(Debug, Default)]
pub(super) struct UnengagedTangent {
    /// Whether the tangent in the matrix was assembled projected; `None` before it was.
    projected: Option<bool>,
    /// Its values, kept once a round adds pieces to them.
    kept: Option<Vec<f64>>,
}

impl UnengagedTangent {
    /// Fills `stiffness` with the tangent, projected if `project` (assembled by `assemble` unless
    /// it was last assembled so), plus the `engaged` pieces, none on the `pinned` nodes.
    pub(super) fn fill(
        &mut self,
        stiffness: &mut Stiffness,
        project: bool,
        (engaged, pinned): (Option<&Engaged>, &[bool]),
        assemble: impl FnOnce(&mut Stiffness),
    ) {
        if self.projected == Some(project) {
            match &self.kept {
                Some(kept) => stiffness.values.copy_from_slice(kept),
                // Nothing was added to the values since they were assembled.
                None => self.kept = Some(stiffness.values.clone()),
            }
        } else {
            assemble(stiffness);
            self.projected = Some(project);
            self.kept = engaged.map(|_| stiffness.values.clone());
        }
        if let Some(engaged) = engaged {
            engaged.add_to(stiffness, pinned);
        }
    }
}

/// The direction (m per node) `solve(rhs, engaged)` gives for the out-of-balance force
/// `residual` (N), solved again, up to [`ENGAGING_ROUNDS`] times, with the contact pieces
/// `engaged_for(direction)` finds it landing on, while the new direction still descends (see the
/// module's documentation); with what the solve of the direction taken returned beside it
/// (`None` when a later solve was not taken: the system last solved is not that direction's).
pub(super) fn engaging<T>(
    residual: &[DVec3],
    mut solve: impl FnMut(&[DVec3], Option<&Engaged>) -> Result<(Vec<DVec3>, T), Error>,
    engaged_for: impl Fn(&[DVec3]) -> Option<Engaged>,
) -> Result<(Vec<DVec3>, Option<T>), Error> {
    let (mut direction, solved) = solve(residual, None)?;
    let mut taken = Some(solved);
    for _ in 0..ENGAGING_ROUNDS {
        let Some(engaged) = engaged_for(&direction) else {
            break;
        };
        let rhs: Vec<DVec3> = (residual.iter().zip(&engaged.forces))
            .map(|(r, f)| *r + *f)
            .collect();
        let (again, solved) = solve(&rhs, Some(&engaged))?;
        let descent = dot(residual, &again);
        if descent <= 0.0 {
            taken = None;
            break;
        }
        (direction, taken) = (again, Some(solved));
    }
    Ok((direction, taken))
}
