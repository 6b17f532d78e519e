//! # `rapier_fvm._native`
//!
//! The Python module of `rapier_fvm` (the package `rapier_fvm` re-exports it): worlds of rigid
//! and soft bodies built body by body or read from scene files, stepped with the GIL released,
//! read and driven through numpy arrays, saved and restored bit for bit; scene runs as
//! `rapier-fvm run` does them. SI units throughout (m, s, kg, Pa, N).
//!
//! One module per concept: `model` (materials, meshes, shapes), `world` (a world and its steps), `state`
//! (saved, restored and pickled), `rigid` and `soft` (bodies of each kind), `loads` (loads on soft
//! bodies), `scene` (scene files and runs), `overrides` (a scene's values set at key paths),
//! `handles`, `arrays` (numpy in and out) and `errors` (the library's errors as Python
//! exceptions).

mod arrays;
mod errors;
mod handles;
mod loads;
mod model;
mod overrides;
mod rigid;
mod scene;
mod soft;
mod state;
mod world;

use pyo3::prelude::*;

/// The module `rapier_fvm._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<errors::Error>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add_class::<model::Material>()?;
    m.add_class::<model::Mesh>()?;
    m.add_class::<model::Shape>()?;
    m.add_class::<handles::SoftBody>()?;
    m.add_class::<handles::RigidBody>()?;
    m.add_class::<handles::Collider>()?;
    m.add_class::<world::World>()?;
    m.add_function(wrap_pyfunction!(scene::run_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene::advise, m)?)?;
    m.add_function(wrap_pyfunction!(state::_unpickle_world, m)?)?;
    Ok(())
}
