//! Python: physically consistent identification (`identify_consistent_parameters`) and its
//! result, `ConsistentFit`.

use std::sync::Arc;

use numpy::PyArray1;
use pyo3::prelude::*;

use super::scalars;

use super::detached;
use super::direct::{base_options, states, FrictionNames, PyBaseModel};
use super::robot::PyRobot;
use crate::direct::{
    identify_consistent_parameters as consistent_rs, ConsistentFit, ConsistentOptions,
};
use crate::model::Model;

/// Physically consistent parameters: every body's pseudo-inertia positive semi-definite (a
/// rigid body with a non-negative density can have them), viscous, Coulomb and armature
/// coefficients >= 0. Attributes:
/// - `model`: a BaseParameterModel of the consistent parameters (predict, linearize, save);
///   its standard errors are the unconstrained fit's (valid where no constraint is active);
/// - `unconstrained`: the BaseParameterModel of the same data without constraints;
/// - `theta` (p,), `names` (p,): the full consistent parameters (10 per body in
///   `Robot.regressor` order, kg, kg m, kg m^2 about the body frame, then the joint terms);
/// - `cost`, `unconstrained_cost`: the weighted residual sums of squares; `residual_growth`
///   their ratio (1 = the constraints cost nothing);
/// - `active`: the constraints the solution presses against, as sentences;
/// - `iterations`, `converged`; `robot()`: the robot with these parameters.
#[pyclass(name = "ConsistentFit", module = "perturbid_rs", frozen)]
pub(crate) struct PyConsistentFit {
    pub(crate) fit: ConsistentFit,
    pub(crate) model: Arc<Model>,
}

#[pymethods]
impl PyConsistentFit {
    #[getter]
    fn model(&self) -> PyBaseModel {
        PyBaseModel {
            fit: self.fit.model.clone(),
            model: self.model.clone(),
        }
    }
    #[getter]
    fn unconstrained(&self) -> PyBaseModel {
        PyBaseModel {
            fit: self.fit.unconstrained.clone(),
            model: self.model.clone(),
        }
    }
    /// The consistent parameters as a table (pandas): index `parameter` (full names as in
    /// `names`), columns `body` (the link or joint), `quantity` ('m', 'mcx', ..., 'Izz',
    /// 'viscous', 'coulomb', 'armature', 'offset') and `value` (kg, kg m, kg m^2 about the
    /// body frame; N m s/rad, N m, kg m^2, N m for the joint terms of a revolute joint).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let names = &self.fit.layout.names;
        let split = |n: &String| -> (String, String) {
            match n.rsplit_once('.') {
                Some((b, q)) => (b.to_string(), q.to_string()),
                None => (String::new(), n.clone()),
            }
        };
        let (body, quantity): (Vec<String>, Vec<String>) = names.iter().map(split).unzip();
        super::tables::dataframe(
            py,
            vec![
                ("body", pyo3::types::PyList::new(py, body)?.into_any()),
                (
                    "quantity",
                    pyo3::types::PyList::new(py, quantity)?.into_any(),
                ),
                (
                    "value",
                    PyArray1::from_slice(py, &self.fit.solution.theta).into_any(),
                ),
            ],
            Some(("parameter", names.clone())),
        )
    }
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.solution.theta)
    }
    #[getter]
    fn names(&self) -> Vec<String> {
        self.fit.layout.names.clone()
    }
    #[getter]
    fn cost(&self) -> f64 {
        self.fit.solution.cost
    }
    #[getter]
    fn unconstrained_cost(&self) -> f64 {
        self.fit.solution.unconstrained_cost
    }
    #[getter]
    fn residual_growth(&self) -> f64 {
        self.fit.residual_growth()
    }
    #[getter]
    fn active(&self) -> Vec<String> {
        self.fit.solution.active.clone()
    }
    #[getter]
    fn iterations(&self) -> usize {
        self.fit.solution.iterations
    }
    #[getter]
    fn converged(&self) -> bool {
        self.fit.solution.converged
    }
    /// The robot with the consistent parameters (inertias, armature, viscous and Coulomb
    /// friction as `damping` and `friction`; offsets stay in `model`).
    fn robot(&self) -> PyResult<PyRobot> {
        Ok(PyRobot::new(self.fit.robot(&self.model)?))
    }
    fn __repr__(&self) -> String {
        let s = &self.fit.solution;
        format!(
            "ConsistentFit(robot='{}', parameters={}, residual_growth={:.6}, active={}, iterations={})",
            self.fit.model.robot,
            s.theta.len(),
            self.fit.residual_growth(),
            s.active.len(),
            s.iterations
        )
    }
}

