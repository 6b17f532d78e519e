//! Pieces shared by the Newton solvers (static equilibrium, implicit integration): the residual
//! norm and a backtracking line search that guarantees the minimized energy decreases.

use crate::body::SoftBody;
use rapier3d::glamx::DVec3;

/// Euclidean norm of a field of per-node vectors.
pub(crate) fn norm(v: &[DVec3]) -> f64 {
    v.iter().map(|x| x.length_squared()).sum::<f64>().sqrt()
}

/// Moves `body` along `direction` from its current positions by the largest step `α` in
/// `1, 1/2, 1/4, …, 1/1024` that satisfies the Armijo condition on `energy` (J), whose gradient
/// is `-residual` (N), so that the energy decreases; if none does, the smallest step is taken
/// and the caller's convergence test decides.
pub(crate) fn line_search(
    body: &mut SoftBody,
    residual: &[DVec3],
    direction: &[DVec3],
    energy: impl Fn(&SoftBody) -> f64,
) {
    const ARMIJO: f64 = 1e-4;
    const MIN_STEP: f64 = 1.0 / 1024.0;
    let start = body.positions.clone();
    let initial = energy(body);
    let slope: f64 = -residual
        .iter()
        .zip(direction)
        .map(|(r, s)| r.dot(*s))
        .sum::<f64>();
    // Energies of large bodies are sums of many terms; differences below this are round-off.
    let round_off = 1e-12 * initial.abs();
    let mut alpha = 1.0;
    loop {
        for ((x, x0), s) in body.positions.iter_mut().zip(&start).zip(direction) {
            *x = *x0 + *s * alpha;
        }
        let trial = energy(body);
        if trial <= initial + ARMIJO * alpha * slope + round_off || alpha <= MIN_STEP {
            return;
        }
        alpha *= 0.5;
    }
}
