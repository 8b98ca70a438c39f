//! The globally linearised model in Python: `identify_global_linear` (`GlobalLinearModel`),
//! the paper's direct-method rows (mirrors `crate::direct::global_linear`).

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::{at_states, expansion_dict, matrix_to_numpy as mat, ArrayLike};
use super::detached;
use super::direct::states;
use super::operating_point::PyOperatingPoint;
use super::samples::{samples, Given};
use crate::direct::{identify_global_linear as global_rs, GlobalLinearModel};
use crate::document::Document;
use crate::states::States;
use crate::torque_model::TorqueModel;

/// The globally linearised model: constant D, H, G and an offset about an operating point.
/// `D`, `H`, `G` (n, n); `torque` (n,) the fitted torque at the operating point; `stderr` dict;
/// `residual_rms` (n,); `cond`; `predict(q, qd, qdd)`.
#[pyclass(name = "GlobalLinearModel", module = "perturbid_rs", frozen)]
pub(crate) struct PyGlobalLinear {
    fit: GlobalLinearModel,
}

#[pymethods]
impl PyGlobalLinear {
    #[getter(D)]
    fn d<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.fit.d)
    }
    #[getter(H)]
    fn h<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.fit.h)
    }
    #[getter(G)]
    fn g<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.fit.g)
    }
    #[getter]
    fn torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.offset)
    }
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.fit.offset.len();
        let s = &self.fit.stderr;
        let d = PyDict::new(py);
        d.set_item(
            "torque",
            PyArray1::from_iter(py, s.column(0).iter().copied()),
        )?;
        for (k, name) in ["D", "H", "G"].iter().enumerate() {
            d.set_item(*name, mat(py, &s.columns(1 + k * n, n).into_owned())?)?;
        }
        Ok(d)
    }
    #[getter]
    fn residual_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.residual_rms)
    }
    /// The model as a tidy table (pandas), as `LocalModel.to_dataframe()`: columns `term`
    /// ('T', 'D', 'H', 'G'), `torque`, `joint`, `value`, `std`.
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.fit.offset.len();
        let s = &self.fit.stderr;
        let std_of = |k: usize| s.columns(1 + k * n, n).into_owned();
        let (sd, sh, sg) = (std_of(0), std_of(1), std_of(2));
        let torque_std: Vec<f64> = s.column(0).iter().copied().collect();
        super::tables::linear_model_frame(
            py,
            &self.fit.joint_names,
            &self.fit.offset,
            &torque_std,
            &[
                ("D", &self.fit.d, &sd),
                ("H", &self.fit.h, &sh),
                ("G", &self.fit.g, &sg),
            ],
        )
    }
    #[getter]
    fn cond(&self) -> f64 {
        self.fit.cond
    }
    #[getter]
    fn op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.fit.op.clone(),
        }
    }
    /// The model at `op`: dict `torque` (n,), `D`, `H`, `G` (n, n; the same everywhere),
    /// `G_static` None, as a LocalModel answers it.
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        op: &PyOperatingPoint,
    ) -> PyResult<Bound<'py, PyDict>> {
        expansion_dict(py, &TorqueModel::linearize(&self.fit, &op.op)?)
    }
    /// `T + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)`: (n,) each or (k, n).
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let fit = &self.fit;
        let name = "GlobalLinearModel.predict";
        at_states(py, fit.offset.len(), [&q, &qd, &qdd], name, |s| {
            fit.predict(s)
        })
    }
    /// The model as JSON (`perturbid-global-linear-model/1`), as `save` writes it.
    fn to_json(&self) -> String {
        Document::to_json(&self.fit)
    }
    /// A model from the JSON of `to_json`, checked: every shape against the joints, standard
    /// errors and residuals >= 0. Raises InputError naming the field.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self {
            fit: <GlobalLinearModel as Document>::from_json(text)?,
        })
    }
    /// Writes the model to `path` as JSON (atomically: a temporary file renamed into place);
    /// `perturbid validate` and `predict` read it. Raises FileError when it cannot be written.
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        Ok(detached(py, "GlobalLinearModel.save", || {
            Document::save(&self.fit, &path)
        })?)
    }
    /// A model saved by `save`, checked as `from_json` checks it. Raises FileError for a file
    /// that cannot be read, InputError naming the file and field of a document that is not a
    /// globally linearised model.
    #[staticmethod]
    fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let fit = detached(py, "GlobalLinearModel.load", || {
            GlobalLinearModel::load(&path)
        })?;
        Ok(Self { fit })
    }
}

/// Fits the globally linearised model at `op` to samples `q`, `qd`, `qdd`, `tau` (each (k, n):
/// rad, rad/s, rad/s^2, N m), or to a Recording given whole as `q` (preprocessed: with its
/// velocities and accelerations), alone.
#[pyfunction]
#[pyo3(signature = (op, q, qd=None, qdd=None, tau=None))]
pub(crate) fn identify_global_linear<'py>(
    py: Python<'py>,
    op: &PyOperatingPoint,
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    tau: Option<Bound<'py, PyAny>>,
) -> PyResult<PyGlobalLinear> {
    let given = Given {
        qd,
        qdd,
        tau,
        t: None,
        coulomb: None,
    };
    let a = samples(q, given, true, false)?.arrays()?;
    let c = states(op.op.n(), &a.q, &a.qd, &a.qdd, a.tau.as_ref())?;
    let fit = detached(py, "identify_global_linear", || {
        global_rs(
            &op.op,
            &States::new(op.op.n(), &c[0], Some(&c[1]), Some(&c[2]))?,
            &c[3],
        )
    })?;
    Ok(PyGlobalLinear { fit })
}
