//! The time budget of a case: a resolution is skipped when the previous, smaller one predicts
//! it would run longer than the limit.

use crate::setup::Solver;

/// Longest a single case may be predicted to run (wall seconds).
pub const CASE_LIMIT_S: f64 = 60.0;

/// Prediction of the next case's wall time from the last one run with the same solver.
pub struct Budget {
    exponent: f64,
    limit_s: f64,
    last: Option<(usize, f64)>,
}

impl Budget {
    /// A budget for a sequence of growing resolutions run with `solver`.
    pub fn new(solver: Solver, limit_s: f64) -> Self {
        Budget {
            exponent: solver.cost_exponent(),
            limit_s,
            last: None,
        }
    }

    /// `Err(reason)` when a case of `particles` particles is predicted to exceed the limit.
    pub fn check(&self, particles: usize) -> Result<(), String> {
        let Some((n, wall)) = self.last else {
            return Ok(());
        };
        let predicted = wall * (particles as f64 / n as f64).powf(self.exponent);
        if predicted > self.limit_s {
            Err(format!(
                "predicted {predicted:.0} s from the {n}-particle case ({wall:.1} s, cost ~ n^{:.2}), \
                 over the {:.0} s budget",
                self.exponent, self.limit_s
            ))
        } else {
            Ok(())
        }
    }

    /// Records a case that ran.
    pub fn record(&mut self, particles: usize, wall_s: f64) {
        self.last = Some((particles, wall_s));
    }
}
