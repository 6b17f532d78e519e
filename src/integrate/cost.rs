//! The predicted cost of a frame with each integrator, from constants measured on the machine
//! that runs it (`rapier-fvm calibrate` measures them and prints them as a scene's
//! `[integrator.cost]` table; [`CostModel::default`] holds those measured on the development
//! machine):
//!
//! - explicit: `n (T c_tet d + P s c_point)`: the `n` substeps the stability limit needs, `T`
//!   tetrahedra at `c_tet` each (the material model's), `d` the factor damping costs (1 when
//!   undamped), and `P` contact points swept `s` times per substep at `c_point` each;
//! - implicit: `k (T g (N c_newton + F c_factor) + L (c_cg + T c_cg_tet) + E (c_energy +
//!   R c_partner))`: `k`
//!   substeps, each of `N` Newton iterations (residual, line search and solve, at `c_newton`
//!   per tetrahedron, the material model's) and `F` numeric factorizations with their
//!   tangent's assembly (`c_factor`), these per tetrahedron of a body of a thousand and dearer
//!   in larger ones by `g = (T/1000)^α` (the sparse factorization's fill grows faster than the
//!   mesh), `L` conjugate gradient iterations (`c_cg` each and `c_cg_tet` per tetrahedron: a
//!   sparse matrix–vector product and the vector operations), and `E` evaluations of the
//!   incremental potential's energy (`c_energy` each whatever the size: its contact terms and
//!   what the line search does beyond the elements, whose energy is in `c_newton`; and
//!   `c_partner` per dynamic rigid body the body touches, of which there are `R`: its response,
//!   solved at each evaluation). `N`, `F`, `L` and `E` are the body's
//!   own means over its recent implicit frames ([`NewtonHistory`]); until it has them, `N` is
//!   [`CostModel::newton_iterations`], with [`ASSUMED_FACTORIZATIONS_PER_ITERATION`] (one if
//!   the factorization may not be reused; none for a body the linear solver would solve by the
//!   conjugate gradient, which takes the iterations that solver predicts, see
//!   [`LinearSolver::Automatic`](crate::linear_solver::LinearSolver)) and
//!   [`ASSUMED_EVALUATIONS_PER_ITERATION`], and each explicit frame draws them back towards
//!   that.
//!
//! Only the ratio of the two predictions decides, so the constants need be right relative to
//! each other on the machine at hand; a run's report gives each body's predictions beside its
//! measured time per frame. Counting the factorizations and energy evaluations apart from the
//! iterations matters where a body reuses its factorization in quiet frames and refactors
//! several times an iteration in hard ones (a tangent projected, a substep redone), or where
//! its line searches shorten the step many times (a soft stack under a box, 19 evaluations a
//! step). Measured on the implicit body steps of `rapier-fvm calibrate`'s cases, the showcase,
//! the game scene (`benches/scenes/game.toml`), a 320-tetrahedron cube dropped at 1/240 s
//! frames and the resting cube at 1 080 and 13 720 tetrahedra: this model fitted to them all
//! puts 98 to 100 % of each one's steps within a factor of two of their time (83 % of the
//! smaller resting cube's 30); fitted to calibrate's cases alone, each one's total within a
//! factor of 1.6 and the showcase's bodies within 1.71; the model before (the Newton iterations
//! alone) put 69 % of the game's steps within a factor of two (one run of the build before).

use super::{ImplicitIntegrator, ImplicitReport};
use crate::Error;
use crate::material::MaterialModel;

