//! Solving the Newton system `K u = r` of a Newton iteration: `K` the assembled tangent (N/m,
//! symmetric, pinned nodes' rows and columns the identity), `r` the out-of-balance force (N), `u`
//! the step (m).
//!
//! Two methods:
//! - a sparse direct solve, faer's Cholesky factorization (the fill-reducing ordering and
//!   symbolic analysis, in which faer picks a simplicial or supernodal factorization from the
//!   fill, are computed once per body and reused);
//! - the preconditioned conjugate gradient on the assembled matrix, with a 3 x 3 block-Jacobi
//!   preconditioner (each node's diagonal block inverted), started from zero.
//!
//! Either one reports a tangent that is not positive definite (the Cholesky factorization fails,
//! or the conjugate gradient meets a direction of zero or negative curvature `pᵀ K p <= 0`); the
//! caller then reassembles the tangent with each element's stress tangent projected to be
//! positive semi-definite and solves again.
//!
//! A conjugate gradient stopped early still returns a descent direction of the potential: from
//! zero, every iterate `u_k` of the conjugate gradient on a matrix whose curvature was positive
//! along every search direction has `rᵀ u_k > 0`.
//!
//! # Choosing
//! The conjugate gradient's cost is its iteration count times a sparse matrix-vector product.
//! On the implicit integrator's matrix `M/h² + K` its iterations grow with the square root of the
//! condition number, about `κ ≈ 1 + (ω_max h)²` (the highest mode's angular frequency `ω_max`
//! against the step `h`): few for soft or finely stepped bodies, thousands for a stiff body at a
//! frame step. The Cholesky factorization's cost grows faster than linearly with the size of the
//! mesh (its fill), but does not depend on the conditioning. [`LinearSolver::Automatic`]
//! compares the two predictions; see its documentation for the rule and its calibration.

mod conjugate_gradient;

use crate::Error;
use crate::assembly::Factor;
use crate::assembly::{Stiffness, factorize, solve};
use crate::body::DeformableBody;
use conjugate_gradient::{CgOutcome, conjugate_gradient};
use rapier3d::glamx::DVec3;

/// How the Newton system of each implicit iteration is solved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum LinearSolver {
    /// Chooses, each frame, between [`LinearSolver::Direct`] and the conjugate gradient by their
    /// predicted costs per solve.
    ///
    /// - The conjugate gradient is predicted to take `N = C sqrt(κ) ln(2/tol) / 2` iterations at
    ///   `tol` = [`AUTOMATIC_CG_TOLERANCE`], `C` = [`CG_ITERATION_FACTOR`], with the condition
    ///   number of `M/ĥ² + K` estimated from the highest and lowest wave modes,
    ///   `κ = (1 + ω_max² w) / (1 + ω_min² w)`, `w = ĥ (ĥ + β)`: `ω_max = 2 c_p / ℓ` (rad/s) from
    ///   [`DeformableBody::wave_length_scale`] `ℓ` and the material's
    ///   [`dilatational_wave_speed`](crate::material::Material::dilatational_wave_speed) `c_p`,
    ///   `ω_min = c̄ / D` with `D` the diagonal of the body's bounding box and `c̄` the body's
    ///   mean wave speed (`c_p` but for region materials: the mean stiffness over the mean
    ///   density), `ĥ` the substep (s),
    ///   `β = (φ + 2ψ)/(λ + 2μ)` the damping's stiffness-proportional time (s, zero undamped).
    ///   (Isolated lower modes, such as the bending of a slender part, cost a few iterations
    ///   each and are left out.)
    /// - A Cholesky factorization and solve is predicted to cost as much as `R = A sqrt(n)`
    ///   matrix-vector products, `n` the free degrees of freedom, `A` = [`CHOLESKY_COST_SCALE`].
    /// - The conjugate gradient is used when `N < R` and `n` >= [`MIN_AUTOMATIC_CG_DOFS`], with at
    ///   most `2R` iterations per solve; a solve that does not converge within them is redone
    ///   by the direct method, which then serves the rest of the frame. Its relative tolerance
    ///   is half of what Newton's tolerance asks of the step (the target residual over the
    ///   current one), within [`MIN_AUTOMATIC_CG_TOLERANCE`] and [`AUTOMATIC_CG_TOLERANCE`]: a
    ///   nearly linear step then takes one Newton iteration, as with the direct solve, and
    ///   early iterations of a nonlinear one are not solved beyond use.
    ///
    /// Calibration (`cargo run --release --example solver_knobs calibrate`, one core of a 2-core
    /// AMD EPYC shared with other work, so timings vary by up to a factor of 2 between runs):
    /// measured iterations to 1e-3 over `sqrt(κ) ln(2/tol) / 2` were 0.16–0.17 on stiff beams
    /// (E = 1e9 Pa, 1/60 s, 1.6k–100k tetrahedra) and 0.345–0.36 on soft cubes (E = 1e5 Pa,
    /// 1/240 s, 5k–98k tetrahedra), hence `C = 0.35`; a Cholesky factorization and solve cost
    /// `R/sqrt(n)` = 1.2–3.5 matrix-vector products on the beams and 2.8–10 on the cubes
    /// (compact bodies fill more), hence `A = 2`, which leans toward the direct solve. Below
    /// 1000 free degrees of freedom both cost about the same (0.5 ms per frame on a beam of 270
    /// free degrees of freedom at 0.2 ms steps) and the direct solve is exact. On whole frames
    /// the rule picks the direct solve for the stiff beams (about twice as fast as the
    /// conjugate gradient at 1.6k and 13k tetrahedra, within noise at 100k) and the conjugate
    /// gradient for the soft cubes (2 times faster at 5k tetrahedra, 3–6 at 20k, 10 at 53k,
    /// 14–20 at 98k).
    #[default]
    Automatic,
    /// The sparse Cholesky factorization: exact to round-off, cost independent of the
    /// conditioning.
    Direct,
    /// The block-Jacobi preconditioned conjugate gradient, started from zero. A body with a
    /// [chamber](crate::load::Load::Chamber) is solved by factorization all the same.
    ConjugateGradient {
        /// Stop when the residual of the linear system is below this fraction of its
        /// right-hand side, `‖K u - r‖ <= tolerance ‖r‖` (dimensionless, positive).
        tolerance: f64,
        /// Iterations per solve at most (at least 1); a solve stopped by this limit returns its
        /// last iterate, still a descent direction.
        max_iterations: usize,
    },
}

