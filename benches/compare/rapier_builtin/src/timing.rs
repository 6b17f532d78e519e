//! Per-step times: this thread's CPU clock and the wall clock, reduced to medians.

use serde_json::{Value, json};
use std::time::Instant;

/// The CPU and wall time of every timed step, in seconds.
#[derive(Default)]
pub struct Timer {
    cpu: Vec<f64>,
    wall: Vec<f64>,
}

impl Timer {
    /// Runs `f` (one step) and records its CPU and wall time.
    pub fn time<R>(&mut self, f: impl FnOnce() -> R) -> R {
        let (c0, w0) = (thread_cpu_s(), Instant::now());
        let out = f();
        self.cpu.push(thread_cpu_s() - c0);
        self.wall.push(w0.elapsed().as_secs_f64());
        out
    }

    /// Number of timed steps.
    pub fn len(&self) -> usize {
        self.cpu.len()
    }

    /// The fields every line carries: median CPU and wall ms per step, the step count and
    /// their CPU total.
    pub fn fields(&self) -> Value {
        json!({
            "ms_per_step": median(&self.cpu).map(|s| s * 1e3),
            "wall_ms_per_step": median(&self.wall).map(|s| s * 1e3),
            "steps_timed": self.cpu.len(),
            "cpu_s_total": self.cpu.iter().sum::<f64>(),
        })
    }
}

/// Median of `values` (mean of the two middle ones for an even count); `None` if empty.
fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some(0.5 * (v[n / 2 - 1] + v[n / 2])),
    }
}

/// CPU seconds consumed so far by the calling thread (`CLOCK_THREAD_CPUTIME_ID`); rapier runs
/// single-threaded here (no `parallel` feature), so this is the whole step's CPU time.
fn thread_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable `timespec` and the clock id is a kernel constant.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}
