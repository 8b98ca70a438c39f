//! The paper's method in Python: `OperatingPoint`, `Plan` and `Experiment`, `LocalModel`, and
//! the functions `plan_experiments` and `identify_local` (mirrors `crate::local`).

use std::sync::Arc;

use pyo3::prelude::*;

use super::detached;
use pyo3::types::{PyDict, PyList};

use super::arrays::{
    matrix_to_numpy as mat, per_joint, read_batch, rows, to_numpy, vec1, vector, ArrayLike,
};
use super::recording::PyRecording;
use super::robot::PyRobot;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::local::{
    identify_local as identify_rs, plan_experiments as plan_rs, CrossingTimes, Design, Estimate,
    Estimator, ExperimentKind, FitOptions, IdentifyOptions, LocalModel, OperatingPoint, Plan,
    PlanOptions, ReversalHandling, Size,
};
use crate::recording::Recording;

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

/// A plan of experiments at an operating point (from `plan_experiments`). `experiments` lists
/// them in order; `to_json()` / `Plan.from_json(text)` save and load it.
#[pyclass(name = "Plan", module = "perturbid_rs", frozen)]
pub(crate) struct PyPlan {
    pub plan: Arc<Plan>,
}

#[pymethods]
impl PyPlan {
    #[getter]
    fn op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.plan.op.clone(),
        }
    }
    /// What the planner found the user should know (also issued as PerturbidWarning).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.plan.warnings.clone()
    }
    /// Sampling rate of the trajectories (Hz).
    #[getter]
    fn rate(&self) -> f64 {
        self.plan.rate
    }
    #[getter]
    fn robot(&self) -> String {
        self.plan.robot.clone()
    }
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.plan.joint_names.clone()
    }
    #[getter]
    fn design(&self) -> &'static str {
        self.plan.design.name()
    }
    /// The experiments, in order.
    #[getter]
    fn experiments(&self) -> Vec<PyExperiment> {
        (0..self.plan.experiments.len())
            .map(|index| PyExperiment {
                plan: self.plan.clone(),
                index,
            })
            .collect()
    }
    /// The experiment named `kind` ('nominal', 'G_static', 'G', 'H' or 'D').
    fn experiment(&self, kind: &str) -> PyResult<PyExperiment> {
        let k = kind.parse::<ExperimentKind>()?;
        let index = self
            .plan
            .experiments
            .iter()
            .position(|e| e.kind == k)
            .ok_or_else(|| Error::InvalidArgument {
                argument: "kind".into(),
                message: format!("the plan has no '{kind}' experiment"),
            })?;
        Ok(PyExperiment {
            plan: self.plan.clone(),
            index,
        })
    }
    fn __len__(&self) -> usize {
        self.plan.experiments.len()
    }
    /// The plan as JSON text.
    fn to_json(&self) -> String {
        Document::to_json(&*self.plan)
    }
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self {
            plan: Arc::new(<Plan as Document>::from_json(text)?),
        })
    }
    fn __repr__(&self) -> String {
        let kinds: Vec<String> = self
            .plan
            .experiments
            .iter()
            .map(|e| format!("{}: {:.1} s", e.kind.name(), e.duration()))
            .collect();
        format!(
            "Plan(robot='{}', rate={} Hz, experiments=[{}])",
            self.plan.robot,
            self.plan.rate,
            kinds.join(", ")
        )
    }
}

/// One experiment of a plan: a trajectory from rest to rest through K crossings.
///
/// `t` (s, shape `(m,)`), `q`, `qd`, `qdd` (shape `(m, n)`) are its samples at the plan's rate;
/// `crossing_times` (s, `(K,)`) when it passes the perturbed operating point; `deltas` (`(K, n)`)
/// the planned perturbations of the perturbed variable.
#[pyclass(name = "Experiment", module = "perturbid_rs", frozen)]
pub(crate) struct PyExperiment {
    plan: Arc<Plan>,
    index: usize,
}

