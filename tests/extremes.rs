//! The extremes table, over E in {1e3, 1e5, 1e7, 1e9, 1e11} Pa, ν in {-0.9, -0.5, 0, 0.3, 0.45,
//! 0.49, 0.499, 0.4999} and frame steps in {1e-4, 1/240, 1/60, 1/30} s, with the automatic choice
//! of integrator, 20 frames per case, on two scenes (stable Neo-Hookean, ρ = 1000 kg/m³):
//!
//! - the reference cantilever (L = 1 m, 0.1 x 0.1 m, 20 x 2 x 2 cells) released from rest under
//!   gravity;
//! - a 10 cm cube (4 x 4 x 4 cells) hitting a fixed ground half-space (friction 0.5) at the speed
//!   of a 0.5 m drop (3.13 m/s), released 1 mm above it so that every step length sees the impact.
//!
//! A case is stable when every position stays finite and the total energy (kinetic + elastic +
//! gravitational) never rises above its initial value by more than 1e-3 of m g (1 m): neither
//! integrator may create energy; symplectic Euler's measured energy fluctuates by O(hω) around a
//! conserved value, which stays far below that bound. (The implicit contact penalty's stored
//! energy is not counted: it is released within a few steps and is below a microjoule at rest.)
//! It is refused when the crate returns an error. No case may be unstable.
//!
//! The test runs the whole table (320 cases, about 20 s on two cores) and prints it with a JSON
//! summary (`unstable` must be 0): `cargo test --release --test extremes -- --nocapture`.

mod common;

use common::timoshenko_tip_deflection;
use rapier_fvm::integrate::AutomaticReport;
use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, ColliderSet, RigidBodySet, SharedShape};
use std::time::Instant;

/// Young's moduli (Pa) of the sweep.
const YOUNG: [f64; 5] = [1e3, 1e5, 1e7, 1e9, 1e11];
/// Poisson's ratios of the sweep.
const POISSON: [f64; 8] = [-0.9, -0.5, 0.0, 0.3, 0.45, 0.49, 0.499, 0.4999];
/// Frame steps (s) of the sweep.
const FRAME_DT: [f64; 4] = [1e-4, 1.0 / 240.0, 1.0 / 60.0, 1.0 / 30.0];
/// Frames simulated per case of the full sweep.
const FRAMES: usize = 20;

/// The scenes of the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scene {
    /// The clamped reference beam under its own weight.
    Cantilever,
    /// A cube landing on the ground.
    DroppedCube,
}

/// Both scenes.
const SCENES: [Scene; 2] = [Scene::Cantilever, Scene::DroppedCube];

/// How one case ended.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    /// Finite, energy bounded.
    Stable,
    /// A typed error before or while stepping.
    Refused(Error),
    /// Non-finite state or energy growth (must never happen).
    Unstable(String),
}

/// One row of the table.
#[derive(Debug, Clone)]
struct Case {
    /// The scene.
    scene: Scene,
    /// Young's modulus (Pa).
    young: f64,
    /// Poisson's ratio.
    poisson: f64,
    /// Frame step (s).
    frame_dt: f64,
    /// The outcome.
    outcome: Outcome,
    /// Integrator of the last frame: explicit substeps, or Newton and conjugate-gradient
    /// iterations.
    integrator: String,
    /// Wall time per frame (ms).
    ms_per_frame: f64,
    /// Tip deflection over the Timoshenko value, minus one, once the beam has come to rest.
    tip_error: Option<f64>,
}

