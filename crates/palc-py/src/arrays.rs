//! NumPy arrays in and out: float64, C-contiguous, shapes checked with the argument
//! named in the error.
//!
//! An input is passed through `numpy.ascontiguousarray(x, dtype=float64)`, which
//! returns a float64 C-contiguous array unchanged and converts lists, integer arrays
//! and strided views; what cannot be converted, or has the wrong number of
//! dimensions or columns, is a `palc.ShapeError` whose `field` is the argument.

use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{Raise, message};

/// A `ShapeError` naming `argument`.
fn shape_error(py: Python<'_>, argument: &str, text: String) -> PyErr {
    message(py, &Raise::field("ShapeError", argument), &text)
}

/// The values of `obj` as a float64 C-contiguous array, copied out, with its shape.
fn contiguous(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    argument: &str,
) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let converted = py
        .import("numpy")?
        .call_method("ascontiguousarray", (obj,), Some(&kwargs))
        .map_err(|e| {
            shape_error(
                py,
                argument,
                format!("`{argument}` cannot be converted to a float64 array: {e}"),
            )
        })?;
    let array = converted
        .cast::<PyArrayDyn<f64>>()
        .map_err(|_| shape_error(py, argument, format!("`{argument}` is not a float64 array")))?;
    let readonly = array.readonly();
    let values = readonly
        .as_slice()
        .map_err(|e| shape_error(py, argument, format!("`{argument}` is not contiguous: {e}")))?;
    Ok((array.shape().to_vec(), values.to_vec()))
}

/// A 2-D array of `columns` columns (any number if `None`): its rows, columns and
/// values in row-major order.
pub(crate) fn matrix(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    argument: &str,
    columns: Option<usize>,
) -> PyResult<(usize, usize, Vec<f64>)> {
    let (shape, values) = contiguous(py, obj, argument)?;
    let expected = columns.map_or_else(|| "(n, d)".to_owned(), |d| format!("(n, {d})"));
    match shape[..] {
        [rows, cols] if columns.is_none_or(|d| d == cols) => Ok((rows, cols, values)),
        _ => Err(shape_error(
            py,
            argument,
            format!("`{argument}` has shape {shape:?}, expected {expected}"),
        )),
    }
}

/// A 1-D array of `length` entries (any length if `None`).
pub(crate) fn vector(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    argument: &str,
    length: Option<usize>,
) -> PyResult<Vec<f64>> {
    let (shape, values) = contiguous(py, obj, argument)?;
    match shape[..] {
        [n] if length.is_none_or(|l| l == n) => Ok(values),
        _ => Err(shape_error(
            py,
            argument,
            format!(
                "`{argument}` has shape {shape:?}, expected ({},)",
                length.map_or_else(|| "n".to_owned(), |l| l.to_string())
            ),
        )),
    }
}

/// A new `(rows, columns)` array of `values` in row-major order.
pub(crate) fn to_matrix<'py>(
    py: Python<'py>,
    rows: usize,
    columns: usize,
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray1::from_vec(py, values).reshape([rows, columns])
}

/// A new 1-D array of `values`.
pub(crate) fn to_vector(py: Python<'_>, values: Vec<f64>) -> Bound<'_, PyArray1<f64>> {
    PyArray1::from_vec(py, values)
}
