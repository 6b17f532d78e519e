//! What the runner's command-line tests share: running the `rapier-fvm` binary from the
//! workspace root, and scratch files under the test target's temporary folder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `rapier-fvm` with `args` from the workspace root (where the README's commands run).
pub fn rapier_fvm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rapier-fvm"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("the binary runs")
}

/// A scratch file `name` with `content`, in the folder `folder` of the test target's temporary
/// folder.
pub fn scratch(folder: &str, name: &str, content: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, content).unwrap();
    path
}
