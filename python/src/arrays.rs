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

/// `object` (argument `name`: a numpy array or nested sequences of numbers) as a 2D numpy
/// array of `columns` columns, cast to `dtype` (a numpy type name), with the shape it had.
fn rows_in<'py>(
    name: &str,
    object: &Bound<'py, PyAny>,
    columns: usize,
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let numpy = object.py().import("numpy")?;
    let array = numpy.call_method1("asarray", (object,))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let size: usize = array.getattr("size")?.extract()?;
    if size == 0 {
        return numpy.call_method1("zeros", ((0, columns), dtype));
    }
    if shape.len() != 2 || shape[1] != columns {
        return Err(argument(
            name,
            format!("expected an (n, {columns}) array, got the shape {shape:?}"),
        ));
    }
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    let allowed = if dtype == "float64" { "iuf" } else { "iu" };
    if !allowed.contains(kind.as_str()) {
        let given = array.getattr("dtype")?.str()?;
        return Err(argument(
            name,
            format!(
                "expected {} values, got the dtype {given}",
                kind_name(dtype)
            ),
        ));
    }
    array.call_method1("astype", (dtype,))
}

/// What values of the numpy type `dtype` are, for messages.
fn kind_name(dtype: &str) -> &'static str {
    if dtype == "float64" {
        "numeric"
    } else {
        "integer"
    }
}

/// The rows of `object` (argument `name`, an `(n, 3)` array-like of numbers) as vectors, each
/// finite.
///
/// # Errors
/// A `ValueError` naming `name` (and the row) for a wrong shape, a dtype that is not numeric or
/// a value that is not finite.
pub fn vectors_in(name: &str, object: &Bound<'_, PyAny>) -> PyResult<Vec<DVec3>> {
    let array: PyReadonlyArray2<'_, f64> = rows_in(name, object, 3, "float64")?.extract()?;
    (array.as_array().rows().into_iter().enumerate())
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

/// The rows of `object` (argument `name`, an `(n, K)` array-like of integers) as node
/// indices.
///
/// # Errors
/// A `ValueError` naming `name` (and the row) for a wrong shape, values that are not integers
/// or an index below 0 or past `u32`.
pub fn indices_in<const K: usize>(
    name: &str,
    object: &Bound<'_, PyAny>,
) -> PyResult<Vec<[u32; K]>> {
    let array: PyReadonlyArray2<'_, i64> = rows_in(name, object, K, "int64")?.extract()?;
    (array.as_array().rows().into_iter().enumerate())
        .map(|(i, row)| {
            let mut indices = [0u32; K];
            for (slot, &index) in indices.iter_mut().zip(row.iter()) {
                *slot = u32::try_from(index).map_err(|_| {
                    argument(name, format!("row {i}: node index {index} out of range"))
                })?;
            }
            Ok(indices)
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
