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
mod knobs;
mod record;
mod scaling;

use clap::Parser;
use compare_common::cli::{Args, Scene};
use std::process::ExitCode;

/// The `benches/compare` scenes on `rapier_fvm` (JSON lines on stdout).
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: Args,
}

/// Runs the scene's cases, emitting one line each.
fn run(scene: Scene, quick: bool) {
    match scene {
        Scene::Cantilever => beam::scene_cantilever(quick),
        Scene::Poisson => beam::scene_poisson(quick),
        Scene::Vibration => beam::scene_vibration(quick),
        Scene::Drop => contact::scene_drop(quick),
        Scene::BoxOnBlock => contact::scene_box_on_block(quick),
        Scene::Scaling => scaling::scene_scaling(quick),
    }
}

/// Runs the chosen scenes on a one-thread pool.
fn main() -> ExitCode {
    let cli = Cli::parse();
    // Single-thread cases, as the peers': the library's parallel loops stay on this one thread.
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("error: could not build a one-thread pool: {e}");
            return ExitCode::FAILURE;
        }
    };
    cli.args
        .run_scenes(|scene, quick| pool.install(|| run(scene, quick)));
    ExitCode::SUCCESS
}
