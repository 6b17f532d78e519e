//! The Newton systems of 2D bodies: which coordinates are unknown (the held axes are not), the
//! positions Newton moves ([`crate::newton::Configuration`]), the solve of `K d = r` by faer's
//! sparse Cholesky factorization, and Newton's iterations on a potential ([`minimize`]), shared
//! by the static and the implicit solvers, with the 3D solvers' line search, tolerance and
//! round-off floor.

use super::body::PlanarBody;
use super::evaluate::patch_tangent;
use crate::Error;
use crate::assembly::{Factor, SymbolicFactor};
use crate::newton::{
    Configuration, Search, accepted_within, descend, norm, stalled_at_round_off, without_descent,
};
use crate::statics::StaticSettings;
use faer::Mat;
use faer::sparse::{SparseColMat, Triplet};
use rapier3d::glamx::DVec2;

/// A triplet `(row, column, value)` of a sparse matrix being assembled.
pub(super) type Entry = Triplet<usize, usize, f64>;

/// The unknowns of a body's Newton system: per node and axis, the index of the coordinate
/// among them, or `None` where the axis is held.
pub(super) struct Unknowns {
    pub(super) index: Vec<[Option<usize>; 2]>,
    pub(super) count: usize,
}

impl Unknowns {
    /// The unknowns of a body held along the `pinned` axes.
    pub(super) fn new(pinned: &[[bool; 2]]) -> Self {
        let mut count = 0;
        let mut number = |held: bool| {
            (!held).then(|| {
                count += 1;
                count - 1
            })
        };
        let index = pinned
            .iter()
            .map(|p| [number(p[0]), number(p[1])])
            .collect();
        Self { index, count }
    }

    /// `forces` (N per node) with the held axes' components zeroed.
    pub(super) fn free_part(&self, forces: impl Iterator<Item = DVec2>) -> Vec<DVec2> {
        (forces.zip(&self.index))
            .map(|(f, slots)| {
                DVec2::new(
                    if slots[0].is_some() { f.x } else { 0.0 },
                    if slots[1].is_some() { f.y } else { 0.0 },
                )
            })
            .collect()
    }

    /// The elastic tangent `−∂f_int/∂x` (N/m) of `body` at `positions` over the unknowns.
    pub(super) fn elastic_entries(&self, body: &PlanarBody, positions: &[DVec2]) -> Vec<Entry> {
        let mut entries = Vec::new();
        body.with_law(|law| {
            let evaluation = body.evaluate(law, positions);
            body.element_tangent(law, &evaluation, &self.index, &mut entries);
            patch_tangent(body, law, &evaluation, &self.index, &mut entries);
        });
        entries
    }

    /// The solution `d` (m per node, zero along held axes) of `K d = r` for the matrix of
    /// `entries` and the right-hand side `residual` (N per node), at Newton's `iteration`.
    ///
    /// # Errors
    /// [`Error::AllocationFailed`] if faer cannot hold the matrix, [`Error::IndefiniteStiffness`]
    /// if it cannot factor it.
    pub(super) fn solve(
        &self,
        entries: &[Entry],
        residual: &[DVec2],
        iteration: usize,
    ) -> Result<Vec<DVec2>, Error> {
        let n = self.count;
        let k = SparseColMat::try_new_from_triplets(n, n, entries).map_err(|_| {
            Error::AllocationFailed {
                what: "the tangent of a 2D body",
                bytes: (entries.len() as u64).saturating_mul(24),
            }
        })?;
        let indefinite = Error::IndefiniteStiffness { iteration };
        let symbolic = SymbolicFactor::try_new(k.symbolic()).ok_or(indefinite.clone())?;
        let factor = Factor::try_new(symbolic, k.as_ref()).ok_or(indefinite)?;
        let mut rhs = Mat::<f64>::zeros(n, 1);
        for (r, slots) in residual.iter().zip(&self.index) {
            for (a, slot) in slots.iter().enumerate() {
                if let Some(k) = slot {
                    rhs[(*k, 0)] = r.to_array()[a];
                }
            }
        }
        factor.solve_in_place(rhs.as_mut());
        let component = |slot: Option<usize>| slot.map_or(0.0, |k| rhs[(k, 0)]);
        Ok((self.index.iter())
            .map(|s| DVec2::new(component(s[0]), component(s[1])))
            .collect())
    }
}

/// What Newton moves: a body's positions (m), evaluated with the body's elasticity.
pub(super) struct Placed<'a> {
    pub(super) body: &'a PlanarBody,
    pub(super) positions: Vec<DVec2>,
}

impl Configuration for Placed<'_> {
    type Vector = DVec2;
    fn copy_positions(&self) -> Vec<DVec2> {
        self.positions.clone()
    }
    fn place(&mut self, start: &[DVec2], direction: &[DVec2], alpha: f64) {
        for ((x, x0), d) in self.positions.iter_mut().zip(start).zip(direction) {
            *x = *x0 + *d * alpha;
        }
    }
}

/// A potential Newton's method minimizes over a body's positions.
pub(super) trait Minimized {
    /// Minus its gradient (N per node) where `placed` is, zero along held axes.
    fn residual(&self, placed: &Placed<'_>) -> Vec<DVec2>;
    /// Its value (J) where `placed` is.
    fn potential(&self, placed: &Placed<'_>) -> f64;
    /// The Newton direction (m per node) for `residual` where `placed` is, at Newton's
    /// `iteration`.
    fn direction(
        &self,
        placed: &Placed<'_>,
        residual: &[DVec2],
        iteration: usize,
    ) -> Result<Vec<DVec2>, Error>;
}

/// Newton's iterations on `problem` from `placed`, until the out-of-balance force is below
/// `settings.tolerance` times the larger of `load` (N) and the first out-of-balance force, or
/// sits at its round-off floor below 1e-6 of it: the iterations and the final relative
/// residual, `placed` left where they end.
///
/// # Errors
/// Those of [`Minimized::direction`]; [`Error::StaticSolveDidNotConverge`] when no step
/// descends above round-off or the iterations run out.
pub(super) fn minimize(
    problem: &impl Minimized,
    placed: &mut Placed<'_>,
    load: f64,
    settings: &StaticSettings,
) -> Result<(usize, f64), Error> {
    let mut residual = problem.residual(placed);
    let reference = load.max(norm(&residual));
    if reference == 0.0 {
        return Ok((0, 0.0));
    }
    let mut history = Vec::new();
    for iteration in 0..settings.max_iterations {
        let relative = norm(&residual) / reference;
        if relative <= settings.tolerance || stalled_at_round_off(&history, relative) {
            return Ok((iteration, relative));
        }
        history.push(relative);
        let direction = problem.direction(placed, &residual, iteration)?;
        let energy = |placed: &Placed<'_>| problem.potential(placed);
        let potential = energy(placed);
        let residual_at = |placed: &mut Placed<'_>| problem.residual(placed);
        match descend(
            placed,
            &residual,
            potential,
            &direction,
            Search::Thorough,
            energy,
            residual_at,
        ) {
            Some((next, _)) => residual = next,
            None => return without_descent(iteration, relative),
        }
    }
    let relative = norm(&residual) / reference;
    accepted_within(settings.max_iterations, relative, settings.tolerance)
}