/// Identifies physically consistent parameters of `robot` from samples `q`, `qd`, `qdd`, `tau`
/// (each (k, n); rad, rad/s, rad/s^2, N m): the weighted least squares of
/// `identify_base_parameters` (same `friction`, `weighting`, `gravity`) over the parameter sets
/// a real robot can have, solved by an interior-point (log-barrier Newton) method. The robot's own
/// parameters are a weak prior (`prior_weight` relative to each column's norm) that decides
/// what the data do not. `t` ((k,) s), when the samples are a log: its qd and qdd columns are
/// checked first, as `identify_base_parameters` checks them. What the checks of the data find
/// (torque columns, a lag, zero offsets, friction left out) is warned of (PerturbidWarning).
/// `coulomb` ((k, n)): the Coulomb term's column for filtered torques, as in
/// `identify_base_parameters`; a Recording as `q`, alone, gives its own, and a list of them
/// is fitted as runs one after the other, as `identify_base_parameters` fits them (what each
/// one's preprocessing found kept in the models' `logs`; one Recording's in the one-log
/// fields); `offset_per_log` fits each one's own torque offset, as `identify_base_parameters`
/// does; `noise` and `noise_correlation` as there (the noise weighting, and the residuals
/// judged against the noise). Returns a ConsistentFit.
#[pyfunction]
#[pyo3(signature = (robot, q, qd=None, qdd=None, tau=None, friction=None, weighting="wls", gravity=true, prior_weight=1e-6, max_iterations=2000, t=None, coulomb=None, offset_per_log=false, noise=None, noise_correlation=1.0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_consistent_parameters<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    tau: Option<Bound<'py, PyAny>>,
    friction: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
    #[pyo3(from_py_with = scalars::real)] prior_weight: f64,
    #[pyo3(from_py_with = scalars::count)] max_iterations: usize,
    t: Option<Bound<'py, PyAny>>,
    coulomb: Option<Bound<'py, PyAny>>,
    offset_per_log: bool,
    noise: Option<super::arrays::ArrayLike<'py>>,
    #[pyo3(from_py_with = scalars::real)] noise_correlation: f64,
) -> PyResult<PyConsistentFit> {
    let options = base_options(friction, weighting, gravity)?;
    let consistent = ConsistentOptions {
        prior_weight,
        max_iterations,
        ..ConsistentOptions::default()
    };
    let model = &robot.model;
    let given = super::samples::Given {
        qd,
        qdd,
        tau,
        t,
        coulomb,
    };
    // several Recordings, fitted together; one Recording's findings are kept with the model
    let listed = super::recording_list::recordings_given(&q, &given)?;
    let options = super::recording_list::with_offset_per_log(
        options,
        offset_per_log,
        listed.as_ref().map(Vec::len),
    )?;
    let recs = match &listed {
        Some(recs) => recs.clone(),
        None => (q.cast::<super::recording::PyRecording>().ok())
            .map(|r| vec![r.get().rec.clone()])
            .unwrap_or_default(),
    };
    let options =
        super::noise::with_noise(options, noise, noise_correlation, &recs, &model.joint_names)?;
    let findings = |c: ConsistentFit| -> ConsistentFit {
        // a list's in `logs`, as identify_base_parameters keeps them
        let keep = |m: crate::direct::BaseModel| match (&listed, recs.as_slice()) {
            (Some(_), recs) => super::recording_list::with_logs(m, recs),
            (None, [rec]) => m.with_findings_of(rec),
            (None, _) => m,
        };
        ConsistentFit {
            model: keep(c.model),
            unconstrained: keep(c.unconstrained),
            ..c
        }
    };
    if listed.is_some() {
        let fit = detached(py, "identify_consistent_parameters", || {
            let (set, options) = super::recording_list::recording_set(model, &recs, &options)?;
            let (states, tau) = set.train()?;
            let c = consistent_rs(model, &states, tau, &options, &consistent)?;
            Ok::<_, crate::error::Error>(findings(c))
        })?;
        // the Recordings' own findings were warned of by the preprocessing that made them
        super::errors::warn_all(py, &fit.model.fit_warnings())?;
        return Ok(PyConsistentFit {
            fit,
            model: Arc::new(model.clone()),
        });
    }
    let a = super::samples::samples(q, given, true, true)?.arrays()?;
    let c = states(model.nv, &a.q, &a.qd, &a.qdd, a.tau.as_ref())?;
    let coulomb = super::direct::coulomb_column(model.nv, a.coulomb.as_ref())?;
    let t = (a.t.as_ref())
        .map(|t| super::arrays::vector("t", t))
        .transpose()?;
    let fit = detached(py, "identify_consistent_parameters", || {
        let what = "identify_consistent_parameters' samples";
        super::direct::check_sample_derivatives(what, model.nv, t, &c)?;
        let s = super::direct::fit_states(model.nv, &c, coulomb.as_deref())?;
        Ok::<_, crate::error::Error>(findings(consistent_rs(
            model,
            &s,
            &c[3],
            &options,
            &consistent,
        )?))
    })?;
    // what the data's checks found (torque columns, lag, offsets, friction left out), as the
    // command line and identify_base_parameters warn of it (a Recording's own findings were
    // warned of by its preprocessing)
    match recs.is_empty() {
        true => super::errors::warn_all(py, &fit.model.warnings())?,
        false => super::errors::warn_all(py, &fit.model.fit_warnings())?,
    }
    Ok(PyConsistentFit {
        fit,
        model: Arc::new(model.clone()),
    })
}
