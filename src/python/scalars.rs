//! Scalar arguments from Python: real numbers, counts and seeds, refusing `bool`.
//!
//! pyo3 reads a Python `bool` (a subclass of `int`) as 1 or 0 where an `f64`, `usize` or `u64`
//! is asked for, so `rate=True` would run at 1 Hz and `n=True` plan one pass. The functions
//! here are `#[pyo3(from_py_with = ...)]` extractors for such arguments: they refuse `bool`
//! with a `TypeError` (which pyo3 prefixes with the argument's name) and otherwise extract as
//! pyo3 does (`int`, `float` and numpy scalars; an integer from a `float` is refused).

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyBool;

fn not_bool(obj: &Bound<'_, PyAny>, expected: &str) -> PyResult<()> {
    if obj.is_instance_of::<PyBool>() || is_numpy_bool(obj) {
        return Err(PyTypeError::new_err(format!(
            "expected {expected}, got a bool ({})",
            obj.str().map(|s| s.to_string()).unwrap_or_default()
        )));
    }
    Ok(())
}

/// numpy's `bool_` is not a Python `bool`; it converts to a number all the same.
fn is_numpy_bool(obj: &Bound<'_, PyAny>) -> bool {
    let ty = obj.get_type();
    matches!(
        (ty.module(), ty.name()),
        (Ok(m), Ok(n)) if m == "numpy" && n == "bool"
    )
}

/// A real number (`f64`): `int`, `float` or a numpy scalar, not a `bool`.
pub(crate) fn real(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    not_bool(obj, "a real number")?;
    obj.extract()
}

/// `None` as such, anything else through `extract`.
fn or_none<T>(
    obj: &Bound<'_, PyAny>,
    extract: fn(&Bound<'_, PyAny>) -> PyResult<T>,
) -> PyResult<Option<T>> {
    if obj.is_none() {
        return Ok(None);
    }
    extract(obj).map(Some)
}

/// A real number or `None`.
pub(crate) fn real_or_none(obj: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    or_none(obj, real)
}

/// An unsigned integer as pyo3 extracts it, with a negative or too large integer refused as
/// a `TypeError` saying so (pyo3's own `OverflowError` names neither the argument nor the
/// value).
fn unsigned(obj: &Bound<'_, PyAny>, expected: &str) -> PyResult<u64> {
    not_bool(obj, expected)?;
    obj.extract::<u64>().map_err(|e| {
        if !e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) {
            return e;
        }
        let shown = obj.str().map(|s| s.to_string()).unwrap_or_default();
        let why = match obj.lt(0) {
            Ok(true) => "a negative one",
            _ => "one too large",
        };
        PyTypeError::new_err(format!("expected {expected}, got {why} ({shown})"))
    })
}

/// A non-negative integer (`usize`): `int` or a numpy integer, not a `bool` nor a `float`.
pub(crate) fn count(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    let n = unsigned(obj, "a non-negative integer")?;
    usize::try_from(n).map_err(|_| {
        PyTypeError::new_err(format!(
            "expected a non-negative integer, got one too large ({n})"
        ))
    })
}

/// A non-negative integer or `None`.
pub(crate) fn count_or_none(obj: &Bound<'_, PyAny>) -> PyResult<Option<usize>> {
    or_none(obj, count)
}

/// A random seed (`u64`): a non-negative integer, not a `bool`.
pub(crate) fn seed(obj: &Bound<'_, PyAny>) -> PyResult<u64> {
    unsigned(obj, "a non-negative integer seed")
}
