//! Loads in scenes: a keyframed chamber pressure selected by a mesh file's region runs exactly
//! as the library's API driven by hand each frame, the energy audit counts the work of the
//! loads and of their changes, a chamber pumped to a volume holds it, and malformed loads are
//! refused at their key and line.

use rapier_fvm::load::LoadHandle;
use rapier_fvm::mesh::import;
use rapier_fvm::prelude::*;
use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::Simulation;
use std::path::{Path, PathBuf};

/// Where the scene pretends to live, so that `../meshes/` is the shipped meshes' folder.
fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/pneumatic_finger.toml")
}

/// The shipped pneumatic finger scene.
fn finger_scene() -> Scene {
    let text = std::fs::read_to_string(scene_path()).unwrap();
    Scene::parse(scene_path(), text).unwrap_or_else(|e| panic!("{e}"))
}

/// The finger of the scene driven by the scene's keyframes, and the same finger built and
/// driven with the library's API (the file's "chamber" region's boundary triangles, the pressure
/// set each frame to the keyframes' line 0 → 5 kPa over 1 s): the same positions, bit for bit,
/// after 12 frames.
#[test]
fn a_keyframed_chamber_pressure_runs_as_the_api_driven_by_hand() {
    let scene = finger_scene();
    let mut sim = Simulation::build(&scene).unwrap();
    let dt = scene.world.dt;
    for frame in 1..=12 {
        sim.drive_loads(frame as f64 * dt, &scene.source).unwrap();
        for (_, outcome) in sim.world.step() {
            outcome.unwrap();
        }
    }
    let by_scene = sim.world.soft_bodies[sim.soft[0].handle]
        .positions()
        .to_vec();

    let file =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/pneumatic_finger_v41.msh");
    let raw = import::load_raw(&file, 1.0, &import::SurfaceOptions::default()).unwrap();
    let regions = raw.regions_in_mesh();
    let mesh = raw.into_mesh().unwrap();
    let region = |name: &str| {
        regions
            .iter()
            .find(|r| r.name == name)
            .unwrap()
            .nodes
            .clone()
    };
    let (base, chamber_nodes) = (region("base"), region("chamber"));
    let chamber: Vec<[u32; 3]> = (mesh.surface_triangles().into_iter())
        .filter(|t| t.iter().all(|n| chamber_nodes.contains(n)))
        .collect();
    let silicone = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.45, 1070.0).unwrap();
    let finger = DeformableBodyBuilder::new(mesh, silicone)
        .damping(RayleighDamping::stiffness_proportional(2e-3, silicone.lame()).unwrap())
        .pinned_nodes(base)
        .build()
        .unwrap();
    let mut world = FvmWorld::default();
    world.physics.gravity = rapier_fvm::glamx::Vec3::ZERO;
    world.physics.integration_parameters.dt = dt as f32;
    let handle = world.soft_bodies.insert(finger);
    let pressure = world.soft_bodies[handle]
        .add_load(Load::Pressure {
            triangles: chamber,
            pressure: 0.0,
        })
        .unwrap();
    for frame in 1..=12 {
        let value = 5e3 * (frame as f64 * dt).min(1.0);
        world.soft_bodies[handle]
            .set_load(pressure, LoadValue::Scalar(value))
            .unwrap();
        for (_, outcome) in world.step() {
            outcome.unwrap();
        }
    }
    let by_hand = world.soft_bodies[handle].positions();
    assert_eq!(by_scene.as_slice(), by_hand);
    let rest = sim.soft[0].rest.clone();
    let moved = by_hand
        .iter()
        .zip(&rest)
        .map(|(x, r)| x.distance(*r))
        .fold(0.0, f64::max);
    assert!(moved > 1e-5, "the pressure moved the finger by {moved} m");
}

