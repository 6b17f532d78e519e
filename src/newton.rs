//! Pieces shared by the Newton solvers (static equilibrium, implicit integration of a body or of
//! bodies touching each other, in 3D and in the plane): the residual norm and a backtracking
//! line search that guarantees the minimized energy decreases, over any [`Configuration`] of
//! nodes whose positions are [`NodeVector`]s (`DVec3`, or `DVec2` for 2D bodies).

use crate::Error;
use crate::body::DeformableBody;
use rapier3d::glamx::{DVec2, DVec3};
use std::ops::{Add, Mul, Sub};

/// A node's position or a per-node vector in 2D or 3D: what Newton's pieces compute with.
pub(crate) trait NodeVector:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self>
{
    /// The number of components.
    const DIM: usize;
    /// The dot product.
    fn dot(self, other: Self) -> f64;
    /// The squared Euclidean length.
    fn length_squared(self) -> f64;
    /// The vector whose component `k` is `f(self_k, k)`.
    fn map_components(self, f: impl FnMut(f64, usize) -> f64) -> Self;
}

impl NodeVector for DVec3 {
    const DIM: usize = 3;
    fn dot(self, other: Self) -> f64 {
        DVec3::dot(self, other)
    }
    fn length_squared(self) -> f64 {
        DVec3::length_squared(self)
    }
    fn map_components(self, mut f: impl FnMut(f64, usize) -> f64) -> Self {
        DVec3::new(f(self.x, 0), f(self.y, 1), f(self.z, 2))
    }
}

impl NodeVector for DVec2 {
    const DIM: usize = 2;
    fn dot(self, other: Self) -> f64 {
        DVec2::dot(self, other)
    }
    fn length_squared(self) -> f64 {
        DVec2::length_squared(self)
    }
    fn map_components(self, mut f: impl FnMut(f64, usize) -> f64) -> Self {
        DVec2::new(f(self.x, 0), f(self.y, 1))
    }
}

/// Refuses a Newton tolerance that is not positive and finite.
pub(crate) fn check_tolerance(tolerance: f64) -> Result<(), Error> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidSetting {
            parameter: "tolerance",
            value: tolerance,
            reason: "must be positive and finite",
        })
    }
}

/// What Newton moves: the positions (m) of a set of nodes, one body's or a group's, in a fixed
/// order.
pub(crate) trait Configuration {
    /// A node's position (m).
    type Vector: NodeVector;
    /// The positions (m), in order.
    fn copy_positions(&self) -> Vec<Self::Vector>;
    /// Sets the positions to `start + alpha direction` (m).
    fn place(&mut self, start: &[Self::Vector], direction: &[Self::Vector], alpha: f64);
    /// Sets the positions to `positions` (m).
    fn set(&mut self, positions: &[Self::Vector]) {
        self.place(positions, positions, 0.0);
    }
}

impl Configuration for DeformableBody {
    type Vector = DVec3;
    fn copy_positions(&self) -> Vec<DVec3> {
        self.positions.clone()
    }
    fn place(&mut self, start: &[DVec3], direction: &[DVec3], alpha: f64) {
        for ((x, x0), s) in self.positions.iter_mut().zip(start).zip(direction) {
            *x = *x0 + *s * alpha;
        }
    }
}

