//! The `rapier-fvm` binary: help, exit codes, and one-line errors without a panic.

mod common;

use common::{rapier_fvm, scratch};
use std::path::Path;
use std::process::Output;

/// Asserts a failure with status 1 and one line on stderr mentioning `words`.
fn assert_one_line_error(output: &Output, words: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "stderr: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr:?}");
    assert!(stderr.starts_with("error: "), "{stderr:?}");
    assert!(stderr.contains(words), "{words:?} in {stderr:?}");
    assert!(!stderr.contains("panicked"), "{stderr:?}");
}

#[test]
fn help_documents_both_subcommands() {
    let output = rapier_fvm(&["--help"]);
    assert!(output.status.success());
    let help = String::from_utf8_lossy(&output.stdout);
    assert!(help.contains("run") && help.contains("check"), "{help}");
    let output = rapier_fvm(&["run", "--help"]);
    let help = String::from_utf8_lossy(&output.stdout);
    for word in ["--out", "--duration", "report.json", ".pvd", "pictures"] {
        assert!(help.contains(word), "{word} in {help}");
    }
    let output = rapier_fvm(&["check", "--help"]);
    let help = String::from_utf8_lossy(&output.stdout);
    for word in ["--scale", "--young", "--poisson", "--density"] {
        assert!(help.contains(word), "{word} in {help}");
    }
}

#[test]
fn a_missing_scene_fails_in_one_line() {
    let output = rapier_fvm(&["run", "no/such/scene.toml", "--out", "unused"]);
    assert_one_line_error(&output, "no/such/scene.toml");
}

#[test]
fn a_malformed_scene_fails_in_one_line_with_file_line_and_key() {
    let path = scratch(
        "cli",
        "malformed.toml",
        "[world]\nduration = 1.0\ngravty = [0, -9.81, 0]\n",
    );
    let output = rapier_fvm(&["run", path.to_str().unwrap(), "--out", "unused"]);
    assert_one_line_error(&output, "malformed.toml:3: world.gravty: unknown field");
}

#[test]
fn a_malformed_mesh_fails_in_one_line() {
    let path = scratch(
        "cli",
        "broken.msh",
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2\n",
    );
    let output = rapier_fvm(&["check", path.to_str().unwrap()]);
    assert_one_line_error(&output, "broken.msh");
    let output = rapier_fvm(&["check", "no/such/mesh.msh"]);
    assert_one_line_error(&output, "no/such/mesh.msh");
}

#[test]
fn check_reports_a_shipped_mesh() {
    let output = rapier_fvm(&[
        "check",
        "assets/meshes/cube_v41_ascii.msh",
        "--young",
        "1e5",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    for word in [
        "tetrahedra",
        "volume",
        "dihedral",
        "radius ratio",
        "inverted",
        "stable time step",
    ] {
        assert!(text.contains(word), "{word} in {text}");
    }
}

#[test]
fn wrong_arguments_exit_with_status_two() {
    let output = rapier_fvm(&["run"]);
    assert_eq!(output.status.code(), Some(2));
    let output = rapier_fvm(&["check", "x.msh", "--young", "stiff"]);
    assert_eq!(output.status.code(), Some(2));
}

#[test]
fn a_short_run_succeeds_and_prints_a_summary() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_run");
    let output = rapier_fvm(&[
        "run",
        "assets/scenes/cantilever.toml",
        "--out",
        out.to_str().unwrap(),
        "--duration",
        "0.05",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(text.contains("cantilever: 3 frames"), "{text}");
    assert!(text.contains("tip deflection"), "{text}");
    assert!(out.join("report.json").is_file());
}
