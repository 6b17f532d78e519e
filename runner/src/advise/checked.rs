//! The chosen set of changes, run together and kept only once it is within the target and
//! faster than the scene as written.

use super::Recommendation;
use super::candidates::Candidate;
use super::choose::{Limits, Measured, predict, without_largest};
use super::trial::trial_error;
use crate::sim::Report;
use std::path::Path;
use toml_edit::Value;

/// Why a chosen change left the set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeftOut {
    /// The set run with it could not be run, exceeded the target or was not stable.
    Error,
    /// The set run with it was not faster than the scene as written.
    Time,
}

/// A set of changes, run until within the target and faster.
#[derive(Debug)]
pub struct CheckedSet {
    /// The changes kept (indices into the alternatives).
    pub chosen: Vec<usize>,
    /// The changes that left the set, and why.
    pub left_out: Vec<(usize, LeftOut)>,
    /// The edits of the changes kept.
    pub edits: Vec<(String, Value)>,
    /// The set's run, its error and worst probe against the reference (none for no change).
    pub run: Option<(Report, f64, String)>,
}

/// Runs the changes `chosen` of `all` together with `run_set`; while the set cannot be run,
/// its error against `first` exceeds the target or the run is not stable, leaves out the change
/// of largest error `measured` alone, and while it is not faster than the reference by the
/// smallest saving counted (`limits`), the change of smallest saving.
pub fn check_set(
    mut chosen: Vec<usize>,
    (all, measured): (&[Candidate], &[Option<Measured>]),
    (first, limits): (&Report, Limits),
    mut run_set: impl FnMut(&[(String, Value)]) -> Result<Report, String>,
) -> CheckedSet {
    let mut left_out = Vec::new();
    loop {
        let edits: Vec<(String, Value)> = (chosen.iter())
            .flat_map(|i| all[*i].edits.clone())
            .collect();
        if edits.is_empty() {
            return CheckedSet {
                chosen,
                left_out,
                edits,
                run: None,
            };
        }
        let report = run_set(&edits).ok().filter(|r| r.stability.stable);
        let error = report.as_ref().map(|r| trial_error(r, first));
        let (fewer, why) = match (report, error) {
            (Some(report), Some((error, worst))) if error <= limits.target => {
                if limits.cheaper(report.ms_per_frame) {
                    let run = Some((report, error, worst));
                    return CheckedSet {
                        chosen,
                        left_out,
                        edits,
                        run,
                    };
                }
                (
                    without_largest(measured, &chosen, |m| m.ms_per_frame),
                    LeftOut::Time,
                )
            }
            _ => (
                without_largest(measured, &chosen, |m| m.error),
                LeftOut::Error,
            ),
        };
        left_out.extend(
            chosen
                .iter()
                .filter(|i| !fewer.contains(i))
                .map(|i| (*i, why)),
        );
        chosen = fewer;
    }
}

/// The recommendation of the set `checked` of the changes `all` (`measured` alone), the scene
/// as written held to `limits`, written into `file`.
pub fn recommendation(
    checked: &CheckedSet,
    (all, measured): (&[Candidate], &[Option<Measured>]),
    limits: Limits,
    file: &Path,
) -> Recommendation {
    let (predicted_error, predicted_ms) = predict(measured, &checked.chosen, limits.reference_ms);
    let (measured_ms, measured_error, worst_probe) = match &checked.run {
        Some((report, error, worst)) => (report.ms_per_frame, *error, worst.clone()),
        None => (limits.reference_ms, 0.0, String::new()),
    };
    Recommendation {
        changes: (checked.chosen.iter())
            .map(|i| all[*i].label.clone())
            .collect(),
        file: file.display().to_string(),
        predicted_error,
        measured_error,
        worst_probe,
        predicted_ms_per_frame: predicted_ms,
        measured_ms_per_frame: measured_ms,
        speed_up: limits.reference_ms / measured_ms,
        within_target: measured_error <= limits.target,
    }
}