impl PyExperiment {
    fn exp(&self) -> &crate::local::Experiment {
        &self.plan.experiments[self.index]
    }
    fn samples(&self) -> crate::trajectory::Samples {
        self.exp().trajectory.sample(self.plan.rate)
    }
}

#[pymethods]
impl PyExperiment {
    /// 'nominal', 'G_static', 'G', 'H' or 'D'.
    #[getter]
    fn kind(&self) -> &'static str {
        self.exp().kind.name()
    }
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.samples().t)
    }
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.samples().q, self.plan.n())
    }
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.samples().qd, self.plan.n())
    }
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.samples().qdd, self.plan.n())
    }
    #[getter]
    fn crossing_times<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(
            py,
            &self
                .exp()
                .crossings
                .iter()
                .map(|c| c.time)
                .collect::<Vec<_>>(),
        )
    }
    /// G-static only: time (s) of the reference rest posture at `q*`; otherwise None.
    #[getter]
    fn reference_time(&self) -> Option<f64> {
        self.exp().reference.as_ref().map(|c| c.time)
    }
    #[getter]
    fn deltas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.exp().deltas)
    }
    /// Half-width (s) of the window around each crossing where the trajectory is exactly the
    /// crossing's quadratic.
    #[getter]
    fn window(&self) -> f64 {
        self.exp().window
    }
    #[getter]
    fn duration(&self) -> f64 {
        self.exp().duration()
    }
    /// cond(X) of the perturbations, each joint's column scaled to unit norm (1 for an
    /// orthogonal design; the planner warns above 30); None for the nominal experiment.
    #[getter]
    fn cond(&self) -> Option<f64> {
        self.exp().design_cond()
    }
    fn __repr__(&self) -> String {
        let e = self.exp();
        format!(
            "Experiment('{}', crossings={}, duration={:.2} s)",
            e.kind.name(),
            e.crossings.len(),
            e.duration()
        )
    }
}

