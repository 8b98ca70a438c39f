//! Python: tables in and out through pandas (an optional dependency: `pip install
//! perturbid_rs[tables]`): `to_dataframe()` on recordings, models, fits and validations, and
//! the columns of a DataFrame read as a recording (`Recording.from_dataframe`).

use numpy::{PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::Error;

/// A column read from a frame: its name (as the map reads it) and its values.
type Column = (String, Vec<f64>);

/// The columns of the pandas DataFrame `frame` as named `f64` columns for
/// [`crate::io::Table::from_columns`], `source` naming it in errors: numbers (floats, integers,
/// pandas' nullable types, whose missing values become NaN and are refused there); the time
/// column `t` may hold datetimes or timedeltas, read as seconds from its first row, and may be
/// the index when named `t` and no column is. A column named by anything but a string, or
/// holding booleans, text, categories or times (other than `t`), is refused by name; so is a
/// frame of more than [`crate::limits::MAX_VALUES`] values. TypeError for what is not a frame.
/// The columns are those `map` reads for the joints `joints`, renamed and scaled as it says
/// ([`crate::io::ColumnMap::select`]): those it leaves out are not converted, and their names
/// are returned beside the columns read.
pub(crate) fn frame_columns(
    frame: &Bound<'_, PyAny>,
    source: &str,
    map: &crate::io::ColumnMap,
    joints: &[String],
) -> PyResult<(Vec<Column>, Vec<String>)> {
    let py = frame.py();
    let bad = |message: String| -> PyErr {
        Error::Recording {
            recording: source.into(),
            message,
        }
        .into()
    };
    if !(frame.hasattr("columns")? && frame.hasattr("iloc")? && frame.hasattr("index")?) {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "expected a pandas DataFrame, got {}",
            frame.get_type().name()?
        )));
    }
    let names: Vec<Bound<'_, PyAny>> = frame
        .getattr("columns")?
        .try_iter()?
        .collect::<PyResult<_>>()?;
    let rows = frame.len()?;
    if rows as f64 * (names.len() + 1) as f64 > crate::limits::MAX_VALUES {
        return Err(bad(format!(
            "{rows} rows of {} columns: more than {} values (docs/limits.md)",
            names.len(),
            crate::limits::MAX_VALUES
        )));
    }
    if rows == 0 {
        return Err(bad("no data rows".into()));
    }
    let iloc = frame.getattr("iloc")?;
    let mut columns: Vec<(String, Bound<'_, PyAny>)> = Vec::with_capacity(names.len() + 1);
    for (c, n) in names.iter().enumerate() {
        let name: String = n.extract().map_err(|_| {
            let shown = n.repr().map_or("?".into(), |r| r.to_string());
            let kind = n.get_type().name().map_or("?".into(), |k| k.to_string());
            bad(format!(
                "column {} is named {shown} ({kind}): expected a name such as 't', 'q1' or 'tau_<joint>'",
                c + 1
            ))
        })?;
        let series = iloc.get_item((pyo3::types::PySlice::full(py), c))?;
        columns.push((name, series));
    }
    if !columns.iter().any(|(n, _)| n == "t") {
        let index = frame.getattr("index")?;
        if index
            .getattr("name")?
            .extract::<Option<String>>()
            .ok()
            .flatten()
            .as_deref()
            == Some("t")
        {
            columns.insert(0, ("t".into(), index.call_method0("to_series")?));
        }
    }
    // the columns `map` reads, under the names it gives them (those it leaves out are not
    // converted: they may hold text)
    let names: Vec<String> = columns.iter().map(|c| c.0.clone()).collect();
    let (selection, left_out) = map.select(source, &names, joints)?;
    let numbers = PyDict::new(py);
    numbers.set_item("dtype", "float64")?;
    numbers.set_item("na_value", f64::NAN)?;
    selection
        .keep
        .into_iter()
        .map(|k| {
            let (name, series) = (k.name, &columns[k.source].1);
            let dtype = series.getattr("dtype")?;
            let kind: String = dtype.getattr("kind")?.extract()?;
            let values = match kind.as_str() {
                "f" | "i" | "u" => series.call_method("to_numpy", (), Some(&numbers))?,
                "M" | "m" if name == "t" => {
                    // differences in the column's own unit, to seconds: an epoch stamp keeps
                    // its nanoseconds
                    let start = series.getattr("iloc")?.get_item(0)?;
                    series
                        .call_method1("__sub__", (start,))?
                        .getattr("dt")?
                        .call_method0("total_seconds")?
                        .call_method("to_numpy", (), Some(&numbers))?
                }
                _ => {
                    let times = if matches!(kind.as_str(), "M" | "m") {
                        " (only 't' may hold times)"
                    } else {
                        ""
                    };
                    let own = &columns[k.source].0;
                    let words = if kind == "O" {
                        format!(" (a column of words is left out with ignore_columns=['{own}'])")
                    } else {
                        String::new()
                    };
                    return Err(bad(format!(
                        "column '{own}' holds {} values: expected numbers{times}{words}",
                        dtype.str()?
                    )));
                }
            };
            let values: PyReadonlyArray1<'_, f64> = values.extract()?;
            debug_assert_eq!(values.len(), rows);
            Ok((
                name,
                values.as_array().iter().map(|v| v * k.scale).collect(),
            ))
        })
        .collect::<PyResult<Vec<_>>>()
        .map(|read| (read, left_out))
}

