//! Pieces shared by the Newton solvers (static equilibrium, implicit integration): the residual
//! norm and a backtracking line search that guarantees the minimized energy decreases.

use crate::Error;
use crate::body::SoftBody;
use rapier3d::glamx::DVec3;

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

/// Euclidean norm of a field of per-node vectors.
pub(crate) fn norm(v: &[DVec3]) -> f64 {
    v.iter().map(|x| x.length_squared()).sum::<f64>().sqrt()
}

/// One Newton update of `body`'s positions along `direction`: the line search below, or, when
/// the energy's decrease is lost in its round-off (close to the solution), the largest step of
/// the same sequence that lowers the out-of-balance force. Returns the new residual, or `None`
/// (positions unchanged) if neither descends.
pub(crate) fn descend(
    body: &mut SoftBody,
    residual: &[DVec3],
    direction: &[DVec3],
    energy: impl Fn(&SoftBody) -> f64,
    mut residual_at: impl FnMut(&mut SoftBody) -> Vec<DVec3>,
) -> Option<Vec<DVec3>> {
    if line_search(body, residual, direction, energy) {
        return Some(residual_at(body));
    }
    let start = body.positions.clone();
    let current = norm(residual);
    let mut alpha = 1.0;
    while alpha >= MIN_STEP {
        for ((x, x0), s) in body.positions.iter_mut().zip(&start).zip(direction) {
            *x = *x0 + *s * alpha;
        }
        let next = residual_at(body);
        if norm(&next) < current {
            return Some(next);
        }
        alpha *= 0.5;
    }
    body.positions.copy_from_slice(&start);
    None
}

/// The smallest step fraction the searches try.
const MIN_STEP: f64 = 1.0 / 1024.0;

/// Moves `body` along `direction` from its current positions by the largest step `α` in
/// `1, 1/2, 1/4, …, 1/1024` that satisfies the Armijo condition on `energy` (J), whose gradient
/// is `-residual` (N), so that the energy decreases. Returns `false`, with the positions put
/// back, if no such step exists (the direction no longer descends above round-off).
fn line_search(
    body: &mut SoftBody,
    residual: &[DVec3],
    direction: &[DVec3],
    energy: impl Fn(&SoftBody) -> f64,
) -> bool {
    const ARMIJO: f64 = 1e-4;
    let start = body.positions.clone();
    let initial = energy(body);
    let slope: f64 = -residual
        .iter()
        .zip(direction)
        .map(|(r, s)| r.dot(*s))
        .sum::<f64>();
    // Energies of large bodies are sums of many terms; differences below this are round-off.
    // (Callers measure the load's work from a fixed nearby state, so the energy's size does not
    // depend on where the coordinate origin is.)
    let round_off = 1e-12 * initial.abs();
    let mut alpha = 1.0;
    while alpha >= MIN_STEP {
        for ((x, x0), s) in body.positions.iter_mut().zip(&start).zip(direction) {
            *x = *x0 + *s * alpha;
        }
        if energy(body) <= initial + ARMIJO * alpha * slope + round_off {
            return true;
        }
        alpha *= 0.5;
    }
    body.positions.copy_from_slice(&start);
    false
}
