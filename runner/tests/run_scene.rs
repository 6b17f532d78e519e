//! Running shipped scenes: every one parses and builds; a short run writes the report, the
//! ParaView series, the surfaces, the pictures and the plots; the `.vtu` read back matches the
//! body's state.

mod scenes;

use rapier_fvm::glamx::DVec3;
use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::{self, RunOptions, Simulation};
use scenes::{run_scene, scene_path};
use std::path::{Path, PathBuf};
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, Vtk};

/// A fresh output folder for `test`.
fn out_dir(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(test);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn every_shipped_scene_parses_and_builds() {
    let names = [
        "cantilever.toml",
        "cantilever_quadratic.toml",
        "cage_beam.toml",
        "drop.toml",
        "rigid_on_soft.toml",
        "grasp.toml",
        "soft_stack.toml",
        "hanging_rope.toml",
        "showcase.toml",
        "spinning_block.toml",
        "pneumatic_finger.toml",
        "tossed_bricks.toml",
    ];
    let folder = scene_path("");
    let mut found: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    found.sort();
    // The 2D scenes (tests/planar_scenes.rs).
    let planar = ["planar_drop.toml", "planar_rolling_disk.toml"];
    let mut expected: Vec<String> = (names.iter().chain(&planar))
        .map(|n| (*n).to_owned())
        .collect();
    expected.sort();
    assert_eq!(found, expected, "the scenes shipped");
    for name in names {
        let scene = Scene::load(scene_path(name)).unwrap_or_else(|e| panic!("{e}"));
        let simulation = Simulation::build(&scene).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(simulation.soft.len(), scene.soft_body.len(), "{name}");
        assert_eq!(simulation.probes.len(), scene.probe.len(), "{name}");
    }
}

/// The points and a named point field of a `.vtu` file.
fn read_vtu(path: &Path, field: &str) -> (Vec<f64>, Vec<f64>) {
    let vtk = Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("not an inline piece");
    };
    let numbers = |buffer: &IOBuffer| buffer.clone().cast_into::<f64>().expect("f64 data");
    let points = numbers(&piece.points);
    let values = piece
        .data
        .point
        .iter()
        .find_map(|attribute| match attribute {
            Attribute::DataArray(array) if array.name == field => Some(numbers(&array.data)),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no point field {field}"));
    (points, values)
}

#[test]
fn a_short_drop_writes_every_output_and_the_vtu_matches_the_body() {
    let scene = Scene::load(scene_path("drop.toml")).unwrap();
    let out = out_dir("short_drop");
    let options = RunOptions {
        out: out.clone(),
        duration: Some(0.1),
        progress: false,
    };
    let report = sim::run(&scene, &options).unwrap();
    assert_eq!(report.frames, 6);
    assert_eq!(report.soft_bodies[0].element_kind, "linear tetrahedra");
    assert_eq!(report.soft_bodies[0].elements, 1080);
    assert_eq!(report.soft_bodies[0].nodes, 343);
    assert_eq!(report.soft_bodies[0].embedded_tets, None);
    assert!(!report.stability.any_error && report.stability.final_state_finite);
    // report.json holds the same.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["scene"], "drop");
    assert_eq!(json["frames"], 6);
    assert_eq!(json["probes"][0]["values"].as_array().unwrap().len(), 7);
    assert!(json["ms_per_frame"].as_f64().unwrap() > 0.0);
    // Each frame's stepping time, summing to the stepping time, and the one body awake (the
    // cube falls for all six frames).
    let times = &report.frame_times;
    assert_eq!(times.ms.len(), 6);
    assert!(times.ms.iter().all(|&t| t > 0.0));
    let summed: f64 = times.ms.iter().sum();
    assert!((summed - 1e3 * report.stepping_time_s).abs() < 1e-6 * summed);
    assert_eq!(times.awake_soft_bodies, vec![1; 6]);
    assert_eq!(json["frame_times"]["ms"].as_array().unwrap().len(), 6);
    // Where the stepping went: the cube's steps, without rigid partners (only the fixed ground
    // is near it), and the detection of its contacts, each a part of the stepping (one thread
    // steps the lone cube at a time).
    let parts = times.parts.expect("a 3D run reports its parts");
    assert!(parts.soft_steps_s > 0.0 && parts.contact_detection_s > 0.0);
    assert_eq!(parts.implicit_with_rigid_partners_s, 0.0);
    assert_eq!(parts.explicit_with_rigid_partners_s, 0.0);
    assert!(parts.soft_steps_s + parts.contact_detection_s < report.stepping_time_s);
    assert!(
        json["frame_times"]["parts"]["contact_detection_s"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    // Saved frames 0, 3, 6: one .vtu each, an OBJ each, the index.
    let pvd = std::fs::read_to_string(out.join("paraview/drop.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3);
    for frame in 0..3 {
        assert!(out.join(format!("paraview/cube_{frame:05}.vtu")).is_file());
    }
    for frame in [0, 3, 6] {
        assert!(out.join(format!("obj/surface_{frame:05}.obj")).is_file());
    }
    // Pictures at the frames nearest 0, 0.3, 0.5 and 1.5 s, clamped to the 6 frames run.
    for file in [
        "view_00000.png",
        "stress_00000.png",
        "view_00006.png",
        "stress_00006.png",
    ] {
        let png = std::fs::read(out.join("pictures").join(file)).unwrap();
        assert_eq!(&png[1..4], b"PNG", "{file}");
    }
    for file in [
        "cube_centre_height_change.png",
        "ground_reaction.png",
        "stepping_time_per_frame.png",
    ] {
        assert!(out.join("plots").join(file).is_file(), "{file}");
    }

    // The last .vtu: one point per node, and the displacement of the node the probe follows
    // equals the probe's final value (read from the body's state after the last frame).
    let (points, displacement) = read_vtu(&out.join("paraview/cube_00002.vtu"), "displacement");
    assert_eq!(points.len(), 3 * 343);
    assert_eq!(displacement.len(), 3 * 343);
    let simulation = Simulation::build(&scene).unwrap();
    let body = &simulation.world.soft_bodies[simulation.soft[0].handle];
    let node = body.mesh().nearest_node(DVec3::ZERO) as usize;
    let probe = report.probes[0].final_value;
    assert!(probe < -0.04, "the cube fell: {probe}");
    assert!((displacement[3 * node + 1] - probe).abs() < 1e-12);
    // Displacements are the points less the rest positions.
    for (n, rest) in simulation.soft[0].rest.iter().enumerate() {
        for axis in 0..3 {
            let i = 3 * n + axis;
            assert!((points[i] - rest[axis] - displacement[i]).abs() < 1e-12);
        }
    }
}

#[test]
fn a_cage_reports_its_hexahedra_and_the_fine_mesh_it_carries() {
    // cage_beam.toml: 5 x 1 x 1 quadratic hexahedra (11 x 3 x 3 nodes) carrying 40 x 4 x 4
    // cells of five tetrahedra.
    let scene = Scene::load(scene_path("cage_beam.toml")).unwrap();
    let options = RunOptions {
        out: out_dir("short_cage"),
        duration: Some(0.05),
        progress: false,
    };
    let report = sim::run(&scene, &options).unwrap();
    let beam = &report.soft_bodies[0];
    assert_eq!(beam.element_kind, "quadratic hexahedra");
    assert_eq!(beam.elements, 5);
    assert_eq!(beam.nodes, 99);
    assert_eq!(beam.embedded_tets, Some(3200));
    assert!(!report.stability.any_error && report.stability.final_state_finite);
}

/// Runs `toml` (read as the shipped scene `{name}.toml`) for `duration` (s) into the fresh
/// folder `name`; returns the report as `report.json` holds it.
fn run_text(name: &str, toml: &str, duration: f64) -> serde_json::Value {
    let (_, out) = run_scene(name, toml, Some(duration));
    serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap()
}

/// The audit's flags of a soft body in `report.json`.
const FLAGS: [&str; 5] = [
    "energy_gained",
    "penetration",
    "crossing",
    "inverted_elements",
    "collapsed_elements",
];

#[test]
fn the_report_flags_a_cube_set_half_inside_the_ground_and_calls_it_unstable() {
    // A 10 cm cube whose centre is 1 cm above a fixed ground: its bottom 4 cm lie inside, far
    // deeper than the audit's tolerance (a quarter of the 1.67 cm cells' smallest altitude).
    let text = std::fs::read_to_string(scene_path("drop.toml"))
        .unwrap()
        .replace(
            "translation = [0.0, 0.55, 0.0]",
            "translation = [0.0, 0.01, 0.0]",
        );
    let report = run_text("half_inside", &text, 0.05);
    let cube = &report["soft_bodies"][0];
    let penetration = &cube["stability_flags"]["penetration"];
    assert_eq!(penetration["first_frame"], 1);
    assert_eq!(penetration["unit"], "m");
    // The deepest point lies about 4 cm deep and is pushed out by at most 0.1 m/s.
    let worst = penetration["worst"].as_f64().unwrap();
    assert!(worst > 0.03 && worst <= 0.04 + 1e-6, "{worst}");
    assert_eq!(cube["stable"], false);
    assert_eq!(report["stability"]["stable"], false);
    assert_eq!(report["stability"]["unstable_bodies"][0], "cube");
}

#[test]
fn a_short_drop_reports_every_flag_and_a_verdict_that_follows_them() {
    let text = std::fs::read_to_string(scene_path("drop.toml")).unwrap();
    let report = run_text("drop_flags", &text, 0.1);
    let cube = &report["soft_bodies"][0];
    let flags = cube["stability_flags"].as_object().unwrap();
    let mut keys: Vec<&str> = flags.keys().map(String::as_str).collect();
    keys.sort_unstable();
    let mut expected = FLAGS.to_vec();
    expected.sort_unstable();
    assert_eq!(keys, expected);
    // The cube falls freely for the whole 0.1 s (it starts 0.5 m up): nothing may be raised.
    assert!(flags.values().all(serde_json::Value::is_null), "{flags:?}");
    assert_eq!(cube["stable"], true);
    assert_eq!(report["stability"]["stable"], true);
    assert!(report["stability"]["system_energy_gained"].is_null());
}