/// The loosest relative tolerance (dimensionless) of the conjugate gradient
/// [`LinearSolver::Automatic`] uses, and the one its prediction assumes.
pub const AUTOMATIC_CG_TOLERANCE: f64 = 1e-3;

/// The tightest relative tolerance (dimensionless) of the conjugate gradient
/// [`LinearSolver::Automatic`] uses.
pub const MIN_AUTOMATIC_CG_TOLERANCE: f64 = 1e-8;

/// Below this many free degrees of freedom [`LinearSolver::Automatic`] always solves directly.
pub const MIN_AUTOMATIC_CG_DOFS: usize = 1000;

/// Iterations of the block-Jacobi conjugate gradient over `sqrt(κ) ln(2/tol) / 2`
/// (dimensionless), the largest measured; see [`LinearSolver::Automatic`].
pub const CG_ITERATION_FACTOR: f64 = 0.35;

/// Scale `A` of the cost of a Cholesky factorization and solve, `A sqrt(n)` matrix-vector
/// products for `n` free degrees of freedom (dimensionless); see [`LinearSolver::Automatic`].
pub const CHOLESKY_COST_SCALE: f64 = 2.0;

impl LinearSolver {
    /// Refuses a non-positive or non-finite tolerance and zero iterations.
    pub(crate) fn check(&self) -> Result<(), Error> {
        if let LinearSolver::ConjugateGradient {
            tolerance,
            max_iterations,
        } = *self
        {
            if !(tolerance.is_finite() && tolerance > 0.0) {
                return Err(Error::InvalidSetting {
                    parameter: "linear_solver.tolerance",
                    value: tolerance,
                    reason: "must be positive and finite",
                });
            }
            if max_iterations == 0 {
                return Err(Error::InvalidSetting {
                    parameter: "linear_solver.max_iterations",
                    value: 0.0,
                    reason: "at least one conjugate gradient iteration is needed",
                });
            }
        }
        Ok(())
    }

