//! Python: results as tables, `to_dataframe()` on models, fits and validations (pandas, an
//! optional dependency: `pip install perturbid_rs[tables]`).

use pyo3::prelude::*;
use pyo3::types::PyDict;

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
