//! Region materials in scenes: a mesh file's volume group or a box of element centroids given
//! its own Young's modulus and density, the same elements by either selection running to the
//! same bits, a cage file's volume group selecting its hexahedra, and the refusals at their keys.

mod scenes;

use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::{self, Simulation};
use scenes::{run_scene, scene_path};

/// gmsh's two 10 cm boxes side by side (`two_volumes_v41.msh` scaled by 0.1: volumes "left",
/// x in [0, 0.1] m, and "right") as one body hanging from its "clamp" face x = 0, the right box
/// given `materials`.
fn two_boxes(materials: &str) -> String {
    format!(
        r#"name = "two_materials"

[world]
duration = 0.05

[[soft_body]]
name = "bar"
mesh = {{ file = "../meshes/two_volumes_v41.msh", scale = 0.1 }}
material = {{ model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }}
damping = {{ stiffness_time = 2e-3 }}
materials = [{materials}]
pinned = [{{ region = "clamp" }}]

[[probe]]
name = "sag"
kind = "displacement"
body = "bar"
point = [0.2, 0.05, 0.05]
component = "y"
"#
    )
}

#[test]
fn a_file_s_volume_and_the_box_of_its_elements_give_the_same_material_run() {
    // The right box's elements are those whose centroid has x > 0.1 m: by its volume group
    // and by that box, the same elements take E = 4e5 Pa and 2500 kg/m³, so the runs agree to
    // the bit; the mass is the two boxes' 1e-3 m³ at their densities (1e-12), and the stiffer,
    // heavier right box sags otherwise than the uniform bar.
    let stiff = "young = 4e5, density = 2500.0";
    let by_region = two_boxes(&format!(r#"{{ region = "right", {stiff} }}"#));
    let by_box = two_boxes(&format!(
        "{{ min = [0.1, -1.0, -1.0], max = [1.0, 1.0, 1.0], {stiff} }}"
    ));
    let scene = Scene::parse(scene_path("two_materials.toml"), by_region.clone()).unwrap();
    let simulation = Simulation::build(&scene).unwrap_or_else(|e| panic!("{e}"));
    let body = &simulation.world.soft_bodies[simulation.soft[0].handle];
    let mass = body.total_mass();
    assert!((mass / 3.5 - 1.0).abs() < 1e-12, "mass {mass} kg");
    let (region, boxed) = (
        run_scene("by_region", &by_region, None).0,
        run_scene("by_box", &by_box, None).0,
    );
    let uniform = run_scene("uniform", &two_boxes(""), None).0;
    let sag = |report: &sim::Report| report.probes[0].values.clone();
    assert_eq!(sag(&region), sag(&boxed));
    let (mixed, plain) = (region.probes[0].final_value, uniform.probes[0].final_value);
    println!("end sag after 0.05 s: right box stiff {mixed:.6e} m, uniform {plain:.6e} m");
    assert!(region.stability.stable && mixed < 0.0 && plain < 0.0);
    assert!(
        (mixed / plain - 1.0).abs() > 0.05,
        "{mixed} against {plain}"
    );
}

/// gmsh's 10 x 5 x 2.5 cm block of hexahedra (`{file}` scaled by 0.1) as a cage hanging from
/// its face x = 0, of `young` (Pa) and `materials`.
fn hanging_cage(file: &str, young: f64, materials: &str) -> String {
    format!(
        r#"name = "cage_material"

[world]
duration = 0.05

[[soft_body]]
name = "block"
mesh = {{ file = "../meshes/{file}", scale = 0.1 }}
material = {{ model = "stable_neo_hookean", young = {young:e}, poisson = 0.3, density = 1000.0 }}
damping = {{ stiffness_time = 2e-3 }}
elements = "quadratic_hex"
materials = [{materials}]
pinned = [{{ min = [-0.001, -1.0, -1.0], max = [0.001, 1.0, 1.0] }}]

[[probe]]
name = "sag"
kind = "displacement"
body = "block"
point = [0.1, 0.025, 0.0125]
component = "y"
"#
    )
}

#[test]
fn a_cage_file_s_volume_group_selects_its_hexahedra() {
    // The volume group "block" lists the file's split tetrahedra; as a material's region on a
    // cage it selects the cage's hexahedra, all 24 of them: the block of E = 1e5 Pa given
    // E = 3e5 Pa by its group runs as the block of 3e5 Pa (the factor rounds otherwise than the
    // modulus: 1e-9 relative).
    for nodes in [27, 8] {
        let file = format!("box_hex{nodes}_v41.msh");
        let given = run_scene(
            &format!("cage{nodes}_given"),
            &hanging_cage(&file, 1e5, r#"{ region = "block", young = 3e5 }"#),
            None,
        )
        .0;
        let plain = run_scene(
            &format!("cage{nodes}_plain"),
            &hanging_cage(&file, 3e5, ""),
            None,
        )
        .0;
        let (a, b) = (given.probes[0].final_value, plain.probes[0].final_value);
        println!("{nodes}-node cage: sag {a:.9e} m given, {b:.9e} m plain");
        assert!(a < -1e-5 && (a / b - 1.0).abs() < 1e-9, "{a} against {b}");
    }
}

#[test]
fn a_cage_file_s_partial_volume_group_selects_its_own_hexahedra() {
    // gmsh's two blocks of 2 x 3 x 2 hexahedra side by side (`two_blocks_hex{8,27}_v41.msh`,
    // x < 5 cm "soft", x > 5 cm "stiff"): the group "stiff" and the box of the centroids
    // x > 5 cm give the same 12 hexahedra E = 1e6 Pa, so the runs agree to the bit, and the
    // stiff end sags otherwise than the uniform block.
    let stiff = "young = 1e6, density = 1000.0";
    for nodes in [27, 8] {
        let file = format!("two_blocks_hex{nodes}_v41.msh");
        let region = format!(r#"{{ region = "stiff", {stiff} }}"#);
        let boxed = format!("{{ min = [0.05, -1.0, -1.0], max = [1.0, 1.0, 1.0], {stiff} }}");
        let by_region = run_scene(
            &format!("blocks{nodes}_region"),
            &hanging_cage(&file, 1e5, &region),
            None,
        )
        .0;
        let by_box = run_scene(
            &format!("blocks{nodes}_box"),
            &hanging_cage(&file, 1e5, &boxed),
            None,
        )
        .0;
        let uniform = run_scene(
            &format!("blocks{nodes}_uniform"),
            &hanging_cage(&file, 1e5, ""),
            None,
        )
        .0;
        let sag = |report: &sim::Report| report.probes[0].values.clone();
        assert_eq!(sag(&by_region), sag(&by_box), "{nodes}-node hexahedra");
        let (mixed, plain) = (
            by_region.probes[0].final_value,
            uniform.probes[0].final_value,
        );
        println!(
            "{nodes}-node blocks: sag {mixed:.6e} m with the stiff end, {plain:.6e} m uniform"
        );
        assert!(
            mixed < 0.0 && (mixed / plain - 1.0).abs() > 0.05,
            "{mixed} against {plain}"
        );
    }
}

#[test]
fn a_material_region_that_selects_no_element_is_refused_at_its_key() {
    let build_error = |materials: &str| {
        let scene = Scene::parse(scene_path("bad.toml"), two_boxes(materials)).unwrap();
        match Simulation::build(&scene) {
            Ok(_) => panic!("{materials}: the scene should be refused"),
            Err(error) => error,
        }
    };
    let surface = build_error(r#"{ region = "clamp", young = 2e5 }"#);
    assert_eq!(surface.key.as_deref(), Some("soft_body[0].materials[0]"));
    assert!(
        surface
            .message
            .contains("the region holds no volume element"),
        "{surface}"
    );
    let empty = build_error("{ min = [5.0, 5.0, 5.0], max = [6.0, 6.0, 6.0], young = 2e5 }");
    assert_eq!(empty.key.as_deref(), Some("soft_body[0].materials[0]"));
    assert!(
        empty
            .message
            .contains("the box holds no element's centroid"),
        "{empty}"
    );
    let missing = build_error(r#"{ region = "lid", young = 2e5 }"#);
    assert_eq!(
        missing.key.as_deref(),
        Some("soft_body[0].materials[0].region")
    );
    // Neither constant given: refused when the scene is read.
    let error =
        Scene::parse(scene_path("bad.toml"), two_boxes(r#"{ region = "right" }"#)).unwrap_err();
    assert_eq!(error.key.as_deref(), Some("soft_body[0].materials[0]"));
    assert!(error.message.contains("give `young`"), "{error}");
    // Nodal averaging mixes elements in its patches: refused when the scene is read.
    let averaged = two_boxes(r#"{ region = "right", young = 2e5 }"#)
        .replace("pinned =", "volumetric = \"nodal_average\"\npinned =");
    let error = Scene::parse(scene_path("bad.toml"), averaged).unwrap_err();
    assert_eq!(error.key.as_deref(), Some("soft_body[0].materials"));
    assert!(error.message.contains("nodal_average"), "{error}");
}