/// A `pandas.DataFrame` of `columns` (name, values), in order, with `index` as its index when
/// given. Raises ImportError naming the extra when pandas is not installed.
pub(crate) fn dataframe<'py>(
    py: Python<'py>,
    columns: Vec<(&str, Bound<'py, PyAny>)>,
    index: Option<(&str, Vec<String>)>,
) -> PyResult<Bound<'py, PyAny>> {
    let pandas = py.import("pandas").map_err(|_| {
        pyo3::exceptions::PyImportError::new_err(
            "to_dataframe() needs pandas: pip install 'perturbid_rs[tables]' (or pandas)",
        )
    })?;
    let data = PyDict::new(py);
    for (name, values) in columns {
        data.set_item(name, values)?;
    }
    let frame = pandas.call_method1("DataFrame", (data,))?;
    match index {
        Some((name, labels)) => {
            frame.setattr("index", pandas.call_method1("Index", (labels,))?)?;
            frame.getattr("index")?.setattr("name", name)?;
            Ok(frame)
        }
        None => Ok(frame),
    }
}

/// The tidy table of a linear model (local or globally linearised): one row per entry, columns
/// `term` ('T', then the names of `parts`), `torque` (the joint whose torque the row is),
/// `joint` (the joint whose change multiplies the entry; empty for T), `value`, `std`.
pub(crate) fn linear_model_frame<'py>(
    py: Python<'py>,
    names: &[String],
    torque: &[f64],
    torque_std: &[f64],
    parts: &[(&str, &nalgebra::DMatrix<f64>, &nalgebra::DMatrix<f64>)],
) -> PyResult<Bound<'py, PyAny>> {
    let (mut term, mut tq, mut joint) = (Vec::new(), Vec::new(), Vec::new());
    let (mut value, mut std) = (Vec::new(), Vec::new());
    for (i, name) in names.iter().enumerate() {
        term.push("T");
        tq.push(name.clone());
        joint.push(String::new());
        value.push(torque[i]);
        std.push(torque_std.get(i).copied().unwrap_or(f64::NAN));
    }
    for (k, m, e) in parts {
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                term.push(k);
                tq.push(names[i].clone());
                joint.push(names[j].clone());
                value.push(m[(i, j)]);
                std.push(e[(i, j)]);
            }
        }
    }
    dataframe(
        py,
        vec![
            ("term", pyo3::types::PyList::new(py, term)?.into_any()),
            ("torque", pyo3::types::PyList::new(py, tq)?.into_any()),
            ("joint", pyo3::types::PyList::new(py, joint)?.into_any()),
            ("value", numpy::PyArray1::from_vec(py, value).into_any()),
            ("std", numpy::PyArray1::from_vec(py, std).into_any()),
        ],
        None,
    )
}
