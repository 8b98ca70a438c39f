//! Python: `identify_payload` (`PayloadFit`; mirrors `crate::direct::payload`): a payload's
//! mass, centre of mass and inertia from a log of the robot carrying it, against a model of
//! the robot alone or its URDF.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use std::sync::Arc;

use super::arrays::{at_states_with, matrix_to_numpy as mat, vec1, vector};
use super::detached;
use super::direct::{
    check_sample_derivatives, coulomb_column, fit_states, friction_terms, states, states_of,
    FrictionNames, PyBaseModel,
};
use super::recording_list::{recording_set, recordings_given};
use super::robot::PyRobot;
use super::samples::{samples, Given};
use crate::direct::BaseModel;
use crate::direct::{
    identify_payload as payload_rs, PayloadFit, PayloadOptions, Reference, Weighting,
};
use crate::gravity::Gravity;
use crate::model::payload::Payload;
use crate::model::Model;

/// A payload identified from a log of the robot carrying it (`identify_payload`).
///
/// - `payload`: dict `link`, `mass` (kg), `com` ((3,) m), `inertia` ((6,) `[ixx, ixy, ixz,
///   iyy, iyz, izz]` kg m^2 about the centre of mass), in the link's joint frame: the dict
///   `identify_drive_gains` takes as a known payload and `TrueRobot` as its `payload`; None
///   where no payload is seen (its mass not above 0 by 3 standard errors), or where the fit
///   cannot vouch for it (`usable` False: no rigid body, a torque column read wrong; see
///   `findings`);
/// - `payload_stderr`: dict `mass`, `com`, `inertia`, their standard errors (delta rule);
/// - `names`, `theta`, `stderr` (m,): the payload's ten parameters (Pinocchio's order, about
///   the joint frame: kg, kg m, kg m^2) and the joint terms fitted beside it, with standard
///   errors (inflated for correlated residuals, and with the reference model's share,
///   `stderr_of_reference`); `correlation` (m, m);
/// - `reference_rms`, `payload_torque_rms`, `residual_rms`, `sigma` (n,): per joint, the
///   torques less the reference's, the payload's torques, the fit's residuals, the weights
///   (N m); `cond`, `samples`; `consistent`, `residual_growth`, `not_a_rigid_body`;
/// - `findings`: what the fit cannot vouch for, each also warned of.
#[pyclass(name = "PayloadFit", module = "perturbid_rs", frozen)]
pub(crate) struct PyPayloadFit {
    pub(crate) fit: PayloadFit,
    /// The robot and the model of it alone (None: its URDF) the payload was identified
    /// against, for `predict`.
    robot: Arc<Model>,
    reference: Option<BaseModel>,
}

fn payload_dict<'py>(py: Python<'py>, p: &Payload) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("link", &p.link)?;
    d.set_item("mass", p.mass)?;
    d.set_item("com", p.com.to_vec())?;
    d.set_item("inertia", p.inertia.to_vec())?;
    Ok(d)
}

