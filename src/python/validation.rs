//! Python: `validate(model, q, qd, qdd, tau)` and its result, `Validation`.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;

use super::arrays::{read_batch, to_numpy, ArrayLike};
use super::tables::dataframe;
use crate::validation::{validate as validate_rs, Validation};

/// A model's torques against measured ones. Attributes: `joints` (names), `rms`,
/// `relative_rms` (NaN where the measured torque is zero), `max` (n,) per joint (N m; fraction);
/// `residuals` (k, n): measured - predicted (N m); `samples`. `to_dataframe()`: the per-joint
/// table (pandas).
#[pyclass(name = "Validation", module = "perturbid_rs", frozen)]
pub(crate) struct PyValidation {
    v: Validation,
    n: usize,
}

#[pymethods]
impl PyValidation {
    #[getter]
    fn joints(&self) -> Vec<String> {
        self.v.joints.iter().map(|j| j.joint.clone()).collect()
    }
    #[getter]
    fn rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(py, self.v.joints.iter().map(|j| j.rms))
    }
    #[getter]
    fn relative_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(
            py,
            self.v
                .joints
                .iter()
                .map(|j| j.relative_rms.unwrap_or(f64::NAN)),
        )
    }
    #[getter]
    fn max<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(py, self.v.joints.iter().map(|j| j.max))
    }
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_numpy(
            py,
            self.v.residuals.clone(),
            self.v.samples,
            false,
            &[self.n],
        )
    }
    #[getter]
    fn samples(&self) -> usize {
        self.v.samples
    }
    /// The per-joint table: index `joint`, columns `rms`, `relative_rms`, `max`.
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        dataframe(
            py,
            vec![
                ("rms", self.rms(py).into_any()),
                ("relative_rms", self.relative_rms(py).into_any()),
                ("max", self.max(py).into_any()),
            ],
            Some(("joint", self.joints())),
        )
    }
    fn __repr__(&self) -> String {
        let worst = self
            .v
            .joints
            .iter()
            .filter_map(|j| j.relative_rms)
            .fold(0.0, f64::max);
        format!(
            "Validation(samples={}, joints={}, worst relative RMS={:.2} %)",
            self.v.samples,
            self.n,
            100.0 * worst
        )
    }
}

/// Validates `model` (anything with `predict(q, qd, qdd)`: a LocalModel, BaseParameterModel,
/// GlobalLinearModel) on measured states and torques `q`, `qd`, `qdd`, `tau` ((k, n) each;
/// rad, rad/s, rad/s^2, N m). The joints are named after `model.joint_names` where it has
/// them. Returns a Validation.
#[pyfunction]
pub(crate) fn validate<'py>(
    model: Bound<'py, PyAny>,
    q: Bound<'py, PyAny>,
    qd: Bound<'py, PyAny>,
    qdd: Bound<'py, PyAny>,
    tau: ArrayLike<'py>,
) -> PyResult<PyValidation> {
    let measured = {
        let array = tau.as_array();
        let n = *array.shape().last().unwrap_or(&0);
        if n == 0 {
            return Err(crate::Error::Shape {
                argument: "tau".into(),
                expected: "(k, n) measured torques".into(),
                got: format!("shape {:?}", array.shape()),
            }
            .into());
        }
        let batch = read_batch(n, &[("tau", &tau)])?;
        (n, batch.columns[0].to_vec())
    };
    let (n, measured) = measured;
    let predicted = model.call_method1("predict", (q, qd, qdd))?;
    let predicted: Vec<f64> = predicted
        .extract::<Bound<'py, numpy::PyArrayDyn<f64>>>()?
        .to_vec()?;
    let joints: Vec<String> = match model.getattr("joint_names") {
        Ok(j) => j.extract()?,
        Err(_) => (1..=n).map(|j| format!("joint{j}")).collect(),
    };
    Ok(PyValidation {
        v: validate_rs(&joints, &predicted, &measured)?,
        n,
    })
}
