//! Every kind of scene error names the file, the key path and the line.

use rapier_fvm_runner::scene::{Scene, SceneError};

/// A valid scene; each test breaks one line of it.
const VALID: &str = r#"name = "test"

[world]
duration = 0.1
dt = 0.01

[[rigid_body]]
name = "ground"
kind = "fixed"
shape = { half_space = { normal = [0.0, 1.0, 0.0] } }

[[soft_body]]
name = "cube"
mesh = { cuboid = { half_extents = [0.05, 0.05, 0.05], cells = [2, 2, 2] } }
translation = [0.0, 0.1, 0.0]

[soft_body.material]
model = "stable_neo_hookean"
young = 1e5
poisson = 0.3
density = 1000.0

[[probe]]
name = "reaction"
kind = "contact_force"
rigid = "ground"
"#;

/// `VALID` with `from` replaced by `to` (which must occur once).
fn broken(from: &str, to: &str) -> String {
    assert_eq!(VALID.matches(from).count(), 1, "{from:?} must occur once");
    VALID.replace(from, to)
}

/// The error of parsing `text` as `scenes/bad.toml`.
fn error(text: String) -> SceneError {
    match Scene::parse("scenes/bad.toml", text) {
        Ok(_) => panic!("the scene should be refused"),
        Err(error) => error,
    }
}

/// Asserts the message names the file, the line and the key, and mentions `words`.
fn assert_names(error: &SceneError, line: usize, key: &str, words: &str) {
    let message = error.to_string();
    assert!(
        message.starts_with(&format!("scenes/bad.toml:{line}: ")),
        "file and line {line} in {message:?}"
    );
    assert!(message.contains(key), "key {key} in {message:?}");
    assert!(message.contains(words), "{words:?} in {message:?}");
    assert_eq!(error.line, Some(line));
    assert!(!message.contains('\n'), "one line: {message:?}");
}

#[test]
fn the_valid_scene_parses() {
    let scene = Scene::parse("scenes/ok.toml", VALID.to_owned()).unwrap();
    assert_eq!(scene.soft_body[0].material.young, 1e5);
    assert_eq!(scene.world.frames(), 10);
}

#[test]
fn an_unknown_key_is_named_with_its_line() {
    let e = error(broken("young = 1e5", "yuong = 1e5"));
    assert_names(
        &e,
        19,
        "soft_body[0].material.yuong",
        "unknown field `yuong`",
    );
}

#[test]
fn a_missing_key_is_named_at_its_table() {
    let e = error(broken("density = 1000.0\n", ""));
    assert_names(&e, 17, "soft_body[0].material", "missing field `density`");
}

#[test]
fn a_wrong_type_is_named_with_its_line() {
    let e = error(broken("young = 1e5", "young = \"stiff\""));
    assert_names(&e, 19, "soft_body[0].material.young", "invalid type");
}

#[test]
fn an_unknown_model_is_named_with_the_models_known() {
    let e = error(broken("\"stable_neo_hookean\"", "\"neo_hookean\""));
    assert_names(&e, 18, "soft_body[0].material.model", "stable_neo_hookean");
}

#[test]
fn a_negative_young_modulus_is_refused() {
    let e = error(broken("young = 1e5", "young = -1e5"));
    assert_names(&e, 19, "soft_body[0].material.young", "positive");
}

#[test]
fn a_poisson_ratio_of_one_half_is_refused() {
    let e = error(broken("poisson = 0.3", "poisson = 0.5"));
    assert_names(&e, 20, "soft_body[0].material.poisson", "(-1, 0.5)");
}

#[test]
fn a_time_step_that_underflows_rapiers_f32_step_is_refused() {
    // 1e-46 s is a positive f64 but rounds to zero in rapier's f32 step: every frame would be a
    // pause.
    let e = error(broken("dt = 0.01", "dt = 1e-46"));
    assert_names(&e, 5, "world.dt", "not a positive f32 step");
}

#[test]
fn a_zero_time_step_is_refused() {
    let e = error(broken("dt = 0.01", "dt = 0.0"));
    assert_names(&e, 5, "world.dt", "positive");
}

