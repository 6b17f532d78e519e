//! Soft bodies set spinning (`angvel`) and moving by regions (`velocity`) from scene files, and
//! the probes that check what follows: momentum, angular momentum and energy of a free body
//! against their closed forms, and the force on a dropped cube against its change of momentum.

mod scenes;

use rapier_fvm_runner::scene::Scene;
use scenes::{run_scene, scene_path};
use serde_json::Value;
use std::path::PathBuf;

/// Runs `toml` (read as the shipped scene `{name}.toml`) for its duration, or `duration` (s),
/// into the fresh folder `name`; returns `report.json` and the folder.
fn run(name: &str, toml: &str, duration: Option<f64>) -> (Value, PathBuf) {
    let (_, out) = run_scene(name, toml, duration);
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    (serde_json::from_str(&report).unwrap(), out)
}

/// The values of the probe `name` in `report`, after checking its kind and unit.
fn probe(report: &Value, name: &str, kind: &str, unit: &str) -> Vec<f64> {
    let probe = (report["probes"].as_array().unwrap().iter())
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no probe {name:?} in the report"));
    assert_eq!(probe["kind"], kind, "{name}");
    assert_eq!(probe["unit"], unit, "{name}");
    let values: Vec<f64> = (probe["values"].as_array().unwrap().iter())
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(probe["final_value"].as_f64(), values.last().copied());
    values
}