/// The round-off floor (N) of a residual `residual` (N) at the configuration's positions: how much
/// the residual changes when every coordinate moves by its own rounding, one unit in the last
/// place (`ε |x|`, signs alternating in a fixed pseudo-random pattern). Newton's iterates carry at
/// least that error, so no solve can bring the residual much below it: very stiff or nearly
/// incompressible material (`K ε |x|` large against the load), or a stiff coupling term. The
/// positions are put back.
pub(crate) fn round_off_floor<C: Configuration>(
    config: &mut C,
    residual: &[C::Vector],
    mut residual_at: impl FnMut(&mut C) -> Vec<C::Vector>,
) -> f64 {
    let start = config.copy_positions();
    // A multiplicative hash of the coordinate's index picks its sign: deterministic, and with
    // no pattern a smooth residual could cancel.
    let sign = |i: usize| {
        if (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 63 == 0 {
            1.0
        } else {
            -1.0
        }
    };
    let dim = C::Vector::DIM;
    let ulps: Vec<C::Vector> = start
        .iter()
        .enumerate()
        .map(|(n, x)| {
            x.map_components(|c, k| {
                c.abs().max(f64::MIN_POSITIVE) * f64::EPSILON * sign(dim * n + k)
            })
        })
        .collect();
    config.place(&start, &ulps, 1.0);
    let moved = residual_at(config);
    config.set(&start);
    moved
        .iter()
        .zip(residual)
        .map(|(a, b)| (*a - *b).length_squared())
        .sum::<f64>()
        .sqrt()
}

/// The largest relative residual accepted as round-off when Newton stops reducing it.
pub(crate) const ROUND_OFF_CEILING: f64 = 1e-6;

/// Whether Newton's relative residual `relative`, after the earlier ones in `history`, sits at
/// its round-off floor: Newton more than halves the residual each iteration until round-off in
/// the force sum sets a floor (about 1e-9 on 1e5 elements); a tiny residual (at most
/// [`ROUND_OFF_CEILING`]) that fails to halve twice in a row is there.
pub(crate) fn stalled_at_round_off(history: &[f64], relative: f64) -> bool {
    let failed_to_halve = |older: f64, newer: f64| newer > 0.5 * older;
    match history {
        [.., older, last] => {
            relative <= ROUND_OFF_CEILING
                && failed_to_halve(*last, relative)
                && failed_to_halve(*older, *last)
        }
        _ => false,
    }
}

/// How a Newton loop ends when its line search finds no descent at `iteration` with the
/// relative residual `relative`: a tiny residual (at most [`ROUND_OFF_CEILING`]) is accepted as
/// round-off, anything else refused ([`accepted_within`]).
///
/// # Errors
/// [`Error::StaticSolveDidNotConverge`] above the ceiling.
pub(crate) fn without_descent(iteration: usize, relative: f64) -> Result<(usize, f64), Error> {
    accepted_within(iteration, relative, ROUND_OFF_CEILING)
}

/// How a Newton loop ends after `iterations` with the relative residual `relative`: accepted
/// (`(iterations, relative residual)`) if it is at most `limit` (the tolerance after the last
/// iteration).
///
/// # Errors
/// [`Error::StaticSolveDidNotConverge`] otherwise.
pub(crate) fn accepted_within(
    iterations: usize,
    relative: f64,
    limit: f64,
) -> Result<(usize, f64), Error> {
    if relative <= limit {
        Ok((iterations, relative))
    } else {
        Err(Error::StaticSolveDidNotConverge {
            iterations,
            residual: relative,
        })
    }
}

/// Euclidean norm of a field of per-node vectors.
/// `Σ aᵢ·bᵢ` over the nodes of two per-node vectors.
pub(crate) fn dot<V: NodeVector>(a: &[V], b: &[V]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

pub(crate) fn norm<V: NodeVector>(v: &[V]) -> f64 {
    v.iter().map(|x| x.length_squared()).sum::<f64>().sqrt()
}

/// How far a Newton update searches along its direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Search {
    /// Steps `1, 1/2, …, 1/1024` on the energy, a shortened step then moved to the lowest energy
    /// a golden-section search finds between it and twice it (see [`lowest_along`]); then,
    /// when the decrease the direction promises is lost in the energy's round-off (close to the
    /// solution, see [`ENERGY_RESOLUTION`]), the largest step of the same sequence that lowers
    /// the out-of-balance force; then the energy again at `1/2048, …, 2⁻³⁰` (see
    /// [`DEEP_STEP`]).
    Thorough,
    /// The full step or half of it, on the energy only: for a direction expected to be nearly
    /// the Newton step (from an earlier tangent's factorization).
    Short,
}

/// One Newton update of `body`'s positions along `direction` from where the minimized energy
/// is `energy_now` (J), searching as `search` says. Returns the new residual and energy, or
/// `None` (positions unchanged) if no step descends.
pub(crate) fn descend<C: Configuration>(
    body: &mut C,
    residual: &[C::Vector],
    energy_now: f64,
    direction: &[C::Vector],
    search: Search,
    energy: impl Fn(&C) -> f64,
    mut residual_at: impl FnMut(&mut C) -> Vec<C::Vector>,
) -> Option<(Vec<C::Vector>, f64)> {
    let steps = match search {
        Search::Thorough => (1.0, MIN_STEP),
        Search::Short => (1.0, 0.5),
    };
    let searched = Searched {
        residual,
        energy: energy_now,
        direction,
    };
    let start = body.copy_positions();
    let refine = search == Search::Thorough;
    if let Some(accepted) = search_energy(body, (&start, searched), &energy, steps, refine) {
        return Some((residual_at(body), accepted));
    }
    if search == Search::Short {
        return None;
    }
    // The out-of-balance force decides only where the energy cannot: where the decrease the
    // direction promises is lost in the energy's round-off. Elsewhere a step that raises the
    // energy is not taken, however it changes the force.
    let promised = dot(residual, direction);
    let current = if promised <= ENERGY_RESOLUTION * energy_now.abs() {
        norm(residual)
    } else {
        0.0
    };
    let mut alpha = 1.0;
    while current > 0.0 && alpha >= MIN_STEP {
        body.place(&start, direction, alpha);
        let next = residual_at(body);
        if norm(&next) < current {
            return Some((next, energy(body)));
        }
        alpha *= 0.5;
    }
    body.set(&start);
    let deep = (MIN_STEP / 2.0, DEEP_STEP);
    let accepted = search_energy(body, (&start, searched), &energy, deep, true)?;
    Some((residual_at(body), accepted))
}

/// A Newton update's search: the out-of-balance force (N) and the minimized energy (J) where it
/// starts, and its direction (m per node).
struct Searched<'a, V> {
    residual: &'a [V],
    energy: f64,
    direction: &'a [V],
}

impl<V> Clone for Searched<'_, V> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<V> Copy for Searched<'_, V> {}

