//! A mesh file's regions (Gmsh physical groups) in scenes: a body pinned by its physical surface
//! runs as the same body pinned by the equivalent box, each volume of a file can be a body of
//! its own, and a region the file does not have is refused at its key with the file's regions.

mod scenes;

use rapier_fvm_runner::scene::{Scene, SceneError};
use rapier_fvm_runner::sim::{self, Simulation};
use scenes::{run_scene, scene_path};

/// A 10 cm cube read from gmsh's `cube_regions_v22.msh` (its face x = 0 the surface group
/// "clamp", tag 1), hanging from that face under gravity and sagging; `pinned` selects the face.
fn hanging_cube(pinned: &str, elements: &str) -> String {
    format!(
        r#"name = "hanging"

[world]
duration = 0.15

[[soft_body]]
name = "cube"
mesh = {{ file = "../meshes/cube_regions_v22.msh", scale = 0.1 }}
material = {{ model = "stable_neo_hookean", young = 2e4, poisson = 0.3, density = 1000.0 }}
damping = {{ stiffness_time = 2e-3 }}
elements = "{elements}"
pinned = [{pinned}]

[[probe]]
name = "sag"
kind = "displacement"
body = "cube"
point = [0.1, 0.0, 0.05]
component = "y"
"#
    )
}

