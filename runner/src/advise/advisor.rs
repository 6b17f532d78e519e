//! [`advise`]: the reference, each alternative, the chosen set; the files written.

use super::candidates::{Candidate, Group, candidates};
use super::choose::{Measured, choose, predict, without_largest_error};
use super::trial::{TrialRun, run_trial, trial_error};
use super::{Advice, AdviseError, AdviseOptions, Alternative, BodyAdvice, Recommendation};
use crate::scene::Scene;
use crate::scene::edit::edited;
use crate::sim::Report;
use std::path::Path;
use std::time::Duration;
use toml_edit::Value;

/// The smallest relative saving counted, whatever the reference's spread.
const SMALLEST_SAVING: f64 = 0.03;

/// Advises on the scene file `path` (see the module): runs it, its alternatives and the chosen
/// set over the window, writes the folder `options.out`, and returns the advice; `progress`
/// hears a line per run.
///
/// # Errors
/// An [`AdviseError`] if the target is not in (0, 1), the scene cannot be read or run as
/// written, has no probe, or a file cannot be written. An alternative that cannot be run is a
/// verdict in the advice, not an error.
pub fn advise(
    path: &Path,
    options: &AdviseOptions,
    mut progress: impl FnMut(&str),
) -> Result<Advice, AdviseError> {
    if !(options.target > 0.0 && options.target < 1.0) {
        return Err(AdviseError::Target(options.target));
    }
    let (text, scene) = read_scene(path)?;
    let window = options.window.unwrap_or(scene.world.duration);
    let trials = options.out.join("trials");
    let run = |edits: &[(String, Value)], folder: &str, limit: Option<Duration>| {
        run_trial((path, &text), edits, (window, limit), trials.join(folder))
    };
    // The first run in a process pays for its thread pool's start and its first allocations:
    // its probes are the reference (every run of a scene is the same to the bit), its time is not.
    let first = run(&[], "reference", None).map_err(AdviseError::Scene)?;
    let second = run(&[], "reference", None).map_err(AdviseError::Scene)?;
    progress(&format!(
        "reference: {:.3} ms per frame",
        second.ms_per_frame
    ));
    // An alternative is not waited for past twice the scene's own stepping time (it could not
    // be chosen), and a second for noise.
    let limit = Duration::from_secs_f64(2.0 * second.stepping_time_s + 1.0);
    let all = candidates(&scene);
    let runs: Vec<TrialRun> = (all.iter().enumerate())
        .map(|(k, candidate)| {
            let report = run(
                &candidate.edits,
                &folder_name(k, &candidate.label),
                Some(limit),
            );
            progress(&format!(
                "{}/{}: {}",
                k + 1,
                all.len(),
                summary(&report, &first)
            ));
            report
        })
        .collect();
    let again = run(&[], "reference", None).map_err(AdviseError::Scene)?;
    let reference_ms = (second.ms_per_frame + again.ms_per_frame) / 2.0;
    let spread = (second.ms_per_frame - again.ms_per_frame).abs() / reference_ms;
    let measured: Vec<Option<Measured>> = (all.iter().zip(&runs))
        .map(|(c, r)| measure(c, r, &first))
        .collect();
    let threshold = spread.max(SMALLEST_SAVING);
    let chosen = choose(&measured, reference_ms, options.target, threshold);
    let checked = check_set(
        chosen,
        (&all, &measured),
        (&first, options.target),
        |edits| {
            let report = run(edits, "recommended", None).map_err(AdviseError::Scene)?;
            progress(&format!(
                "recommended set: {}",
                summary(&Ok(report.clone()), &first)
            ));
            Ok(report)
        },
    )?;
    let file = options.out.join("recommended.toml");
    write_recommended(&scene, (path, &text), &checked.edits, &file)?;
    let recommendation = recommendation(
        &checked,
        (&all, &measured),
        reference_ms,
        options.target,
        &file,
    );
    let alternatives = alternatives(
        (&all, &runs, &measured),
        &checked,
        &first,
        (reference_ms, threshold, options.target),
    );
    let advice = Advice {
        scene_file: path.display().to_string(),
        target: options.target,
        window_s: window,
        reference_ms_per_frame: reference_ms,
        reference_spread: spread,
        soft_bodies: body_advice(&scene, &first, &all, &alternatives),
        integrators: (all.iter().zip(&alternatives))
            .filter(|(c, _)| c.group == Group::Integrator)
            .map(|(_, a)| a.clone())
            .collect(),
        recommendation,
    };
    write_json(&advice, &options.out.join("advice.json"))?;
    Ok(advice)
}

