//! What the runner's scene tests share: a scene's text run as if it were a shipped scene file
//! (meshes it names resolve from `assets/scenes/`), into a fresh folder of the test target's
//! temporary folder.

use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::{self, RunOptions};
use std::path::{Path, PathBuf};

/// The path of the shipped scene file `file` (with its extension).
pub fn scene_path(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/scenes")
        .join(file)
}

/// Runs `text`, read as the shipped scene `{name}.toml`, for its duration or `duration` (s),
/// into the fresh folder `name`; returns the report and the folder.
pub fn run_scene(name: &str, text: &str, duration: Option<f64>) -> (sim::Report, PathBuf) {
    let scene = Scene::parse(scene_path(&format!("{name}.toml")), text.to_owned())
        .unwrap_or_else(|e| panic!("{e}"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&out);
    let options = RunOptions {
        out: out.clone(),
        duration,
        progress: false,
    };
    let report = sim::run(&scene, &options).unwrap_or_else(|e| panic!("{e}"));
    (report, out)
}