#[test]
fn a_probe_on_a_missing_body_is_refused() {
    let e = error(broken("rigid = \"ground\"", "rigid = \"floor\""));
    assert_names(&e, 26, "probe[0].rigid", "no rigid body is named \"floor\"");
}

#[test]
fn an_attachment_to_a_missing_body_is_refused() {
    let e = error(broken(
        "translation = [0.0, 0.1, 0.0]",
        "translation = [0.0, 0.1, 0.0]\nattach = [{ rigid = \"hook\", min = [-1, -1, -1], max = [1, 1, 1] }]",
    ));
    assert_names(&e, 16, "soft_body[0].attach[0].rigid", "\"hook\"");
}

/// `VALID` with `key` added to the soft body, on line 16.
fn with_soft_body_key(key: &str) -> String {
    broken(
        "translation = [0.0, 0.1, 0.0]",
        &format!("translation = [0.0, 0.1, 0.0]\n{key}"),
    )
}

#[test]
fn a_non_finite_angular_velocity_is_refused() {
    let e = error(with_soft_body_key("angvel = [nan, 0.0, 0.0]"));
    assert_names(&e, 16, "soft_body[0].angvel", "must be finite");
}

#[test]
fn an_angular_velocity_of_the_wrong_length_is_refused() {
    let e = error(with_soft_body_key("angvel = [0.0, 3.0]"));
    assert_names(
        &e,
        16,
        "soft_body[0].angvel",
        "expected an array of length 3",
    );
}

#[test]
fn a_region_velocity_faster_than_light_is_refused() {
    let e = error(with_soft_body_key(
        "velocity = [{ min = [-1, -1, -1], max = [1, 1, 1], linvel = [4e8, 0, 0] }]",
    ));
    assert_names(
        &e,
        16,
        "soft_body[0].velocity[0].linvel",
        "faster than light",
    );
}

#[test]
fn a_region_velocity_box_upside_down_is_refused() {
    let e = error(with_soft_body_key(
        "velocity = [{ min = [1, -1, -1], max = [-1, 1, 1], linvel = [1, 0, 0] }]",
    ));
    assert_names(&e, 16, "soft_body[0].velocity[0].max", "below min");
}

#[test]
fn a_region_velocity_without_its_velocity_is_refused() {
    let e = error(with_soft_body_key(
        "velocity = [{ min = [-1, -1, -1], max = [1, 1, 1] }]",
    ));
    assert_names(&e, 16, "soft_body[0].velocity[0]", "missing field `linvel`");
}

#[test]
fn an_angular_velocity_for_a_region_is_refused_as_unknown() {
    let e = error(with_soft_body_key(
        "velocity = [{ min = [-1, -1, -1], max = [1, 1, 1], linvel = [1, 0, 0], angvel = [0, 0, 1] }]",
    ));
    assert_names(
        &e,
        16,
        "soft_body[0].velocity[0].angvel",
        "unknown field `angvel`",
    );
}

#[test]
fn a_region_velocity_box_holding_no_node_is_refused_when_built() {
    let text = with_soft_body_key(
        "velocity = [{ min = [0.5, 0.5, 0.5], max = [1, 1, 1], linvel = [1, 0, 0] }]",
    );
    let scene = Scene::parse("scenes/bad.toml", text).unwrap();
    let e = match rapier_fvm_runner::sim::Simulation::build(&scene) {
        Ok(_) => panic!("the empty box should be refused"),
        Err(e) => e,
    };
    assert_names(&e, 16, "soft_body[0].velocity[0]", "holds no node");
}

#[test]
fn a_momentum_probe_takes_no_rigid_body() {
    let e = error(broken(
        "kind = \"contact_force\"",
        "kind = \"angular_momentum\"",
    ));
    assert_names(&e, 26, "probe[0].rigid", "takes no `rigid`");
    let e = error(broken("kind = \"contact_force\"", "kind = \"momentum\""));
    assert_names(&e, 26, "probe[0].rigid", "takes no `rigid`");
}

