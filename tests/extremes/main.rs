//! The extremes sweep: every case ends stable, refused with a typed error, or unstable, and the
//! verdict is the per-frame audit's (`coupling::Audit`, default tolerances: see its module):
//!
//! - **stable**: every frame's state is finite and the audit is clean: no energy gained in the
//!   coupled system (soft and dynamic rigid bodies, against the previous frame plus kinematic
//!   work, tolerance 0.1 % of the kinetic and elastic energy plus the allowances for f32
//!   rounding and explicit oscillation), no contact point past a collider
//!   deeper than max(1 mm, a quarter of the smallest element altitude) and none through one, no
//!   inverted element and none below 1 % of its rest volume, no failed Newton solve;
//! - **refused**: a step returned a typed error (too many explicit substeps, ...) other than a
//!   non-finite state or an implicit matrix that cannot be factored (those mean a blow-up);
//! - **unstable**: anything else.
//!
//! Two parts, 20 frames per case, at frame steps 1e-4, 1/240, 1/60 and 1/30 s:
//!
//! 1. The material grid (stable Neo-Hookean, ρ = 1000 kg/m³, automatic integrator, one
//!    coupling substep per frame): E in {1e3, 1e5, 1e7, 1e9, 1e11} Pa x ν in {-0.9, -0.5, 0,
//!    0.3, 0.45, 0.49, 0.499, 0.4999} on the reference cantilever released from rest and on a
//!    10 cm cube striking the ground at 3.13 m/s (320 cases).
//! 2. Partners, impacts, walls and ν < 0 (the scenes of `scenes::Scene`), each under the
//!    automatic, forced explicit and forced implicit integrators with rapier's four coupling
//!    substeps per frame: rigid boxes of 1 g (on E = 1e9 Pa) and 100 kg (on E = 1e6 Pa) resting
//!    on a soft block; balls of 1e-3 and 1e3 times a soft rope's mass glued under it; a 100 g
//!    ball at 30 m/s into a soft block; soft cubes at 30 and 100 m/s into the ground; soft cubes
//!    at 30 m/s (E = 1e6 Pa) and 100 m/s (E = 1e9 Pa) at a 2 mm wall; cubes of ν = -0.9 and
//!    -0.99 dropped on the ground (132 cases). The grid keeps the automatic integrator alone to
//!    keep the run to about two minutes on two cores.
//!
//! Cases unstable because of bugs not fixed yet are listed in `known::KNOWN` with what goes
//! wrong and the value measured; the test fails when a case outside the list is unstable and
//! when a listed case is no longer unstable, so the list can only shrink. It prints the table and
//! a JSON summary: `cargo test --release --test extremes -- --nocapture`.

#[path = "../common/mod.rs"]
mod common;
mod known;
mod scenes;

use common::timoshenko_tip_deflection;
use rapier_fvm::coupling::{Audit, FrameAudit};
use rapier_fvm::integrate::AutomaticReport;
use rapier_fvm::prelude::*;
use scenes::Scene;
use std::time::Instant;

/// Young's moduli (Pa) of the grid.
const YOUNG: [f64; 5] = [1e3, 1e5, 1e7, 1e9, 1e11];
/// Poisson's ratios of the grid.
const POISSON: [f64; 8] = [-0.9, -0.5, 0.0, 0.3, 0.45, 0.49, 0.499, 0.4999];
/// Frame steps (s) of the sweep.
const FRAME_DT: [f64; 4] = [1e-4, 1.0 / 240.0, 1.0 / 60.0, 1.0 / 30.0];
/// Frames simulated per case.
const FRAMES: usize = 20;
/// The partner, impact, wall and ν < 0 scenes.
const PARTNER_SCENES: [Scene; 11] = [
    Scene::BoxOnBlock(1e-3),
    Scene::BoxOnBlock(100.0),
    Scene::BallOnRope(1e-3),
    Scene::BallOnRope(1e3),
    Scene::FastBall,
    Scene::FastCube(30.0),
    Scene::FastCube(100.0),
    Scene::ThinWall(30.0),
    Scene::ThinWall(100.0),
    Scene::NegativePoisson(-0.9),
    Scene::NegativePoisson(-0.99),
];
/// The integrators the partner scenes run under.
const INTEGRATORS: [Option<IntegratorKind>; 3] = [
    None,
    Some(IntegratorKind::Explicit),
    Some(IntegratorKind::Implicit),
];