/// Seconds per unit of work of each integrator, measured on one machine (with the threads
/// rayon is given there).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct CostModel {
    /// Explicit: seconds per tetrahedron per substep (internal forces and the update), for the
    /// linear, St. Venant–Kirchhoff and stable Neo-Hookean models.
    pub explicit_tet: f64,
    /// Explicit: seconds per tetrahedron per substep for the corotated model (its polar
    /// decomposition per element).
    pub explicit_tet_corotated: f64,
    /// Explicit: how many times the cost of an undamped tetrahedron a damped one costs
    /// (dimensionless, at least 1).
    pub explicit_damped_factor: f64,
    /// Explicit: seconds per contact point per velocity sweep per substep.
    pub explicit_contact_point: f64,
    /// Implicit: seconds per tetrahedron per Newton iteration beyond its factorization
    /// (residual, line search, solve) in a body of a thousand tetrahedra, for the linear, St.
    /// Venant–Kirchhoff and stable Neo-Hookean models.
    pub newton_tet: f64,
    /// Implicit: how the cost per tetrahedron of a Newton iteration and of a factorization grow
    /// with the body's tetrahedra `T`, as `(T/1000)^α` (dimensionless, from 0 to 1).
    pub newton_size_exponent: f64,
    /// Implicit: seconds per tetrahedron per Newton iteration for the corotated model.
    pub newton_tet_corotated: f64,
    /// Implicit: seconds per tetrahedron per numeric factorization of the Newton system, with
    /// the assembly of its tangent, in a body of a thousand tetrahedra.
    #[cfg_attr(feature = "serde-serialize", serde(default = "default_factorization"))]
    pub factorization_tet: f64,
    /// Implicit: seconds per evaluation of the incremental potential's energy, whatever the
    /// body's size (its contact terms, the line search's own work).
    #[cfg_attr(feature = "serde-serialize", serde(default = "default_energy"))]
    pub energy_evaluation: f64,
    /// Implicit: seconds per evaluation of the energy per dynamic rigid body the body's
    /// contacts or attachments touch (its response, solved at each evaluation).
    #[cfg_attr(feature = "serde-serialize", serde(default = "default_partner"))]
    pub partner_evaluation: f64,
    /// Implicit: seconds per conjugate gradient iteration whatever the body's size (its vector
    /// operations' fixed costs).
    #[cfg_attr(
        feature = "serde-serialize",
        serde(default = "default_conjugate_gradient")
    )]
    pub conjugate_gradient_iteration: f64,
    /// Implicit: seconds per tetrahedron per conjugate gradient iteration (a sparse
    /// matrix–vector product and the vector operations).
    #[cfg_attr(
        feature = "serde-serialize",
        serde(default = "default_conjugate_gradient_tet")
    )]
    pub conjugate_gradient_tet: f64,
    /// Implicit: Newton iterations per substep assumed for a body that has not yet taken an
    /// implicit step.
    pub newton_iterations: f64,
}

impl Default for CostModel {
    /// Measured by `rapier-fvm calibrate` on the development machine (two cores): see the
    /// README's "Choosing the integrator".
    fn default() -> Self {
        Self {
            explicit_tet: 25.9e-9,
            explicit_tet_corotated: 107.7e-9,
            explicit_damped_factor: 1.27,
            explicit_contact_point: 149e-9,
            newton_tet: 0.165e-6,
            newton_size_exponent: 0.20,
            newton_tet_corotated: 0.472e-6,
            factorization_tet: default_factorization(),
            energy_evaluation: default_energy(),
            partner_evaluation: default_partner(),
            conjugate_gradient_iteration: default_conjugate_gradient(),
            conjugate_gradient_tet: default_conjugate_gradient_tet(),
            newton_iterations: 1.36,
        }
    }
}

/// [`CostModel::factorization_tet`] of [`CostModel::default`] (s).
fn default_factorization() -> f64 {
    1.34e-6
}

/// [`CostModel::energy_evaluation`] of [`CostModel::default`] (s).
fn default_energy() -> f64 {
    35.0e-6
}

/// [`CostModel::partner_evaluation`] of [`CostModel::default`] (s).
fn default_partner() -> f64 {
    19.4e-6
}

/// [`CostModel::conjugate_gradient_iteration`] of [`CostModel::default`] (s).
fn default_conjugate_gradient() -> f64 {
    22.9e-6
}

/// [`CostModel::conjugate_gradient_tet`] of [`CostModel::default`] (s).
fn default_conjugate_gradient_tet() -> f64 {
    7.21e-9
}

/// What a frame's prediction needs to know of a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Workload {
    /// Tetrahedra.
    pub(crate) tets: f64,
    /// The material model.
    pub(crate) model: MaterialModel,
    /// Whether the body is damped.
    pub(crate) damped: bool,
    /// Contact points against colliders, the body's own triangles and rigid corners (those
    /// with other soft bodies are counted for their group).
    pub(crate) contact_points: f64,
    /// Velocity sweeps per explicit substep.
    pub(crate) sweeps: f64,
    /// Dynamic rigid bodies the contacts and attachments touch.
    pub(crate) rigid_partners: f64,
    /// The work per implicit substep expected.
    pub(crate) newton: NewtonWork,
}

