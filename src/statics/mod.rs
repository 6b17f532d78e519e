//! Static analysis: the equilibrium `f_int(x) + M g + f_load(x) = 0` of a body under gravity and
//! its loads ([`crate::load`]) with its pinned nodes held, found by Newton's method on the total
//! potential energy; the pressure at which a cavity's equilibrium encloses a given volume
//! ([`inflate_to_volume`]); and the natural frequencies of small vibrations about the current
//! configuration.
//!
//! Both use the sparse tangent stiffness `K = -∂f_int/∂x` and faer's sparse Cholesky
//! factorization, so they need `K` positive definite on the free nodes: pin enough nodes to stop
//! rigid motion.

mod cavity;

pub use cavity::{CavityReport, inflate_to_volume};

use crate::Error;
use crate::assembly::{Stiffness, factorize, solve};
use crate::body::DeformableBody;
use crate::integrate::SolverWorkspace;
use crate::linear_solver::{Method, solve_newton_system};
use crate::load::ChamberSolve;
use crate::newton::{
    Search, accepted_within, check_tolerance, descend, norm, round_off_floor, stalled_at_round_off,
    without_descent,
};
use rapier3d::glamx::{DMat3, DVec3};

/// Convergence settings of [`solve_equilibrium`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSettings {
    /// Stop when the norm of the out-of-balance force is below this fraction of the load's norm
    /// (dimensionless), or when it stops falling below 1e-6 (the round-off floor of large meshes).
    pub tolerance: f64,
    /// Give up after this many Newton iterations.
    pub max_iterations: usize,
}

impl Default for StaticSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-8,
            max_iterations: 50,
        }
    }
}

/// What [`solve_equilibrium`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticReport {
    /// Newton iterations performed.
    pub iterations: usize,
    /// Final out-of-balance force norm over the load norm; 0 for a body found in equilibrium
    /// under no load (its out-of-balance force the round-off of its force sum).
    pub relative_residual: f64,
}

/// Moves `body` to static equilibrium under `gravity` (m/s²) and its loads, starting from its
/// current positions,
/// with pinned nodes held where they are and all velocities set to zero.
///
/// # Errors
/// [`Error::NonFiniteInput`] for a non-finite gravity, [`Error::InvalidSetting`] for a
/// non-positive tolerance, [`Error::NoFreeNode`] if every node is
/// pinned, [`Error::IndefiniteStiffness`] if the tangent stiffness cannot be factored (too few
/// pinned nodes), [`Error::StaticSolveDidNotConverge`] if the tolerance is not met. On error the
/// body is left as it was.
pub fn solve_equilibrium(
    body: &mut DeformableBody,
    gravity: DVec3,
    settings: &StaticSettings,
) -> Result<StaticReport, Error> {
    if !gravity.is_finite() {
        return Err(Error::NonFiniteInput {
            parameter: "gravity",
        });
    }
    check_tolerance(settings.tolerance)?;
    if body.pinned.iter().all(|&p| p) {
        return Err(Error::NoFreeNode);
    }
    let mut workspace = SolverWorkspace::new();
    workspace.save_state(body);
    let mut stiffness = workspace.take_tangent(body);
    let result = crate::parallel::on_pool(|| newton(body, &mut stiffness, gravity, settings));
    match result {
        Ok(_) => body.count_state_edit(),
        Err(_) => workspace.restore_state(body),
    }
    result
}

/// Newton's iterations of [`solve_equilibrium`].
fn newton(
    body: &mut DeformableBody,
    stiffness: &mut Stiffness,
    gravity: DVec3,
    settings: &StaticSettings,
) -> Result<StaticReport, Error> {
    body.velocities.fill(DVec3::ZERO);
    let load = body.dead_load(gravity);
    let mut residual = out_of_balance(body, &load);
    let reference = norm(&load).max(norm(&residual));
    if reference == 0.0 || in_equilibrium_unloaded(body, &residual, &load) {
        return Ok(StaticReport {
            iterations: 0,
            relative_residual: 0.0,
        });
    }
    let mut history: Vec<f64> = Vec::new();
    let start = body.positions.clone();
    for iteration in 0..settings.max_iterations {
        let relative = norm(&residual) / reference;
        if relative <= settings.tolerance || stalled_at_round_off(&history, relative) {
            return Ok(StaticReport {
                iterations: iteration,
                relative_residual: relative,
            });
        }
        history.push(relative);
        let step = newton_direction(body, stiffness, &residual, iteration)?;
        // This iteration's energy holds the follower loads' part no potential gives (a free
        // rim's, see `crate::load`) at its value here: its gradient is the residual here.
        let origins = body.cone_origins();
        let mut held = load.clone();
        body.add_rim_forces(&origins, &mut held);
        let energy = |body: &DeformableBody| potential_energy(body, (&held, &origins), &start);
        let potential = energy(body);
        match descend(
            body,
            &residual,
            potential,
            &step,
            Search::Thorough,
            energy,
            |body| out_of_balance(body, &load),
        ) {
            Some((next, _)) => residual = next,
            None => return without_descent(iteration, relative).map(report),
        }
    }
    let relative = norm(&residual) / reference;
    accepted_within(settings.max_iterations, relative, settings.tolerance).map(report)
}

/// The report of Newton's `(iterations, relative residual)`.
fn report((iterations, relative_residual): (usize, f64)) -> StaticReport {
    StaticReport {
        iterations,
        relative_residual,
    }
}