/// The finger inflated over 0.5 s: the audit counts the pressure's work (its potential `p V`
/// and the work of each change of `p` between frames), so the run is found stable; without
/// them every frame of the inflation showed as an energy gain (62 of 90 frames, up to 0.22 mJ,
/// before the loads were counted).
#[test]
fn the_energy_audit_counts_the_work_of_the_loads() {
    let scene = finger_scene();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("finger_audit");
    let _ = std::fs::remove_dir_all(&out);
    let options = rapier_fvm_runner::sim::RunOptions {
        out,
        duration: Some(0.5),
        progress: false,
    };
    let report = rapier_fvm_runner::sim::run(&scene, &options).unwrap_or_else(|e| panic!("{e}"));
    assert!(report.stability.stable, "{:?}", report.stability);
    let elastic = report.probes[1].final_value;
    assert!(
        elastic > 1e-4,
        "the chamber was inflated: elastic energy {elastic} J"
    );
}

/// The pneumatic finger scene with its load replaced by `load`, parsed.
fn with_load(load: &str) -> Result<Scene, rapier_fvm_runner::scene::SceneError> {
    let text = std::fs::read_to_string(scene_path()).unwrap();
    let original = r#"  { pressure = [{ time = 0.0, value = 0.0 }, { time = 1.0, value = 5e3 }], region = "chamber" },"#;
    assert!(text.contains(original));
    Scene::parse(scene_path(), text.replace(original, load))
}

