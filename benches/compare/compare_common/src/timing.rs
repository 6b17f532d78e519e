//! Per-step times: a CPU clock and the wall clock, reduced to medians as the peers' scripts do.

use rustix::time::{ClockId, clock_gettime};
use serde_json::{Value, json};
use std::time::Instant;

/// Which CPU clock a [`Timer`] reads.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum CpuClock {
    /// The calling thread's (`CLOCK_THREAD_CPUTIME_ID`): the whole step's CPU time when the step
    /// runs on a one-thread pool, as every case but the scaling scene's multi-thread ones does.
    Thread,
    /// The process's, all threads summed (`CLOCK_PROCESS_CPUTIME_ID`): for steps spread over
    /// several threads.
    Process,
}

impl CpuClock {
    /// CPU seconds consumed so far on this clock.
    fn now_s(self) -> f64 {
        let id = match self {
            CpuClock::Thread => ClockId::ThreadCPUTime,
            CpuClock::Process => ClockId::ProcessCPUTime,
        };
        let ts = clock_gettime(id);
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    }

    /// The clock's name in the `settings` of a line.
    pub fn name(self) -> &'static str {
        match self {
            CpuClock::Thread => "thread CPU time (CLOCK_THREAD_CPUTIME_ID)",
            CpuClock::Process => "process CPU time, all threads (CLOCK_PROCESS_CPUTIME_ID)",
        }
    }
}

/// The CPU and wall time of every timed step, in seconds.
pub struct Timer {
    clock: CpuClock,
    cpu: Vec<f64>,
    wall: Vec<f64>,
}

impl Timer {
    /// An empty timer reading `clock`.
    pub fn new(clock: CpuClock) -> Self {
        Timer {
            clock,
            cpu: Vec::new(),
            wall: Vec::new(),
        }
    }

    /// Runs `f` (one step) and records its CPU and wall time.
    pub fn time<R>(&mut self, f: impl FnOnce() -> R) -> R {
        let (c0, w0) = (self.clock.now_s(), Instant::now());
        let out = f();
        self.cpu.push(self.clock.now_s() - c0);
        self.wall.push(w0.elapsed().as_secs_f64());
        out
    }

    /// Number of timed steps.
    pub fn steps_timed(&self) -> usize {
        self.cpu.len()
    }

    /// Wall seconds of the timed steps so far.
    pub fn wall_total_s(&self) -> f64 {
        self.wall.iter().sum()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn thread_clock_counts_work() {
        let mut timer = Timer::new(CpuClock::Thread);
        let sum = timer.time(|| {
            (0..std::hint::black_box(2_000_000u64))
                .map(|k| k ^ (k >> 3))
                .sum::<u64>()
        });
        assert!(sum > 0 && timer.steps_timed() == 1 && timer.cpu[0] > 0.0);
    }
}