    /// The method for substeps of `h` (s) on `body` in its current shape: the direct one for a
    /// body with a [chamber](crate::load::Load::Chamber), whatever is chosen (its liquid's
    /// tangent is taken in with the factorization).
    pub(crate) fn method(&self, body: &DeformableBody, h: f64) -> Method {
        if body.has_chambers() {
            return Method::Direct;
        }
        match *self {
            LinearSolver::Direct => Method::Direct,
            LinearSolver::ConjugateGradient {
                tolerance,
                max_iterations,
            } => Method::ConjugateGradient {
                tolerance,
                max_iterations,
            },
            // A body too small for the conjugate gradient needs no prediction (its wave length
            // scale is a pass over the elements).
            LinearSolver::Automatic if free_dofs(body) < MIN_AUTOMATIC_CG_DOFS => Method::Direct,
            LinearSolver::Automatic => {
                let prediction = predict(body, h, AUTOMATIC_CG_TOLERANCE);
                if prediction.cg_iterations < prediction.cholesky_in_products {
                    Method::AutomaticConjugateGradient {
                        max_iterations: (2.0 * prediction.cholesky_in_products).ceil() as usize,
                    }
                } else {
                    Method::Direct
                }
            }
        }
    }

    /// The conjugate gradient iterations per solve predicted for substeps of `h` (s) on `body`
    /// in its current shape (see [`LinearSolver::Automatic`]), at most the solver's limit, or
    /// `None` where the direct method is used.
    pub(crate) fn predicted_cg_iterations(&self, body: &DeformableBody, h: f64) -> Option<f64> {
        let (tolerance, most) = match self.method(body, h) {
            Method::Direct => return None,
            Method::ConjugateGradient {
                tolerance,
                max_iterations,
            } => (tolerance, max_iterations),
            Method::AutomaticConjugateGradient { max_iterations } => {
                (AUTOMATIC_CG_TOLERANCE, max_iterations)
            }
        };
        Some(predict(body, h, tolerance).cg_iterations.min(most as f64))
    }
}

/// The predicted costs [`LinearSolver::Automatic`] compares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverPrediction {
    /// Estimated condition number `κ` of `M/ĥ² + K` (dimensionless).
    pub condition: f64,
    /// Predicted conjugate gradient iterations per solve.
    pub cg_iterations: f64,
    /// Predicted cost of a Cholesky factorization and solve, in matrix-vector products.
    pub cholesky_in_products: f64,
    /// Unknowns: three per free node.
    pub free_dofs: usize,
}

/// The prediction [`LinearSolver::Automatic`] makes for substeps of `h` (s) on `body` in its
/// current shape, for a conjugate gradient of relative tolerance `tolerance`.
pub fn predict(body: &DeformableBody, h: f64, tolerance: f64) -> SolverPrediction {
    let material = body.material();
    let highest = 2.0 * material.dilatational_wave_speed() / body.wave_length_scale();
    let (low, high) = crate::mesh::bounding_box(body.positions().iter().copied());
    let lowest = body.mean_wave_speed() / (high - low).length();
    let beta = body.damping().map_or(0.0, |d| {
        d.p_wave_viscosity() / material.lame().p_wave_modulus()
    });
    let weight = h * (h + beta);
    let condition = (1.0 + highest * highest * weight) / (1.0 + lowest * lowest * weight);
    // A flat element (ℓ = 0) makes the estimate infinite (or NaN): the direct solve is chosen.
    let cg_iterations = CG_ITERATION_FACTOR * condition.sqrt() * (2.0 / tolerance).ln() / 2.0;
    let free = free_dofs(body);
    SolverPrediction {
        condition,
        cg_iterations: if cg_iterations.is_nan() {
            f64::INFINITY
        } else {
            cg_iterations
        },
        cholesky_in_products: CHOLESKY_COST_SCALE * (free as f64).sqrt(),
        free_dofs: free,
    }
}

/// The unknowns of `body`'s Newton system: three per free node.
fn free_dofs(body: &DeformableBody) -> usize {
    3 * (0..body.node_count())
        .filter(|&n| !body.is_pinned(n))
        .count()
}

/// A resolved choice of [`LinearSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Method {
    Direct,
    ConjugateGradient {
        tolerance: f64,
        max_iterations: usize,
    },
    /// The conjugate gradient of [`LinearSolver::Automatic`]: its tolerance is set per solve from
    /// what Newton asks, and a solve that does not converge is redone by the direct method.
    AutomaticConjugateGradient {
        max_iterations: usize,
    },
}

/// What one Newton system solve did.
pub(crate) struct Solution {
    /// The step (m per node).
    pub(crate) direction: Vec<DVec3>,
    /// Conjugate gradient iterations, over every attempt.
    pub(crate) cg_iterations: usize,
    /// Whether the exact tangent was found not positive definite and the projected one solved.
    pub(crate) projected: bool,
    /// Whether the conjugate gradient fell back to the direct method (the caller keeps it for
    /// the rest of the frame).
    pub(crate) fell_back: bool,
    /// The Cholesky factorization solved with, when the direct method was used.
    pub(crate) factor: Option<Factor>,
    /// Numeric Cholesky factorizations attempted (two when the exact tangent failed and the
    /// projected one was factored).
    pub(crate) factorizations: usize,
}

