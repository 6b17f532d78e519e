//! The scenes of `benches/compare` (see its README) on rapier3d 0.36.1's own built-in soft
//! bodies: one JSON object per case on stdout, progress on stderr.
//!
//! ```text
//! rapier_builtin_cases [--quick] [--scene NAME]...
//! ```
//!
//! Every case runs with both of rapier's soft-body solvers: the default constraint solver and
//! the `fem` solver (implicit Euler, conjugate gradient with its iteration cap raised from 20 to
//! 256). Cells are `SoftBodyCellModel::Corotational` (the default `Volume` model ignores
//! Young's modulus) and masses are lumped from the density (rapier's default is 1 kg per
//! particle).

mod beam;
mod budget;
mod contact;
mod record;
mod scaling;
mod setup;

use clap::Parser;
use compare_common::cli::{Args, Scene};

/// The benches/compare scenes on rapier3d 0.36.1's built-in soft bodies (JSON lines on stdout).
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

/// Runs the chosen scenes.
fn main() {
    Cli::parse().args.run_scenes(run);
}
