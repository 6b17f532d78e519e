//! [`advise`]: the reference, each alternative alone, the chosen set run and checked.

use super::candidates::{Candidate, candidates};
use super::checked::{check_set, recommendation};
use super::choose::{Limits, Measured, choose};
use super::entries::{alternatives, body_advice};
use super::files::{folder_name, prepare_folder, write_json, write_recommended};
use super::trial::{TrialRun, run_trial, trial_error};
use super::{Advice, AdviseError, AdviseOptions};
use crate::scene::{Scene, dimension_of};
use crate::sim::Report;
use std::path::Path;
use std::time::Duration;
use toml_edit::Value;

/// The smallest relative saving counted, whatever the reference's spread.
const SMALLEST_SAVING: f64 = 0.03;

/// The reference's relative spread above which its times are called noise.
const NOISY_SPREAD: f64 = 0.25;

/// The largest relative saving asked of a change, whatever the reference's spread (a spread of
/// 1.7 would otherwise ask more than the whole time).
const MOST_SAVING: f64 = 0.5;

/// Advises on the scene file `path` (see the module): runs it, its alternatives and the chosen
/// set over the window, writes the folder `options.out`, and returns the advice; `progress`
/// hears a line per run.
///
/// # Errors
/// An [`AdviseError`] if the target is not in (0, 1) or the duration not positive, the scene
/// is 2D, cannot be read, has no probe, cannot be run as written or runs unstable, if the
/// output folder would overwrite the scene or empty a folder `advise` did not write, or a file
/// cannot be written. An alternative that cannot be run is a verdict in the
/// advice, not an error.
pub fn advise(
    path: &Path,
    options: &AdviseOptions,
    progress: impl FnMut(&str),
) -> Result<Advice, AdviseError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        AdviseError::Reference(format!("{}: cannot read the scene: {e}", path.display()))
    })?;
    advise_text((path, text), options, progress)
}

/// [`advise`] on `text`, read as the scene file `path` (its mesh files are named relative to
/// `path`'s folder): a scene file's text edited before (the Python package's overrides).
///
/// # Errors
/// Those of [`advise`].
pub fn advise_text(
    (path, text): (&Path, String),
    options: &AdviseOptions,
    mut progress: impl FnMut(&str),
) -> Result<Advice, AdviseError> {
    let scene = read_scene((path, &text), options)?;
    let window = options.window.unwrap_or(scene.world.duration);
    let trials = prepare_folder(path, &options.out)?;
    let run = |edits: &[(String, Value)], folder: &str, limit: Option<Duration>| {
        run_trial((path, &text), edits, (window, limit), trials.join(folder))
    };
    // The first run in a process pays for its thread pool's start and its first allocations:
    // its probes are the reference (every run of a scene is the same to the bit), its time is not.
    let first = reference(run(&[], "reference", None))?;
    let second = reference(run(&[], "reference", None))?;
    progress(&format!(
        "reference: {:.3} ms per frame",
        second.ms_per_frame
    ));
    // An alternative is not waited for past twice the scene's own stepping time and a second
    // (it could not be chosen).
    let limit = Duration::from_secs_f64(2.0 * second.stepping_time_s + 1.0);
    let all = candidates(&scene, options.target);
    let runs: Vec<TrialRun> = (all.iter().enumerate())
        .map(|(k, candidate)| {
            let folder = folder_name(k, &candidate.label);
            let report = run(&candidate.edits, &folder, Some(limit));
            progress(&format!(
                "{}/{}: {}",
                k + 1,
                all.len(),
                summary(&report, &first)
            ));
            report
        })
        .collect();
    let again = reference(run(&[], "reference", None))?;
    let reference_ms = (second.ms_per_frame + again.ms_per_frame) / 2.0;
    let spread = (second.ms_per_frame - again.ms_per_frame).abs() / reference_ms;
    let measured: Vec<Option<Measured>> = (all.iter().zip(&runs))
        .map(|(c, r)| measure(c, r, &first))
        .collect();
    let warnings: Vec<String> = (spread > NOISY_SPREAD)
        .then(|| {
            format!(
                "the scene's two timed runs differ by {:.0} %: times this short are noise (no \
                 saving under {:.0} % is counted); a longer --duration times them better",
                spread * 100.0,
                spread.min(MOST_SAVING) * 100.0
            )
        })
        .into_iter()
        .collect();
    let saving = spread.clamp(SMALLEST_SAVING, MOST_SAVING);
    let limits = Limits {
        reference_ms,
        saving,
        target: options.target,
    };
    let chosen = choose(&measured, limits);
    let checked = check_set(chosen, (&all, &measured), (&first, limits), |edits| {
        let report = run(edits, "recommended", None);
        progress(&format!("recommended set: {}", summary(&report, &first)));
        report
    });
    let rejected = trials.join("recommended");
    if checked.run.is_none() && rejected.is_dir() {
        // The last set run and refused: not what is recommended.
        std::fs::remove_dir_all(&rejected).map_err(|e| AdviseError::Write(rejected, e))?;
    }
    let file = options.out.join("recommended.toml");
    write_recommended(&scene, (path, &text), &checked.edits, &file)?;
    let alternatives = alternatives((&all, &runs, &measured), &checked, &first, limits);
    let advice = Advice {
        scene_file: path.display().to_string(),
        target: options.target,
        window_s: first.simulated_time,
        reference_ms_per_frame: reference_ms,
        reference_spread: spread,
        warnings,
        soft_bodies: body_advice(&scene, &first, &all, &alternatives),
        scene_alternatives: (all.iter().zip(&alternatives))
            .filter(|(c, _)| c.group.is_scene_wide())
            .map(|(_, a)| a.clone())
            .collect(),
        recommendation: recommendation(&checked, (&all, &measured), limits, &file),
    };
    write_json(&advice, &options.out.join("advice.json"))?;
    Ok(advice)
}