#[pymethods]
impl PyPayloadFit {
    /// The payload, where the fit vouches for it (see the class docs), else None.
    #[getter]
    fn payload<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.fit
            .usable_payload()
            .map(|p| payload_dict(py, p))
            .transpose()
    }
    /// The estimate whether or not the fit vouches for it (None only where no payload is
    /// seen): for a look at what a refused fit made of the log.
    #[getter]
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.payload.as_ref())
            .map(|p| payload_dict(py, p))
            .transpose()
    }
    /// Whether `payload` is given (a payload seen, a rigid body, the log's columns right).
    #[getter]
    fn usable(&self) -> bool {
        self.fit.usable_payload().is_some()
    }
    #[getter]
    fn payload_stderr<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.payload_stderr.as_ref())
            .map(|s| {
                let d = PyDict::new(py);
                d.set_item("mass", s.mass)?;
                d.set_item("com", s.com.to_vec())?;
                d.set_item("inertia", s.inertia.to_vec())?;
                Ok(d)
            })
            .transpose()
    }
    /// The residuals against the torques' noise measured apart (a dict as
    /// `BaseParameterModel.noise_fit`), else None.
    #[getter]
    fn noise_fit<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.noise_fit.as_ref())
            .map(|f| super::noise::noise_fit_dict(py, f))
            .transpose()
    }
    /// The robot's joints, in the columns' order of `sigma`, `residual_rms` and the others.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.fit.joint_names.clone()
    }
    #[getter]
    fn link(&self) -> &str {
        &self.fit.link
    }
    /// 'urdf' or 'base_model'.
    #[getter]
    fn reference(&self) -> &str {
        &self.fit.reference
    }
    #[getter]
    fn names(&self) -> Vec<String> {
        self.fit.names.clone()
    }
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.theta)
    }
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.stderr)
    }
    #[getter]
    fn stderr_of_reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.stderr_of_reference)
    }
    #[getter]
    fn correlation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.fit.correlation)
    }
    #[getter]
    fn reference_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.reference_rms)
    }
    #[getter]
    fn payload_torque_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.payload_torque_rms)
    }
    #[getter]
    fn residual_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.residual_rms)
    }
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.fit.sigma)
    }
    #[getter]
    fn cond(&self) -> f64 {
        self.fit.cond
    }
    #[getter]
    fn samples(&self) -> usize {
        self.fit.samples
    }
    /// 'fitted', or 'point_mass' (the inertia about the centre of mass 0 by assumption).
    #[getter]
    fn inertia(&self) -> &'static str {
        self.fit.inertia.name()
    }
    #[getter]
    fn consistent(&self) -> bool {
        self.fit.consistent
    }
    /// With `offset_per_log`: `logs`, and `deviations` and `stderr` ((logs, n), N m), each
    /// log's torque offset less the logs' mean; None otherwise.
    #[getter]
    fn log_offsets<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(o) = &self.fit.log_offsets else {
            return Ok(None);
        };
        super::direct::log_offsets_dict(py, o, self.fit.logs.clone()).map(Some)
    }
    #[getter]
    fn residual_growth(&self) -> Option<f64> {
        self.fit.residual_growth
    }
    #[getter]
    fn not_a_rigid_body(&self) -> Option<String> {
        self.fit.not_a_rigid_body.clone()
    }
    #[getter]
    fn findings(&self) -> Vec<String> {
        self.fit.findings.clone()
    }
    /// The torques (N m) of the robot carrying the payload at `q`, `qd`, `qdd` ((n,) each or
    /// (k, n); or a Recording as `q`, alone, with its Coulomb column): the reference's (the
    /// model of the robot alone, or the URDF), the payload's and the joint terms fitted beside
    /// it. `coulomb`, shaped as `q`: the Coulomb term's column in place of sign(qd).
    #[pyo3(signature = (q, qd=None, qdd=None, coulomb=None))]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Option<Bound<'py, PyAny>>,
        qdd: Option<Bound<'py, PyAny>>,
        coulomb: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let a = states_of(q, qd, qdd, coulomb)?;
        let reference = match &self.reference {
            Some(m) => Reference::Model(m),
            None => Reference::Urdf,
        };
        let (fit, robot) = (&self.fit, &self.robot);
        at_states_with(
            py,
            robot.nv,
            [&a.q, &a.qd, &a.qdd],
            a.coulomb.as_ref(),
            "PayloadFit.predict",
            |s| fit.predict(robot, reference, s),
        )
    }
    /// The fit as the JSON document `perturbid identify-payload` writes as payload_fit.json.
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.fit).expect("serialisable")
    }
    fn __repr__(&self) -> String {
        match &self.fit.payload {
            Some(p) => format!(
                "PayloadFit(link='{}', mass={:.6} kg, com={:?} m, usable={})",
                self.fit.link,
                p.mass,
                p.com,
                self.fit.usable_payload().is_some()
            ),
            None => format!("PayloadFit(link='{}', no payload seen)", self.fit.link),
        }
    }
}

