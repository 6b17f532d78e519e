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
//! It is refused when the crate returns an error. The last line is a JSON summary; `unstable`
//! must be 0.
//!
//! Run with `cargo run --release --example extremes`.

use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, ColliderSet, RigidBodySet, SharedShape};
use std::time::Instant;

/// Young's moduli (Pa) of the sweep.
pub const YOUNG: [f64; 5] = [1e3, 1e5, 1e7, 1e9, 1e11];
/// Poisson's ratios of the sweep.
pub const POISSON: [f64; 8] = [-0.9, -0.5, 0.0, 0.3, 0.45, 0.49, 0.499, 0.4999];
/// Frame steps (s) of the sweep.
pub const FRAME_DT: [f64; 4] = [1e-4, 1.0 / 240.0, 1.0 / 60.0, 1.0 / 30.0];
/// Frames simulated per case.
pub const FRAMES: usize = 20;

/// The scenes of the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scene {
    /// The clamped reference beam under its own weight.
    Cantilever,
    /// A cube landing on the ground.
    DroppedCube,
}

/// Both scenes.
pub const SCENES: [Scene; 2] = [Scene::Cantilever, Scene::DroppedCube];

/// How one case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Finite, energy bounded.
    Stable,
    /// A typed error before or while stepping.
    Refused(Error),
    /// Non-finite state or energy growth (must never happen).
    Unstable(String),
}

/// One row of the table.
#[derive(Debug, Clone)]
pub struct Case {
    /// The scene.
    pub scene: Scene,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Frame step (s).
    pub frame_dt: f64,
    /// The outcome.
    pub outcome: Outcome,
    /// Integrator of the last frame: explicit substeps, or Newton and conjugate-gradient
    /// iterations.
    pub integrator: String,
    /// Wall time per frame (ms).
    pub ms_per_frame: f64,
    /// Tip deflection over the Timoshenko value, minus one, once the beam has come to rest.
    pub tip_error: Option<f64>,
}

/// Timoshenko tip deflection (m) of the beam under its own weight.
fn timoshenko(young: f64, poisson: f64) -> f64 {
    let (side, length, gravity, density) = (0.1f64, 1.0f64, 9.81, 1000.0);
    let (area, inertia) = (side * side, side.powi(4) / 12.0);
    let q = density * area * gravity;
    let shear = young / (2.0 * (1.0 + poisson));
    let kappa = 10.0 * (1.0 + poisson) / (12.0 + 11.0 * poisson);
    q * length.powi(4) / (8.0 * young * inertia) + q * length.powi(2) / (2.0 * kappa * shear * area)
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

/// Runs one case of the sweep.
pub fn run_case(scene: Scene, young: f64, poisson: f64, frame_dt: f64, frames: usize) -> Case {
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
    let gravity = DVec3::new(0.0, -9.81, 0.0);
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
    let energy = |b: &DeformableBody| {
        b.kinetic_energy() + b.elastic_energy() + b.gravity_potential_energy(gravity)
    };
    let initial = energy(&body);
    let scale = body.total_mass() * 9.81 * 1.0;
    let integrator = AutomaticIntegrator::default();
    let start = Instant::now();
    for _ in 0..frames {
        let stepped = body
            .detect_contacts(
                &colliders,
                &RigidBodySet::new(),
                frame_dt,
                gravity,
                &ContactSettings::default(),
            )
            .map(|_| ())
            .and_then(|()| integrator.step(&mut body, frame_dt, gravity));
        match stepped {
            Ok(report) => {
                case.integrator = match (report.explicit, report.implicit) {
                    (Some(explicit), _) => format!("explicit x{}", explicit.substeps),
                    (_, Some(implicit)) => {
                        format!(
                            "implicit, {} Newton, {} CG",
                            implicit.newton_iterations, implicit.linear_iterations
                        )
                    }
                    _ => String::from("-"),
                };
            }
            Err(error) => {
                case.outcome = match error {
                    Error::NonFiniteState { .. } => Outcome::Unstable(error.to_string()),
                    other => Outcome::Refused(other),
                };
                return case;
            }
        }
        let now = energy(&body);
        if !now.is_finite() || now > initial + 1e-3 * scale {
            case.outcome = Outcome::Unstable(format!("energy rose by {:.3e} J", now - initial));
            return case;
        }
    }
    case.ms_per_frame = start.elapsed().as_secs_f64() * 1e3 / frames as f64;
    let at_rest = body.velocities().iter().all(|v| v.length() < 1e-3);
    if let Some(tip) = tip {
        let deflection = body.mesh().positions()[tip].y - body.positions()[tip].y;
        let reference = timoshenko(young, poisson);
        // Beam theory applies to small deflections (under 5 % of the length).
        if at_rest && reference < 0.05 {
            case.tip_error = Some(deflection / reference - 1.0);
        }
    }
    case
}

#[allow(dead_code)]
fn main() {
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
    let (mut cases, mut stable, mut refused, mut unstable) = (0, 0, 0, 0);
    for scene in SCENES {
        for &young in &YOUNG {
            for &poisson in &POISSON {
                for &frame_dt in &FRAME_DT {
                    let case = run_case(scene, young, poisson, frame_dt, FRAMES);
                    cases += 1;
                    let outcome = match &case.outcome {
                        Outcome::Stable => {
                            stable += 1;
                            String::from("stable")
                        }
                        Outcome::Refused(_) => {
                            refused += 1;
                            String::from("refused")
                        }
                        Outcome::Unstable(_) => {
                            unstable += 1;
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
            }
        }
    }
    println!(
        "{{\"cases\": {cases}, \"stable\": {stable}, \"refused\": {refused}, \"unstable\": {unstable}, \"frames_per_case\": {FRAMES}}}"
    );
}
