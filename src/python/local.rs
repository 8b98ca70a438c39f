//! The paper's method in Python: `OperatingPoint`, `Plan` and `Experiment`, `Recording`,
//! `LocalModel`, and the functions `plan_experiments`, `simulate` and `identify_local`.

use std::sync::Arc;

use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::arrays::{matrix_to_numpy as mat, read_batch, to_numpy};
use super::robot::PyRobot;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::local::{
    identify_local as identify_rs, plan_experiments as plan_rs, CrossingTimes, Design, Estimate,
    Estimator, ExperimentKind, FitOptions, IdentifyOptions, LocalModel, OperatingPoint, Plan,
    PlanOptions, Size,
};
use crate::recording::Recording;
use crate::simulation::{simulate_plan, Friction, SimulationOptions};

type ArrayLike<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

fn vec1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyAny> {
    PyArray1::from_slice(py, v).into_any()
}

fn rows<'py>(py: Python<'py>, v: &[f64], n: usize) -> PyResult<Bound<'py, PyAny>> {
    to_numpy(py, v.to_vec(), v.len() / n.max(1), false, &[n])
}

/// A 1-D array-like of length `n` (or a scalar broadcast to `n`).
fn per_joint(name: &str, value: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f64>> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok(vec![x; n]);
    }
    let arr: ArrayLike<'_> = value.extract().map_err(|_| Error::InvalidArgument {
        argument: name.into(),
        message: "expected a number or a sequence of numbers".into(),
    })?;
    if arr.shape() != [n] {
        return Err(Error::Shape {
            argument: name.into(),
            expected: format!("a number or shape ({n},)"),
            got: format!("shape {:?}", arr.shape()),
        }
        .into());
    }
    Ok(arr.as_array().iter().copied().collect())
}

fn vector(name: &str, a: &ArrayLike<'_>) -> Result<Vec<f64>> {
    if a.ndim() != 1 {
        return Err(Error::Shape {
            argument: name.into(),
            expected: "a 1-D array".into(),
            got: format!("shape {:?}", a.shape()),
        });
    }
    Ok(a.as_array().iter().copied().collect())
}

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
/// - `experiments`: a subset of ['nominal', 'G_static', 'G', 'H', 'D'].
///
/// Raises InputError when the plan would break a joint limit (naming joint, time and limit).
#[pyfunction]
#[pyo3(signature = (robot, op, design="random", n=None, seed=0, rate=1000.0, *, experiments=None, dq=None, dqd=None, dqdd=None,
    dq_fraction=0.01, dqd_fraction=0.05, dqdd_fraction=0.05, window=0.05, dwell=1.0, margin=0.8, symmetric=true))]
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
    let plan = py.detach(|| plan_rs(&robot.model, &op.op, &options))?;
    Ok(PyPlan {
        plan: Arc::new(plan),
    })
}

/// A recording of one run: `t` (s, `(m,)`, increasing), `q` (rad, `(m, n)`), `tau` (N m,
/// `(m, n)`), and optionally `qd`, `qdd` when the robot logs them.
#[pyclass(name = "Recording", module = "perturbid_rs", frozen)]
#[derive(Clone)]
pub(crate) struct PyRecording {
    pub rec: Arc<Recording>,
}

fn matrix_rows(
    name: &str,
    a: &ArrayLike<'_>,
    m: usize,
    n: Option<usize>,
) -> Result<(usize, Vec<f64>)> {
    let shape = a.shape().to_vec();
    match shape.as_slice() {
        [rows, cols] if *rows == m && n.is_none_or(|n| n == *cols) => {
            Ok((*cols, a.as_array().iter().copied().collect()))
        }
        _ => Err(Error::Shape {
            argument: name.into(),
            expected: format!(
                "shape ({m}, {}) like t",
                n.map_or("n".to_string(), |n| n.to_string())
            ),
            got: format!("shape {shape:?}"),
        }),
    }
}

impl PyRecording {
    /// A checked recording from numpy arrays.
    pub(crate) fn build(
        t: ArrayLike<'_>,
        q: ArrayLike<'_>,
        tau: ArrayLike<'_>,
        qd: Option<ArrayLike<'_>>,
        qdd: Option<ArrayLike<'_>>,
        name: &str,
    ) -> Result<Recording> {
        let t = vector("t", &t)?;
        let m = t.len();
        let (n, q) = matrix_rows("q", &q, m, None)?;
        let (_, tau) = matrix_rows("tau", &tau, m, Some(n))?;
        let qd = qd
            .map(|a| matrix_rows("qd", &a, m, Some(n)).map(|r| r.1))
            .transpose()?;
        let qdd = qdd
            .map(|a| matrix_rows("qdd", &a, m, Some(n)).map(|r| r.1))
            .transpose()?;
        Recording::new(name, n, t, q, tau, qd, qdd)
    }
}