impl CostModel {
    /// Predicted seconds of an explicit frame of `substeps` for `work`.
    pub(crate) fn explicit_seconds(&self, work: &Workload, substeps: f64) -> f64 {
        let per_tet = match work.model {
            MaterialModel::Corotated => self.explicit_tet_corotated,
            _ => self.explicit_tet,
        };
        let damping = if work.damped {
            self.explicit_damped_factor
        } else {
            1.0
        };
        substeps * work.tets * per_tet * damping
            + self.contact_seconds(work.contact_points, work.sweeps, substeps)
    }

    /// Predicted seconds of sweeping `points` contact points `sweeps` times per explicit
    /// substep over `substeps`.
    pub(crate) fn contact_seconds(&self, points: f64, sweeps: f64, substeps: f64) -> f64 {
        substeps * points * sweeps * self.explicit_contact_point
    }

    /// Predicted seconds of an implicit frame of `substeps` for `work`.
    pub(crate) fn implicit_seconds(&self, work: &Workload, substeps: f64) -> f64 {
        let per_iteration = match work.model {
            MaterialModel::Corotated => self.newton_tet_corotated,
            _ => self.newton_tet,
        };
        let size = (work.tets / 1000.0).powf(self.newton_size_exponent);
        let newton = &work.newton;
        let direct =
            newton.iterations * per_iteration + newton.factorizations * self.factorization_tet;
        let conjugate_gradient =
            self.conjugate_gradient_iteration + work.tets * self.conjugate_gradient_tet;
        substeps
            * (work.tets * size * direct
                + newton.linear_iterations * conjugate_gradient
                + newton.energy_evaluations
                    * (self.energy_evaluation + work.rigid_partners * self.partner_evaluation))
    }
}

/// The work of an implicit substep: Newton iterations, numeric factorizations, conjugate
/// gradient iterations and energy evaluations (each a mean per substep).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct NewtonWork {
    /// Newton iterations.
    pub iterations: f64,
    /// Numeric factorizations of the Newton system.
    pub factorizations: f64,
    /// Conjugate gradient iterations.
    pub linear_iterations: f64,
    /// Evaluations of the incremental potential's energy.
    pub energy_evaluations: f64,
}

/// Factorizations per Newton iteration assumed of a body solved directly that may reuse its
/// factorization, before its own implicit frames: `rapier-fvm calibrate`'s drop solved directly
/// took 0.77 a substep in 2.51 iterations (the chord method refactors in a landing, rarely at
/// rest).
pub const ASSUMED_FACTORIZATIONS_PER_ITERATION: f64 = 0.3;

/// Energy evaluations per Newton iteration assumed before a body's own implicit frames (the
/// solve's start and its line searches' trials): 4.56 a substep in 2.51 iterations in
/// `rapier-fvm calibrate`'s drop solved directly, 3.36 in 1.36 by the conjugate gradient.
pub const ASSUMED_EVALUATIONS_PER_ITERATION: f64 = 2.0;

impl NewtonWork {
    /// `iterations` Newton iterations solved directly, each with
    /// [`ASSUMED_EVALUATIONS_PER_ITERATION`] and, if the factorization may be reused,
    /// [`ASSUMED_FACTORIZATIONS_PER_ITERATION`] (else one factorization each).
    pub(crate) fn assumed_direct(iterations: f64, reuse: bool) -> Self {
        let factorizations = if reuse {
            ASSUMED_FACTORIZATIONS_PER_ITERATION
        } else {
            1.0
        };
        Self {
            iterations,
            factorizations: factorizations * iterations,
            linear_iterations: 0.0,
            energy_evaluations: ASSUMED_EVALUATIONS_PER_ITERATION * iterations,
        }
    }

    /// Every count times `factor`.
    fn times(&self, factor: f64) -> Self {
        Self {
            iterations: self.iterations * factor,
            factorizations: self.factorizations * factor,
            linear_iterations: self.linear_iterations * factor,
            energy_evaluations: self.energy_evaluations * factor,
        }
    }

    /// Every count moved `weight` of the way towards `new`'s.
    fn towards(&self, new: &Self, weight: f64) -> Self {
        let blend = |mean: f64, new: f64| mean + weight * (new - mean);
        Self {
            iterations: blend(self.iterations, new.iterations),
            factorizations: blend(self.factorizations, new.factorizations),
            linear_iterations: blend(self.linear_iterations, new.linear_iterations),
            energy_evaluations: blend(self.energy_evaluations, new.energy_evaluations),
        }
    }