/// The body of `scene`, and the node whose deflection beam theory predicts (cantilever only).
fn build(scene: Scene, young: f64, poisson: f64) -> Result<(DeformableBody, Option<usize>), Error> {
    let material = Material::new(MaterialModel::StableNeoHookean, young, poisson, 1000.0)?;
    match scene {
        Scene::Cantilever => {
            let half = DVec3::new(0.5, 0.05, 0.05);
            let mesh = mesh::cuboid(half, [20, 2, 2])?;
            let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
            let tip = mesh.nearest_node(DVec3::new(half.x, 0.0, 0.0)) as usize;
            let body = DeformableBodyBuilder::new(mesh, material)
                .translation(DVec3::new(half.x, 0.0, 0.0))
                .pinned_nodes(clamped)
                .build()?;
            Ok((body, Some(tip)))
        }
        Scene::DroppedCube => {
            let mesh = mesh::cuboid(DVec3::splat(0.05), [4, 4, 4])?;
            let body = DeformableBodyBuilder::new(mesh, material)
                .translation(DVec3::new(0.0, 0.051, 0.0))
                .linvel(DVec3::new(0.0, -(2.0 * 9.81 * 0.5f64).sqrt(), 0.0))
                .build()?;
            Ok((body, None))
        }
    }
}

/// The fixed ground: the half-space below y = 0, friction 0.5.
fn ground() -> ColliderSet {
    let mut colliders = ColliderSet::new();
    colliders.insert(
        ColliderBuilder::new(SharedShape::halfspace(rapier3d::glamx::Vec3::Y))
            .friction(0.5)
            .build(),
    );
    colliders
}

/// The integrator of a frame, as the table names it.
fn integrator_label(report: &AutomaticReport) -> String {
    match (report.explicit, report.implicit) {
        (Some(explicit), _) => format!("explicit x{}", explicit.substeps),
        (_, Some(implicit)) => {
            format!(
                "implicit, {} Newton, {} CG",
                implicit.newton_iterations, implicit.linear_iterations
            )
        }
        _ => String::from("-"),
    }
}

/// Steps `body` `frames` frames, noting them in `case`; false once a frame fails or gains energy.
fn step_frames(
    body: &mut DeformableBody,
    colliders: &ColliderSet,
    frames: usize,
    case: &mut Case,
) -> bool {
    let gravity = common::gravity();
    let energy = |b: &DeformableBody| {
        b.kinetic_energy() + b.elastic_energy() + b.gravity_potential_energy(gravity)
    };
    let initial = energy(body);
    let scale = body.total_mass() * 9.81 * 1.0;
    let integrator = AutomaticIntegrator::default();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..frames {
        let stepped = constraints
            .detect_contacts(
                body,
                colliders,
                &RigidBodySet::new(),
                case.frame_dt,
                gravity,
                &ContactSettings::default(),
            )
            .map(|_| ())
            .and_then(|()| {
                integrator.step(
                    body,
                    &mut constraints,
                    &mut workspace,
                    case.frame_dt,
                    gravity,
                )
            });
        match stepped {
            Ok(report) => case.integrator = integrator_label(&report),
            Err(error) => {
                case.outcome = match error {
                    Error::NonFiniteState { .. } => Outcome::Unstable(error.to_string()),
                    other => Outcome::Refused(other),
                };
                return false;
            }
        }
        let now = energy(body);
        if !now.is_finite() || now > initial + 1e-3 * scale {
            case.outcome = Outcome::Unstable(format!("energy rose by {:.3e} J", now - initial));
            return false;
        }
    }
    true
}

/// Runs one case of the sweep.
fn run_case(scene: Scene, young: f64, poisson: f64, frame_dt: f64, frames: usize) -> Case {
    let mut case = Case {
        scene,
        young,
        poisson,
        frame_dt,
        outcome: Outcome::Stable,
        integrator: String::from("-"),
        ms_per_frame: 0.0,
        tip_error: None,
    };
    let (mut body, tip) = match build(scene, young, poisson) {
        Ok(built) => built,
        Err(error) => {
            case.outcome = Outcome::Refused(error);
            return case;
        }
    };
    let colliders = match scene {
        Scene::Cantilever => ColliderSet::new(),
        Scene::DroppedCube => ground(),
    };
    let start = Instant::now();
    if !step_frames(&mut body, &colliders, frames, &mut case) {
        return case;
    }
    case.ms_per_frame = start.elapsed().as_secs_f64() * 1e3 / frames as f64;
    let at_rest = body.velocities().iter().all(|v| v.length() < 1e-3);
    if let Some(tip) = tip {
        let deflection = body.mesh().positions()[tip].y - body.positions()[tip].y;
        let reference = timoshenko_tip_deflection(young, poisson);
        // Beam theory applies to small deflections (under 5 % of the length).
        if at_rest && reference < 0.05 {
            case.tip_error = Some(deflection / reference - 1.0);
        }
    }
    case
}

