//! The Python exception hierarchy and the mapping of [`crate::Error`] onto it, by its
//! [`ErrorKind`]:
//!
//! - `PerturbidError(Exception)`: base of everything the library raises;
//! - `ModelError`: a URDF or robot model that cannot be built (limits included);
//! - `InputError`, also a `ValueError`: an argument of the wrong shape, with NaN/inf, or out of
//!   range; a plan that breaks the joint limits; a recording or JSON document that cannot be
//!   used;
//! - `NumericalError`, also an `ArithmeticError`: a numerical failure (a mass matrix not
//!   positive definite, a regression whose data do not excite every direction);
//! - `FileError`, also an `OSError`: a file that cannot be read or written;
//! - `InternalError`, also a `RuntimeError`: a bug of this library caught at its boundary
//!   (never a bare `PanicException`).
//!
//! Ctrl-C during long work raises Python's own `KeyboardInterrupt`. Results the library cannot
//! fully vouch for come with a `PerturbidWarning` (a `UserWarning`), also recorded in their
//! diagnostics.
//!
//! The classes are made with Python's `type()`, so that they can have two bases.

use pyo3::exceptions::{
    PyArithmeticError, PyException, PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyUserWarning,
    PyValueError,
};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

use crate::error::{Error, ErrorKind};

/// One exception class: its name, docstring and the bases after `PerturbidError`.
struct Class {
    name: &'static str,
    doc: &'static str,
    cell: PyOnceLock<Py<PyType>>,
}

/// A class definition with an empty cell, made on first use.
macro_rules! class {
    ($name:literal, $doc:literal) => {
        Class {
            name: $name,
            doc: $doc,
            cell: PyOnceLock::new(),
        }
    };
}

static BASE: Class = class!("PerturbidError", "Base class of all perturbid_rs errors.");
static MODEL: Class = class!("ModelError", "A URDF or robot model that cannot be built.");
static INPUT: Class = class!(
    "InputError",
    "An argument, recording or document of the wrong shape, non-finite, or out of range."
);
static NUMERICAL: Class = class!("NumericalError", "A numerical failure.");
static FILE: Class = class!("FileError", "A file that cannot be read or written.");
static INTERNAL: Class = class!(
    "InternalError",
    "A bug of perturbid_rs caught at its boundary: please report it."
);
static WARNING: Class = class!(
    "PerturbidWarning",
    "A result the library computed but cannot fully vouch for (also in the result's diagnostics)."
);

impl Class {
    /// The class, made on first use.
    fn get<'py>(&'static self, py: Python<'py>) -> PyResult<&'py Bound<'py, PyType>> {
        self.cell
            .get_or_try_init(py, || {
                let bases = if self.name == BASE.name {
                    PyTuple::new(py, [py.get_type::<PyException>()])?
                } else if self.name == WARNING.name {
                    PyTuple::new(py, [py.get_type::<PyUserWarning>()])?
                } else {
                    let second = match self.name {
                        "InputError" => Some(py.get_type::<PyValueError>()),
                        "NumericalError" => Some(py.get_type::<PyArithmeticError>()),
                        "FileError" => Some(py.get_type::<PyOSError>()),
                        "InternalError" => Some(py.get_type::<PyRuntimeError>()),
                        _ => None,
                    };
                    let base = BASE.get(py)?.clone();
                    PyTuple::new(py, std::iter::once(base).chain(second).collect::<Vec<_>>())?
                };
                let namespace = PyDict::new(py);
                namespace.set_item("__doc__", self.doc)?;
                namespace.set_item("__module__", "perturbid_rs")?;
                let class = py
                    .get_type::<PyType>()
                    .call1((self.name, bases, namespace))?
                    .cast_into::<PyType>()?;
                Ok(class.unbind())
            })
            .map(|c| c.bind(py))
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    for class in [
        &BASE, &MODEL, &INPUT, &NUMERICAL, &FILE, &INTERNAL, &WARNING,
    ] {
        m.add(class.name, class.get(py)?)?;
    }
    Ok(())
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let class = match e.kind() {
            ErrorKind::Interrupted => return PyKeyboardInterrupt::new_err(e.to_string()),
            ErrorKind::Model => &MODEL,
            ErrorKind::Input => &INPUT,
            ErrorKind::Numerical => &NUMERICAL,
            ErrorKind::File => &FILE,
            ErrorKind::Internal => &INTERNAL,
        };
        Python::attach(|py| match class.get(py) {
            Ok(t) => PyErr::from_type(t.clone(), e.to_string()),
            Err(failed) => failed,
        })
    }
}

/// Issues each of `messages` as a `perturbid_rs.PerturbidWarning` (a `UserWarning`) pointing
/// at the caller's line.
pub(crate) fn warn_all(py: Python<'_>, messages: &[String]) -> PyResult<()> {
    let class = WARNING.get(py)?;
    for m in messages {
        let text = std::ffi::CString::new(m.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, class, &text, 1)?;
    }
    Ok(())
}