#[test]
fn a_body_pinned_by_its_physical_surface_runs_as_one_pinned_by_the_same_box() {
    // The box around x = 0 (the cube spans [0, 0.1] m) holds exactly the clamp's nodes, so the
    // two runs must agree to the bit, for linear and for quadratic tetrahedra (whose clamp
    // takes the face's mid-edge nodes too). The cube sags by millimetres: the pins hold.
    let the_box = "{ min = [-0.001, -1.0, -1.0], max = [0.001, 1.0, 1.0] }";
    for elements in ["linear", "quadratic"] {
        let by_region = run_scene(
            &format!("pinned_by_region_{elements}"),
            &hanging_cube(r#"{ region = "clamp" }"#, elements),
            None,
        )
        .0;
        let by_tag = run_scene(
            &format!("pinned_by_tag_{elements}"),
            &hanging_cube("{ region = 1 }", elements),
            None,
        )
        .0;
        let by_box = run_scene(
            &format!("pinned_by_box_{elements}"),
            &hanging_cube(the_box, elements),
            None,
        )
        .0;
        let sag = |report: &sim::Report| report.probes[0].values.clone();
        assert_eq!(sag(&by_region), sag(&by_box), "{elements}");
        assert_eq!(sag(&by_tag), sag(&by_box), "{elements}");
        let last = by_box.probes[0].final_value;
        assert!(last < -1e-4 && last > -0.05, "{elements}: sag {last} m");
        assert!(by_region.stability.stable, "{elements}");
    }
}

#[test]
fn each_volume_of_a_file_becomes_a_body_of_its_own() {
    // Two unit boxes side by side in one gmsh file, scaled to 10 cm: "left" and "right" as two
    // bodies, the left pinned by the file's "clamp", the right given a velocity by its "load".
    let text = r#"name = "two"

[world]
duration = 0.02

[[soft_body]]
name = "left"
mesh = { file = "../meshes/two_volumes_v41.msh", scale = 0.1, region = "left" }
material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
pinned = [{ region = "clamp" }]

[[soft_body]]
name = "right"
mesh = { file = "../meshes/two_volumes_v41.msh", scale = 0.1, region = 2 }
material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
velocity = [{ region = "load", linvel = [0.0, 0.0, 0.1] }]
"#;
    let scene = Scene::parse(scene_path("two_volumes.toml"), text.to_owned()).unwrap();
    let simulation = Simulation::build(&scene).unwrap_or_else(|e| panic!("{e}"));
    let whole = rapier_fvm::mesh::import::load(
        scene_path("x").with_file_name("../meshes/two_volumes_v41.msh"),
        0.1,
        &Default::default(),
    )
    .unwrap();
    let mut tets = 0;
    for (entry, side) in simulation.soft.iter().zip([0.0, 0.1]) {
        let body = &simulation.world.soft_bodies[entry.handle];
        tets += body.mesh().tet_count();
        let volume = body.mesh().volume();
        assert!(
            (volume - 1e-3).abs() < 1e-15,
            "{}: {volume} m^3",
            entry.name
        );
        for p in &entry.rest {
            assert!(
                p.x >= side - 1e-12 && p.x <= side + 0.1 + 1e-12,
                "{}",
                entry.name
            );
        }
    }
    assert_eq!(tets, whole.tet_count());
}

/// The error of building `text`.
fn build_error(text: String) -> SceneError {
    let scene = Scene::parse(scene_path("bad_region.toml"), text).unwrap();
    match Simulation::build(&scene) {
        Ok(_) => panic!("the scene should be refused"),
        Err(error) => error,
    }
}

#[test]
fn a_region_the_file_lacks_is_refused_at_its_key_with_the_file_s_regions() {
    let error = build_error(hanging_cube(r#"{ region = "lid" }"#, "linear"));
    assert_eq!(error.key.as_deref(), Some("soft_body[0].pinned[0].region"));
    assert_eq!(error.line, Some(12));
    assert!(
        error.message.ends_with(
            "cube_regions_v22.msh: region \"lid\": the file's regions are \"clamp\" (surface, \
             tag 1), \"body\" (volume, tag 2)"
        ),
        "{error}"
    );
    // A surface is not a body.
    let text = hanging_cube(r#"{ region = "clamp" }"#, "linear")
        .replace("scale = 0.1 }", r#"scale = 0.1, region = "clamp" }"#);
    let error = build_error(text);
    assert_eq!(error.key.as_deref(), Some("soft_body[0].mesh.region"));
    assert!(
        error.message.ends_with("is not a volume of tetrahedra"),
        "{error}"
    );
    // A generator's mesh has no regions: refused when the scene is read.
    let text = hanging_cube(r#"{ region = "clamp" }"#, "linear").replace(
        r#"{ file = "../meshes/cube_regions_v22.msh", scale = 0.1 }"#,
        "{ cuboid = { half_extents = [0.05, 0.05, 0.05], cells = [2, 2, 2] } }",
    );
    let error = Scene::parse(scene_path("generator.toml"), text).unwrap_err();
    assert_eq!(error.key.as_deref(), Some("soft_body[0].mesh"));
    assert!(error.message.contains("this mesh is not a file"), "{error}");
    // A box and a region at once, or half a box.
    for pinned in [
        r#"{ region = "clamp", min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }"#,
        "{ min = [0.0, 0.0, 0.0] }",
    ] {
        let error =
            Scene::parse(scene_path("both.toml"), hanging_cube(pinned, "linear")).unwrap_err();
        assert_eq!(
            error.key.as_deref(),
            Some("soft_body[0].pinned[0]"),
            "{pinned}"
        );
    }
}

#[test]
fn a_vtu_file_s_cell_tags_select_as_the_gmsh_file_s_regions() {
    // meshio's VTU of the same two boxes keeps the physical tags as cell data, without names:
    // by tag, the left box is a body of its own pinned by its clamp (tag 3, the 44 nodes at
    // x = 0), the right one another, as from the gmsh file.
    let text = r#"name = "two_vtu"

[world]
duration = 0.02

[[soft_body]]
name = "left"
mesh = { file = "../meshes/two_volumes_meshio.vtu", scale = 0.1, region = 1 }
material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
pinned = [{ region = 3 }]

[[soft_body]]
name = "right"
mesh = { file = "../meshes/two_volumes_meshio.vtu", scale = 0.1, region = 2 }
material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
velocity = [{ region = 4, linvel = [0.0, 0.0, 0.1] }]
"#;
    let scene = Scene::parse(scene_path("two_volumes_vtu.toml"), text.to_owned()).unwrap();
    let simulation = Simulation::build(&scene).unwrap_or_else(|e| panic!("{e}"));
    let left = &simulation.world.soft_bodies[simulation.soft[0].handle];
    let right = &simulation.world.soft_bodies[simulation.soft[1].handle];
    for body in [left, right] {
        assert!((body.mesh().volume() - 1e-3).abs() < 1e-15);
    }
    let pinned: Vec<usize> = (0..left.node_count())
        .filter(|&n| left.is_pinned(n))
        .collect();
    assert_eq!(pinned.len(), 44);
    assert!(pinned.iter().all(|&n| left.positions()[n].x.abs() < 1e-12));
    assert_eq!(left.mesh().tet_count() + right.mesh().tet_count(), 1455);
}

/// A 10 x 5 x 2.5 cm block of 4 x 3 x 2 hexahedra (gmsh's `box_hex27_v41.msh` or
/// `box_hex8_v41.msh` at a scale of 0.1, its face x = 0 the surface group "clamp") as a cage, hanging from that face
/// under gravity; `mesh` is the mesh's table, `pinned` selects the face, `end` is the middle of
/// the free end in the mesh's coordinates.
fn hanging_cage(mesh: &str, pinned: &str, end: [f64; 3]) -> String {
    format!(
        r#"name = "hanging_cage"

[world]
duration = 0.1

[[soft_body]]
name = "block"
mesh = {mesh}
material = {{ model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }}
damping = {{ stiffness_time = 2e-3 }}
elements = "quadratic_hex"
pinned = [{pinned}]

[[probe]]
name = "sag"
kind = "displacement"
body = "block"
point = {end:?}
component = "y"
"#
    )
}

#[test]
fn a_cage_read_from_a_file_hangs_from_its_physical_surface_as_the_generated_cage() {
    // The file's clamp and the box around x = 0 select the same nodes: the same run to the bit.
    // The generator's cage of the same cells, moved onto the file's box, has the same elements
    // numbered otherwise (and another subdivision, which only contacts and output use): the
    // same sag up to the rounding of sums taken in another order (1e-9 relative).
    // The same for the file of linear hexahedra, given their edge, face and centre nodes (the
    // clamp widened to those of its face).
    let the_box = "{ min = [-0.001, -1.0, -1.0], max = [0.001, 1.0, 1.0] }";
    let end = [0.1, 0.025, 0.0125];
    let clamp = r#"{ region = "clamp" }"#;
    let mut read = Vec::new();
    for nodes in [27, 8] {
        let file = format!(r#"{{ file = "../meshes/box_hex{nodes}_v41.msh", scale = 0.1 }}"#);
        let by_region = run_scene(
            &format!("cage{nodes}_by_region"),
            &hanging_cage(&file, clamp, end),
            None,
        )
        .0;
        let by_box = run_scene(
            &format!("cage{nodes}_by_box"),
            &hanging_cage(&file, the_box, end),
            None,
        )
        .0;
        let sag = |report: &sim::Report| report.probes[0].values.clone();
        assert_eq!(sag(&by_region), sag(&by_box), "{nodes}-node hexahedra");
        assert!(by_region.stability.stable);
        read.push(by_box.probes[0].final_value);
    }
    // The generator's box is centred at the origin: moved by half its size onto the file's.
    let cuboid = r#"{ cuboid = { half_extents = [0.05, 0.025, 0.0125], cells = [4, 3, 2] } }"#;
    let centred_box = "{ min = [-0.051, -1.0, -1.0], max = [-0.049, 1.0, 1.0] }";
    let generated = hanging_cage(cuboid, centred_box, [0.05, 0.0, 0.0]).replace(
        "elements = \"quadratic_hex\"",
        "elements = \"quadratic_hex\"\ntranslation = [0.05, 0.025, 0.0125]",
    );
    let generated = run_scene("cage_generated", &generated, None).0;
    let made = generated.probes[0].final_value;
    for (read, nodes) in read.into_iter().zip([27, 8]) {
        println!("cage sag after 0.1 s: {nodes}-node file {read:.9e} m, generator {made:.9e} m");
        assert!(read < -1e-4 && read > -0.05, "sag {read} m");
        assert!(
            (read / made - 1.0).abs() < 1e-9,
            "file {read}, generator {made}"
        );
    }
}