#[test]
fn a_contact_force_on_soft_probe_needs_its_soft_body() {
    let e = error(broken(
        "kind = \"contact_force\"",
        "kind = \"contact_force_on_soft\"",
    ));
    assert_names(&e, 23, "probe[0]", "needs `body`");
    let e = error(broken(
        "kind = \"contact_force\"",
        "kind = \"contact_force_on_soft\"\nbody = \"ball\"",
    ));
    assert_names(&e, 26, "probe[0].body", "no soft body is named \"ball\"");
}

#[test]
fn two_mesh_sources_are_refused() {
    let e = error(broken(
        "cells = [2, 2, 2] } }",
        "cells = [2, 2, 2] }, sphere = { radius = 0.1, cells_across = 4 } }",
    ));
    assert_names(&e, 14, "soft_body[0].mesh", "exactly one");
}

#[test]
fn a_toml_syntax_error_gives_its_line() {
    let e = error(broken("duration = 0.1", "duration = "));
    assert_eq!(e.line, Some(4), "{e}");
    assert!(e.to_string().starts_with("scenes/bad.toml:4: "), "{e}");
}

#[test]
fn a_missing_mesh_file_is_named_at_its_key() {
    let scene = Scene::parse(
        "scenes/bad.toml",
        broken(
            "{ cuboid = { half_extents = [0.05, 0.05, 0.05], cells = [2, 2, 2] } }",
            "{ file = \"missing.msh\" }",
        ),
    )
    .unwrap();
    let e = match rapier_fvm_runner::sim::Simulation::build(&scene) {
        Ok(_) => panic!("the missing mesh should be refused"),
        Err(e) => e,
    };
    assert_names(&e, 14, "soft_body[0].mesh.file", "missing.msh");
}

#[test]
fn a_missing_scene_file_names_the_file() {
    let e = Scene::load("scenes/no_such_scene.toml").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("scenes/no_such_scene.toml: cannot read"),
        "{e}"
    );
}

#[test]
fn a_cost_model_table_sets_the_automatic_choices_costs() {
    let text =
        format!("{VALID}\n[integrator.cost]\nnewton_tet = 2.5e-6\nexplicit_damped_factor = 1.5\n");
    let scene = Scene::parse("scenes/ok.toml", text).unwrap();
    let cost = scene.integrator.integrator().cost;
    assert_eq!(cost.newton_tet, 2.5e-6);
    assert_eq!(cost.explicit_damped_factor, 1.5);
    let default = rapier_fvm::integrate::CostModel::default();
    assert_eq!(
        cost.explicit_tet, default.explicit_tet,
        "unset keys keep the default"
    );
}

#[test]
fn a_negative_cost_is_refused() {
    let line = VALID.lines().count() + 3;
    let e = error(format!("{VALID}\n[integrator.cost]\nnewton_tet = -1e-6\n"));
    assert_names(&e, line, "integrator.cost.newton_tet", "positive");
}

#[test]
fn a_damping_cost_factor_below_one_is_refused() {
    let line = VALID.lines().count() + 3;
    let e = error(format!(
        "{VALID}\n[integrator.cost]\nexplicit_damped_factor = 0.5\n"
    ));
    assert_names(
        &e,
        line,
        "integrator.cost.explicit_damped_factor",
        "at least 1",
    );
}

#[test]
fn a_vector_with_more_elements_than_its_key_takes_is_refused() {
    // Not truncated to its first three: refused at its line.
    let e = error(broken(
        "dt = 0.01",
        "dt = 0.01\ngravity = [0.0, -9.81, 0.0, 7.0]",
    ));
    assert_names(&e, 6, "world.gravity", "more than the key takes");
    let e = error(with_soft_body_key("angvel = [0.0, 3.0, 0.0, 1.0]"));
    assert_names(&e, 16, "soft_body[0].angvel", "more than the key takes");
}

#[test]
fn a_stand_in_tolerance_out_of_range_is_named_with_its_line() {
    for bad in ["0.0", "1.5", "-1e-3"] {
        let e = error(broken(
            "translation = [0.0, 0.1, 0.0]",
            &format!("translation = [0.0, 0.1, 0.0]\nrigid_stand_in = {bad}"),
        ));
        assert_names(&e, 16, "soft_body[0].rigid_stand_in", "must lie in (0, 1)");
    }
}