/// Plans the experiments at `op` for `robot`. See the Rust `PlanOptions` for every default.
///
/// - `design`: 'random' (the paper's draws) or 'orthogonal' (cond(X) = 1);
/// - `n`: perturbations per experiment (default 2N, symmetric +- pairs);
/// - `dq`, `dqd`, `dqdd`: absolute perturbation sizes (a number or one per joint; rad, rad/s,
///   rad/s^2), else `dq_fraction` of the position range (0.01), `dqd_fraction` of the speed
///   limit (0.05), `dqdd_fraction` of the acceleration limit (0.05);
/// - `rate` (Hz), `window` (crossing half-width, s), `dwell` (static hold, s), `margin`
///   (fraction of speed/acceleration limits transitions may use);
/// - `experiments`: a subset of ['nominal', 'G_static', 'G', 'H', 'D'];
/// - `keep_velocity_sign`: keep the velocity perturbations below 0.9 |qd*| of each joint, so
///   that friction cancels from H* (otherwise a joint they reverse gets a PerturbidWarning);
/// - `friction_aware_h`: plan 2 (N + 2) H passes (N + 1 pairs determine it, one more gives its standard errors) for `identify_local(friction_aware_h=True)`;
/// - `encoder_step`: the steps the robot's encoders log positions in (rad, or m for a
///   prismatic joint; a number or one per joint, 0 for unknown), when known: each experiment's
///   crossings are read as the identification will read them, and the joints whose
///   perturbations they would resolve to worse than a tenth get a warning with the window or
///   perturbation size that would resolve them (a revolution of 4,096 counts: 2 pi / 4096).
///
/// Raises InputError when the plan would break a joint limit (naming joint, time and limit).
/// The planner's warnings are issued as `PerturbidWarning` and kept in `Plan.warnings`.
#[pyfunction]
#[pyo3(signature = (robot, op, design="random", n=None, seed=0, rate=1000.0, *, experiments=None, dq=None, dqd=None, dqdd=None,
    dq_fraction=0.01, dqd_fraction=0.05, dqdd_fraction=0.05, window=0.05, dwell=1.0, margin=0.8, symmetric=true, keep_velocity_sign=false, friction_aware_h=false, encoder_step=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_experiments(
    py: Python<'_>,
    robot: &PyRobot,
    op: &PyOperatingPoint,
    design: &str,
    n: Option<usize>,
    seed: u64,
    rate: f64,
    experiments: Option<Vec<String>>,
    dq: Option<Bound<'_, PyAny>>,
    dqd: Option<Bound<'_, PyAny>>,
    dqdd: Option<Bound<'_, PyAny>>,
    dq_fraction: f64,
    dqd_fraction: f64,
    dqdd_fraction: f64,
    window: f64,
    dwell: f64,
    margin: f64,
    symmetric: bool,
    keep_velocity_sign: bool,
    friction_aware_h: bool,
    encoder_step: Option<Bound<'_, PyAny>>,
) -> PyResult<PyPlan> {
    let nv = robot.model.nv;
    let size = |name: &str, abs: &Option<Bound<'_, PyAny>>, frac: f64| -> PyResult<Size> {
        Ok(match abs {
            Some(v) => Size::Absolute(per_joint(name, v, nv)?),
            None => Size::Fraction(frac),
        })
    };
    let mut options = PlanOptions {
        design: design.parse::<Design>()?,
        count: n,
        seed,
        rate,
        window,
        dwell,
        margin,
        symmetric,
        keep_velocity_sign,
        friction_aware_h,
        encoder_step: encoder_step
            .map(|v| per_joint("encoder_step", &v, nv))
            .transpose()?,
        ..PlanOptions::default()
    };
    options.sizes.position = size("dq", &dq, dq_fraction)?;
    options.sizes.velocity = size("dqd", &dqd, dqd_fraction)?;
    options.sizes.acceleration = size("dqdd", &dqdd, dqdd_fraction)?;
    if let Some(list) = experiments {
        options.experiments = list
            .iter()
            .map(|k| k.parse::<ExperimentKind>())
            .collect::<Result<_>>()?;
    }
    let plan = detached(py, "plan_experiments", || {
        plan_rs(&robot.model, &op.op, &options)
    })?;
    super::errors::warn_all(py, &plan.warnings)?;
    Ok(PyPlan {
        plan: Arc::new(plan),
    })
}

/// Identifies the local model from `plan` and `recordings`: one per experiment, in any order,
/// each saying which experiment it is a run of (`Recording.experiment`, set by `simulate`, or a
/// name such as `D.csv`).
///
/// - `crossing_times`: 'detected' (default: each recording's clock offset from the plan is
///   found in its positions, sub-sample, and refused above `max_shift` s; the offsets are in
///   `diagnostics['offsets']`) or 'planned' (the recording's clock starts with the plan);
/// - `window`: half-width (s) of the fits around each crossing (default: the plan's);
/// - `torque_degree`: degree of the torque fit (default 6);
/// - `recorded_derivatives`: use the recordings' qd/qdd columns instead of differentiating q;
/// - `estimator`: 'separated' (the paper) or 'combined' (all crossings in one regression);
/// - `friction_aware_h`: H* from the differences of the H passes' +- pairs with each joint's
///   Coulomb step as its own column (exact for viscous and Coulomb friction that reverses
///   between passes; the plan needs `friction_aware_h=True`); the steps are in
///   `LocalModel.coulomb`.
#[pyfunction]
#[pyo3(signature = (plan, recordings, crossing_times="detected", max_shift=0.5, window=None, torque_degree=6, recorded_derivatives=false, estimator="separated", friction_aware_h=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_local(
    py: Python<'_>,
    plan: &PyPlan,
    recordings: Vec<Bound<'_, PyRecording>>,
    crossing_times: &str,
    max_shift: f64,
    window: Option<f64>,
    torque_degree: usize,
    recorded_derivatives: bool,
    estimator: &str,
    friction_aware_h: bool,
) -> PyResult<PyLocalModel> {
    let times = match crossing_times {
        "planned" => CrossingTimes::Planned,
        "detected" => CrossingTimes::Detected { max_shift },
        other => {
            return Err(Error::InvalidArgument {
                argument: "crossing_times".into(),
                message: format!("'{other}'; expected 'planned' or 'detected'"),
            }
            .into())
        }
    };
    let options = IdentifyOptions {
        times,
        fit: FitOptions {
            window,
            torque_degree,
            recorded_derivatives,
        },
        estimator: estimator.parse::<Estimator>()?,
        friction_aware_h,
    };
    let recs: Vec<Recording> = recordings.iter().map(|r| (*r.get().rec).clone()).collect();
    let plan = plan.plan.clone();
    let model = detached(py, "identify_local", || identify_rs(&plan, &recs, &options))?;
    super::errors::warn_all(py, &model.diagnostics.warnings)?;
    Ok(PyLocalModel { model })
}