/// Identifies the payload fixed to `link` (a link of `robot` that moves: a body's own, or one
/// behind fixed joints such as a flange or tool frame; the payload in its frame) from a log of the robot carrying it: `q`, `qd`, `qdd`, `tau` (each (k, n); rad,
/// rad/s, rad/s^2, N m), or a Recording as `q` alone (`preprocess`'s: its states, torques,
/// time and Coulomb column), or a list of them (logs of other motions with the same payload,
/// fitted together, each checked alone against the robot's model and named in its findings).
///
/// `model`: a BaseParameterModel of the robot without the payload, identified with
/// `identify_base_parameters` (or `identify_drive_gains`: then give the Recording in torques,
/// `rec.in_torques(model.drive_gains['gain'])`), whose prediction the torques are measured
/// against and whose parameters' uncertainty is carried into the payload's; None (default):
/// against the URDF's own parameters, taken as exact. `terms`: the joint terms fitted beside
/// the payload (None: an offset a joint with a model, viscous, Coulomb and offset without;
/// or 'all', 'none', a list of 'viscous', 'coulomb', 'offset', 'armature'); `weighting`
/// 'wls', 'ols' or 'noise' (by the torques' noise measured apart: `noise=` and
/// `noise_correlation=` as `identify_base_parameters` takes them, or a Recording's periods;
/// with a noise the residuals are judged against it, `noise_fit`); `gravity`: whether `tau` includes gravity (as the model's must);
/// `inertia`: 'fitted' (all ten parameters) or 'point_mass' (the inertia about the centre of
/// mass taken as 0, the mass and centre alone fitted: for a log that determines a small
/// payload's inertia loosely or not at all, as poses held still do); `consistent`: a rigid
/// body by construction; `offset_per_log` (a list of Recordings): a torque offset of each
/// log's own beside the joint terms' offset, then their mean (`PayloadFit.log_offsets`).
/// `t` ((k,) s) checks a log's own qd and qdd
/// columns against the derivatives of q and qd; `coulomb` ((k, n)) the Coulomb column of
/// torques low-pass filtered. Findings are warned of (`PerturbidWarning`) and kept in
/// `findings`.
#[pyfunction]
#[pyo3(signature = (robot, q, qd=None, qdd=None, tau=None, *, link, model=None, terms=None, weighting="wls", gravity=true, inertia="fitted", consistent=false, t=None, coulomb=None, offset_per_log=false, noise=None, noise_correlation=1.0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_payload<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    tau: Option<Bound<'py, PyAny>>,
    link: &str,
    model: Option<PyRef<'py, PyBaseModel>>,
    terms: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
    inertia: &str,
    consistent: bool,
    t: Option<Bound<'py, PyAny>>,
    coulomb: Option<Bound<'py, PyAny>>,
    offset_per_log: bool,
    noise: Option<super::arrays::ArrayLike<'py>>,
    #[pyo3(from_py_with = super::scalars::real)] noise_correlation: f64,
) -> PyResult<PyPayloadFit> {
    let robot_model = &robot.model;
    let n = robot_model.nv;
    let reference = match &model {
        Some(m) => Reference::Model(&m.fit),
        None => Reference::Urdf,
    };
    let mut options = PayloadOptions::new(link, &reference);
    if terms.is_some() {
        options.terms = friction_terms(terms)?;
    }
    options.weighting = weighting.parse::<Weighting>()?;
    options.gravity = Gravity::from(gravity);
    options.consistent = consistent;
    options.inertia = inertia.parse()?;
    options.offset_per_run = offset_per_log;
    let given = Given {
        qd,
        qdd,
        tau,
        t,
        coulomb,
    };
    let listed = recordings_given(&q, &given)?;
    let one = (q.cast::<super::recording::PyRecording>().ok()).map(|r| r.get().rec.clone());
    let fitted = listed
        .clone()
        .unwrap_or_else(|| one.iter().cloned().collect());
    options.noise = super::noise::torque_noise(
        noise,
        noise_correlation,
        &fitted,
        &robot_model.joint_names,
        options.weighting,
    )?;
    // a list of Recordings: logs fitted together, each checked alone
    if let Some(recs) = listed {
        let fit = detached(py, "identify_payload", || {
            let (set, set_options) = recording_set(robot_model, &recs, &Default::default())?;
            if recs.len() > 1 {
                options.runs = set_options.runs;
                options.log_names = recs.iter().map(|r| r.name.clone()).collect();
            }
            let (states, tau) = set.train()?;
            payload_rs(robot_model, reference, &states, tau, &options)
                .map_err(|e| crate::direct::log_offsets::as_argument(e, "offset_per_log"))
        })?;
        super::errors::warn_all(py, &fit.findings)?;
        return Ok(PyPayloadFit {
            fit,
            robot: Arc::new(robot_model.clone()),
            reference: model.as_ref().map(|m| m.fit.clone()),
        });
    }
    let a = samples(q, given, true, true)?.arrays()?;
    let c = states(n, &a.q, &a.qd, &a.qdd, a.tau.as_ref())?;
    let coulomb = coulomb_column(n, a.coulomb.as_ref())?;
    let t = a.t.as_ref().map(|t| vector("t", t)).transpose()?;
    let fit = detached(py, "identify_payload", || {
        check_sample_derivatives("identify_payload's samples", n, t, &c)?;
        let s = fit_states(n, &c, coulomb.as_deref())?;
        payload_rs(robot_model, reference, &s, &c[3], &options)
            .map_err(|e| crate::direct::log_offsets::as_argument(e, "offset_per_log"))
    })?;
    super::errors::warn_all(py, &fit.findings)?;
    Ok(PyPayloadFit {
        fit,
        robot: Arc::new(robot_model.clone()),
        reference: model.as_ref().map(|m| m.fit.clone()),
    })
}