/// The Newton direction (m per node) for the out-of-balance force `residual` (N) at Newton's
/// `iteration`, the chambers' liquids' stiffness taken in. The exact tangent converges
/// quadratically; where the body is in an unstable (buckling) state it is indefinite, and the
/// projected tangent still gives a descent direction.
fn newton_direction(
    body: &DeformableBody,
    stiffness: &mut Stiffness,
    residual: &[DVec3],
    iteration: usize,
) -> Result<Vec<DVec3>, Error> {
    let solution = solve_newton_system(
        Method::Direct,
        1.0,
        stiffness,
        residual,
        iteration,
        |stiffness, project| assemble_elastic(stiffness, body, project),
    )?;
    Ok(match &solution.factor {
        Some(factor) => {
            let chambers = body.chamber_terms();
            ChamberSolve::new(factor, &chambers).take_in(residual, solution.direction)
        }
        None => solution.direction,
    })
}

/// The lowest natural frequency (Hz) of small undamped vibrations about the current positions,
/// with pinned nodes held: `K φ = ω² M φ` (`K` the tangent stiffness, the loads' and the
/// chambers' liquids' included) solved by inverse iteration with the lumped mass until
/// the Rayleigh quotient changes by less than 1e-13 (relative), or 500 iterations, after which
/// the current estimate is returned (convergence is geometric in the ratio of the two lowest
/// distinct frequencies, so 500 iterations are only reached for nearly equal ones).
///
/// # Errors
/// [`Error::NoFreeNode`] if every node is pinned; [`Error::IndefiniteStiffness`] if the tangent
/// stiffness cannot be factored (e.g. no pinned node, so rigid modes have zero frequency).
pub fn fundamental_frequency(body: &DeformableBody) -> Result<f64, Error> {
    if body.pinned.iter().all(|&p| p) {
        return Err(Error::NoFreeNode);
    }
    const MAX_ITERATIONS: usize = 500;
    const TOLERANCE: f64 = 1e-13;
    let mut stiffness = Stiffness::new(body);
    assemble_elastic(&mut stiffness, body, false);
    let factor = factorize(&mut stiffness, 0)?;
    let chambers = body.chamber_terms();
    let solver = ChamberSolve::new(&factor, &chambers);
    let masses = &body.masses;
    let free = |n: usize| !body.pinned[n];
    // Start from a fixed pseudo-random motion of the free nodes, which has a component on every
    // mode (a uniform start would miss modes of zero net motion, such as torsion).
    let mut mode: Vec<DVec3> = (0..body.node_count())
        .map(|n| {
            if free(n) {
                DVec3::new(hash_unit(3 * n), hash_unit(3 * n + 1), hash_unit(3 * n + 2))
            } else {
                DVec3::ZERO
            }
        })
        .collect();
    let mut eigenvalue = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let mass_times_mode: Vec<DVec3> = mode.iter().zip(masses).map(|(x, m)| *x * *m).collect();
        let next = solver.take_in(&mass_times_mode, solve(&factor, &mass_times_mode));
        // Rayleigh quotient of the previous iterate: xᵀ M x / xᵀ M K⁻¹ M x.
        let x_m_x: f64 = mode
            .iter()
            .zip(&mass_times_mode)
            .map(|(a, b)| a.dot(*b))
            .sum();
        let x_m_y: f64 = next
            .iter()
            .zip(&mass_times_mode)
            .map(|(a, b)| a.dot(*b))
            .sum();
        let estimate = x_m_x / x_m_y;
        let y_m_y: f64 = next
            .iter()
            .zip(masses)
            .map(|(y, m)| m * y.length_squared())
            .sum();
        mode = next.iter().map(|y| *y / y_m_y.sqrt()).collect();
        let converged = (estimate - eigenvalue).abs() <= TOLERANCE * estimate;
        eigenvalue = estimate;
        if converged {
            break;
        }
    }
    Ok(eigenvalue.sqrt() / (2.0 * std::f64::consts::PI))
}

/// The elastic tangent stiffness at the body's current positions, projected per element to be
/// positive semi-definite if `project`.
fn assemble_elastic(stiffness: &mut Stiffness, body: &DeformableBody, project: bool) {
    stiffness.assemble(body, None, project, |_, _| [DMat3::ZERO; 9]);
}

/// `f_int(x) + load`, zero on pinned nodes (N).
fn out_of_balance(body: &mut DeformableBody, load: &[DVec3]) -> Vec<DVec3> {
    // The velocities are zero, so the damping adds nothing.
    let mut forces = body.internal_forces();
    body.add_follower_forces(&mut forces);
    (0..load.len())
        .map(|n| {
            if body.pinned[n] {
                DVec3::ZERO
            } else {
                forces[n] + load[n]
            }
        })
        .collect()
}

/// Whether the body is in equilibrium under no dead load: its out-of-balance force `residual`
/// (N, the follower loads' included) within twice its round-off floor at the body's positions
/// ([`round_off_floor`]), which no Newton step can lower and which would otherwise be its own
/// reference (a body at rest, its loads at zero).
fn in_equilibrium_unloaded(body: &mut DeformableBody, residual: &[DVec3], load: &[DVec3]) -> bool {
    if norm(load) > 0.0 {
        return false;
    }
    let floor = round_off_floor(body, residual, |body| out_of_balance(body, load));
    norm(residual) <= 2.0 * floor
}

/// Total potential energy (J): elastic energy plus the follower loads' potential (cones from
/// `origins`) minus the work of the constant `load`, measured from the positions `start` (m)
/// the solve began at.
fn potential_energy(
    body: &DeformableBody,
    (load, origins): (&[DVec3], &[DVec3]),
    start: &[DVec3],
) -> f64 {
    let load_work: f64 = load
        .iter()
        .zip(body.positions.iter().zip(start))
        .map(|(f, (x, x0))| f.dot(*x - *x0))
        .sum();
    body.elastic_energy() + body.follower_potential(origins, start) - load_work
}

/// A fixed pseudo-random number in [-1, 1) for index `i` (`SplitMix64`).
fn hash_unit(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}
