//! The crate's errors as Python exceptions, with the same messages.
//!
//! `rapier_fvm.Error` (a `ValueError`) is what the library refuses: a mesh, material, setting
//! or state, or a step that failed; `rapier_fvm.SceneError` (a subclass) is a scene file that
//! cannot be read, naming the file, line and key as `rapier-fvm run` does. Arguments of the
//! wrong shape or kind raise `ValueError`/`TypeError` naming the argument, and a handle this
//! world holds no body or collider for raises `KeyError`. Handles are indices into a world's
//! sets, as rapier's are: a handle of another world names whatever this world holds there.

use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::{PyErr, create_exception};

create_exception!(
    rapier_fvm,
    Error,
    PyValueError,
    "What rapier_fvm refuses: invalid meshes, materials, settings or states, failed steps."
);
create_exception!(
    rapier_fvm,
    SceneError,
    Error,
    "A scene file that cannot be read or built, naming its file, line and key."
);

/// The library's error as a `rapier_fvm.Error`.
pub fn library(error: rapier_fvm::Error) -> PyErr {
    Error::new_err(error.to_string())
}

/// A scene's error as a `rapier_fvm.SceneError`.
pub fn scene(error: impl std::fmt::Display) -> PyErr {
    SceneError::new_err(error.to_string())
}

/// A `ValueError` naming the argument `name`.
pub fn argument(name: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {message}"))
}

/// A `KeyError` for a handle this world does not hold.
pub fn unknown(kind: &str, handle: impl std::fmt::Debug) -> PyErr {
    PyKeyError::new_err(format!("no {kind} {handle:?} in this world"))
}
