//! Python: `validate(model, q, qd, qdd, tau)` and its result, `Validation`.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;

use pyo3::types::PyDict;

use super::arrays::{read_batch, to_numpy};
use super::detached;
use super::direct::PyBaseModel;
use super::errors::warn_all;
use super::findings::{
    position_offsets_dict, position_range_dicts, torque_column_dicts, torque_lag_dict,
};
use super::local_model::PyLocalModel;
use super::tables::dataframe;
use crate::direct::position_offsets::{check_position_offsets_in_validation, PositionOffsets};
use crate::direct::position_range::{check_position_range, JointRange};
use crate::direct::torque_columns::{check_torque_columns, TorqueColumn};
use crate::direct::torque_lag::{check_torque_lag, validation_findings, TorqueLag};
use crate::local::Extrapolation;
use crate::validation::{stored_stderr, validate as validate_rs, Validation};

/// A model's torques against measured ones. Attributes: `joints` (names), `rms`,
/// `relative_rms` (NaN where the measured torque is zero), `mean`, `max` (n,) per joint (N m;
/// fraction);
/// `residuals` (k, n): measured - predicted (N m); `samples`; `torque_columns` (for a
/// BaseParameterModel: the measured torque columns against its robot's model, as
/// `BaseParameterModel.torque_columns`; empty otherwise), `torque_lag` (likewise, as
/// `BaseParameterModel.torque_lag`; None otherwise), `position_range` (likewise, as
/// `BaseParameterModel.position_range`; empty otherwise), `position_offsets` (for a
/// BaseParameterModel: the joints' zero offsets of this data against its parameters, held; a
/// dict as `BaseParameterModel.position_offsets`; None otherwise), `extrapolation` (for a
/// LocalModel, where the states go beyond the region it was identified over; None
/// otherwise), `noise_fit` (for a Recording averaged over its periods, the errors against the
/// noise they measured; None otherwise). `to_dataframe()`: the
/// per-joint table (pandas).
#[pyclass(name = "Validation", module = "perturbid_rs", frozen)]
pub(crate) struct PyValidation {
    v: Validation,
    n: usize,
    torque_columns: Vec<TorqueColumn>,
    torque_lag: Option<TorqueLag>,
    position_range: Vec<JointRange>,
    position_offsets: Option<PositionOffsets>,
    extrapolation: Option<Extrapolation>,
    noise_fit: Option<crate::direct::NoiseFit>,
}

