//! The Python exception hierarchy and the mapping of [`crate::Error`] onto it:
//!
//! - `PerturbidError(Exception)`: base of everything the library raises;
//! - `ModelError`: a URDF or robot model that cannot be built;
//! - `InputError`: an argument of the wrong shape, with NaN/inf, or out of range; a plan that
//!   breaks the joint limits; a recording or JSON document that cannot be used;
//! - `NumericalError`: a numerical failure (e.g. a mass matrix not positive definite, a
//!   regression whose data do not excite every direction);
//! - `FileError`: a file that cannot be read or written.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

use crate::error::Error;

create_exception!(
    perturbid_rs,
    PerturbidError,
    PyException,
    "Base class of all perturbid_rs errors."
);
create_exception!(
    perturbid_rs,
    ModelError,
    PerturbidError,
    "A URDF or robot model that cannot be built."
);
create_exception!(
    perturbid_rs,
    InputError,
    PerturbidError,
    "An argument of the wrong shape, non-finite, or out of range."
);
create_exception!(
    perturbid_rs,
    NumericalError,
    PerturbidError,
    "A numerical failure."
);
create_exception!(
    perturbid_rs,
    FileError,
    PerturbidError,
    "A file that cannot be read or written."
);

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("PerturbidError", py.get_type::<PerturbidError>())?;
    m.add("ModelError", py.get_type::<ModelError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("FileError", py.get_type::<FileError>())?;
    Ok(())
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let msg = e.to_string();
        match e {
            Error::Io { .. } => FileError::new_err(msg),
            Error::Shape { .. }
            | Error::NonFiniteInput { .. }
            | Error::InvalidArgument { .. }
            | Error::LimitViolation { .. }
            | Error::PositionLimit { .. }
            | Error::Recording { .. }
            | Error::Json { .. } => InputError::new_err(msg),
            Error::Numerical { .. } | Error::RankDeficient { .. } => NumericalError::new_err(msg),
            Error::UrdfSyntax { .. }
            | Error::UnsupportedJoint { .. }
            | Error::RootCount { .. }
            | Error::Cycle { .. }
            | Error::DuplicateChild { .. }
            | Error::DuplicateName { .. }
            | Error::UnknownLink { .. }
            | Error::JointReference { .. }
            | Error::InvalidInertia { .. }
            | Error::MasslessSubtree { .. }
            | Error::InvalidAxis { .. }
            | Error::MissingLimit { .. }
            | Error::NonFiniteUrdf { .. }
            | Error::UnknownRobot { .. } => ModelError::new_err(msg),
        }
    }
}