/// The local model `tau ~= T* + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)` at an operating
/// point, with its uncertainty.
///
/// - `torque` (`T*`, `(n,)`), `D`, `H`, `G`, `G_static` (`(n, n)`, row = torque, column =
///   joint; None when the plan had no such experiment);
/// - `cond`: dict of cond(X) per estimate (columns scaled to unit norm);
/// - `stderr`: dict of standard errors, same shapes ('torque', 'D', 'H', 'G', 'G_static');
/// - `residual_rms`: dict of per-joint regression residual RMS (N m);
/// - `planned_op`: the operating point of the plan, which the nominal passes crossed: T* holds
///   there and `predict` expands about it; `op`: the point as measured at the nominal crossings
///   (a diagnostic of the tracking; noisier than the plan);
/// - `diagnostics`: clock offsets, velocity reversals met at crossings, warnings;
/// - `coulomb`: the Coulomb steps of the friction-aware H regression, when used.
#[pyclass(name = "LocalModel", module = "perturbid_rs", frozen)]
pub(crate) struct PyLocalModel {
    pub model: LocalModel,
}

impl PyLocalModel {
    fn parts(&self) -> [(&'static str, &Option<Estimate>); 4] {
        let m = &self.model;
        [
            ("D", &m.d),
            ("H", &m.h),
            ("G", &m.g),
            ("G_static", &m.g_static),
        ]
    }
    fn get<'py>(
        &self,
        py: Python<'py>,
        e: &Option<Estimate>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        e.as_ref().map(|e| mat(py, &e.matrix)).transpose()
    }
}

