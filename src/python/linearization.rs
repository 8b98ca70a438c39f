//! `perturbid_rs.Linearization`: the local model at an operating point as numpy arrays.

use pyo3::prelude::*;

/// The linearisation of the inverse dynamics at an operating point `(q*, qd*, qdd*)`:
/// `tau - T* ~= D dqdd + H dqd + G dq`. For a batch of `k` operating points every array gains a
/// leading axis of length `k`.
///
/// Attributes (N m or N; matrices with row = torque, column = joint):
/// - `torque`: `T*`, shape `(n,)`;
/// - `D`: `d tau / d qdd = M(q*)`, shape `(n, n)`;
/// - `H`: `d tau / d qd`, shape `(n, n)`;
/// - `G`: `d tau / d q` at the operating point, shape `(n, n)`;
/// - `G_static`: `d tau / d q` at rest at `q*` (the gravity stiffness), shape `(n, n)`.
#[pyclass(name = "Linearization", module = "perturbid_rs", frozen)]
pub(crate) struct PyLinearization {
    #[pyo3(get)]
    pub torque: Py<PyAny>,
    #[pyo3(get, name = "D")]
    pub d: Py<PyAny>,
    #[pyo3(get, name = "H")]
    pub h: Py<PyAny>,
    #[pyo3(get, name = "G")]
    pub g: Py<PyAny>,
    #[pyo3(get, name = "G_static")]
    pub g_static: Py<PyAny>,
}

#[pymethods]
impl PyLinearization {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Linearization(torque={})",
            self.torque.bind(py).repr()?
        ))
    }
}