    /// `iterations` Newton iterations, each with the rest of the work of an iteration of
    /// `like`, or each factorizing if `like` has no iteration.
    fn scaled(iterations: f64, like: &NewtonWork) -> Self {
        if like.iterations > 0.0 {
            like.times(iterations / like.iterations)
        } else {
            Self::assumed_direct(iterations, false)
        }
    }
}

/// A body's implicit work per substep ([`NewtonWork`]), averaged over its recent implicit frames
/// (each new frame weighs [`NewtonHistory::WEIGHT`]), and drawn back towards the cost model's
/// assumption by each explicit frame (by [`NewtonHistory::FORGETTING`]), so that a body that left the
/// implicit integrator after a few hard frames (an impact) tries it again once they are
/// forgotten. It also keeps the Newton iterations a budget of the automatic choice allowed and
/// its frames left unspent, for a harder frame to use (see [`NewtonHistory::budget`]). The same
/// run gives the same history (counts, not times), so the choices it drives repeat bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct NewtonHistory {
    mean: Option<NewtonWork>,
    /// Newton iterations per substep allowed and left unspent by the last implicit frames.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    saved: f64,
    /// Whether the last frame was implicit (`None` before any frame).
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    last_implicit: Option<bool>,
}

impl NewtonHistory {
    /// The weight of the newest frame in the mean.
    const WEIGHT: f64 = 0.25;

    /// The fraction of its distance to the assumption an explicit frame draws the mean back.
    const FORGETTING: f64 = 1.0 / 16.0;

    /// The most frames' worth of Newton iterations a body saves up (see
    /// [`NewtonHistory::budget`]).
    const SAVED_FRAMES: f64 = 8.0;

    /// The Newton iterations per substep a frame allowed `affordable` of them may take: those,
    /// plus what the last implicit frames were allowed and left unspent, up to
    /// [`NewtonHistory::SAVED_FRAMES`] frames' worth. So a frame harder than the rest (a box
    /// landing on a soft stack took 46 iterations where its neighbours took one or two) may
    /// spend what easy ones saved, while the body's implicit frames together stay within what
    /// the explicit frames would have cost.
    pub(crate) fn budget(&self, affordable: f64) -> f64 {
        (self.saved + affordable).min(Self::SAVED_FRAMES * affordable)
    }

    /// Takes in an implicit frame of `frame` work over `substeps`, allowed `allowed` Newton
    /// iterations per substep.
    fn record(&mut self, frame: NewtonWork, substeps: u32, allowed: usize) {
        let new = frame.times(1.0 / f64::from(substeps.max(1)));
        self.saved = (allowed as f64 - new.iterations).max(0.0);
        self.last_implicit = Some(true);
        self.mean = Some(match self.mean {
            Some(mean) => mean.towards(&new, Self::WEIGHT),
            None => new,
        });
    }

    /// Takes in an implicit frame's `outcome` by `integrator`: its work, or for a frame it
    /// could not take, every iteration it was allowed (what the attempt cost), each with the
    /// rest of the work of the body's mean iteration.
    pub(crate) fn record_outcome(
        &mut self,
        outcome: &Result<ImplicitReport, Error>,
        integrator: &ImplicitIntegrator,
    ) {
        let allowed = integrator.max_newton_iterations;
        match outcome {
            Ok(report) => {
                let frame = NewtonWork {
                    iterations: report.newton_iterations as f64,
                    factorizations: report.factorizations as f64,
                    linear_iterations: report.linear_iterations as f64,
                    energy_evaluations: report.energy_evaluations as f64,
                };
                self.record(frame, report.substeps, allowed);
            }
            Err(_) => {
                let like = self.mean.unwrap_or_default();
                self.record(NewtonWork::scaled(allowed as f64, &like), 1, allowed);
            }
        }
    }

    /// Takes in an explicit frame: the mean work moves towards `assumed`, and nothing is
    /// saved.
    pub(crate) fn forget(&mut self, assumed: &NewtonWork) {
        self.saved = 0.0;
        self.last_implicit = Some(false);
        if let Some(mean) = &mut self.mean {
            *mean = mean.towards(assumed, Self::FORGETTING);
        }
    }

    /// Whether the body's last frame was implicit (`None` before any frame).
    pub(crate) fn last_implicit(&self) -> Option<bool> {
        self.last_implicit
    }