#[pymethods]
impl PyLocalModel {
    /// What happened during the identification: `offsets` (dict experiment -> clock offset
    /// in s found between the recording and the plan), `reversals` (list of dicts:
    /// `experiment`, `crossing` (None for the reference posture), `joint`, `at` (s from the
    /// crossing), `handling` ('narrowed' or 'step'), `window` (s)), `combined` (dict block ->
    /// (relative difference, largest difference in standard errors) of the combined estimate
    /// against the separated one), `unperturbed_deviation` (how far the variables an experiment
    /// did not perturb stray, in standard errors of their measurement: ~1 for noise, far above
    /// for tracking errors), `unmeasured` (list of dicts: `experiment`, `joint`, `value` in N m,
    /// for torques that read one value throughout), `noise` (list of dicts: `experiment`,
    /// `joint`, `samples` (N m, one torque sample's noise), `passes` (N m, what varied from pass
    /// to pass beyond it, or None), `step` (N m, the step the torque was logged in where it is
    /// coarser than its noise: the standard errors of its rows include the rounding; else
    /// None)), `glitches` (list of dicts: `experiment`, `crossing` (None for the reference
    /// posture), `signal` ('q', 'qd', 'qdd' or 'tau'), `joint`, `sample` (0-based index in its
    /// recording), `time` (s, the recording's clock), `value` (as recorded), `noise_levels`
    /// (how far off the fit of its window's other samples, or None beyond any scale: a million
    /// times the spread of the window's values),
    /// `replaced` (True: an isolated glitch replaced by that fit; False: kept, one of more than
    /// 3 in its window)), `dropouts` (list of dicts: `experiment`, `signal`, `first_sample`
    /// (0-based row of its recording), `samples`, `from`, `to` (s): rows in which every joint
    /// of a signal read exactly 0 while the robot moved, removed before the windows were
    /// read), `held_readings` (list of dicts: `experiment` and the keys of
    /// `Recording.glitches`: samples of one joint's reading held while it moved, replaced
    /// before the windows were read), `warnings` (list of str).
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = &self.model.diagnostics;
        let out = PyDict::new(py);
        let offsets = PyDict::new(py);
        for o in &d.offsets {
            offsets.set_item(&o.experiment, o.offset)?;
        }
        out.set_item("offsets", offsets)?;
        let reversals = d
            .reversals
            .iter()
            .map(|r| {
                let e = PyDict::new(py);
                e.set_item("experiment", &r.experiment)?;
                e.set_item("crossing", r.crossing)?;
                e.set_item("joint", &r.joint)?;
                e.set_item("at", r.at)?;
                let handling = match r.handling {
                    ReversalHandling::Narrowed => "narrowed",
                    ReversalHandling::Step => "step",
                };
                e.set_item("handling", handling)?;
                e.set_item("window", r.window)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("reversals", reversals)?;
        let combined = PyDict::new(py);
        for b in &d.combined {
            combined.set_item(&b.block, (b.relative, b.standard_errors))?;
        }
        out.set_item("combined", combined)?;
        out.set_item("unperturbed_deviation", d.unperturbed_deviation)?;
        let unmeasured = d
            .unmeasured
            .iter()
            .map(|u| {
                let e = PyDict::new(py);
                e.set_item("experiment", &u.experiment)?;
                e.set_item("joint", &u.joint)?;
                e.set_item("value", u.value)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("unmeasured", unmeasured)?;
        let noise = d
            .noise
            .iter()
            .map(|e| {
                let entry = PyDict::new(py);
                entry.set_item("experiment", &e.experiment)?;
                entry.set_item("joint", &e.joint)?;
                entry.set_item("samples", e.samples)?;
                entry.set_item("passes", e.passes)?;
                entry.set_item("step", e.step)?;
                entry.set_item("position_step", e.position_step)?;
                Ok(entry)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("noise", noise)?;
        let glitches = d
            .glitches
            .iter()
            .map(|g| {
                let e = PyDict::new(py);
                e.set_item("experiment", &g.experiment)?;
                e.set_item("crossing", g.crossing)?;
                e.set_item("signal", &g.signal)?;
                e.set_item("joint", &g.joint)?;
                e.set_item("sample", g.sample)?;
                e.set_item("time", g.time)?;
                e.set_item("value", g.value)?;
                e.set_item("noise_levels", g.noise_levels)?;
                e.set_item("replaced", g.replaced)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("glitches", glitches)?;
        let dropouts = d
            .dropouts
            .iter()
            .map(|r| super::recording::dropout_dict(py, r))
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("dropouts", dropouts)?;
        let held = d
            .held_readings
            .iter()
            .map(|g| super::recording::glitch_dict(py, g))
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("held_readings", held)?;
        out.set_item("warnings", d.warnings.clone())?;
        Ok(out)
    }

    /// The Coulomb steps from the friction-aware H regression (None when it was not used):
    /// dict joint name -> step (N m; the two Coulomb levels summed) or None where no pair of H
    /// passes reversed the joint.
    #[getter]
    fn coulomb<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(c) = &self.model.coulomb else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        for (name, step) in c.joint_names.iter().zip(&c.step) {
            out.set_item(name, *step)?;
        }
        Ok(Some(out))
    }

    /// The model as a tidy table (pandas): one row per entry, columns `term` ('T', 'D', 'H',
    /// 'G', 'G_static'), `torque` (the joint whose torque the row is), `joint` (the joint
    /// whose change multiplies the entry; empty for T*), `value` and `std` (NaN where
    /// unknown). Units: N m for T*; N m s^2/rad, N m s/rad, N m/rad for D*, H*, G* (m in
    /// place of rad for prismatic joints).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.model;
        type Part<'a> = (
            &'a str,
            &'a nalgebra::DMatrix<f64>,
            &'a nalgebra::DMatrix<f64>,
        );
        let parts: Vec<Part<'_>> = self
            .parts()
            .iter()
            .filter_map(|(k, e)| e.as_ref().map(|e| (*k, &e.matrix, &e.stderr)))
            .collect();
        super::tables::linear_model_frame(py, &m.joint_names, &m.torque, &m.torque_stderr, &parts)
    }
    #[getter]
    fn torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.model.torque)
    }
    #[getter(D)]
    fn d<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.d)
    }
    #[getter(H)]
    fn h<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.h)
    }
    #[getter(G)]
    fn g<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.g)
    }
    #[getter(G_static)]
    fn g_static<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.g_static)
    }
    /// The combined estimate `[D H G]`, shape `(n, 3n)`, or None.
    #[getter]
    fn combined<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.combined)
    }
    #[getter]
    fn cond<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, e.cond)?;
            }
        }
        Ok(d)
    }
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("torque", vec1(py, &self.model.torque_stderr))?;
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, mat(py, &e.stderr)?)?;
            }
        }
        Ok(d)
    }
    #[getter]
    fn residual_rms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, vec1(py, &e.residual_rms))?;
            }
        }
        Ok(d)
    }
    #[getter]
    fn op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.model.op.clone(),
        }
    }
    #[getter]
    fn planned_op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.model.planned_op.clone(),
        }
    }
    #[getter]
    fn joint_names<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, &self.model.joint_names)
    }
    #[getter]
    fn estimator(&self) -> &'static str {
        match self.model.estimator {
            Estimator::Separated => "separated",
            Estimator::Combined => "combined",
        }
    }
    /// The model at `op` (an OperatingPoint): dict `torque` (n,, its prediction there), `D`,
    /// `H`, `G` (n, n; the same everywhere), `G_static` (n, n, or None without that
    /// experiment): the question every identified model answers the same way.
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        op: &PyOperatingPoint,
    ) -> PyResult<Bound<'py, PyDict>> {
        let e = crate::torque_model::TorqueModel::linearize(&self.model, &op.op)?;
        super::arrays::expansion_dict(py, &e)
    }
    /// Predicted torques (N m) at `q`, `qd`, `qdd`: shape `(n,)` each or a batch `(k, n)`;
    /// `T* + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)` about the planned operating point.
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.n();
        let batch = read_batch(n, &[("q", &q), ("qd", &qd), ("qdd", &qdd)])?;
        let out = self.model.predict(&batch.states(n)?)?;
        to_numpy(py, out, batch.k, batch.single, &[n])
    }
    /// The model as JSON text (matrices as lists of rows).
    fn to_json(&self) -> String {
        Document::to_json(&self.model)
    }
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self {
            model: <LocalModel as Document>::from_json(text)?,
        })
    }
    fn __repr__(&self) -> String {
        let parts: Vec<String> = self
            .parts()
            .iter()
            .filter_map(|(k, e)| e.as_ref().map(|e| format!("{k}: cond {:.3}", e.cond)))
            .collect();
        format!(
            "LocalModel(robot='{}', {} estimator, {})",
            self.model.robot,
            self.estimator(),
            parts.join(", ")
        )
    }
}