/// A load naming no kind or two, a cable without its path, a negative tension, keyframes out
/// of order and a box selecting no boundary triangle are refused at the load's key and line.
#[test]
fn malformed_loads_are_refused_at_their_key() {
    let line = 19;
    for (load, key, words) in [
        (r#"  { region = "chamber" },"#, "loads[0]", "give one of"),
        (
            r#"  { pressure = 1.0, tension = 2.0, region = "chamber" },"#,
            "loads[0]",
            "give one of",
        ),
        (
            "  { tension = 2.0 },",
            "loads[0].path",
            "a `tension` and a `path`",
        ),
        (
            "  { tension = -2.0, path = [[0, 0, 0], [0.1, 0, 0]] },",
            "loads[0].tension",
            "negative",
        ),
        (
            r#"  { pressure = [{ time = 1.0, value = 0.0 }, { time = 0.5, value = 1.0 }], region = "chamber" },"#,
            "loads[0].pressure[1].time",
            "increasing",
        ),
        (
            "  { body_force = [0, 0, 1], region = 3 },",
            "loads[0]",
            "only a `pressure`, a `traction` or a `volume_ratio`",
        ),
        (
            r#"  { volume_ratio = [{ time = 0.0, value = 1.0 }, { time = 1.0, value = 0.0 }], region = "chamber" },"#,
            "loads[0].volume_ratio",
            "must be positive",
        ),
        (
            r#"  { pressure = 1.0, bulk_modulus = 1e9, region = "chamber" },"#,
            "loads[0].bulk_modulus",
            "a chamber's",
        ),
        (
            r#"  { volume_ratio = 1.1, bulk_modulus = -1.0, region = "chamber" },"#,
            "loads[0].bulk_modulus",
            "positive and finite",
        ),
    ] {
        let error = with_load(load)
            .err()
            .unwrap_or_else(|| panic!("{load} should be refused"));
        let message = error.to_string();
        assert!(
            message.contains(&format!("pneumatic_finger.toml:{line}: ")),
            "{message}"
        );
        assert!(
            message.contains(&format!("soft_body[0].{key}")),
            "{key} in {message}"
        );
        assert!(message.contains(words), "{words:?} in {message}");
    }
    // A box around no boundary triangle parses, and is refused when the body is built.
    let scene = with_load(
        "  { traction = [0, 1, 0], min = [0.04, -0.001, -0.001], max = [0.05, 0.001, 0.001] },",
    )
    .unwrap();
    let error = Simulation::build(&scene)
        .err()
        .expect("no boundary triangle in the box");
    let message = error.to_string();
    assert!(
        message.contains("soft_body[0].loads[0]") && message.contains("no boundary triangle"),
        "{message}"
    );
    // A chamber whose box selects the far half of the finger: its walls are not closed.
    let scene =
        with_load("  { volume_ratio = 1.1, min = [0.05, -0.02, -0.02], max = [0.2, 0.02, 0.02] },")
            .unwrap();
    let error = Simulation::build(&scene)
        .err()
        .expect("an open chamber is refused");
    let message = error.to_string();
    assert!(
        message.contains("soft_body[0].loads[0]") && message.contains("closed"),
        "{message}"
    );
    // A chamber on the finger's whole outer surface: closed, but around the body, not a cavity.
    let scene =
        with_load("  { volume_ratio = 1.1, min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0] },")
            .unwrap();
    let message = Simulation::build(&scene).err().unwrap().to_string();
    assert!(message.contains("enclose no cavity"), "{message}");
}

/// The finger's chamber filled with water that a pump takes to 1.5 times the cavity's rest
/// volume over 0.5 s, then holds (the shipped scene's pressure replaced by `volume_ratio`
/// keyframes), with probes of the cavity's volume and pressure: the run is stable (the audit
/// counts the liquid's energy and the pump's work as it counts a pressure's), the finger bends
/// toward its floor as under pressure, and from 0.5 s on the cavity encloses the pumped volume
/// to 1e-5 (water gives way by `p/K`, 3.5e-6 at the 7.7 kPa measured).
#[test]
fn a_chamber_pumped_to_a_volume_holds_it() {
    let load = r#"  { volume_ratio = [{ time = 0.0, value = 1.0 }, { time = 0.5, value = 1.5 }], region = "chamber" },"#;
    let probes = "\n[[probe]]\nname = \"volume\"\nkind = \"cavity_volume\"\nbody = \"finger\"\n\
                  load = 0\n\n[[probe]]\nname = \"pressure\"\nkind = \"cavity_pressure\"\n\
                  body = \"finger\"\nload = 0\n";
    let text = std::fs::read_to_string(scene_path()).unwrap();
    let original = r#"  { pressure = [{ time = 0.0, value = 0.0 }, { time = 1.0, value = 5e3 }], region = "chamber" },"#;
    let text = text.replace(original, load) + probes;
    let scene = Scene::parse(scene_path(), text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulation::build(&scene).unwrap();
    let body = &sim.world.soft_bodies[sim.soft[0].handle];
    let rest = (body.load(LoadHandle(0)).unwrap())
        .enclosed_volume(body.positions())
        .unwrap();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("finger_chamber");
    let _ = std::fs::remove_dir_all(&out);
    let options = rapier_fvm_runner::sim::RunOptions {
        out,
        duration: Some(0.75),
        progress: false,
    };
    let report = rapier_fvm_runner::sim::run(&scene, &options).unwrap_or_else(|e| panic!("{e}"));
    assert!(report.stability.stable, "{:?}", report.stability);
    let series = |name: &str| {
        let probe = report.probes.iter().find(|p| p.name == name).unwrap();
        let samples: Vec<(f64, f64)> = probe
            .times
            .iter()
            .copied()
            .zip(probe.values.clone())
            .collect();
        samples
    };
    let (volumes, pressures, tip) = (
        series("volume"),
        series("pressure"),
        series("tip deflection"),
    );
    let worst = (volumes.iter())
        .filter(|(t, _)| *t >= 0.5)
        .map(|(_, volume)| (volume / (1.5 * rest) - 1.0).abs())
        .fold(0.0, f64::max);
    let (last_volume, last_pressure) = (volumes.last().unwrap().1, pressures.last().unwrap().1);
    println!(
        "rest {:.4} cm³; at 0.75 s {:.4} cm³ ({:+.3e} of 1.5x rest) at {last_pressure:.1} Pa; \
         tip {:.3} mm; from 0.5 s on, the volume within {worst:.2e} of the pumped one",
        rest * 1e6,
        last_volume * 1e6,
        last_volume / (1.5 * rest) - 1.0,
        tip.last().unwrap().1 * 1e3
    );
    assert!(worst < 1e-5, "{worst:e}");
    assert!(last_pressure > 0.0 && tip.last().unwrap().1 < 0.0);
}
