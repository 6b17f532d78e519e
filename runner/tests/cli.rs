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
fn help_documents_the_subcommands() {
    let output = rapier_fvm(&["--help"]);
    assert!(output.status.success());
    let help = String::from_utf8_lossy(&output.stdout);
    for word in ["run", "check", "advise", "calibrate"] {
        assert!(help.contains(word), "{word} in {help}");
    }
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
fn check_lists_a_file_s_regions() {
    // gmsh's two boxes: 1 455 tetrahedra, 718 of them in "left" and 737 in "right".
    let output = rapier_fvm(&["check", "assets/meshes/two_volumes_v41.msh"]);
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    for line in [
        "  tetrahedra          1455 (linear)",
        "  region              \"clamp\" (surface, tag 3): 44 nodes",
        "  region              \"left\" (volume, tag 1): 235 nodes, 718 tetrahedra",
        "  region              \"right\" (volume, tag 2): 237 nodes, 737 tetrahedra",
    ] {
        assert!(text.lines().any(|l| l == line), "{line:?} in {text}");
    }
}

#[test]
fn check_counts_a_file_s_hexahedra_and_their_curved_volume() {
    // gmsh's 1 x 0.5 x 0.25 m box of 4 x 3 x 2 27-node hexahedra through the VTK library's
    // legacy writer: 9 x 7 x 5 lattice nodes, 48 tetrahedra per hexahedron, its cell tags.
    let output = rapier_fvm(&["check", "assets/meshes/box_hex27_vtk9.vtk"]);
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    for line in [
        "  hexahedra           24 (27-node), split into 1152 tetrahedra",
        "  nodes               315 (0 unused)",
        "  volume              1.250000e-1 m³",
        "  folded              0",
        "  region              unnamed (volume, tag 1): 315 nodes, 1152 tetrahedra",
    ] {
        assert!(text.lines().any(|l| l == line), "{line:?} in {text}");
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

#[test]
fn a_reader_that_stops_early_ends_the_run_quietly() {
    // As `rapier-fvm run ... | head -1`: the pipe is closed before the summary is printed. The
    // program ends quietly with 141, as a shell reports `cat` ended by SIGPIPE; before, it
    // printed "error: internal error: failed printing to stdout: Broken pipe".
    use std::process::{Command, Stdio};
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_pipe");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rapier-fvm"))
        .args([
            "run",
            "assets/scenes/cantilever.toml",
            "--duration",
            "0.05",
            "--out",
        ])
        .arg(&out)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.is_empty(), "{stderr:?}");
    assert_eq!(output.status.code(), Some(141));
    assert!(out.join("report.json").is_file(), "the run itself finished");
}

#[test]
fn calibrate_prints_a_cost_table_a_scene_reads() {
    // The measured values differ from machine to machine and run to run; what is checked is
    // that the printed table is a scene's `[integrator.cost]`, read back to the printed digits,
    // every value finite and positive (a contact point's cost, the size exponent and the
    // implicit work's fitted parts may be zero: the fit keeps them not negative), and the
    // cases' progress on stderr.
    let output = rapier_fvm(&["calibrate"]);
    assert!(output.status.success());
    let table = String::from_utf8_lossy(&output.stdout);
    let progress = String::from_utf8_lossy(&output.stderr);
    assert!(progress.contains("implicit, dropped"), "{progress}");
    let scene = format!(
        "name = \"c\"\n[world]\nduration = 0.1\n[[soft_body]]\nname = \"cube\"\n\
         mesh = {{ cuboid = {{ half_extents = [0.05, 0.05, 0.05], cells = [2, 2, 2] }} }}\n\
         material = {{ model = \"linear\", young = 1e5, poisson = 0.3, density = 1000.0 }}\n{table}"
    );
    let scene = rapier_fvm_runner::scene::Scene::parse("calibrated.toml", scene).unwrap();
    let cost = scene.integrator.integrator().cost;
    let printed = |key: &str| -> f64 {
        let line = table
            .lines()
            .find(|l| l.starts_with(&format!("{key} ")))
            .unwrap();
        line.split('=')
            .nth(1)
            .unwrap()
            .split('#')
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    for (key, value) in [
        ("explicit_tet", cost.explicit_tet),
        ("explicit_tet_corotated", cost.explicit_tet_corotated),
        ("explicit_damped_factor", cost.explicit_damped_factor),
        ("explicit_contact_point", cost.explicit_contact_point),
        ("newton_tet", cost.newton_tet),
        ("newton_size_exponent", cost.newton_size_exponent),
        ("newton_tet_corotated", cost.newton_tet_corotated),
        ("factorization_tet", cost.factorization_tet),
        ("energy_evaluation", cost.energy_evaluation),
        ("partner_evaluation", cost.partner_evaluation),
        (
            "conjugate_gradient_iteration",
            cost.conjugate_gradient_iteration,
        ),
        ("conjugate_gradient_tet", cost.conjugate_gradient_tet),
        ("newton_iterations", cost.newton_iterations),
    ] {
        // A contact point may cost nothing measurable; the size exponent lies in [0, 1], and is
        // 0 when a larger body costs no more per tetrahedron (on two threads its loops split);
        // the implicit work's parts are fitted not negative, and may come out zero.
        let positive = matches!(
            key,
            "explicit_tet"
                | "explicit_tet_corotated"
                | "explicit_damped_factor"
                | "newton_iterations"
        );
        let least = if positive { f64::MIN_POSITIVE } else { 0.0 };
        assert!(value.is_finite() && value >= least, "{key} = {value}");
        assert_eq!(value, printed(key), "{key}");
    }
}

#[test]
fn advise_prints_its_table_and_writes_a_scene_that_runs() {
    // The cantilever over 0.2 s (12 frames), 5 % allowed: every alternative is listed with its
    // verdict, and the recommended file is a scene `run` takes.
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_advise");
    let _ = std::fs::remove_dir_all(&out);
    let output = rapier_fvm(&[
        "advise",
        "assets/scenes/cantilever.toml",
        "--out",
        out.to_str().unwrap(),
        "--duration",
        "0.2",
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success() && stderr.is_empty(), "{stderr}");
    let text = String::from_utf8_lossy(&output.stdout);
    for words in [
        "target 5.00 %",
        "beam: model linear",
        "beam: cells [10, 1, 1]",
        "integrator explicit",
        "recommended: ",
        "within the target",
    ] {
        assert!(text.contains(words), "{words:?} in {text}");
    }
    assert!(out.join("advice.json").is_file());
    let recommended = out.join("recommended.toml");
    let run = rapier_fvm(&[
        "run",
        recommended.to_str().unwrap(),
        "--out",
        out.join("run").to_str().unwrap(),
        "--duration",
        "0.05",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let output = rapier_fvm(&[
        "advise",
        "assets/scenes/cantilever.toml",
        "--out",
        "unused",
        "--target",
        "0",
    ]);
    assert_one_line_error(
        &output,
        "the target must be a relative error in (0, 1), got 0",
    );
}