/// The largest distance of `values` from `expected`, relative to `expected`.
fn largest_relative_change(values: &[f64], expected: f64) -> f64 {
    values
        .iter()
        .map(|v| (v - expected).abs() / expected.abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_spin_and_region_velocities_are_read_from_the_scene() {
    let text = std::fs::read_to_string(scene_path("spinning_block.toml"))
        .unwrap()
        .replace(
            "angvel = [0.0, 0.0, 3.0]",
            "angvel = [0.0, 0.0, 3.0]\nvelocity = [{ min = [0.1, -1, -1], max = [1, 1, 1], \
             linvel = [0.0, 1.0, 0.0] }]",
        );
    let scene = Scene::parse(scene_path("spinning_block.toml"), text).unwrap();
    let block = &scene.soft_body[0];
    assert_eq!(block.angvel, [0.0, 0.0, 3.0]);
    assert_eq!(block.linvel, [0.1, 0.0, 0.0]);
    assert_eq!(block.velocity.len(), 1);
    assert_eq!(block.velocity[0].min, Some([0.1, -1.0, -1.0]));
    assert_eq!(block.velocity[0].linvel, [0.0, 1.0, 0.0]);
    // Left out, they are zero and none.
    let plain = Scene::load(scene_path("drop.toml")).unwrap();
    assert_eq!(plain.soft_body[0].angvel, [0.0; 3]);
    assert!(plain.soft_body[0].velocity.is_empty());
}

#[test]
fn the_spinning_block_keeps_its_momenta_from_their_closed_forms() {
    // spinning_block.toml: 8 kg, half extents a = 0.2, b = 0.1 m in 8 x 4 cells, spun at
    // ω = 3 rad/s about z and drifting at 0.1 m/s along x, in zero gravity, for 3 s. The lumped
    // masses weigh each axis's second moment as the trapezoidal rule: I_zz =
    // m (a² (1 + 2/8²) + b² (1 + 2/4²)) / 3 = 0.14 kg m², so L = I ω = 0.42 N m s and the
    // kinetic energy is m v²/2 + I ω²/2 = 0.67 J. The automatic integrator steps it explicitly,
    // which keeps both momenta to round-off (3e-15 relative measured; 1e-12 allowed), while the
    // kinetic energy falls into elastic energy (the spin stretches the block) and the damping.
    let text = std::fs::read_to_string(scene_path("spinning_block.toml")).unwrap();
    let (report, out) = run("momentum_probes_spinning_block", &text, None);
    assert_eq!(report["frames"], 180);
    let (mass, speed, omega) = (8.0, 0.1, 3.0);
    let trapezoidal = |half: f64, cells: f64| half * half * (1.0 + 2.0 / (cells * cells)) / 3.0;
    let inertia = mass * (trapezoidal(0.2, 8.0) + trapezoidal(0.1, 4.0));
    let spin = probe(&report, "angular momentum z", "angular_momentum", "N m s");
    let spin_norm = probe(
        &report,
        "angular momentum norm",
        "angular_momentum",
        "N m s",
    );
    let momentum = probe(&report, "linear momentum x", "momentum", "kg m/s");
    assert_eq!(spin.len(), 181);
    assert!(
        largest_relative_change(&spin, inertia * omega) < 1e-12,
        "{spin:?}"
    );
    assert!(largest_relative_change(&spin_norm, inertia * omega) < 1e-12);
    assert!(largest_relative_change(&momentum, mass * speed) < 1e-12);
    let kinetic = probe(&report, "kinetic energy", "energy", "J");
    let elastic = probe(&report, "elastic energy", "energy", "J");
    let kinetic0 = 0.5 * mass * speed * speed + 0.5 * inertia * omega * omega;
    assert!((kinetic[0] - kinetic0).abs() < 1e-12 * kinetic0);
    assert!(elastic[0].abs() < 1e-20, "the block starts unstrained");
    let (kinetic_end, elastic_end) = (kinetic[180], elastic[180]);
    assert!(kinetic_end < kinetic0 && elastic_end > 0.0);
    assert!(
        kinetic_end + elastic_end < kinetic0,
        "the damping takes energy out"
    );
    for name in ["angular_momentum_z", "linear_momentum_x", "kinetic_energy"] {
        assert!(out.join(format!("plots/{name}.png")).is_file(), "{name}");
    }
}

#[test]
fn a_region_starts_at_its_own_velocity() {
    // A 1 kg cube of 4 x 4 x 4 cells in zero gravity whose nodes at x ≥ 0 start at 1 m/s along
    // y: they hold 1/2 + 1/(2·4) of the mass (the lumped masses weigh the planes of nodes as
    // the trapezoidal rule), so the momentum is 0.625 kg m/s, kept by the free body, and the
    // kinetic energy 0.3125 J at the start.
    let text = r#"
[world]
duration = 0.05
gravity = [0.0, 0.0, 0.0]

[[soft_body]]
name = "cube"
mesh = { cuboid = { half_extents = [0.05, 0.05, 0.05], cells = [4, 4, 4] } }
material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
velocity = [{ min = [0.0, -1.0, -1.0], max = [1.0, 1.0, 1.0], linvel = [0.0, 1.0, 0.0] }]

[[probe]]
name = "momentum y"
kind = "momentum"
component = "y"

[[probe]]
name = "kinetic energy"
kind = "energy"
energy = "kinetic"
"#;
    let (report, _) = run("momentum_probes_region_velocity", text, None);
    let momentum = probe(&report, "momentum y", "momentum", "kg m/s");
    assert!(
        largest_relative_change(&momentum, 0.625) < 1e-12,
        "{momentum:?}"
    );
    let kinetic = probe(&report, "kinetic energy", "energy", "J");
    assert!((kinetic[0] - 0.3125).abs() < 1e-12);
}

#[test]
fn the_force_on_a_dropped_cube_is_its_change_of_momentum_less_its_weight() {
    // drop.toml for 0.75 s: the 1 kg cube lands at about 0.32 s and bounces. Over each frame,
    // the change of its momentum is its weight's impulse plus the contact force's on it
    // (`contact_force_on_soft`, the opposite of the ground reaction): Δp / Δt = m g + F, to
    // 1.4e-5 N measured (1e-4 N allowed) against an impact force of some 280 N; the frame step
    // and gravity are rapier's f32, whose rounding (1e-7 relative) makes most of it.
    let probes = r#"
[[probe]]
name = "momentum y"
kind = "momentum"
body = "cube"
component = "y"

[[probe]]
name = "force on the cube"
kind = "contact_force_on_soft"
body = "cube"
component = "y"
"#;
    let text = std::fs::read_to_string(scene_path("drop.toml")).unwrap() + probes;
    let (report, _) = run("momentum_probes_drop_momentum", &text, Some(0.75));
    let momentum = probe(&report, "momentum y", "momentum", "kg m/s");
    let force = probe(&report, "force on the cube", "contact_force_on_soft", "N");
    let reaction = probe(&report, "ground reaction", "contact_force", "N");
    let times: Vec<f64> = (report["probes"][0]["times"].as_array().unwrap().iter())
        .map(|t| t.as_f64().unwrap())
        .collect();
    let (mass, gravity) = (1.0, -9.81);
    let mut largest_force: f64 = 0.0;
    for frame in 1..times.len() {
        assert_eq!(force[frame], -reaction[frame]);
        let rate = (momentum[frame] - momentum[frame - 1]) / (times[frame] - times[frame - 1]);
        let expected = mass * gravity + force[frame];
        assert!(
            (rate - expected).abs() < 1e-4,
            "frame {frame}: Δp/Δt = {rate} N, m g + F = {expected} N"
        );
        largest_force = largest_force.max(force[frame]);
    }
    assert!(
        largest_force > 100.0,
        "the ground pushed the cube up: {largest_force} N"
    );
}