/// [`line_search`] over `steps` from `start` (where `body` is), then, if `refine` and the step
/// it accepted is shorter than the full one, [`lowest_along`]: the energy (J) where `body` ends.
fn search_energy<C: Configuration>(
    body: &mut C,
    (start, searched): (&[C::Vector], Searched<C::Vector>),
    energy: &impl Fn(&C) -> f64,
    steps: (f64, f64),
    refine: bool,
) -> Option<f64> {
    let (alpha, accepted) = line_search(body, searched, energy, steps)?;
    Some(if refine && alpha < 1.0 {
        lowest_along(body, (start, searched.direction), (alpha, accepted), energy)
    } else {
        accepted
    })
}

/// The energy decrease (relative to the energy) a direction must promise, `r·d`, for the
/// energy alone to judge its steps: below it the energy's round-off (about `1e-12` of it, more
/// for sums of many terms) hides the decrease, and the out-of-balance force judges.
const ENERGY_RESOLUTION: f64 = 1e-9;

/// The smallest step fraction the thorough search tries first.
const MIN_STEP: f64 = 1.0 / 1024.0;

/// The smallest step fraction the thorough search tries last, `2⁻³⁰`: a Newton direction
/// computed where a contact is not yet active (its penalty missing from the tangent) or where
/// friction slides (no stiffness along the slip) can overshoot by many orders of magnitude, and
/// a shorter step that still lowers the energy is progress (the next iteration's tangent has
/// the contact or the sticking friction in it).
const DEEP_STEP: f64 = 1.0 / 1_073_741_824.0;

/// Golden-section evaluations of the energy [`lowest_along`] makes.
const REFINEMENTS: usize = 16;

/// Moves `body`, placed at the step `alpha` along `direction` from `start` (m) with the energy
/// `value` (J) there, to the lowest energy (J, returned) among `alpha` and the points a
/// golden-section search over `[alpha, 2 alpha]` evaluates.
///
/// A Newton step the line search shortened crossed something its quadratic model did not see:
/// a contact's friction turning from sliding one way to sliding the other (a point that should
/// stick, which the model, flat along the slip, carries past its stick zone of
/// `stiction_speed h`), or a stiff penalty coming into force. The halvings stop anywhere short
/// of the rejected step `2 alpha`, and the next iteration, from the same side, meets the same
/// kink again; the lowest point up to the rejected step lands at it, where the next model sees
/// the contact stuck or pressed. It has no more energy than `alpha`'s at a longer step, so it
/// meets the same sufficient decrease.
fn lowest_along<C: Configuration>(
    body: &mut C,
    (start, direction): (&[C::Vector], &[C::Vector]),
    (alpha, value): (f64, f64),
    energy: &impl Fn(&C) -> f64,
) -> f64 {
    let at = |step: f64, body: &mut C| {
        body.place(start, direction, step);
        energy(body)
    };
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let (mut low, mut high) = (alpha, 2.0 * alpha);
    let mut inner = [high - ratio * (high - low), low + ratio * (high - low)];
    let mut values = [at(inner[0], body), at(inner[1], body)];
    for _ in 2..REFINEMENTS {
        if values[0] < values[1] {
            high = inner[1];
            inner = [high - ratio * (high - low), inner[0]];
            values = [at(inner[0], body), values[0]];
        } else {
            low = inner[0];
            inner = [inner[1], low + ratio * (high - low)];
            values = [values[1], at(inner[1], body)];
        }
    }
    let (best, lowest) = [(inner[0], values[0]), (inner[1], values[1])]
        .into_iter()
        .fold((alpha, value), |a, b| if b.1 < a.1 { b } else { a });
    body.place(start, direction, best);
    lowest
}

/// Moves `body` along `direction` from its current positions, where `energy` (J) is `initial`
/// and its gradient is `-residual` (N), by the largest step `α` in `largest, largest/2, …` down
/// to `smallest` that satisfies the Armijo condition, so that the energy decreases. Returns the
/// step and the energy there, or `None`, with the positions put back, if no such step exists
/// (the direction no longer descends above round-off).
fn line_search<C: Configuration>(
    body: &mut C,
    Searched {
        residual,
        energy: initial,
        direction,
    }: Searched<C::Vector>,
    energy: impl Fn(&C) -> f64,
    (largest, smallest): (f64, f64),
) -> Option<(f64, f64)> {
    const ARMIJO: f64 = 1e-4;
    let start = body.copy_positions();
    let slope: f64 = -residual
        .iter()
        .zip(direction)
        .map(|(r, s)| r.dot(*s))
        .sum::<f64>();
    // Energies of large bodies are sums of many terms; differences below this are round-off.
    // (Callers measure the load's work from a fixed nearby state, so the energy's size does not
    // depend on where the coordinate origin is.)
    let round_off = 1e-12 * initial.abs();
    let mut alpha = largest;
    while alpha >= smallest {
        body.place(&start, direction, alpha);
        let value = energy(body);
        if value <= initial + ARMIJO * alpha * slope + round_off {
            return Some((alpha, value));
        }
        alpha *= 0.5;
    }
    body.set(&start);
    None
}
