//! A trial: the scene with some edits, run over the advisor's window into its own folder (the
//! runner's full report; one ParaView frame at each end, no pictures), and how far its probes
//! came from the reference's.
//!
//! A probe's error is the L2 distance of its samples from the reference's over the window,
//! relative to how far the reference's samples move from their first value,
//! `‖q − q_ref‖₂ / ‖q_ref − q_ref(0)‖₂` (every frame's sample: a shift of an impact by a frame
//! costs what the samples it moves differ by, not the peak; the scale is the motion the probe
//! measures, so a scene moved 10 m up measures the same errors). A probe that the reference
//! never moves is scaled by its value, `‖q_ref‖₂`. Neither scale is taken below the probe
//! unit's round-off, `√n` times [`resolution`] over `n` samples (a symmetric cube's sideways
//! displacement of 1e-17 m is no motion to measure errors against); a probe of no unit known
//! that is zero throughout gives an infinite error to any run that moves it. A trial's error is
//! its largest probe error.

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

/// The distance of `probe`'s samples from `reference`'s relative to the reference's motion
/// (see the module): zero for equal series, infinite against a zero scale or for series of
/// other lengths.
pub fn probe_error(probe: &ProbeReport, reference: &ProbeReport) -> f64 {
    if probe.values.len() != reference.values.len() {
        return f64::INFINITY;
    }
    let start = reference.values.first().copied().unwrap_or(0.0);
    let (mut distance, mut motion, mut value) = (0.0, 0.0, 0.0);
    for (q, r) in probe.values.iter().zip(&reference.values) {
        distance += (q - r) * (q - r);
        motion += (r - start) * (r - start);
        value += r * r;
    }
    let floor = reference.values.len() as f64 * resolution(&reference.unit).powi(2);
    let scale = (if motion > 0.0 { motion } else { value }).max(floor);
    if distance == 0.0 {
        0.0
    } else if scale == 0.0 {
        f64::INFINITY
    } else {
        (distance / scale).sqrt()
    }
}

/// The smallest value of a probe in `unit` that is not round-off: 1 nm, 1 nm/s, 1 nN,
/// 1 pJ, 1e-12 kg m/s and N m s, 1 µPa, 1e-18 m³ (a cubic micrometre's billionth); 0 for
/// another unit.
pub fn resolution(unit: &str) -> f64 {
    match unit {
        "m" | "m/s" | "N" => 1e-9,
        "J" | "kg m/s" | "N m s" => 1e-12,
        "Pa" => 1e-6,
        "m³" => 1e-18,
        _ => 0.0,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(values: &[f64]) -> ProbeReport {
        ProbeReport {
            name: "p".to_owned(),
            kind: "position".to_owned(),
            unit: "m".to_owned(),
            final_value: values.last().copied().unwrap_or(f64::NAN),
            times: (0..values.len()).map(|i| i as f64).collect(),
            values: values.to_vec(),
        }
    }

    #[test]
    fn the_error_is_relative_to_the_references_motion_wherever_it_sits() {
        // The reference moves by (0, 3, 4) from its start: ‖motion‖ = 5; the trial is off by
        // (0, 0, 1): 1/5, at 0 or 10 m alike.
        for offset in [0.0, 10.0] {
            let reference = probe(&[offset, offset + 3.0, offset + 4.0]);
            let trial = probe(&[offset, offset + 3.0, offset + 5.0]);
            assert!((probe_error(&trial, &reference) - 0.2).abs() < 1e-12);
        }
        // A reference that never moves is scaled by its value; one that moves by round-off
        // (in m: below 1 nm a sample) by the round-off; a zero one of no unit by nothing.
        let still = probe(&[2.0, 2.0]);
        assert!((probe_error(&probe(&[2.0, 3.0]), &still) - 1.0 / 8f64.sqrt()).abs() < 1e-12);
        let sideways = probe(&[0.0, 1.9e-17]);
        let error = probe_error(&probe(&[0.0, 2e-12]), &sideways);
        assert!(
            (error - (2e-12 - 1.9e-17) / (2f64.sqrt() * 1e-9)).abs() < 1e-15,
            "{error}"
        );
        let mut unitless = probe(&[0.0, 0.0]);
        unitless.unit = String::new();
        assert_eq!(probe_error(&probe(&[0.0, 1e-9]), &unitless), f64::INFINITY);
        assert_eq!(probe_error(&probe(&[0.0, 0.0]), &unitless), 0.0);
    }
}
