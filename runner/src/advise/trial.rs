//! A trial: the scene with some edits, run over the advisor's window into its own folder (the
//! runner's full report; one ParaView frame at each end, no pictures), and how far its probes
//! came from the reference's.
//!
//! A probe's error is its relative L2 distance over the window's samples,
//! `‖q − q_ref‖₂ / ‖q_ref‖₂` (every frame's sample, the reference's time series as the scale:
//! a shift of an impact by a frame costs what the samples it moves differ by, not the peak);
//! a trial's error is its largest probe error.

use crate::scene::Scene;
use crate::scene::edit::edited;
use crate::sim::{self, ProbeReport, Report, RunOptions};
use std::path::{Path, PathBuf};
use std::time::Duration;
use toml_edit::Value;

/// A trial's run: its report, or why it could not be run.
pub type TrialRun = Result<Report, String>;

/// Runs the scene `path` (whose text is `text`) with `edits` over `window` (s), writing into
/// `out`, stopped once its stepping takes longer than `limit`; a scene the edits make invalid
/// (a region left without nodes by a coarser mesh, say), a run that fails or is stopped is the
/// error's message.
pub fn run_trial(
    (path, text): (&Path, &str),
    edits: &[(String, Value)],
    (window, limit): (f64, Option<Duration>),
    out: PathBuf,
) -> TrialRun {
    let text = edited(text, edits).map_err(|e| e.to_string())?;
    let mut scene = Scene::parse(path, text).map_err(|e| e.to_string())?;
    scene.output.pictures = Some(Vec::new());
    scene.output.save_every = usize::MAX;
    let options = RunOptions {
        out,
        duration: Some(window),
        progress: false,
    };
    sim::run_within(&scene, &options, limit).map_err(|e| e.to_string())
}

/// The relative L2 distance of `probe`'s samples from `reference`'s (zero for two zero
/// series; infinite for a non-zero series against a zero one, or series of other lengths).
pub fn probe_error(probe: &ProbeReport, reference: &ProbeReport) -> f64 {
    if probe.values.len() != reference.values.len() {
        return f64::INFINITY;
    }
    let (mut distance, mut scale) = (0.0, 0.0);
    for (q, r) in probe.values.iter().zip(&reference.values) {
        distance += (q - r) * (q - r);
        scale += r * r;
    }
    if distance == 0.0 {
        0.0
    } else if scale == 0.0 {
        f64::INFINITY
    } else {
        (distance / scale).sqrt()
    }
}

/// The largest probe error of `report` against `reference`, and the probe's name (matched by
/// name; a probe missing from `report` is an infinite error). Non-finite values are infinite.
pub fn trial_error(report: &Report, reference: &Report) -> (f64, String) {
    let mut worst = (0.0, String::new());
    for r in &reference.probes {
        let error = (report.probes.iter().find(|p| p.name == r.name))
            .map_or(f64::INFINITY, |p| probe_error(p, r));
        let error = if error.is_nan() { f64::INFINITY } else { error };
        if error > worst.0 || worst.1.is_empty() {
            worst = (error, r.name.clone());
        }
    }
    worst
}