/// The scene of `text`, read as the file `path`, for `options`' target: a 3D scene with a
/// probe.
fn read_scene((path, text): (&Path, &str), options: &AdviseOptions) -> Result<Scene, AdviseError> {
    if !(options.target > 0.0 && options.target < 1.0) {
        return Err(AdviseError::Target(options.target));
    }
    if let Some(window) = options.window.filter(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(AdviseError::Duration(window));
    }
    if dimension_of(text) == Some(2) {
        return Err(AdviseError::Planar(path.display().to_string()));
    }
    let scene = Scene::parse(path, text.to_owned())?;
    if scene.probe.is_empty() {
        return Err(AdviseError::NoProbes(path.display().to_string()));
    }
    Ok(scene)
}

/// The scene as written, `run`: it must have run, and stable (every alternative is measured
/// against it).
fn reference(run: TrialRun) -> Result<Report, AdviseError> {
    let report = run.map_err(AdviseError::Reference)?;
    if !report.stability.stable {
        return Err(AdviseError::Reference(format!(
            "{}: the scene as written is not stable over the window (unstable bodies: {}; see \
             its report in trials/reference): advise measures every alternative against it",
            report.scene_file,
            report.stability.unstable_bodies.join(", ")
        )));
    }
    Ok(report)
}

/// A line on a run against the reference `first`.
fn summary(run: &TrialRun, first: &Report) -> String {
    match run {
        Ok(report) => {
            let (error, probe) = trial_error(report, first);
            let stable = if report.stability.stable {
                ""
            } else {
                ", NOT STABLE"
            };
            format!(
                "{:.3} ms per frame, error {:.3} % ({probe}){stable}",
                report.ms_per_frame,
                error * 100.0,
            )
        }
        Err(message) => format!("not run: {message}"),
    }
}

/// The measurement of `candidate`'s run, if it ran stable.
fn measure(candidate: &Candidate, run: &TrialRun, first: &Report) -> Option<Measured> {
    let report = run.as_ref().ok().filter(|r| r.stability.stable)?;
    let error = trial_error(report, first).0;
    let same_bodies = (report.soft_bodies.iter().zip(&first.soft_bodies)).all(|(a, b)| {
        a.needs.peak_green_strain == b.needs.peak_green_strain
            && a.needs.peak_rotation_deg == b.needs.peak_rotation_deg
    });
    Some(Measured {
        group: candidate.group.clone(),
        error,
        ms_per_frame: report.ms_per_frame,
        identical: error == 0.0 && same_bodies,
    })
}