/// How one case ended.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    /// Finite, and the audit clean every frame.
    Stable,
    /// A typed error before or while stepping.
    Refused(Error),
    /// What the audit or the finiteness check found, at which frame.
    Unstable(String),
}

/// One row of the table.
#[derive(Debug, Clone)]
struct Case {
    /// The scene, material, step and integrator.
    label: String,
    /// The outcome.
    outcome: Outcome,
    /// Integrator of the last frame: explicit substeps, or Newton and CG iterations.
    integrator: String,
    /// Wall time per frame (ms).
    ms_per_frame: f64,
    /// Tip deflection over the Timoshenko value, minus one, once the beam has come to rest.
    tip_error: Option<f64>,
}

/// The integrator of a frame, as the table names it.
fn integrator_label(report: &AutomaticReport) -> String {
    match (report.explicit, report.implicit) {
        (Some(explicit), _) => format!("explicit x{}", explicit.substeps),
        (_, Some(implicit)) => format!(
            "implicit, {} Newton, {} CG",
            implicit.newton_iterations, implicit.linear_iterations
        ),
        _ => String::from("-"),
    }
}

/// What makes `found` (frame `frame`) unclean, if anything: the first failed check.
fn finding(found: &FrameAudit, frame: usize) -> Option<String> {
    let at = format!("frame {frame}");
    if let Some(system) = found.system.filter(|e| e.gained()) {
        return Some(format!(
            "{at}: coupled energy gained {:.3e} J (tolerance {:.1e} J)",
            system.gain, system.tolerance
        ));
    }
    let (_, body) = found.bodies.iter().find(|(_, b)| !b.is_clean())?;
    let p = &body.penetrations;
    Some(if let Some(energy) = body.energy.filter(|e| e.gained()) {
        format!(
            "{at}: energy gained {:.3e} J (tolerance {:.1e} J)",
            energy.gain, energy.tolerance
        )
    } else if body.crossed() {
        format!("{at}: {} nodes through a collider", p.crossed)
    } else if body.penetrates() {
        format!(
            "{at}: {} nodes past a surface, deepest {:.1} mm (tolerance {:.1} mm)",
            p.points,
            p.deepest * 1e3,
            body.penetration_tolerance * 1e3
        )
    } else if body.has_bad_elements() {
        format!(
            "{at}: {} inverted, {} collapsed elements (smallest V/V0 {:.2e})",
            body.inverted_elements, body.collapsed_elements, body.smallest_volume_ratio
        )
    } else {
        format!("{at}: {:?}", body.step_error)
    })
}

/// Runs one case: `frames` frames of `scene` built with `young`, `poisson`, `dt`, `integrator`.
fn run_case(
    label: String,
    build: Result<scenes::Built, Error>,
    young: f64,
    poisson: f64,
    frames: usize,
) -> Case {
    let mut case = Case {
        label,
        outcome: Outcome::Stable,
        integrator: String::from("-"),
        ms_per_frame: 0.0,
        tip_error: None,
    };
    let scenes::Built {
        mut world,
        soft,
        tip,
    } = match build {
        Ok(built) => built,
        Err(error) => {
            case.outcome = Outcome::Refused(error);
            return case;
        }
    };
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let start = Instant::now();
    for frame in 1..=frames {
        let results = world.step();
        for (_, result) in &results {
            match result {
                Ok(report) => case.integrator = integrator_label(report),
                Err(error @ (Error::NonFiniteState { .. } | Error::IndefiniteStiffness { .. })) => {
                    case.outcome = Outcome::Unstable(format!("frame {frame}: {error}"));
                    return case;
                }
                Err(error) => {
                    case.outcome = Outcome::Refused(error.clone());
                    return case;
                }
            }
        }
        if let Some(why) = finding(&audit.check_world(&world, &results), frame) {
            case.outcome = Outcome::Unstable(why);
            return case;
        }
    }
    case.ms_per_frame = start.elapsed().as_secs_f64() * 1e3 / frames as f64;
    let body = &world.soft_bodies[soft];
    if let Some(tip) = tip {
        let at_rest = body.velocities().iter().all(|v| v.length() < 1e-3);
        let deflection = body.mesh().positions()[tip].y - body.positions()[tip].y;
        let reference = timoshenko_tip_deflection(young, poisson);
        // Beam theory applies to small deflections (under 5 % of the length).
        if at_rest && reference < 0.05 {
            case.tip_error = Some(deflection / reference - 1.0);
        }
    }
    case
}

