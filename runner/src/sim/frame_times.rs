//! Where a run's stepping time goes, frame by frame: each frame's stepping wall time (ms) and the
//! soft bodies awake after it, summed up as the median and slowest frame and the frames slower
//! than real time (a frame's stepping longer than its `dt`) with their share of the stepping.

use crate::output::TimeSeries;
use rapier_fvm::coupling::FrameTiming;
use serde::Serialize;

/// Each frame's stepping time and awake soft bodies, with their summary (`frame_times` in
/// `report.json`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FrameTimes {
    /// Stepping wall time (ms) of each frame, the first frame first.
    pub ms: Vec<f64>,
    /// Soft bodies awake (neither asleep nor standing in as a rigid body) after each frame.
    pub awake_soft_bodies: Vec<usize>,
    /// The median frame's stepping time (ms).
    pub median_ms: f64,
    /// The slowest frame (counted from 1), 0 when there are none.
    pub slowest_frame: usize,
    /// The slowest frame's stepping time (ms).
    pub slowest_ms: f64,
    /// The real-time budget of a frame, its `dt` (ms).
    pub budget_ms: f64,
    /// The frames whose stepping took longer than the budget.
    pub over_budget_frames: usize,
    /// Those frames' share of the whole stepping time (0 to 1).
    pub over_budget_share: f64,
    /// Where the stepping time went, summed over the frames (`null` for a 2D scene).
    pub parts: Option<StepParts>,
}

/// Where a run's stepping time went (s, wall clock), from each frame's
/// [`FrameTiming`](rapier_fvm::coupling::FrameTiming): the soft bodies' steps summed body by body
/// over the threads that ran them (so they can add up to more than the stepping time), contact
/// detection and rapier's steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StepParts {
    /// Implicit steps of bodies touching or glued to a dynamic rigid body (s).
    pub implicit_with_rigid_partners_s: f64,
    /// Implicit steps of bodies without dynamic rigid partners (s).
    pub implicit_without_rigid_partners_s: f64,
    /// Explicit steps of bodies touching or glued to a dynamic rigid body (s).
    pub explicit_with_rigid_partners_s: f64,
    /// Explicit steps of bodies without dynamic rigid partners (s).
    pub explicit_without_rigid_partners_s: f64,
    /// Contact detection (s).
    pub contact_detection_s: f64,
    /// rapier's steps (s).
    pub rapier_steps_s: f64,
    /// The soft steps' seconds, both integrators, with and without rigid partners (s).
    pub soft_steps_s: f64,
}

impl StepParts {
    /// The parts of a run whose frames' timings summed to `timing`.
    pub fn of(timing: &FrameTiming) -> Self {
        Self {
            implicit_with_rigid_partners_s: timing.implicit_with_rigid_partners,
            implicit_without_rigid_partners_s: timing.implicit_without_rigid_partners,
            explicit_with_rigid_partners_s: timing.explicit_with_rigid_partners,
            explicit_without_rigid_partners_s: timing.explicit_without_rigid_partners,
            contact_detection_s: timing.contact_detection,
            rapier_steps_s: timing.rapier_steps,
            soft_steps_s: timing.soft_steps(),
        }
    }
}

impl FrameTimes {
    /// The summary of frames that took `ms` (ms each) with `awake_soft_bodies` awake after each,
    /// against the budget of a frame of `dt` (s).
    pub fn new(ms: Vec<f64>, awake_soft_bodies: Vec<usize>, dt: f64) -> Self {
        let budget_ms = dt * 1e3;
        let total: f64 = ms.iter().sum();
        // Summed from +0 (`Sum` starts from -0, printed "-0 %" when no frame is over).
        let (over_frames, over_ms) = (ms.iter().filter(|&&t| t > budget_ms))
            .fold((0, 0.0), |(count, sum), t| (count + 1, sum + t));
        let (slowest_frame, slowest_ms) = (ms.iter().enumerate())
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or((0, 0.0), |(i, &t)| (i + 1, t));
        Self {
            median_ms: median(&ms),
            slowest_frame,
            slowest_ms,
            budget_ms,
            over_budget_frames: over_frames,
            over_budget_share: if total > 0.0 { over_ms / total } else { 0.0 },
            ms,
            awake_soft_bodies,
            parts: None,
        }
    }

    /// These frames with where their stepping time went.
    pub fn with_parts(self, parts: StepParts) -> Self {
        Self {
            parts: Some(parts),
            ..self
        }
    }

    /// The stepping time per frame against simulated time, for a plot.
    pub fn series(&self, dt: f64) -> TimeSeries {
        TimeSeries {
            name: "stepping time per frame".to_owned(),
            unit: "ms".to_owned(),
            samples: (self.ms.iter().enumerate())
                .map(|(i, &t)| ((i + 1) as f64 * dt, t))
                .collect(),
        }
    }
}

/// The median of `values` (the mean of the middle two for an even count), 0 for none.
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => sorted[n / 2],
        _ => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_counts_the_frames_slower_than_real_time_and_their_share() {
        // At 60 Hz the budget is 16.67 ms: frames 2 and 3 (20 and 30 ms) are over it and take
        // 50 of the 65 ms stepped; the median of 5, 10, 20, 30 is 15.
        let times = FrameTimes::new(vec![10.0, 20.0, 30.0, 5.0], vec![3, 3, 2, 1], 1.0 / 60.0);
        assert_eq!(times.over_budget_frames, 2);
        assert!((times.over_budget_share - 50.0 / 65.0).abs() < 1e-15);
        assert_eq!(times.median_ms, 15.0);
        assert_eq!((times.slowest_frame, times.slowest_ms), (3, 30.0));
        assert!((times.budget_ms - 1000.0 / 60.0).abs() < 1e-12);
        let series = times.series(1.0 / 60.0);
        assert_eq!(series.samples[3], (4.0 / 60.0, 5.0));
    }

    #[test]
    fn frames_within_the_budget_have_no_share_over_it() {
        let times = FrameTimes::new(vec![1.0, 2.0, 3.0], vec![1; 3], 1.0 / 60.0);
        assert_eq!(times.over_budget_frames, 0);
        assert!(times.over_budget_share == 0.0 && times.over_budget_share.is_sign_positive());
        assert_eq!(times.median_ms, 2.0);
    }

    #[test]
    fn no_frames_give_an_empty_summary() {
        let times = FrameTimes::new(Vec::new(), Vec::new(), 1.0 / 60.0);
        assert_eq!((times.median_ms, times.slowest_frame), (0.0, 0));
        assert_eq!(
            (times.over_budget_frames, times.over_budget_share),
            (0, 0.0)
        );
    }
}