#[pymethods]
impl PyValidation {
    /// For a Recording averaged over its excitation's periods: the errors judged against the
    /// noise its periods measured (a dict as `BaseParameterModel.noise_fit`, no parameters
    /// fitted to these samples; the model's own uncertainty not counted); None otherwise.
    #[getter]
    fn noise_fit<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, pyo3::types::PyDict>>> {
        (self.noise_fit.as_ref())
            .map(|f| super::noise::noise_fit_dict(py, f))
            .transpose()
    }
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
    /// Per joint, the mean of measured - predicted (N m): the constant part of the error (a
    /// torque offset the log does not share with the model, or a constant misfit).
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(py, self.v.joints.iter().map(|j| j.mean))
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
    /// For a BaseParameterModel, each measured torque column against its robot's model (dicts
    /// as `BaseParameterModel.torque_columns`, each finding also a warning); empty otherwise.
    #[getter]
    fn torque_columns<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        torque_column_dicts(py, &self.torque_columns)
    }
    /// For a BaseParameterModel, the measured torques shifted against their positions (a
    /// dict as `BaseParameterModel.torque_lag`, its finding also a warning); None otherwise.
    #[getter]
    fn torque_lag<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.torque_lag
            .as_ref()
            .map(|l| torque_lag_dict(py, l))
            .transpose()
    }
    /// For a BaseParameterModel, the joints whose measured positions leave their limits
    /// (dicts as `BaseParameterModel.position_range`, their finding also a warning); empty
    /// otherwise.
    #[getter]
    fn position_range<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        position_range_dicts(py, &self.position_range)
    }
    /// For a BaseParameterModel, the joints' zero offsets of the data against the model's
    /// parameters, held (a dict as `BaseParameterModel.position_offsets`; its `finding` names
    /// joints likely zeroed elsewhere since the model was identified, also a warning); None
    /// otherwise, or where no joint's offset is determined.
    #[getter]
    fn position_offsets<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.position_offsets.as_ref())
            .map(|o| position_offsets_dict(py, o, o.finding_beside(&self.torque_columns, true)))
            .transpose()
    }
    /// For a LocalModel whose states go beyond the perturbations it was identified over
    /// (reach above 1.5, `LocalModel.reach`; `predict` warned of it): dict `beyond` (states),
    /// `states`, `largest` (the largest reach), `joint`, `variable` ('q', 'qd' or 'qdd'),
    /// `deviation` (from the operating point) and `perturbation` (the largest the experiments
    /// gave it) where it is; None otherwise.
    #[getter]
    fn extrapolation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(x) = &self.extrapolation else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        out.set_item("beyond", x.beyond)?;
        out.set_item("states", x.states)?;
        out.set_item("largest", x.largest)?;
        out.set_item("joint", &x.joint)?;
        out.set_item("variable", &x.variable)?;
        out.set_item("deviation", x.deviation)?;
        out.set_item("perturbation", x.perturbation)?;
        Ok(Some(out))
    }
    /// Per joint, the RMS of the predictions' standard errors (n,) (N m): the model's own
    /// uncertainty at these states, to weigh `rms` against; NaN where the model gives none (a
    /// GlobalLinearModel, a model saved before they were stored) or one is unknown.
    #[getter]
    fn model_stderr_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(
            py,
            self.v
                .joints
                .iter()
                .map(|j| j.model_stderr_rms.unwrap_or(f64::NAN)),
        )
    }
    /// The per-joint table: index `joint`, columns `rms`, `relative_rms`, `mean`, `max`,
    /// `model_stderr_rms`.
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        dataframe(
            py,
            vec![
                ("rms", self.rms(py).into_any()),
                ("relative_rms", self.relative_rms(py).into_any()),
                ("mean", self.mean(py).into_any()),
                ("max", self.max(py).into_any()),
                ("model_stderr_rms", self.model_stderr_rms(py).into_any()),
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
/// GlobalLinearModel, or a Robot: its own parameters and URDF friction, `Robot.predict`) on measured states and torques `q`, `qd`, `qdd`, `tau` ((k, n) each;
/// rad, rad/s, rad/s^2, N m). The joints are named after `model.joint_names` where it has
/// them. For a BaseParameterModel the torque columns are also checked against its robot's
/// model (swapped columns, the opposite sign, other units: a PerturbidWarning each, and
/// `Validation.torque_columns`), for a lag behind the positions (`Validation.torque_lag`) and
/// for joints zeroed elsewhere than in the model's data (`Validation.position_offsets`;
/// not judged where a torque column is found wrong). For a LocalModel or
/// BaseParameterModel a torque column that holds one value throughout while the robot moves
/// (a dead channel) is refused. A Robot's log is checked as a BaseParameterModel's (its
/// columns, lag and range, with gravity; not its zero offsets), and a robot whose file gives
/// no friction is warned of. `t` ((k,) s), when the samples are a log: its qd and qdd
/// columns are checked first against the derivatives of q and qd, as
/// `identify_base_parameters` checks them. `coulomb` ((k, n), a BaseParameterModel only): the
/// Coulomb term's column for filtered torques (`Recording.coulomb`), given to its `predict`.
/// A Recording as `q`, alone: its states, torques and time, and its Coulomb column for a
/// BaseParameterModel.
/// Returns a Validation.
#[pyfunction]
#[pyo3(signature = (model, q, qd=None, qdd=None, tau=None, t=None, coulomb=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn validate<'py>(
    model: Bound<'py, PyAny>,
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    tau: Option<Bound<'py, PyAny>>,
    t: Option<Bound<'py, PyAny>>,
    coulomb: Option<Bound<'py, PyAny>>,
) -> PyResult<PyValidation> {
    let base_model = model.cast::<PyBaseModel>().is_ok();
    if coulomb.is_some() && !base_model {
        return Err(crate::Error::invalid(
            "coulomb",
            "the Coulomb term's column is a BaseParameterModel's; this model has no Coulomb term to give it to",
        )
        .into());
    }
    let given = super::samples::Given {
        qd,
        qdd,
        tau,
        t,
        coulomb,
    };
    let averaged = (q.cast::<super::recording::PyRecording>().ok())
        .and_then(|r| r.get().rec.period_average.clone());
    let s = super::samples::samples(q, given, true, true)?;
    // a recording's own Coulomb column goes to a base-parameter model only
    let s = super::samples::Samples {
        coulomb: s.coulomb.filter(|_| base_model),
        ..s
    };
    let a = s.arrays()?;
    let (q, qd, qdd) = (&s.q, &s.qd, &s.qdd);
    let tau = (a.tau.as_ref()).ok_or_else(|| {
        crate::Error::invalid(
            "tau",
            "missing: the measured torques are what a model is validated against",
        )
    })?;
    let (t, coulomb) = (&a.t, &a.coulomb);
    let (n, measured) = measured_torques(tau)?;
    if let Some(t) = &t {
        let args = [("q", &a.q), ("qd", &a.qd), ("qdd", &a.qdd), ("tau", tau)];
        let batch = read_batch(n, &args)?;
        let t = super::arrays::vector("t", t)?;
        let samples = &batch.columns;
        detached(model.py(), "validate", || {
            super::direct::check_sample_derivatives("validate's samples", n, Some(t), samples)
        })?;
    }
    let predicted = match &coulomb {
        Some(c) => {
            let kwargs = pyo3::types::PyDict::new(model.py());
            kwargs.set_item("coulomb", c.as_any())?;
            model.call_method("predict", (&q, &qd, &qdd), Some(&kwargs))?
        }
        None => model.call_method1("predict", (&q, &qd, &qdd))?,
    };
    let predicted: Vec<f64> = predicted
        .extract::<Bound<'py, numpy::PyArrayDyn<f64>>>()?
        .to_vec()?;
    let joints: Vec<String> = match model.getattr("joint_names") {
        Ok(j) => j.extract()?,
        Err(_) => (1..=n).map(|j| format!("joint{j}")).collect(),
    };
    let mut v = validate_rs(&joints, &predicted, &measured)?;
    let checks = model_checks(&model, &a, n, &measured, &joints)?;
    let ModelChecks {
        stderr,
        position_range,
        torque_columns,
        torque_lag,
        position_offsets,
        extrapolation,
    } = checks;
    if let Some(se) = &stderr {
        v = v.with_model_stderr(se)?;
    }
    let rms: Vec<f64> = v.joints.iter().map(|j| j.rms).collect();
    let noise_fit = (averaged.as_ref())
        .and_then(|a| crate::direct::TorqueNoise::from_period_average(a, &joints).ok())
        .and_then(|noise| crate::direct::NoiseFit::of(&noise, &rms, v.samples, 0));
    Ok(PyValidation {
        v,
        n,
        torque_columns,
        torque_lag,
        position_range,
        position_offsets,
        extrapolation,
        noise_fit,
    })
}

/// The measured torques `tau` ((k, n)): n and the values, row-major.
fn measured_torques(tau: &super::arrays::ArrayLike<'_>) -> PyResult<(usize, Vec<f64>)> {
    let array = tau.as_array();
    let n = *array.shape().last().unwrap_or(&0);
    if n == 0 {
        return Err(crate::Error::shape(
            "tau",
            "(k, n) measured torques",
            format!("shape {:?}", array.shape()),
        )
        .into());
    }
    let batch = read_batch(n, &[("tau", tau)])?;
    Ok((n, batch.columns[0].to_vec()))
}

/// What validate learns of the model beside its predictions: their standard errors, where
/// the model gives them, and the measured torque columns checked against a base-parameter
/// model's robot (or a Robot's own parameters), as a direct fit checks its own data.
#[derive(Default)]
struct ModelChecks {
    stderr: Option<Vec<f64>>,
    position_range: Vec<JointRange>,
    torque_columns: Vec<TorqueColumn>,
    torque_lag: Option<TorqueLag>,
    position_offsets: Option<PositionOffsets>,
    extrapolation: Option<Extrapolation>,
}

/// The [`ModelChecks`] of `model` on the samples `a` (n joints named `joints`) against the
/// torques `measured`; refuses a torque column that holds one value while the robot moves.
fn model_checks(
    model: &Bound<'_, PyAny>,
    a: &super::samples::SampleArrays<'_>,
    n: usize,
    measured: &[f64],
    joints: &[String],
) -> PyResult<ModelChecks> {
    let (local, base) = (model.cast::<PyLocalModel>(), model.cast::<PyBaseModel>());
    let robot = model.cast::<super::robot::PyRobot>();
    let mut c = ModelChecks::default();
    if local.is_ok() || base.is_ok() || robot.is_ok() {
        let mut args = vec![("q", &a.q), ("qd", &a.qd), ("qdd", &a.qdd)];
        args.extend(a.coulomb.as_ref().map(|c| ("coulomb", c)));
        let batch = read_batch(n, &args)?;
        let states = batch.states(n)?;
        crate::torque_model::refuse_flat_torques(
            &states,
            measured,
            joints,
            crate::torque_model::FOR_A_VALIDATION,
        )?;
        if let Ok(local) = &local {
            let m = &local.get().model;
            c.stderr = stored_stderr(m.predict_stderr(&states))?.ok();
            c.extrapolation = m.extrapolation(&states)?;
        }
        // a robot's own parameters: its torque columns, lag and range checked as a
        // base-parameter model's robot (the zero offsets need a fit's parameters)
        if let Ok(robot) = &robot {
            let r = &robot.get().model;
            let (ranges, columns, lag) = detached(model.py(), "validate", || {
                let g = crate::gravity::Gravity::Included;
                Ok((
                    check_position_range(r, &states),
                    check_torque_columns(r, &states, measured, g)?,
                    check_torque_lag(r, &states, measured, g)?,
                ))
            })?;
            let mut findings = validation_findings(&ranges, &columns, lag.as_ref(), None);
            if !crate::robot_torques::RobotTorques::new(r).has_friction() {
                findings.push(crate::robot_torques::NO_FRICTION.to_string());
            }
            warn_all(model.py(), &findings)?;
            (c.position_range, c.torque_columns, c.torque_lag) = (ranges, columns, lag);
        }
        if let Ok(base) = &base {
            let base = base.get();
            let (se, ranges, columns, lag, offsets) = detached(model.py(), "validate", || {
                let g = base.fit.gravity;
                Ok((
                    stored_stderr(base.fit.predict_stderr(&base.model, &states))?,
                    check_position_range(&base.model, &states),
                    check_torque_columns(&base.model, &states, measured, g)?,
                    check_torque_lag(&base.model, &states, measured, g)?,
                    check_position_offsets_in_validation(
                        &base.model,
                        &base.fit,
                        &states,
                        measured,
                    )?,
                ))
            })?;
            let findings = validation_findings(&ranges, &columns, lag.as_ref(), offsets.as_ref());
            warn_all(model.py(), &findings)?;
            c.stderr = se.ok();
            (c.position_range, c.torque_columns) = (ranges, columns);
            (c.torque_lag, c.position_offsets) = (lag, offsets);
        }
    }
    Ok(c)
}
