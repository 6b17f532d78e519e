//! A scene whose soft bodies would not fit in memory is refused with its estimate,
//! by the checker for generated meshes and by the build for mesh files, before anything is
//! allocated for them; and the estimates count what the generators make.

use rapier_fvm::glamx::DVec3;
use rapier_fvm::mesh::{self, QuadraticHexMesh, QuadraticTetMesh, TetMesh};
use rapier_fvm_runner::scene::budget::{self, BudgetOrigin, MeshCount};
use rapier_fvm_runner::scene::mesh::MeshSpec;
use rapier_fvm_runner::scene::soft_body::ElementsSpec;
use rapier_fvm_runner::scene::{MemoryBudget, Scene, SceneError};
use rapier_fvm_runner::sim::{self, RunOptions};
use std::path::Path;

mod common;

use common::{rapier_fvm, scratch};

/// A scene of one cube of `mesh` (a TOML inline table) and `extra` lines in its soft body.
fn scene(mesh: &str, extra: &str) -> String {
    format!(
        "[world]\nduration = 0.02\n\n[[soft_body]]\nname = \"block\"\nmesh = {mesh}\n{extra}\
         material = {{ model = \"stable_neo_hookean\", young = 1e5, poisson = 0.3, density = 1000.0 }}\n"
    )
}

fn cuboid(cells: [usize; 3]) -> String {
    format!("{{ cuboid = {{ half_extents = [0.05, 0.05, 0.05], cells = {cells:?} }} }}")
}

fn refused(result: Result<Scene, SceneError>) -> SceneError {
    match result {
        Ok(_) => panic!("the scene should be refused"),
        Err(error) => error,
    }
}

#[test]
fn a_scene_of_1500_cubed_cells_is_refused_with_its_estimate() {
    let error = refused(Scene::parse("big.toml", scene(&cuboid([1500; 3]), "")));
    let message = error.to_string();
    assert!(
        message.starts_with("big.toml:6: soft_body[0].mesh: "),
        "{message}"
    );
    // 1501³ nodes and 5 · 1500³ tetrahedra, about 29.5 TB.
    assert!(
        message.contains("3381754501 nodes, 16875000000 tetrahedra"),
        "{message}"
    );
    assert!(message.contains("29548.156 GB"), "{message}");
    assert!(message.contains("--memory-limit"), "{message}");
}

#[test]
fn a_given_budget_refuses_what_exceeds_it_and_accepts_what_fits() {
    // 20³ cells: 9 261 nodes and 40 000 tetrahedra, 20 + 50 + 23.2 = 93.2 MB.
    let text = scene(&cuboid([20; 3]), "");
    let error = refused(Scene::parse_within(
        "b.toml",
        text.clone(),
        MemoryBudget::given(90e6),
    ));
    let message = error.to_string();
    assert!(
        message.contains("about 0.093 GB (9261 nodes, 40000 tetrahedra)"),
        "{message}"
    );
    assert!(
        message.contains("the 0.090 GB allowed by --memory-limit"),
        "{message}"
    );
    assert!(Scene::parse_within("b.toml", text, MemoryBudget::given(95e6)).is_ok());
    // The bodies add up, and the one that takes the sum over the budget is named.
    let two = format!(
        "{}\n[[soft_body]]\nname = \"second\"\nmesh = {}\nmaterial = {{ model = \"linear\", \
         young = 1e5, poisson = 0.3, density = 1000.0 }}\n",
        scene(&cuboid([20; 3]), ""),
        cuboid([20; 3])
    );
    let error = refused(Scene::parse_within(
        "b.toml",
        two,
        MemoryBudget::given(150e6),
    ));
    assert_eq!(error.key.as_deref(), Some("soft_body[1].mesh"));
}

#[test]
fn an_embedded_mesh_counts_too() {
    let embedded = format!("embedded = {}\n", cuboid([40; 3]));
    let text = scene(&cuboid([2; 3]), &embedded);
    let error = refused(Scene::parse_within(
        "e.toml",
        text,
        MemoryBudget::given(200e6),
    ));
    assert_eq!(error.key.as_deref(), Some("soft_body[0].embedded"));
    assert!(
        error.message.contains("68948 nodes, 320040 tetrahedra"),
        "{}",
        error.message
    );
}

#[test]
fn a_mesh_file_is_counted_once_read_before_its_body_is_built() {
    // The checker cannot count a volume file without reading it: the run refuses it once read.
    // cube.node: 341 nodes, 1 140 tetrahedra, 20 + 1.43 + 0.85 = 22.3 MB.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/file_mesh.toml");
    let text = scene("{ file = \"../meshes/cube.node\" }", "");
    let scene = Scene::parse_within(&path, text, MemoryBudget::given(21e6)).unwrap();
    let options = RunOptions {
        out: Path::new(env!("CARGO_TARGET_TMPDIR")).join("memory_budget"),
        duration: None,
        progress: false,
    };
    let message = sim::run(&scene, &options).err().unwrap().to_string();
    assert!(
        message.contains("file_mesh.toml:6: soft_body[0].mesh: "),
        "{message}"
    );
    assert!(
        message.contains("about 0.022 GB (341 nodes, 1140 tetrahedra)"),
        "{message}"
    );
}