/// Why `case` counts as unstable (an unstable outcome or an unfactorable matrix), if it does.
fn instability(case: &Case, label: &str) -> Option<String> {
    match &case.outcome {
        Outcome::Unstable(why) => Some(format!("{label}: {why}")),
        // The implicit matrix M/h² + K (projected) is positive definite for any finite state:
        // failing to factor it means a blow-up, not a refusal.
        Outcome::Refused(Error::IndefiniteStiffness { .. }) => {
            Some(format!("{label}: implicit matrix not positive definite"))
        }
        _ => None,
    }
}

/// The case's scene, material and step, for the failure messages.
fn label(case: &Case) -> String {
    format!(
        "{:?} E {:e} nu {} dt {:.2e}",
        case.scene, case.young, case.poisson, case.frame_dt
    )
}

/// Counts of the full sweep's outcomes.
#[derive(Debug, Default)]
struct Counts {
    cases: usize,
    stable: usize,
    refused: usize,
    unstable: usize,
}

/// Prints the header of the full sweep's table.
fn print_header() {
    println!(
        "{:>12} {:>8} {:>8} {:>9} {:>10} {:>34} {:>10} {:>11}",
        "scene",
        "E (Pa)",
        "nu",
        "dt (s)",
        "outcome",
        "integrator per frame",
        "ms/frame",
        "tip error"
    );
}

/// Prints the row of `case` (and its outcome's reason, if any), counting its outcome.
fn print_row(case: &Case, counts: &mut Counts) {
    let (scene, young, poisson, frame_dt) = (case.scene, case.young, case.poisson, case.frame_dt);
    counts.cases += 1;
    let outcome = match &case.outcome {
        Outcome::Stable => {
            counts.stable += 1;
            String::from("stable")
        }
        Outcome::Refused(_) => {
            counts.refused += 1;
            String::from("refused")
        }
        Outcome::Unstable(_) => {
            counts.unstable += 1;
            String::from("UNSTABLE")
        }
    };
    let error = case
        .tip_error
        .map_or(String::from("-"), |e| format!("{:+.1} %", 100.0 * e));
    println!(
        "{:>12} {young:>8.0e} {poisson:>8} {frame_dt:>9.2e} {outcome:>10} {:>34} {:>10.2} {error:>11}",
        format!("{scene:?}"),
        case.integrator,
        case.ms_per_frame
    );
    match &case.outcome {
        Outcome::Refused(error) => println!("         reason: {error}"),
        Outcome::Unstable(why) => println!("         reason: {why}"),
        Outcome::Stable => {}
    }
}

#[test]
fn every_extreme_case_is_stable_or_refused() {
    print_header();
    let mut counts = Counts::default();
    let mut unstable = Vec::new();
    for scene in SCENES {
        for young in YOUNG {
            for poisson in POISSON {
                for frame_dt in FRAME_DT {
                    let case = run_case(scene, young, poisson, frame_dt, FRAMES);
                    print_row(&case, &mut counts);
                    unstable.extend(instability(&case, &label(&case)));
                }
            }
        }
    }
    let Counts {
        cases,
        stable,
        refused,
        unstable: unstable_count,
    } = counts;
    println!(
        "{{\"cases\": {cases}, \"stable\": {stable}, \"refused\": {refused}, \"unstable\": {unstable_count}, \"frames_per_case\": {FRAMES}}}"
    );
    assert!(unstable.is_empty(), "unstable cases: {unstable:#?}");
}
