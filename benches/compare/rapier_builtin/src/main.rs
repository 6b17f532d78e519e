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
mod fit;
mod record;
mod reference;
mod scaling;
mod setup;
mod timing;

use clap::{Parser, ValueEnum};
use std::time::Instant;

/// The benches/compare scenes on rapier3d 0.36.1's built-in soft bodies (JSON lines on stdout).
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
    #[value(name = "cantilever")]
    Cantilever,
    #[value(name = "poisson")]
    Poisson,
    #[value(name = "vibration")]
    Vibration,
    #[value(name = "drop")]
    Drop,
    #[value(name = "box_on_block")]
    BoxOnBlock,
    #[value(name = "scaling")]
    Scaling,
}

impl Scene {
    const ALL: [Scene; 6] = [
        Scene::Cantilever,
        Scene::Poisson,
        Scene::Vibration,
        Scene::Drop,
        Scene::BoxOnBlock,
        Scene::Scaling,
    ];

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

    fn name(self) -> String {
        self.to_possible_value()
            .map_or_else(String::new, |v| v.get_name().to_string())
    }
}

fn main() {
    let args = Args::parse();
    let total = Instant::now();
    for scene in Scene::ALL {
        if args.scenes.is_empty() || args.scenes.contains(&scene) {
            let t0 = Instant::now();
            scene.run(args.quick);
            eprintln!(
                "[{}] done in {:.1} s",
                scene.name(),
                t0.elapsed().as_secs_f64()
            );
        }
    }
    eprintln!("all done in {:.1} s", total.elapsed().as_secs_f64());
}