#[test]
fn the_estimates_count_what_the_generators_make() {
    let spec = |toml: &str| -> MeshSpec {
        let budget = MemoryBudget::given(1e12);
        let scene = Scene::parse_within("s.toml", scene(toml, ""), budget).unwrap();
        scene.soft_body[0].mesh.clone()
    };
    let count = |mesh: &TetMesh, hexahedra: usize| MeshCount::of(mesh, hexahedra);
    // Cuboids and cages exactly; quadratic tetrahedra exactly on cuboids.
    let box_spec = spec(&cuboid([3, 4, 5]));
    let linear = mesh::cuboid(DVec3::splat(0.05), [3, 4, 5]).unwrap();
    assert_eq!(
        budget::estimate_mesh(&box_spec, ElementsSpec::Linear),
        count(&linear, 0)
    );
    let quadratic = QuadraticTetMesh::from_linear(&linear).unwrap();
    let estimate = budget::estimate_mesh(&box_spec, ElementsSpec::Quadratic);
    assert_eq!(estimate, count(quadratic.subdivided(), 0));
    let cage = QuadraticHexMesh::cuboid(DVec3::splat(0.05), [3, 4, 5]).unwrap();
    let estimate = budget::estimate_mesh(&box_spec, ElementsSpec::QuadraticHex);
    assert_eq!(estimate, count(cage.subdivided(), cage.element_count()));
    // Cylinders and spheres, their quadratic versions included.
    let round = [
        (
            spec(
                "{ cylinder = { radius = 0.05, half_height = 0.1, cells_across = 8, cells_along = 6 } }",
            ),
            mesh::cylinder(0.05, 0.1, 8, 6).unwrap(),
        ),
        (
            spec(
                "{ cylinder = { radius = 0.05, half_height = 0.1, cells_across = 3, cells_along = 1 } }",
            ),
            mesh::cylinder(0.05, 0.1, 3, 1).unwrap(),
        ),
        (
            spec("{ sphere = { radius = 0.05, cells_across = 10 } }"),
            mesh::sphere(0.05, 10).unwrap(),
        ),
        (
            spec("{ sphere = { radius = 0.05, cells_across = 2 } }"),
            mesh::sphere(0.05, 2).unwrap(),
        ),
    ];
    for (spec, built) in round {
        let estimate = budget::estimate_mesh(&spec, ElementsSpec::Linear);
        assert_eq!(estimate, count(&built, 0), "{spec:?}");
        let quadratic = QuadraticTetMesh::from_linear(&built).unwrap();
        let estimate = budget::estimate_mesh(&spec, ElementsSpec::Quadratic);
        assert_eq!(estimate, count(quadratic.subdivided(), 0), "{spec:?}");
    }
    // A filled surface from above: its whole lattice, as if every cube fell inside.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/surface.toml");
    let text = scene(
        "{ file = \"../meshes/sphere.obj\", scale = 0.05, cells_across = 8 }",
        "",
    );
    let scene = Scene::parse_within(&path, text, MemoryBudget::given(1e12)).unwrap();
    let surface = &scene.soft_body[0].mesh;
    let filled = surface.build("mesh", &scene.source).unwrap().mesh;
    let estimate = budget::estimate_mesh(surface, ElementsSpec::Linear);
    let actual = count(&filled, 0);
    assert!(
        estimate.tets >= actual.tets && estimate.nodes >= actual.nodes,
        "{estimate:?}"
    );
    assert!(
        estimate.tets <= 4.0 * actual.tets,
        "{estimate:?} against {actual:?}"
    );
}

#[test]
fn the_memory_available_is_read_on_linux() {
    let budget = MemoryBudget::available();
    if cfg!(target_os = "linux") {
        assert_eq!(budget.origin, BudgetOrigin::Available);
        assert!(budget.bytes > 1e6, "{budget:?}");
    } else {
        assert_eq!(budget.bytes, budget::FALLBACK_BYTES);
    }
}

#[test]
fn run_refuses_a_scene_too_big_in_one_line_and_takes_a_limit() {
    let big = scratch(
        "memory_budget_cli",
        "big.toml",
        &scene(&cuboid([1500; 3]), ""),
    );
    let out = big.with_extension("out");
    let output = rapier_fvm(&["run", big.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("soft_body[0].mesh: the soft bodies would need about"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing was written");
    let small = scratch(
        "memory_budget_cli",
        "small.toml",
        &scene(&cuboid([20; 3]), ""),
    );
    let small = small.to_str().unwrap();
    for (limit, message) in [
        ("0.05", "the 0.050 GB allowed by --memory-limit"),
        ("nan", "--memory-limit must be a positive"),
    ] {
        let output = rapier_fvm(&[
            "run",
            small,
            "--out",
            out.to_str().unwrap(),
            "--memory-limit",
            limit,
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(message), "{stderr}");
    }
}
