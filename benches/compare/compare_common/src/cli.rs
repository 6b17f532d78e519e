//! The command line both programs take, `[--quick] [--scene NAME]...`, and the scene loop.

use clap::ValueEnum;
use std::time::Instant;

/// The options of a comparison program (flattened into its own parser, which has its about).
#[derive(clap::Args)]
pub struct Args {
    /// Smallest resolution of each scene only (a smoke test).
    #[arg(long)]
    pub quick: bool,
    /// Run only this scene (repeatable); default: all.
    #[arg(long = "scene", value_enum)]
    pub scenes: Vec<Scene>,
}

impl Args {
    /// Runs `run(scene, quick)` on every chosen scene in running order, with each scene's and
    /// the total wall time on stderr.
    pub fn run_scenes(&self, mut run: impl FnMut(Scene, bool)) {
        let total = Instant::now();
        for scene in Scene::ALL {
            if self.scenes.is_empty() || self.scenes.contains(&scene) {
                let t0 = Instant::now();
                run(scene, self.quick);
                eprintln!(
                    "[{}] done in {:.1} s",
                    scene.name(),
                    t0.elapsed().as_secs_f64()
                );
            }
        }
        eprintln!("all done in {:.1} s", total.elapsed().as_secs_f64());
    }
}

/// The six scenes, in running order.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Scene {
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
    /// Cost per frame of a resting cube from ~1k tets up.
    #[value(name = "scaling")]
    Scaling,
}

impl Scene {
    /// Every scene, in running order.
    pub const ALL: [Scene; 6] = [
        Scene::Cantilever,
        Scene::Poisson,
        Scene::Vibration,
        Scene::Drop,
        Scene::BoxOnBlock,
        Scene::Scaling,
    ];

    /// The scene's name on the command line and in the lines.
    pub fn name(self) -> String {
        self.to_possible_value()
            .map_or_else(String::new, |v| v.get_name().to_string())
    }
}
