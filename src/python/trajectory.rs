//! `FourierTrajectory` in Python: the excitation of eq. 16 (mirrors `crate::trajectory`).

use numpy::PyArray1;
use pyo3::prelude::*;

use super::scalars;

use super::arrays::{matrix, matrix_to_numpy as mat, to_numpy, ArrayLike};
use crate::error::Error;
use crate::trajectory::FourierTrajectory;

/// A Fourier excitation (eq. 16): `q_i(t) = q0_i + sum_l a_il/(w_f l) sin(w_f l t) -
/// b_il/(w_f l) cos(w_f l t)`. `a`, `b`: (n, L) in rad/s; `q0`: (n,) in rad; the base
/// pulsation `w_f` in rad/s, or `base_frequency` in Hz (default 0.1 Hz).
#[pyclass(name = "FourierTrajectory", module = "perturbid_rs", frozen)]
#[derive(Clone)]
pub(crate) struct PyFourier {
    pub traj: FourierTrajectory,
}

#[pymethods]
impl PyFourier {
    #[new]
    #[pyo3(signature = (a, b, q0, *, w_f=None, base_frequency=None))]
    fn new(
        a: ArrayLike<'_>,
        b: ArrayLike<'_>,
        q0: ArrayLike<'_>,
        #[pyo3(from_py_with = scalars::real_or_none)] w_f: Option<f64>,
        #[pyo3(from_py_with = scalars::real_or_none)] base_frequency: Option<f64>,
    ) -> PyResult<Self> {
        let w_f = match (w_f, base_frequency) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid("w_f", "give w_f or base_frequency, not both").into())
            }
            (Some(w), None) => w,
            (None, f) => 2.0 * std::f64::consts::PI * f.unwrap_or(0.1),
        };
        let q0: Vec<f64> = q0.as_array().iter().copied().collect();
        Ok(Self {
            traj: FourierTrajectory::new(w_f, q0, matrix("a", &a)?, matrix("b", &b)?)?,
        })
    }
    /// Positions, velocities and accelerations at times `t` (s): a tuple of three arrays of
    /// shape (k, n) for `t` of shape (k,), or (n,) for a scalar `t`.
    pub(crate) fn sample<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (times, single) = match t.extract::<f64>() {
            Ok(x) => (vec![x], true),
            Err(_) => {
                let a: ArrayLike<'_> = t.extract()?;
                (super::arrays::vector("t", &a)?, false)
            }
        };
        if let Some(i) = times.iter().position(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("t[{i}]"),
                format!("{}; expected a finite time (s)", times[i]),
            )
            .into());
        }
        let n = self.traj.n();
        crate::limits::check_samples("t", times.len().saturating_sub(1) as f64, 3 * n, || {
            format!("{} times", times.len())
        })?;
        let s = self.traj.sample(&times);
        Ok((
            to_numpy(py, s.q, times.len(), single, &[n])?,
            to_numpy(py, s.qd, times.len(), single, &[n])?,
            to_numpy(py, s.qdd, times.len(), single, &[n])?,
        ))
    }
    #[getter]
    fn a<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.traj.a)
    }
    #[getter]
    fn b<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.traj.b)
    }
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.traj.q0)
    }
    #[getter]
    fn w_f(&self) -> f64 {
        self.traj.w_f
    }
    #[getter]
    fn period(&self) -> f64 {
        self.traj.period()
    }
    #[getter]
    fn harmonics(&self) -> usize {
        self.traj.harmonics()
    }
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.traj).expect("serialisable")
    }
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        crate::json::check_containers(text, "Fourier trajectory")?;
        let t: FourierTrajectory = serde_json::from_str(text).map_err(|e| Error::Json {
            context: "Fourier trajectory".into(),
            message: crate::json::describe_error(&e, text),
        })?;
        Ok(Self {
            traj: FourierTrajectory::new(t.w_f, t.q0, t.a, t.b)?,
        })
    }
    fn __repr__(&self) -> String {
        format!(
            "FourierTrajectory(n={}, harmonics={}, period={:.3} s)",
            self.traj.n(),
            self.traj.harmonics(),
            self.traj.period()
        )
    }
}
