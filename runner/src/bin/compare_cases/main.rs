//! This crate's cases of the peer comparison (`benches/compare`, see its README): the six scenes
//! with the same references and JSON fields as the peers' scripts, one JSON object per case on
//! stdout, progress on stderr.
//!
//! ```text
//! compare_cases [--quick] [--scene NAME]...
//! ```
//!
//! The crate's knobs (element order and resolution, material model, volumetric treatment,
//! integrator and tolerance, coupling substeps) are swept as separate cases, each a point on the
//! Pareto plots of `compare_report`. Every case runs on a one-thread rayon pool and is timed on
//! its thread's CPU clock, as the single-threaded peers are; the scaling scene also runs on all
//! threads.

mod beam;
mod budget;
mod contact;
mod fit;
mod knobs;
mod record;
mod reference;
mod scaling;
mod timing;

use clap::{Parser, ValueEnum};
use std::process::ExitCode;
use std::time::Instant;

/// The `benches/compare` scenes on `rapier_fvm` (JSON lines on stdout).
#[derive(Parser)]
struct Args {
    /// Smallest resolution of each scene only (a smoke test).
    #[arg(long)]
    quick: bool,
    /// Run only this scene (repeatable); default: all.
    #[arg(long = "scene", value_enum)]
    scenes: Vec<Scene>,
}

/// The six scenes, in running order.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Scene {
    /// Static tip deflection of the cantilever at two steps.
    #[value(name = "cantilever")]
    Cantilever,
    /// The static cantilever over Poisson's ratio.
    #[value(name = "poisson")]
    Poisson,
    /// Undamped free vibration of the cantilever at three steps.
    #[value(name = "vibration")]
    Vibration,
    /// A soft cube dropped on the ground.
    #[value(name = "drop")]
    Drop,
    /// A rigid box resting on a soft block.
    #[value(name = "box_on_block")]
    BoxOnBlock,
    /// Cost per frame of a resting cube from ~1k tets up, one thread and all.
    #[value(name = "scaling")]
    Scaling,
}

impl Scene {
    /// Every scene, in running order.
    const ALL: [Scene; 6] = [
        Scene::Cantilever,
        Scene::Poisson,
        Scene::Vibration,
        Scene::Drop,
        Scene::BoxOnBlock,
        Scene::Scaling,
    ];

    /// Runs the scene's cases, emitting one line each.
    fn run(self, quick: bool) {
        match self {
            Scene::Cantilever => beam::scene_cantilever(quick),
            Scene::Poisson => beam::scene_poisson(quick),
            Scene::Vibration => beam::scene_vibration(quick),
            Scene::Drop => contact::scene_drop(quick),
            Scene::BoxOnBlock => contact::scene_box_on_block(quick),
            Scene::Scaling => scaling::scene_scaling(quick),
        }
    }

    /// The scene's name on the command line and in the lines.
    fn name(self) -> String {
        self.to_possible_value()
            .map_or_else(String::new, |v| v.get_name().to_string())
    }
}

/// Runs the chosen scenes on a one-thread pool.
fn main() -> ExitCode {
    let args = Args::parse();
    // Single-thread cases, as the peers': the library's parallel loops stay on this one thread.
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("error: could not build a one-thread pool: {e}");
            return ExitCode::FAILURE;
        }
    };
    let total = Instant::now();
    for scene in Scene::ALL {
        if args.scenes.is_empty() || args.scenes.contains(&scene) {
            let t0 = Instant::now();
            pool.install(|| scene.run(args.quick));
            eprintln!(
                "[{}] done in {:.1} s",
                scene.name(),
                t0.elapsed().as_secs_f64()
            );
        }
    }
    eprintln!("all done in {:.1} s", total.elapsed().as_secs_f64());
    ExitCode::SUCCESS
}
