//! The advice's entries: each alternative with its error, time and verdict, and each soft
//! body's needs, model, elements, alternatives and estimated discretization error.

use super::candidates::{Candidate, Group, edit_text, model_name};
use super::checked::{CheckedSet, LeftOut};
use super::choose::{Limits, Measured};
use super::trial::{TrialRun, trial_error};
use super::{Alternative, BodyAdvice};
use crate::scene::Scene;
use crate::sim::Report;

/// The entries of the alternatives `all`, their `runs` and measurements, with their verdicts
/// given the set `checked`, the reference `first`, and the `limits` changes are held to.
pub fn alternatives(
    (all, runs, measured): (&[Candidate], &[TrialRun], &[Option<Measured>]),
    checked: &CheckedSet,
    first: &Report,
    limits: Limits,
) -> Vec<Alternative> {
    (all.iter().enumerate())
        .map(|(k, c)| {
            let verdict = verdict(k, (&runs[k], measured[k].as_ref()), checked, first, limits);
            entry(
                c,
                &runs[k],
                first,
                verdict,
                super::files::folder_name(k, &c.label),
            )
        })
        .collect()
}

/// Why the `k`-th alternative, run as `run` and measured as `measured`, was chosen or not.
fn verdict(
    k: usize,
    (run, measured): (&TrialRun, Option<&Measured>),
    checked: &CheckedSet,
    first: &Report,
    limits: Limits,
) -> String {
    let Some(m) = measured else {
        return match run {
            Err(message) => format!("not run: {message}"),
            Ok(_) => "not stable".to_owned(),
        };
    };
    let left_out = checked.left_out.iter().find(|(i, _)| *i == k);
    if checked.chosen.contains(&k) {
        "chosen".to_owned()
    } else if let Some((_, why)) = left_out {
        match why {
            LeftOut::Error => {
                "left out: the set with it failed, exceeded the target or was not stable"
            }
            LeftOut::Time => "left out: the set run with it was not faster than the scene",
        }
        .to_owned()
    } else if m.error.is_infinite() {
        let probe = run
            .as_ref()
            .map(|r| trial_error(r, first).1)
            .unwrap_or_default();
        format!("error unbounded: {probe} is zero throughout the scene as written or not finite")
    } else if m.identical {
        "no effect here: the same run to the bit (probes, strains, rotations)".to_owned()
    } else if m.error > limits.target {
        "error above the target".to_owned()
    } else if !limits.cheaper(m.ms_per_frame) {
        format!(
            "not cheaper by {:.0} % or more (timing noise)",
            limits.saving * 100.0
        )
    } else {
        "not chosen: a cheaper change of its kind was, or the target was spent on others".to_owned()
    }
}

/// The `candidate`'s entry in the advice (an infinite error is none: its verdict says why).
fn entry(
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
        edits: candidate.edits.iter().map(edit_text).collect(),
        error: error.as_ref().map(|e| e.0).filter(|e| e.is_finite()),
        worst_probe: error.map(|e| e.1),
        ms_per_frame: report.map(|r| r.ms_per_frame),
        stable: report.map(|r| r.stability.stable),
        verdict,
        folder: format!("trials/{folder}"),
    }
}

/// Each soft body's needs in the reference `first`, what it was given, its alternatives, and
/// its discretization error estimated from its coarser mesh's run if that ran stable:
/// `e_coarse / (r − 1)`, Richardson's estimate at order 1 for the refinement ratio `r` from the
/// coarser mesh to the given one.
pub fn body_advice(
    scene: &Scene,
    first: &Report,
    all: &[Candidate],
    alternatives: &[Alternative],
) -> Vec<BodyAdvice> {
    (scene.soft_body.iter().enumerate())
        .zip(&first.soft_bodies)
        .map(|((i, body), report)| {
            let mine: Vec<(&Candidate, &Alternative)> = (all.iter().zip(alternatives))
                .filter(|(c, _)| c.group.body() == Some(i))
                .collect();
            let coarser = mine.iter().find(|(c, _)| c.group == Group::Resolution(i));
            BodyAdvice {
                name: report.name.clone(),
                needs: report.needs.clone(),
                model: model_name(body.material.model).to_owned(),
                material: report.material.clone(),
                elements: format!("{} {}", report.elements, report.element_kind),
                discretization_error: coarser.and_then(|(c, a)| {
                    let ratio = c.refinement?;
                    a.error
                        .filter(|_| a.stable == Some(true))
                        .map(|e| e / (ratio - 1.0))
                }),
                alternatives: mine.into_iter().map(|(_, a)| a.clone()).collect(),
            }
        })
        .collect()
}