/// The robot's parameters from local models at one or more operating points: T*, D*, H*, G*,
/// Gs (those identified, and switched on by `use`, a subset of ['torque', 'D', 'H', 'G',
/// 'G_static']) stacked into one linear system in the inertial parameters (and the
/// `friction` terms: a comma-separated string or list from 'viscous', 'coulomb', 'offset'),
/// weighted by the models' standard errors. `gravity`: whether the models' torques include
/// gravity. Returns `(model, info)`: a BaseParameterModel of the combinations the points
/// identify, and a dict `rank`, `robot_rank` (the robot's base parameters), `unidentified`
/// (the robot's base parameters these points cannot separate) and `rows`. With
/// `consistent=True` the dict also holds `consistent`: a ConsistentFit of the same rows (the
/// robot's own parameters as the weak prior).
#[pyfunction]
#[pyo3(signature = (robot, models, *, friction=None, gravity=true, r#use=None, consistent=false))]
pub(crate) fn identify_parameters_from_local<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    models: Vec<PyRef<'py, PyLocalModel>>,
    friction: Option<Bound<'py, PyAny>>,
    gravity: bool,
    r#use: Option<Vec<String>>,
    consistent: bool,
) -> PyResult<(super::direct::PyBaseModel, Bound<'py, PyDict>)> {
    use crate::local::{identify_parameters_from_local as from_local, FromLocalOptions};
    let mut options = FromLocalOptions {
        gravity: gravity.into(),
        friction: super::arrays::friction_terms(friction.as_ref())?,
        consistent: consistent.then(crate::direct::ConsistentOptions::default),
        ..FromLocalOptions::default()
    };
    super::arrays::local_parts(r#use, &mut options)?;
    let local: Vec<LocalModel> = models.iter().map(|m| m.model.clone()).collect();
    let model = &robot.model;
    let out = detached(py, "identify_parameters_from_local", || {
        from_local(model, &local, &options)
    })?;
    let info = PyDict::new(py);
    info.set_item("rank", out.rank)?;
    info.set_item("robot_rank", out.robot_rank)?;
    info.set_item("unidentified", out.unidentified.clone())?;
    info.set_item("rows", out.rows)?;
    if let Some(fit) = out.consistent {
        info.set_item(
            "consistent",
            super::consistent::PyConsistentFit {
                fit,
                model: Arc::new(model.clone()),
            },
        )?;
    }
    Ok((
        super::direct::PyBaseModel {
            fit: out.model,
            model: Arc::new(model.clone()),
        },
        info,
    ))
}

/// Operating points to add so that local models there identify every base parameter: greedy
/// D-optimal choice of `count` points among `candidates` random ones within the limits
/// (seeded), given the points already used (`existing`, OperatingPoints). `use` and `friction`
/// as in `identify_parameters_from_local`. Returns a list of `(OperatingPoint, rank)`: the
/// base parameters identified once that point is added.
#[pyfunction]
#[pyo3(signature = (robot, existing=Vec::new(), *, candidates=200, count=3, seed=0, r#use=None))]
pub(crate) fn suggest_operating_points(
    py: Python<'_>,
    robot: &PyRobot,
    existing: Vec<PyRef<'_, PyOperatingPoint>>,
    candidates: usize,
    count: usize,
    seed: u64,
    r#use: Option<Vec<String>>,
) -> PyResult<Vec<(PyOperatingPoint, usize)>> {
    use crate::local::{suggest_operating_points as suggest, FromLocalOptions};
    let mut options = FromLocalOptions::default();
    super::arrays::local_parts(r#use, &mut options)?;
    let existing: Vec<OperatingPoint> = existing.iter().map(|o| o.op.clone()).collect();
    let model = &robot.model;
    let picks = detached(py, "suggest_operating_points", || {
        suggest(model, &existing, &options, candidates, count, seed)
    })?;
    Ok(picks
        .into_iter()
        .map(|p| (PyOperatingPoint { op: p.op }, p.rank))
        .collect())
}