/// The integrator's name in the labels.
fn integrator_name(integrator: Option<IntegratorKind>) -> &'static str {
    match integrator {
        None => "automatic",
        Some(IntegratorKind::Explicit) => "explicit",
        Some(IntegratorKind::Implicit) => "implicit",
    }
}

/// Every case of the sweep, run.
fn sweep() -> Vec<Case> {
    let mut cases = Vec::new();
    for scene in [Scene::Cantilever, Scene::DroppedCube] {
        for young in YOUNG {
            for poisson in POISSON {
                for dt in FRAME_DT {
                    let label = format!("{scene:?} E {young:e} nu {poisson} dt {dt:.2e} automatic");
                    let built = scenes::build(scene, young, poisson, dt, None);
                    cases.push(run_case(label, built, young, poisson, FRAMES));
                }
            }
        }
    }
    for scene in PARTNER_SCENES {
        for integrator in INTEGRATORS {
            for dt in FRAME_DT {
                let name = integrator_name(integrator);
                let label = format!("{scene:?} dt {dt:.2e} {name}");
                let built = scenes::build(scene, 0.0, 0.0, dt, integrator);
                cases.push(run_case(label, built, 0.0, 0.0, FRAMES));
            }
        }
    }
    cases
}

/// The outcome's name in the table.
fn outcome_name(outcome: &Outcome) -> &'static str {
    match outcome {
        Outcome::Stable => "stable",
        Outcome::Refused(_) => "refused",
        Outcome::Unstable(_) => "UNSTABLE",
    }
}

/// Prints the table, one row per case and its outcome's reason.
fn print_table(cases: &[Case]) {
    println!(
        "{:<58} {:>9} {:>32} {:>9} {:>9}",
        "case", "outcome", "integrator per frame", "ms/frame", "tip err"
    );
    for case in cases {
        let error = case
            .tip_error
            .map_or(String::from("-"), |e| format!("{:+.1} %", 100.0 * e));
        println!(
            "{:<58} {:>9} {:>32} {:>9.2} {error:>9}",
            case.label,
            outcome_name(&case.outcome),
            case.integrator,
            case.ms_per_frame
        );
        match &case.outcome {
            Outcome::Refused(error) => println!("    reason: {error}"),
            Outcome::Unstable(why) => {
                println!("    reason: {why}");
                if let Some(known) = known::KNOWN.iter().find(|k| k.case == case.label) {
                    println!(
                        "    known failure: {}; listed as {}",
                        known.what, known.measured
                    );
                }
            }
            Outcome::Stable => {}
        }
    }
}

#[test]
fn every_extreme_case_is_stable_or_refused_or_a_known_failure() {
    let started = Instant::now();
    let cases = sweep();
    print_table(&cases);
    let count = |name: &str| {
        cases
            .iter()
            .filter(|c| outcome_name(&c.outcome) == name)
            .count()
    };
    let grid = 2 * YOUNG.len() * POISSON.len() * FRAME_DT.len();
    println!(
        "{{\"cases\": {}, \"grid_cases\": {grid}, \"partner_cases\": {}, \"stable\": {}, \"refused\": {}, \"unstable\": {}, \"known_failures\": {}, \"frames_per_case\": {FRAMES}, \"seconds\": {:.1}}}",
        cases.len(),
        cases.len() - grid,
        count("stable"),
        count("refused"),
        count("UNSTABLE"),
        known::KNOWN.len(),
        started.elapsed().as_secs_f64()
    );
    let unstable = |label: &str| {
        cases
            .iter()
            .any(|c| c.label == label && matches!(c.outcome, Outcome::Unstable(_)))
    };
    let new_failures: Vec<String> = cases
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Unstable(_)))
        .filter(|c| !known::KNOWN.iter().any(|k| k.case == c.label))
        .map(|c| format!("{}: {:?}", c.label, c.outcome))
        .collect();
    let fixed: Vec<&str> = known::KNOWN
        .iter()
        .filter(|k| !unstable(k.case))
        .map(|k| k.case)
        .collect();
    assert!(
        new_failures.is_empty(),
        "unstable cases not in known::KNOWN: {new_failures:#?}"
    );
    assert!(
        fixed.is_empty(),
        "known failures no longer unstable (remove them from known::KNOWN): {fixed:#?}"
    );
}
