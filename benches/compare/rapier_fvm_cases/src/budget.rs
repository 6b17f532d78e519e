//! The time budget of a case: a run is stopped, and reported as skipped, once the steps done
//! so far predict that the whole case would run longer than the limit.

use std::time::Instant;

/// Longest a single case may be predicted to run (wall seconds).
pub const CASE_LIMIT_S: f64 = 60.0;
/// A prediction is trusted only after this much wall time (s): the first steps of a case are
/// its costliest (the body starts moving), so early predictions run high.
const TRUSTED_AFTER_S: f64 = 2.0;

/// A case's start and limit.
pub struct Deadline {
    start: Instant,
    limit_s: f64,
}

impl Deadline {
    /// Starts the clock of a case allowed `limit_s` wall seconds.
    pub fn start(limit_s: f64) -> Self {
        Deadline {
            start: Instant::now(),
            limit_s,
        }
    }

    /// Wall seconds since the start.
    pub fn elapsed_s(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// `Err(reason)` when `done` of `total` steps predict a case longer than the limit.
    pub fn check(&self, done: usize, total: usize) -> Result<(), String> {
        let elapsed = self.elapsed_s();
        if done == 0 || elapsed < TRUSTED_AFTER_S {
            return Ok(());
        }
        let predicted = elapsed * total as f64 / done as f64;
        if predicted > self.limit_s {
            Err(format!(
                "stopped after {done} of {total} steps ({elapsed:.1} s): predicted {predicted:.0} s, \
                 over the {:.0} s budget of a case",
                self.limit_s
            ))
        } else {
            Ok(())
        }
    }
}
