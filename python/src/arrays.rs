//! Arrays across the boundary: node vectors out as `(n, 3)` float64 numpy arrays, index lists
//! as `(n, k)` uint32 arrays, and arrays in checked for shape and finiteness.
//!
//! Out, each array is built from one pass over the state into memory numpy then owns (no
//! further copy): a view into the world would change under the caller's feet at the next step
//! and dangle when a body set reallocates, so values are handed over, not borrowed.

use crate::errors::argument;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use rapier_fvm::glamx::DVec3;

/// `vectors` as an `(n, 3)` float64 array.
pub fn vectors_out<'py>(py: Python<'py>, vectors: &[DVec3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = vectors.iter().flat_map(|v| v.to_array()).collect();
    rows_out(py, flat, 3)
}

/// `flat` (row-major, `columns` per row) as an `(n, columns)` array.
pub fn rows_out<T: numpy::Element>(
    py: Python<'_>,
    flat: Vec<T>,
    columns: usize,
) -> Bound<'_, PyArray2<T>> {
    let rows = flat.len() / columns.max(1);
    Array2::from_shape_vec((rows, columns), flat)
        .expect("the rows are whole by construction")
        .into_pyarray(py)
}

/// `values` as a one-dimensional array.
pub fn vector_out<T: numpy::Element>(py: Python<'_>, values: Vec<T>) -> Bound<'_, PyArray1<T>> {
    values.into_pyarray(py)
}

/// The rows of the `(n, 3)` array `array` (argument `name`) as vectors, each finite.
///
/// # Errors
/// A `ValueError` naming `name` and the row for a wrong shape or a value that is not finite.
pub fn vectors_in(name: &str, array: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<DVec3>> {
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(argument(
            name,
            format!("expected an (n, 3) array, got {:?}", view.shape()),
        ));
    }
    (view.rows().into_iter().enumerate())
        .map(|(i, row)| {
            let v = DVec3::new(row[0], row[1], row[2]);
            if v.is_finite() {
                Ok(v)
            } else {
                Err(argument(name, format!("row {i} is not finite: {v}")))
            }
        })
        .collect()
}

/// A 3-vector given as a sequence of three numbers (argument `name`).
///
/// # Errors
/// A `ValueError` naming `name` if a value is not finite.
pub fn vector3(name: &str, v: [f64; 3]) -> PyResult<DVec3> {
    let v = DVec3::from_array(v);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(argument(name, format!("not finite: {v}")))
    }
}

/// A 3-vector for rapier, which stores it in `f32` (argument `name`): each value finite in
/// `f32` (below 3.4e38 in magnitude).
///
/// # Errors
/// A `ValueError` naming `name` if a value is not finite in `f32`.
pub fn vector3_f32(name: &str, v: [f64; 3]) -> PyResult<rapier_fvm::glamx::Vec3> {
    let single = DVec3::from_array(v).as_vec3();
    if single.is_finite() {
        Ok(single)
    } else {
        Err(argument(
            name,
            format!("not finite in float32, as rapier stores it: {:?}", v),
        ))
    }
}

/// A number for rapier (argument `name`), finite in `f32`.
///
/// # Errors
/// A `ValueError` naming `name` if it is not finite in `f32`.
pub fn scalar_f32(name: &str, value: f64) -> PyResult<f32> {
    let single = value as f32;
    if single.is_finite() {
        Ok(single)
    } else {
        Err(argument(
            name,
            format!("not finite in float32, as rapier stores it: {value}"),
        ))
    }
}