    /// The mean work per substep, or `assumed` before any implicit frame.
    pub(crate) fn or(&self, assumed: impl FnOnce() -> NewtonWork) -> NewtonWork {
        self.mean.unwrap_or_else(assumed)
    }

    /// Whether the body has taken (or tried) an implicit frame.
    #[cfg(test)]
    pub(crate) fn has_history(&self) -> bool {
        self.mean.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame's (or a substep's) work.
    fn work(iterations: f64, factorizations: f64, linear: f64, energy: f64) -> NewtonWork {
        NewtonWork {
            iterations,
            factorizations,
            linear_iterations: linear,
            energy_evaluations: energy,
        }
    }

    /// `left` equals `right` to round-off (1e-12 relative).
    fn assert_close(left: NewtonWork, right: NewtonWork) {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert!(
            close(left.iterations, right.iterations)
                && close(left.factorizations, right.factorizations)
                && close(left.linear_iterations, right.linear_iterations)
                && close(left.energy_evaluations, right.energy_evaluations),
            "{left:?} against {right:?}"
        );
    }

    #[test]
    fn the_history_is_an_exponential_mean_drawn_back_by_explicit_frames() {
        // Closed form, per substep (iterations, factorizations, conjugate gradient iterations,
        // energy evaluations): (8, 8, 0, 16) over 2 substeps → (4, 4, 0, 8); then (8, 2, 16, 24)
        // → (4 + 4/4, 4 − 2/4, 16/4, 8 + 16/4) = (5, 3.5, 4, 12); an explicit frame draws each
        // 1/16 of the way to the assumption (1, 0.5, 0, 2) → (4.75, 3.3125, 3.75, 11.375); a
        // refused frame allowed 20 counts 20 iterations with the rest of the mean's work per
        // iteration, the mean's work times r = 20/4.75, and the mean moves a quarter of the way
        // to it: w + (r w − w)/4 for each count w.
        let assumed = || work(1.0, 0.5, 0.0, 2.0);
        let mut history = NewtonHistory::default();
        assert_eq!(history.or(assumed), assumed());
        history.forget(&assumed());
        assert!(
            !history.has_history(),
            "nothing to forget before an implicit frame"
        );
        history.record(work(8.0, 8.0, 0.0, 16.0), 2, 100);
        history.record(work(8.0, 2.0, 16.0, 24.0), 1, 100);
        assert_close(history.or(assumed), work(5.0, 3.5, 4.0, 12.0));
        history.forget(&assumed());
        let forgotten = work(4.75, 3.3125, 3.75, 11.375);
        assert_close(history.or(assumed), forgotten);
        let integrator = ImplicitIntegrator {
            max_newton_iterations: 20,
            ..ImplicitIntegrator::default()
        };
        let refused = Err(Error::NewtonDidNotConverge {
            residual: 1.0,
            substeps: 1,
        });
        history.record_outcome(&refused, &integrator);
        let quarter_to = |w: f64| w + (w * 20.0 / 4.75 - w) / 4.0;
        let refused_mean = work(
            8.5625,
            quarter_to(3.3125),
            quarter_to(3.75),
            quarter_to(11.375),
        );
        assert_close(history.or(assumed), refused_mean);
    }

    #[test]
    fn a_frame_may_spend_what_easy_frames_left_of_their_budget_up_to_eight_frames_worth() {
        // Closed form, a budget of 10 a frame: nothing saved → 10; a frame allowed 10 that took
        // 2 leaves 8 → 18; one allowed 100 that took 1 leaves 99 → capped at 80; an explicit
        // frame or a refused one leaves nothing → 10.
        let mut history = NewtonHistory::default();
        assert_eq!(history.budget(10.0), 10.0);
        history.record(work(2.0, 2.0, 0.0, 4.0), 1, 10);
        assert_eq!(history.budget(10.0), 18.0);
        history.record(work(1.0, 1.0, 0.0, 2.0), 1, 100);
        assert_eq!(history.budget(10.0), 80.0);
        history.forget(&work(1.0, 1.0, 0.0, 2.0));
        assert_eq!(history.budget(10.0), 10.0);
        history.record(work(1.0, 1.0, 0.0, 2.0), 1, 100);
        let refused = Err(Error::NewtonDidNotConverge {
            residual: 1.0,
            substeps: 1,
        });
        history.record_outcome(&refused, &ImplicitIntegrator::default());
        assert_eq!(history.budget(10.0), 10.0);
    }
}