#[pymethods]
impl PyRecording {
    #[new]
    #[pyo3(signature = (t, q, tau, qd=None, qdd=None, name="recording"))]
    fn new(
        t: ArrayLike<'_>,
        q: ArrayLike<'_>,
        tau: ArrayLike<'_>,
        qd: Option<ArrayLike<'_>>,
        qdd: Option<ArrayLike<'_>>,
        name: &str,
    ) -> PyResult<Self> {
        Ok(Self {
            rec: Arc::new(Self::build(t, q, tau, qd, qdd, name)?),
        })
    }
    #[getter]
    fn name(&self) -> String {
        self.rec.name.clone()
    }
    #[getter]
    fn n(&self) -> usize {
        self.rec.n
    }
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.rec.t)
    }
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.rec.q, self.rec.n)
    }
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.rec.tau, self.rec.n)
    }
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.rec
            .qd
            .as_ref()
            .map(|v| rows(py, v, self.rec.n))
            .transpose()
    }
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.rec
            .qdd
            .as_ref()
            .map(|v| rows(py, v, self.rec.n))
            .transpose()
    }
    fn __len__(&self) -> usize {
        self.rec.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "Recording('{}', samples={}, joints={})",
            self.rec.name,
            self.rec.len(),
            self.rec.n
        )
    }
}

/// The `friction` argument of `simulate`: a name ('urdf') or anything else (a dict).
#[derive(FromPyObject)]
pub(crate) enum FrictionArg<'py> {
    Name(String),
    Other(Bound<'py, PyAny>),
}

/// Simulates what the robot would log running every experiment of `plan`: torques from the
/// dynamics with `gravity`, `friction` ('urdf', the default: the URDF's `<dynamics damping
/// friction>`; None: none; or a dict with 'viscous' and 'coulomb', a number or one per joint), Gaussian `torque_noise` (N m) and
/// `position_noise` (rad) standard deviations, encoder `quantization` (rad per count), seeded.
/// Returns one Recording per experiment, in the plan's order.
#[pyfunction]
#[pyo3(signature = (robot, plan, gravity=true, friction=Some(FrictionArg::Name("urdf".into())), torque_noise=None, position_noise=None, quantization=None, seed=0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate(
    py: Python<'_>,
    robot: &PyRobot,
    plan: &PyPlan,
    gravity: bool,
    friction: Option<FrictionArg<'_>>,
    torque_noise: Option<Bound<'_, PyAny>>,
    position_noise: Option<Bound<'_, PyAny>>,
    quantization: Option<Bound<'_, PyAny>>,
    seed: u64,
) -> PyResult<Vec<PyRecording>> {
    let model = &robot.model;
    let n = model.nv;
    let mut o = SimulationOptions::new(model);
    o.gravity = gravity.into();
    o.seed = seed;
    let refuse = |what: String| Error::InvalidArgument {
        argument: "friction".into(),
        message: format!("{what}; expected 'urdf', None or a dict with 'viscous' and 'coulomb'"),
    };
    o.friction = match &friction {
        None => Friction::none(n),
        Some(FrictionArg::Name(name)) if name == "urdf" => Friction::from_model(model),
        Some(FrictionArg::Name(name)) => return Err(refuse(format!("'{name}'")).into()),
        Some(FrictionArg::Other(f)) => {
            let d = f.cast::<PyDict>().map_err(|_| refuse(f.to_string()))?;
            let get = |k: &str| -> PyResult<Vec<f64>> {
                match d.get_item(k)? {
                    Some(v) => per_joint(&format!("friction['{k}']"), &v, n),
                    None => Ok(vec![0.0; n]),
                }
            };
            Friction {
                viscous: get("viscous")?,
                coulomb: get("coulomb")?,
            }
        }
    };
    for (target, name, value) in [
        (&mut o.torque_noise, "torque_noise", &torque_noise),
        (&mut o.position_noise, "position_noise", &position_noise),
        (&mut o.quantization, "quantization", &quantization),
    ] {
        if let Some(v) = value {
            *target = per_joint(name, v, n)?;
        }
    }
    let plan = plan.plan.clone();
    let recs = py.detach(|| simulate_plan(model, &plan, &o))?;
    Ok(recs
        .into_iter()
        .map(|r| PyRecording { rec: Arc::new(r) })
        .collect())
}

/// Identifies the local model from `plan` and `recordings` (one per experiment, in order).
///
/// - `crossing_times`: 'planned' (the recording's clock starts with the plan) or 'detected'
///   (the offset between plan and recording is found in the data, within `max_shift` s);
/// - `window`: half-width (s) of the fits around each crossing (default: the plan's);
/// - `torque_degree`: degree of the torque fit (default 6);
/// - `recorded_derivatives`: use the recordings' qd/qdd columns instead of differentiating q;
/// - `estimator`: 'separated' (the paper) or 'combined' (all crossings in one regression).
#[pyfunction]
#[pyo3(signature = (plan, recordings, crossing_times="planned", max_shift=1.0, window=None, torque_degree=6, recorded_derivatives=false, estimator="separated"))]
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
    };
    let recs: Vec<Recording> = recordings.iter().map(|r| (*r.get().rec).clone()).collect();
    let plan = plan.plan.clone();
    let model = py.detach(|| identify_rs(&plan, &recs, &options))?;
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
/// - `op`: the operating point measured at the nominal crossings; `planned_op` the planned one.
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
    /// Predicted torques (N m) at `q`, `qd`, `qdd`: shape `(n,)` each or a batch `(k, n)`.
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
