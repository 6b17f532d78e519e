//! The predicted cost of a frame with each integrator, from constants measured on the machine
//! that runs it (`rapier-fvm calibrate` measures them and prints them as a scene's
//! `[integrator.cost]` table; [`CostModel::default`] holds those measured on the development
//! machine):
//!
//! - explicit: `n (T c_tet d + P s c_point)`: the `n` substeps the stability limit needs, `T`
//!   tetrahedra at `c_tet` each (the material model's), `d` the factor damping costs (1 when
//!   undamped), and `P` contact points swept `s` times per substep at `c_point` each;
//! - implicit: `k N T c_newton (T/1000)^α`: `k` substeps of `N` Newton iterations over `T`
//!   tetrahedra at `c_newton` each at a thousand tetrahedra (the material model's), dearer per
//!   tetrahedron in larger bodies by the exponent `α` (the sparse factorization's fill grows
//!   faster than the mesh). `N` is the body's own mean over its recent implicit frames
//!   ([`NewtonHistory`]), [`CostModel::newton_iterations`] until it has one.
//!
//! Only the ratio of the two predictions decides, so the constants need be right relative to
//! each other on the machine at hand; a run's report gives each body's predictions beside its
//! measured time per frame.

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
    /// Implicit: seconds per tetrahedron per Newton iteration (assembly, factorization or
    /// reuse, solve, line search) in a body of a thousand tetrahedra, for the linear, St.
    /// Venant–Kirchhoff and stable Neo-Hookean models.
    pub newton_tet: f64,
    /// Implicit: how the cost per tetrahedron of a Newton iteration grows with the body's
    /// tetrahedra `T`, as `(T/1000)^α` (dimensionless, from 0 to 1).
    pub newton_size_exponent: f64,
    /// Implicit: seconds per tetrahedron per Newton iteration for the corotated model.
    pub newton_tet_corotated: f64,
    /// Implicit: Newton iterations per substep assumed for a body that has not yet taken an
    /// implicit step.
    pub newton_iterations: f64,
}

impl Default for CostModel {
    /// Measured by `rapier-fvm calibrate` on the development machine (two cores): see the
    /// README's "Choosing the integrator".
    fn default() -> Self {
        Self {
            explicit_tet: 19.0e-9,
            explicit_tet_corotated: 98e-9,
            explicit_damped_factor: 1.64,
            explicit_contact_point: 138e-9,
            newton_tet: 1.10e-6,
            newton_size_exponent: 0.16,
            newton_tet_corotated: 1.69e-6,
            newton_iterations: 1.27,
        }
    }
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
    /// Newton iterations per implicit substep expected.
    pub(crate) newton_iterations: f64,
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
        let per_tet = match work.model {
            MaterialModel::Corotated => self.newton_tet_corotated,
            _ => self.newton_tet,
        };
        let size = (work.tets / 1000.0).powf(self.newton_size_exponent);
        substeps * work.newton_iterations * work.tets * per_tet * size
    }
}

/// A body's Newton iterations per implicit substep, averaged over its recent implicit frames
/// (each new frame weighs [`NewtonHistory::WEIGHT`]), and drawn back towards the cost model's
/// assumption by each explicit frame (by [`NewtonHistory::FORGETTING`]), so that a body that
/// left the implicit integrator after a few hard frames (an impact) tries it again once they are
/// forgotten. It also keeps the Newton iterations a budget of the automatic choice allowed and
/// its frames left unspent, for a harder frame to use (see [`NewtonHistory::budget`]). The same
/// run gives the same history, so the choices it drives repeat bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub(crate) struct NewtonHistory {
    mean: Option<f64>,
    /// Newton iterations per substep allowed and left unspent by the last implicit frames.
    #[cfg_attr(feature = "serde-serialize", serde(default))]
    saved: f64,
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

    /// Takes in an implicit frame of `iterations` Newton iterations over `substeps`, allowed
    /// `allowed` per substep.
    fn record(&mut self, iterations: usize, substeps: u32, allowed: usize) {
        let per_substep = iterations as f64 / f64::from(substeps.max(1));
        self.saved = (allowed as f64 - per_substep).max(0.0);
        self.mean = Some(match self.mean {
            Some(mean) => mean + Self::WEIGHT * (per_substep - mean),
            None => per_substep,
        });
    }

    /// Takes in an implicit frame's `outcome` by `integrator`: its iterations, or for a frame
    /// it could not take, every iteration it was allowed (what the attempt cost).
    pub(crate) fn record_outcome(
        &mut self,
        outcome: &Result<ImplicitReport, Error>,
        integrator: &ImplicitIntegrator,
    ) {
        let allowed = integrator.max_newton_iterations;
        match outcome {
            Ok(report) => self.record(report.newton_iterations, report.substeps, allowed),
            Err(_) => self.record(allowed, 1, allowed),
        }
    }

    /// Takes in an explicit frame: the mean moves towards `assumed`, and nothing is saved.
    pub(crate) fn forget(&mut self, assumed: f64) {
        self.saved = 0.0;
        if let Some(mean) = &mut self.mean {
            *mean += Self::FORGETTING * (assumed - *mean);
        }
    }

    /// The mean, or `default` before any implicit frame.
    pub(crate) fn or(&self, default: f64) -> f64 {
        self.mean.unwrap_or(default)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_history_is_an_exponential_mean_drawn_back_by_explicit_frames() {
        // Closed form: 4 per substep, then 8 → 4 + (8 − 4)/4 = 5; an explicit frame → 5 + (1 −
        // 5)/16 = 4.75; a refused frame of budget 20 → 4.75 + (20 − 4.75)/4 = 8.5625.
        let mut history = NewtonHistory::default();
        assert_eq!(history.or(1.0), 1.0);
        history.forget(1.0);
        assert_eq!(
            history.or(1.0),
            1.0,
            "nothing to forget before an implicit frame"
        );
        history.record(8, 2, 100);
        history.record(8, 1, 100);
        assert_eq!(history.or(1.0), 5.0);
        history.forget(1.0);
        assert_eq!(history.or(1.0), 4.75);
        let integrator = ImplicitIntegrator {
            max_newton_iterations: 20,
            ..ImplicitIntegrator::default()
        };
        let refused = Err(Error::NewtonDidNotConverge {
            residual: 1.0,
            substeps: 1,
        });
        history.record_outcome(&refused, &integrator);
        assert_eq!(history.or(1.0), 8.5625);
    }

    #[test]
    fn a_frame_may_spend_what_easy_frames_left_of_their_budget_up_to_eight_frames_worth() {
        // Closed form, a budget of 10 a frame: nothing saved → 10; a frame allowed 10 that took
        // 2 leaves 8 → 18; one allowed 100 that took 1 leaves 99 → capped at 80; an explicit
        // frame or a refused one leaves nothing → 10.
        let mut history = NewtonHistory::default();
        assert_eq!(history.budget(10.0), 10.0);
        history.record(2, 1, 10);
        assert_eq!(history.budget(10.0), 18.0);
        history.record(1, 1, 100);
        assert_eq!(history.budget(10.0), 80.0);
        history.forget(1.0);
        assert_eq!(history.budget(10.0), 10.0);
        history.record(1, 1, 100);
        let refused = Err(Error::NewtonDidNotConverge {
            residual: 1.0,
            substeps: 1,
        });
        history.record_outcome(&refused, &ImplicitIntegrator::default());
        assert_eq!(history.budget(10.0), 10.0);
    }
}