/// Assembles the tangent with `assemble(stiffness, project)` and solves `K u = rhs` by `method`,
/// reassembling with projection if the exact tangent is not positive definite. `reduction` is
/// the factor by which Newton's tolerance asks the out-of-balance force to fall (its target over
/// `‖rhs‖`); the automatic conjugate gradient solves to half of it, within
/// [`MIN_AUTOMATIC_CG_TOLERANCE`] and [`AUTOMATIC_CG_TOLERANCE`].
///
/// # Errors
/// [`Error::IndefiniteStiffness`] if even the projected tangent cannot be factored.
pub(crate) fn solve_newton_system(
    method: Method,
    reduction: f64,
    stiffness: &mut Stiffness,
    rhs: &[DVec3],
    iteration: usize,
    mut assemble: impl FnMut(&mut Stiffness, bool),
) -> Result<Solution, Error> {
    assemble(stiffness, false);
    let (tolerance, max_iterations, fallback) = match method {
        Method::Direct => {
            let direct = factorize_direct(stiffness, iteration, assemble, false)?;
            return Ok(Solution {
                direction: solve(&direct.factor, rhs),
                cg_iterations: 0,
                projected: direct.projected,
                fell_back: false,
                factorizations: direct.attempts,
                factor: Some(direct.factor),
            });
        }
        Method::ConjugateGradient {
            tolerance,
            max_iterations,
        } => (tolerance, max_iterations, false),
        Method::AutomaticConjugateGradient { max_iterations } => (
            (0.5 * reduction).clamp(MIN_AUTOMATIC_CG_TOLERANCE, AUTOMATIC_CG_TOLERANCE),
            max_iterations,
            true,
        ),
    };
    let b: Vec<f64> = rhs.iter().flat_map(|v| v.to_array()).collect();
    let mut cg_iterations = 0;
    let mut projected = false;
    loop {
        match conjugate_gradient(stiffness.block_rows(), &b, tolerance, max_iterations) {
            CgOutcome::Solved {
                x,
                iterations,
                converged,
            } => {
                cg_iterations += iterations;
                if converged || !fallback {
                    return Ok(Solution {
                        direction: x
                            .chunks_exact(3)
                            .map(|c| DVec3::new(c[0], c[1], c[2]))
                            .collect(),
                        cg_iterations,
                        projected,
                        fell_back: false,
                        factor: None,
                        factorizations: 0,
                    });
                }
                break;
            }
            CgOutcome::NegativeCurvature { iterations } => {
                cg_iterations += iterations;
                if projected {
                    // The projected tangent is positive semi-definite and the mass term makes it
                    // definite; only round-off gets here. The factorization decides.
                    break;
                }
                assemble(stiffness, true);
                projected = true;
            }
        }
    }
    let direct = factorize_direct(stiffness, iteration, assemble, projected)?;
    Ok(Solution {
        direction: solve(&direct.factor, rhs),
        cg_iterations,
        projected: direct.projected,
        fell_back: true,
        factorizations: direct.attempts,
        factor: Some(direct.factor),
    })
}

/// A successful Cholesky factorization of the Newton system.
struct DirectFactorization {
    factor: Factor,
    /// Whether the tangent factored is the projected one.
    projected: bool,
    /// Factorizations attempted: 1, or 2 when the exact tangent failed first.
    attempts: usize,
}

/// The Cholesky factorization of the assembled `stiffness`; if that fails and the tangent is not
/// already `projected`, reassembles with projection and factorizes again.
///
/// # Errors
/// [`Error::IndefiniteStiffness`] if the (projected) tangent cannot be factored.
fn factorize_direct(
    stiffness: &mut Stiffness,
    iteration: usize,
    mut assemble: impl FnMut(&mut Stiffness, bool),
    projected: bool,
) -> Result<DirectFactorization, Error> {
    match factorize(stiffness, iteration) {
        Ok(factor) => Ok(DirectFactorization {
            factor,
            projected,
            attempts: 1,
        }),
        Err(error) if projected => Err(error),
        Err(_) => {
            assemble(stiffness, true);
            Ok(DirectFactorization {
                factor: factorize(stiffness, iteration)?,
                projected: true,
                attempts: 2,
            })
        }
    }
}