/// The recommendation of the set `checked` of the changes `all` (`measured` alone), the scene
/// as written taking `reference_ms` per frame, written into `file`.
fn recommendation(
    checked: &CheckedSet,
    (all, measured): (&[Candidate], &[Option<Measured>]),
    reference_ms: f64,
    target: f64,
    file: &Path,
) -> Recommendation {
    let (predicted_error, predicted_ms) = predict(measured, &checked.chosen, reference_ms);
    let (measured_ms, measured_error, worst_probe) = match &checked.run {
        Some((report, error, worst)) => (report.ms_per_frame, *error, worst.clone()),
        None => (reference_ms, 0.0, String::new()),
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
        speed_up: reference_ms / measured_ms,
        within_target: measured_error <= target,
    }
}

/// The scene file `path`'s text and scene, which must have a probe.
fn read_scene(path: &Path) -> Result<(String, Scene), AdviseError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        AdviseError::Scene(format!("{}: cannot read the scene: {e}", path.display()))
    })?;
    let scene = Scene::parse(path, text.clone()).map_err(|e| AdviseError::Scene(e.to_string()))?;
    if scene.probe.is_empty() {
        return Err(AdviseError::NoProbes(path.display().to_string()));
    }
    Ok((text, scene))
}

/// The advice's entries of the alternatives `all`, their `runs` and measurements, with their
/// verdicts given the set `checked`, the reference `first`, its time per frame, the smallest
/// saving counted and the target.
fn alternatives(
    (all, runs, measured): (&[Candidate], &[TrialRun], &[Option<Measured>]),
    checked: &CheckedSet,
    first: &Report,
    limits: (f64, f64, f64),
) -> Vec<Alternative> {
    let sets = (checked.chosen.as_slice(), checked.left_out.as_slice());
    (all.iter().enumerate())
        .map(|(k, c)| {
            let verdict = verdict(k, &runs[k], measured[k].as_ref(), sets, limits);
            alternative(c, &runs[k], first, verdict, folder_name(k, &c.label))
        })
        .collect()
}

/// A set of changes, run until within the target.
struct CheckedSet {
    /// The changes kept (indices into the alternatives).
    chosen: Vec<usize>,
    /// The changes left out because the set run with them exceeded the target.
    left_out: Vec<usize>,
    /// The edits of the changes kept.
    edits: Vec<(String, Value)>,
    /// The set's run, its error and worst probe against the reference (none for no change).
    run: Option<(Report, f64, String)>,
}

/// Runs the changes `chosen` of `all` together with `run_set` and, while their error against
/// `first` exceeds `target` or the run is not stable, leaves out the change of largest error
/// `measured` alone.
fn check_set(
    mut chosen: Vec<usize>,
    (all, measured): (&[Candidate], &[Option<Measured>]),
    (first, target): (&Report, f64),
    mut run_set: impl FnMut(&[(String, Value)]) -> Result<Report, AdviseError>,
) -> Result<CheckedSet, AdviseError> {
    let mut left_out = Vec::new();
    loop {
        let edits: Vec<(String, Value)> = (chosen.iter())
            .flat_map(|i| all[*i].edits.clone())
            .collect();
        if edits.is_empty() {
            return Ok(CheckedSet {
                chosen,
                left_out,
                edits,
                run: None,
            });
        }
        let report = run_set(&edits)?;
        let (error, worst) = trial_error(&report, first);
        if error <= target && report.stability.stable {
            let run = Some((report, error, worst));
            return Ok(CheckedSet {
                chosen,
                left_out,
                edits,
                run,
            });
        }
        let fewer = without_largest_error(measured, &chosen);
        left_out.extend(chosen.iter().filter(|i| !fewer.contains(i)));
        chosen = fewer;
    }
}

/// The folder of the `k`-th alternative, labelled `label`.
fn folder_name(k: usize, label: &str) -> String {
    let slug: String = (label.chars())
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("{:02}_{slug}", k + 1)
}

/// A line on a run against the reference `first`.
fn summary(run: &TrialRun, first: &Report) -> String {
    match run {
        Ok(report) => {
            let (error, probe) = trial_error(report, first);
            format!(
                "{:.3} ms per frame, error {:.3} % ({probe}){}",
                report.ms_per_frame,
                error * 100.0,
                if report.stability.stable {
                    ""
                } else {
                    ", NOT STABLE"
                }
            )
        }
        Err(message) => format!("not run: {message}"),
    }
}

/// The measurement of `candidate`'s run, if it ran stable.
fn measure(candidate: &Candidate, run: &TrialRun, first: &Report) -> Option<Measured> {
    let report = run.as_ref().ok().filter(|r| r.stability.stable)?;
    Some(Measured {
        group: candidate.group.clone(),
        error: trial_error(report, first).0,
        ms_per_frame: report.ms_per_frame,
    })
}

