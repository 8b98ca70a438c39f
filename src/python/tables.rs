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
