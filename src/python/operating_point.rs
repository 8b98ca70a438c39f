//! Python's `OperatingPoint` (mirrors `crate::operating_point::OperatingPoint`).

use pyo3::prelude::*;

use super::arrays::{vec1, vector, ArrayLike};
use crate::operating_point::OperatingPoint;

/// An operating point `P = (q*, qd*, qdd*)`: joint positions (rad or m), velocities (rad/s or
/// m/s) and accelerations (rad/s^2 or m/s^2), each of shape `(n,)`.
#[pyclass(name = "OperatingPoint", module = "perturbid_rs", frozen)]
#[derive(Clone)]
pub(crate) struct PyOperatingPoint {
    pub op: OperatingPoint,
}

#[pymethods]
impl PyOperatingPoint {
    #[new]
    fn new(q: ArrayLike<'_>, qd: ArrayLike<'_>, qdd: ArrayLike<'_>) -> PyResult<Self> {
        Ok(Self {
            op: OperatingPoint::new(vector("q", &q)?, vector("qd", &qd)?, vector("qdd", &qdd)?)?,
        })
    }
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.op.q)
    }
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.op.qd)
    }
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.op.qdd)
    }
    /// Number of joints.
    #[getter]
    fn n(&self) -> usize {
        self.op.n()
    }
    fn __repr__(&self) -> String {
        format!(
            "OperatingPoint(q={:?}, qd={:?}, qdd={:?})",
            self.op.q, self.op.qd, self.op.qdd
        )
    }
}