/// Why the `k`-th alternative was chosen or not.
fn verdict(
    k: usize,
    run: &TrialRun,
    measured: Option<&Measured>,
    (chosen, left_out): (&[usize], &[usize]),
    (reference_ms, threshold, target): (f64, f64, f64),
) -> String {
    let Some(m) = measured else {
        return match run {
            Err(message) => format!("not run: {message}"),
            Ok(_) => "not stable".to_owned(),
        };
    };
    if chosen.contains(&k) {
        "chosen".to_owned()
    } else if left_out.contains(&k) {
        "left out: the set run with it exceeded the target".to_owned()
    } else if m.error > target {
        "error above the target".to_owned()
    } else if m.ms_per_frame >= reference_ms * (1.0 - threshold) {
        format!("not cheaper by {:.0} % or more", threshold * 100.0)
    } else {
        "not chosen: a cheaper change of its kind, or the target's budget spent".to_owned()
    }
}

/// The `candidate`'s entry in the advice.
fn alternative(
    candidate: &Candidate,
    run: &TrialRun,
    first: &Report,
    verdict: String,
    folder: String,
) -> Alternative {
    let report = run.as_ref().ok();
    let error = report.map(|r| trial_error(r, first));
    Alternative {
        label: candidate.label.clone(),
        edits: (candidate.edits.iter())
            .map(|(key, value)| format!("{key} = {}", value.to_string().trim()))
            .collect(),
        error: error.as_ref().map(|e| e.0),
        worst_probe: error.map(|e| e.1),
        ms_per_frame: report.map(|r| r.ms_per_frame),
        stable: report.map(|r| r.stability.stable),
        verdict,
        folder: format!("trials/{folder}"),
    }
}

/// Each soft body's needs in the reference `first`, what it was given, and its alternatives.
fn body_advice(
    scene: &Scene,
    first: &Report,
    all: &[Candidate],
    alternatives: &[Alternative],
) -> Vec<BodyAdvice> {
    (scene.soft_body.iter().enumerate())
        .zip(&first.soft_bodies)
        .map(|((i, _), report)| {
            let of_body = |c: &Candidate| {
                matches!(c.group, Group::Model(b) | Group::Elements(b) | Group::Resolution(b) if b == i)
            };
            let mine: Vec<(&Candidate, &Alternative)> = (all.iter().zip(alternatives))
                .filter(|(c, _)| of_body(c))
                .collect();
            BodyAdvice {
                name: report.name.clone(),
                needs: report.needs.clone(),
                model: report.material.clone(),
                elements: format!("{} {}", report.elements, report.element_kind),
                discretization_error: (mine.iter())
                    .find(|(c, _)| c.group == Group::Resolution(i))
                    .and_then(|(_, a)| a.error),
                alternatives: mine.into_iter().map(|(_, a)| a.clone()).collect(),
            }
        })
        .collect()
}

/// Writes the scene's text with `edits` into `file`, its mesh files named by absolute paths
/// (they were relative to the scene's folder).
fn write_recommended(
    scene: &Scene,
    (path, text): (&Path, &str),
    edits: &[(String, Value)],
    file: &Path,
) -> Result<(), AdviseError> {
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut all = edits.to_vec();
    for (i, body) in scene.soft_body.iter().enumerate() {
        for (key, mesh) in [
            ("mesh", Some(&body.mesh)),
            ("embedded", body.embedded.as_ref()),
        ] {
            if let Some(name) = mesh.and_then(|m| m.file.as_deref()) {
                let absolute = std::path::absolute(folder.join(name))
                    .map_err(|e| AdviseError::Write(folder.join(name), e))?;
                let value = Value::from(absolute.display().to_string());
                all.push((format!("soft_body[{i}].{key}.file"), value));
            }
        }
    }
    let body = edited(text, &all).map_err(|e| AdviseError::Scene(e.to_string()))?;
    let header = format!(
        "# Written by `rapier-fvm advise` from {}: {}\n",
        path.display(),
        if edits.is_empty() {
            "no change was cheaper within the target".to_owned()
        } else {
            edits
                .iter()
                .map(|(k, v)| format!("{k} = {}", v.to_string().trim()))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    std::fs::write(file, header + &body).map_err(|e| AdviseError::Write(file.to_path_buf(), e))
}

/// Writes `advice` as JSON into `file`.
fn write_json(advice: &Advice, file: &Path) -> Result<(), AdviseError> {
    let json =
        serde_json::to_string_pretty(advice).map_err(|e| AdviseError::Scene(e.to_string()))?;
    std::fs::write(file, json).map_err(|e| AdviseError::Write(file.to_path_buf(), e))
}
