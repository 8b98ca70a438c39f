//! The paper's method in Python: `Plan` and `Experiment`, and the functions
//! `plan_experiments`, `identify_local`, `identify_parameters_from_local` and
//! `suggest_operating_points` (mirrors `crate::local`; the `LocalModel` they return and take is
//! in `local_model.rs`).

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;

use super::scalars;

use super::detached;
use pyo3::types::PyDict;

use super::arrays::{matrix_to_numpy as mat, per_joint, rows, vec1};
use super::local_model::PyLocalModel;
use super::operating_point::PyOperatingPoint;
use super::recording::PyRecording;
use super::robot::PyRobot;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::local::{
    identify_local as identify_rs, plan_experiments as plan_rs, CrossingTimes, Design, Estimator,
    ExperimentKind, FitOptions, IdentifyOptions, LocalModel, OperatingPoint, Plan, PlanOptions,
    Size,
};
use crate::logs::recording::Recording;

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
    /// The next round's plan from this round's recordings (one per experiment): every
    /// experiment's trajectory commanded off its crossings by what the robot missed them by
    /// (`commanded += planned - measured`, on top of earlier rounds'), its crossings and their
    /// times kept, so that a robot tracking it with the same errors passes them. With
    /// `robot`, each refined trajectory is checked against its limits. Identify the next
    /// round's recordings with the refined plan.
    #[pyo3(signature = (recordings, robot=None))]
    fn refine(
        &self,
        py: Python<'_>,
        recordings: Vec<Bound<'_, PyRecording>>,
        robot: Option<PyRef<'_, super::robot::PyRobot>>,
    ) -> PyResult<PyPlan> {
        let recs: Vec<Recording> = recordings.iter().map(|r| (*r.get().rec).clone()).collect();
        let plan = self.plan.clone();
        let model = robot.map(|r| r.model.clone());
        let refined = detached(py, "refine", || {
            crate::local::refine_plan(&plan, &recs, &IdentifyOptions::default(), model.as_ref())
        })?;
        Ok(PyPlan {
            plan: Arc::new(refined),
        })
    }

    /// The experiment named `kind` ('nominal', 'G_static', 'G', 'H' or 'D').
    fn experiment(&self, kind: &str) -> PyResult<PyExperiment> {
        let k = kind.parse::<ExperimentKind>()?;
        let index = self
            .plan
            .experiments
            .iter()
            .position(|e| e.kind == k)
            .ok_or_else(|| {
                Error::invalid("kind", format!("the plan has no '{kind}' experiment"))
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
    /// Writes the plan into `folder` as `perturbid plan` does, for the robot's controller:
    /// one `<experiment>.csv` per experiment (`t` in s, `q1..qN` in rad or m, `qd1..qN`,
    /// `qdd1..qN`, at the plan's rate) and `plan.json`, all or none (an interrupted write
    /// leaves the previous set whole); returns the paths written, in that order. Raises
    /// FileError when the folder cannot be written, InputError when it holds another output
    /// set's files of the same names (recordings: choose another folder).
    fn save(&self, py: Python<'_>, folder: PathBuf) -> PyResult<Vec<PathBuf>> {
        let plan = self.plan.clone();
        Ok(detached(py, "Plan.save", || {
            crate::local::plan_files::plan_files(&plan, &folder)?.commit()
        })?)
    }
    /// Splits `log`, one Recording of a whole session in which the robot ran this plan's
    /// experiments one after the other in the plan's order (moves and pauses of any length
    /// between them, on any clock), into one Recording per experiment, in the plan's order:
    /// each marked with its experiment, its time (s) on the plan's clock, holding its run and
    /// `margin` s either side (default 0.2), for `identify_local`. Each run is sought after the
    /// previous one where the log's positions follow the experiment's plan best. Raises
    /// InputError naming the experiment and the time in the log when a run does not fit where
    /// it must (out of order, missing, a log cut short) or its best stretch does not follow the
    /// plan; KeyboardInterrupt on Ctrl-C. An experiment that ran twice (its plan followed also
    /// between the runs next to it) gets a PerturbidWarning naming both stretches, and one
    /// inside whose run the log has a gap (lost samples, or a step of its clock) one naming it.
    #[pyo3(signature = (log, margin=0.2))]
    fn split_session(
        &self,
        py: Python<'_>,
        log: PyRef<'_, PyRecording>,
        #[pyo3(from_py_with = scalars::real)] margin: f64,
    ) -> PyResult<Vec<PyRecording>> {
        let (plan, log) = (self.plan.clone(), log.rec.clone());
        let (runs, repeated) = detached(py, "Plan.split_session", || {
            let runs =
                crate::local::split_session(&plan, &log, &crate::local::SplitOptions { margin })?;
            let mut repeated = crate::local::repeated_runs(&plan, &log, &runs)?;
            repeated.extend(crate::local::gaps_in_runs(&plan, &log, &runs));
            Ok((runs, repeated))
        })?;
        super::errors::warn_all(py, &repeated)?;
        Ok(runs
            .into_iter()
            .map(|(rec, _)| PyRecording::from(rec))
            .collect())
    }
    /// Reads a plan from `path` (the plan.json of `Plan.save` or `perturbid plan`), checked
    /// as `from_json` checks it; errors name the file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            plan: Arc::new(Plan::load(&path)?),
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
/// - `torque_noise`: the standard deviation of the robot's torque samples (N m, or N for a
///   prismatic joint; a number or one per joint, 0 for unknown), when known: each perturbed
///   experiment's torque changes are predicted from the model and the identification's
///   response test run on draws of that noise; an experiment it would find in fewer than 90 %
///   of runs gets a warning with the perturbation size that would resolve it.
/// - `torque_pass_noise`: what the torque readings vary by from pass to pass beyond the
///   samples' noise (N m a reading, a standard deviation; a number or one per joint, 0 for
///   none): noise slower than a window, a drifting sensor, repeatability, as an identification
///   reports it (`diagnostics['noise']`, `passes`). Added to every reading in the prediction;
///   needs `torque_noise` for each joint it is given for.
///
/// Raises InputError when the plan would break a joint limit (naming joint, time and limit).
/// The planner's warnings are issued as `PerturbidWarning` and kept in `Plan.warnings`.
#[pyfunction]
#[pyo3(signature = (robot, op, design="random", n=None, seed=0, rate=1000.0, *, experiments=None, dq=None, dqd=None, dqdd=None,
    dq_fraction=0.01, dqd_fraction=0.05, dqdd_fraction=0.05, window=0.05, dwell=1.0, margin=0.8, symmetric=true, keep_velocity_sign=false, friction_aware_h=false, encoder_step=None, torque_noise=None, torque_pass_noise=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_experiments(
    py: Python<'_>,
    robot: &PyRobot,
    op: &PyOperatingPoint,
    design: &str,
    #[pyo3(from_py_with = scalars::count_or_none)] n: Option<usize>,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
    #[pyo3(from_py_with = scalars::real)] rate: f64,
    experiments: Option<Vec<String>>,
    dq: Option<Bound<'_, PyAny>>,
    dqd: Option<Bound<'_, PyAny>>,
    dqdd: Option<Bound<'_, PyAny>>,
    #[pyo3(from_py_with = scalars::real)] dq_fraction: f64,
    #[pyo3(from_py_with = scalars::real)] dqd_fraction: f64,
    #[pyo3(from_py_with = scalars::real)] dqdd_fraction: f64,
    #[pyo3(from_py_with = scalars::real)] window: f64,
    #[pyo3(from_py_with = scalars::real)] dwell: f64,
    #[pyo3(from_py_with = scalars::real)] margin: f64,
    symmetric: bool,
    keep_velocity_sign: bool,
    friction_aware_h: bool,
    encoder_step: Option<Bound<'_, PyAny>>,
    torque_noise: Option<Bound<'_, PyAny>>,
    torque_pass_noise: Option<Bound<'_, PyAny>>,
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
        torque_noise: torque_noise
            .map(|v| per_joint("torque_noise", &v, nv))
            .transpose()?,
        torque_pass_noise: torque_pass_noise
            .map(|v| per_joint("torque_pass_noise", &v, nv))
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

/// `identify_local`'s `torque_delay` and `robot`: the delay in seconds, or 0 and the robot
/// whose model estimates it (`torque_delay='estimate'`); either without the other refused.
fn delay_choice(
    torque_delay: Option<&Bound<'_, PyAny>>,
    robot: Option<PyRef<'_, PyRobot>>,
) -> PyResult<(f64, Option<crate::model::Model>)> {
    let estimate = match torque_delay {
        Some(d) if d.extract::<String>().is_ok_and(|s| s == "estimate") => true,
        Some(d) if d.is_instance_of::<pyo3::types::PyString>() => {
            return Err(Error::invalid(
                "torque_delay",
                format!("'{d}'; expected a delay in seconds, or 'estimate'"),
            )
            .into())
        }
        _ => false,
    };
    let seconds = match (torque_delay, estimate) {
        (Some(d), false) => scalars::real(d)?,
        _ => 0.0,
    };
    let refuse = |message: &str| Err(Error::invalid("robot", message).into());
    match (robot, estimate) {
        (Some(r), true) => Ok((seconds, Some(r.model.clone()))),
        (None, true) => refuse("torque_delay='estimate' needs the plan's Robot: give robot="),
        (Some(_), false) => refuse(
            "only torque_delay='estimate' uses the robot; leave it out, or estimate the delay",
        ),
        (None, false) => Ok((seconds, None)),
    }
}

/// One earlier round of `identify_local(rounds=)`: its plan and recordings.
type Round<'py> = (PyRef<'py, PyPlan>, Vec<Bound<'py, PyRecording>>);

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
/// - `torque_delay`: how long after the positions the torque logs what belongs with them (s;
///   default 0; a sensor's or filter's delay): each torque is read that much later; or
///   'estimate': found in the recordings with `robot`'s rigid-body model (a held drive
///   command reads as half a sample early), kept in `diagnostics['torque_delay']`;
/// - `robot`: the plan's Robot, for `torque_delay='estimate'`;
/// - `rounds`: earlier rounds of the plan to pool with this one, `[(plan, recordings), ...]`
///   (the plans `Plan.refine` gave, or the first): their crossings are read against their own
///   plans and joined with these (`identify_local_rounds`); with `torque_delay='estimate'`
///   the delay is found over every round's recordings;
/// - `estimator`: 'separated' (the paper) or 'combined' (all crossings in one regression);
/// - `friction_aware_h`: H* from the differences of the H passes' +- pairs with each joint's
///   Coulomb step as its own column (exact for viscous and Coulomb friction that reverses
///   between passes; the plan needs `friction_aware_h=True`); the steps are in
///   `LocalModel.coulomb`;
/// - `drive_gains`: a BaseParameterModel from `identify_drive_gains`, for recordings whose
///   `tau` holds motor currents: each is put in torques by its gains (as
///   `Recording.in_torques`), the model keeps them (`LocalModel.drive_gains`) and their
///   standard errors enter its predictions' (as `perturbid identify --gains-from`).
#[pyfunction]
#[pyo3(signature = (plan, recordings, crossing_times="detected", max_shift=0.5, window=None, torque_degree=6, recorded_derivatives=false, estimator="separated", friction_aware_h=false, drive_gains=None, torque_delay=None, robot=None, rounds=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_local(
    py: Python<'_>,
    plan: &PyPlan,
    recordings: Vec<Bound<'_, PyRecording>>,
    crossing_times: &str,
    #[pyo3(from_py_with = scalars::real)] max_shift: f64,
    #[pyo3(from_py_with = scalars::real_or_none)] window: Option<f64>,
    #[pyo3(from_py_with = scalars::count)] torque_degree: usize,
    recorded_derivatives: bool,
    estimator: &str,
    friction_aware_h: bool,
    drive_gains: Option<PyRef<'_, super::direct::PyBaseModel>>,
    torque_delay: Option<Bound<'_, PyAny>>,
    robot: Option<PyRef<'_, super::robot::PyRobot>>,
    rounds: Option<Vec<Round<'_>>>,
) -> PyResult<PyLocalModel> {
    let (torque_delay, robot) = delay_choice(torque_delay.as_ref(), robot)?;
    let times = CrossingTimes::new(crossing_times.parse()?, max_shift);
    let options = IdentifyOptions {
        times,
        fit: FitOptions {
            window,
            torque_degree,
            recorded_derivatives,
            torque_delay,
        },
        estimator: estimator.parse::<Estimator>()?,
        friction_aware_h,
    };
    let gains = match &drive_gains {
        None => None,
        Some(m) => {
            let refuse = |message: String| Error::InvalidArgument {
                argument: "drive_gains".into(),
                message,
            };
            let g = (m.fit.drive_gains.as_ref()).ok_or_else(|| {
                refuse(
                    "the model holds no drive gains: give a model from identify_drive_gains".into(),
                )
            })?;
            if m.fit.joint_names != plan.plan.joint_names {
                return Err(refuse(format!(
                    "the model's joints [{}] are not the plan's [{}]",
                    m.fit.joint_names.join(", "),
                    plan.plan.joint_names.join(", ")
                ))
                .into());
            }
            Some(crate::local::SignalGains::from(g))
        }
    };
    let recs: Vec<Recording> = (recordings.iter())
        .map(|r| match &gains {
            Some(g) => r.get().rec.in_torques(&g.gain),
            None => Ok((*r.get().rec).clone()),
        })
        .collect::<Result<_>>()?;
    let plan = plan.plan.clone();
    let earlier: Vec<(Arc<Plan>, Vec<Recording>)> = match rounds {
        Some(rounds) => rounds
            .into_iter()
            .map(|(p, recs)| {
                let recs = (recs.iter())
                    .map(|r| match &gains {
                        Some(g) => r.get().rec.in_torques(&g.gain),
                        None => Ok((*r.get().rec).clone()),
                    })
                    .collect::<Result<Vec<_>>>()?;
                Ok((p.plan.clone(), recs))
            })
            .collect::<Result<_>>()?,
        None => vec![],
    };
    let mut model = detached(py, "identify_local", || {
        let all: Vec<(&Plan, &[Recording])> = (earlier.iter())
            .map(|(p, r)| (p.as_ref(), r.as_slice()))
            .chain([(plan.as_ref(), recs.as_slice())])
            .collect();
        match &robot {
            Some(r) => crate::local::identify_local_rounds_with_delay(
                r,
                &all,
                &options,
                &Default::default(),
            ),
            None if all.len() > 1 => crate::local::identify_local_rounds(&all, &options),
            None => identify_rs(&plan, &recs, &options),
        }
    })?;
    model.drive_gains = gains;
    super::errors::warn_all(py, &model.diagnostics.warnings)?;
    Ok(PyLocalModel { model })
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
    #[pyo3(from_py_with = scalars::count)] candidates: usize,
    #[pyo3(from_py_with = scalars::count)] count: usize,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
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
