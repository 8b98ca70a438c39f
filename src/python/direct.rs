//! The direct method in Python: `identify_base_parameters` (`BaseParameterModel`) (mirrors
//! `crate::direct`; the globally linearised model is `super::global_linear`, the excitation
//! design `super::excitation`).

use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::prelude::*;

use super::scalars;

use super::detached;
use pyo3::types::PyDict;

use super::arrays::{
    at_states_with, expansion_dict, matrix_to_numpy as mat, read_batch, to_numpy, vector, ArrayLike,
};
use super::findings::{
    position_offsets_dict, position_range_dicts, run_check_dicts, torque_column_dicts,
    torque_lag_dict,
};
use super::operating_point::PyOperatingPoint;
use super::recording_list::{recording_set, recordings_given, with_logs, with_offset_per_log};
use super::robot::PyRobot;
use super::samples::{samples, Given};
use crate::direct::{
    identify_base_parameters as base_rs, BaseModel, BaseOptions, FrictionTerms, Weighting,
};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::states::States;
use crate::torque_model::TorqueModel;

/// The `friction` argument of the direct method: a name, names comma separated or a list of
/// names from 'viscous', 'coulomb', 'offset', 'armature' ('all' for the three friction terms,
/// 'none' for none), or anything else (refused).
#[derive(FromPyObject)]
pub(crate) enum FrictionNames<'py> {
    One(String),
    Many(Vec<String>),
    Other(Bound<'py, PyAny>),
}

/// The friction terms of a `friction` argument; `None` means none.
pub(crate) fn friction_terms(value: Option<FrictionNames<'_>>) -> PyResult<FrictionTerms> {
    Ok(match value {
        None => FrictionTerms::NONE,
        // a name, or names comma separated as the command line's --friction takes them
        Some(FrictionNames::One(names)) => names.parse()?,
        Some(FrictionNames::Many(names)) => FrictionTerms::from_names(&names)?,
        Some(FrictionNames::Other(v)) => {
            return Err(Error::invalid(
                "friction",
                format!(
                    "{v}; expected None, 'all', or a list of 'viscous', 'coulomb', 'offset', 'armature'"
                ),
            )
            .into())
        }
    })
}

/// `fit` (read from `source`) checked against the robot `model` it is to predict for: errors
/// name the source.
fn fitted_to(fit: BaseModel, model: &Model, source: &str) -> Result<BaseModel> {
    match fit.on(model) {
        Ok(_) => Ok(fit),
        Err(Error::InvalidArgument { argument, message }) => Err(Error::InvalidArgument {
            argument,
            message: format!("{source}: {message}; give the robot it was identified for"),
        }),
        Err(e) => Err(e),
    }
}

/// Row-major (k, n) samples of three arrays and optionally a fourth.
pub(crate) fn states<'a>(
    n: usize,
    q: &'a ArrayLike<'_>,
    qd: &'a ArrayLike<'_>,
    qdd: &'a ArrayLike<'_>,
    tau: Option<&'a ArrayLike<'_>>,
) -> Result<Vec<Cow<'a, [f64]>>> {
    let mut args = vec![("q", q), ("qd", qd), ("qdd", qdd)];
    if let Some(t) = tau {
        args.push(("tau", t));
    }
    Ok(read_batch(n, &args)?.columns)
}

/// The states (`q`, `qd`, `qdd`, `coulomb` as a prediction takes them; or a Recording as `q`,
/// alone) read as arrays.
pub(crate) fn states_of<'py>(
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    coulomb: Option<Bound<'py, PyAny>>,
) -> PyResult<super::samples::SampleArrays<'py>> {
    let given = Given {
        qd,
        qdd,
        tau: None,
        t: None,
        coulomb,
    };
    samples(q, given, false, false)?.arrays()
}

/// The Coulomb friction term's column a caller gave (`coulomb`, (k, n) or (n,): a
/// preprocessed log's `Recording.coulomb`), read for `n` joints; None where not given.
pub(crate) fn coulomb_column<'a>(
    n: usize,
    coulomb: Option<&'a ArrayLike<'_>>,
) -> Result<Option<Cow<'a, [f64]>>> {
    let Some(c) = coulomb else {
        return Ok(None);
    };
    Ok(read_batch(n, &[("coulomb", c)])?.columns.pop())
}

/// The samples `c` (q, qd, qdd and tau as [`states`] read them) as the states of `n` joints,
/// with the Coulomb term's column `coulomb` where given ([`States::with_coulomb`]).
pub(crate) fn fit_states<'a>(
    n: usize,
    c: &'a [Cow<'_, [f64]>],
    coulomb: Option<&'a [f64]>,
) -> Result<States<'a>> {
    let s = States::new(n, &c[0], Some(&c[1]), Some(&c[2]))?;
    match coulomb {
        Some(x) => s.with_coulomb(x),
        None => Ok(s),
    }
}

/// With `t` given ((k,) s, read by the caller, strictly increasing, one per row of the samples `c`: q, qd, qdd,
/// tau as [`states`] read them), the samples taken for a log: its velocity and acceleration
/// columns are checked against the derivatives of its positions and velocities
/// ([`crate::logs::derivative_columns::check_logged_derivatives`]), so velocities in deg/s, swapped
/// or negated columns are refused naming the joint. Without `t` nothing is checked: states
/// need not be a trajectory. `what` names the samples in messages.
pub(crate) fn check_sample_derivatives(
    what: &str,
    n: usize,
    t: Option<Vec<f64>>,
    c: &[Cow<'_, [f64]>],
) -> Result<()> {
    let Some(t) = t else {
        return Ok(());
    };
    let k = c[0].len() / n;
    if t.len() != k {
        return Err(Error::shape(
            "t",
            format!("({k},): one time per row of q"),
            format!("shape ({},)", t.len()),
        ));
    }
    let log = crate::logs::recording::Recording::new(
        what,
        n,
        t,
        c[0].to_vec(),
        c[3].to_vec(),
        Some(c[1].to_vec()),
        Some(c[2].to_vec()),
    )?;
    crate::logs::derivative_columns::check_logged_derivatives(&log)
}

/// The options of the direct method from its Python arguments (`friction`, `weighting`,
/// `gravity`; the rest default).
pub(crate) fn base_options(
    friction: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
) -> PyResult<BaseOptions> {
    Ok(BaseOptions {
        friction: friction_terms(friction)?,
        weighting: weighting.parse::<Weighting>()?,
        gravity: gravity.into(),
        ..BaseOptions::default()
    })
}

/// [`base_options`] with the base parameters' rank `tolerance` and random states' `seed`, as
/// the fits take them.
pub(crate) fn fit_options(
    friction: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
    tolerance: f64,
    seed: u64,
) -> PyResult<BaseOptions> {
    Ok(BaseOptions {
        tolerance,
        seed,
        ..base_options(friction, weighting, gravity)?
    })
}

/// An identified base-parameter model (the direct method).
///
/// - `theta_base` (p,), `stderr` (p,), `names` (p,): the base parameters, each a kept full
///   parameter with the dropped ones merged into it;
/// - `kept`, `dropped` (indices into the full parameters: 10 per body in `Robot.regressor`
///   order, then the friction terms per joint), `K` (p, len(dropped)):
///   `theta_base = theta[kept] + K @ theta[dropped]`;
/// - `residual_rms`, `sigma` (n,): per-joint fit residuals and WLS weights (N m); `cond`;
/// - `predict(q, qd, qdd)` torques; `mass_matrix(q)` M(q) from the identified parameters.
#[pyclass(name = "BaseParameterModel", module = "perturbid_rs", frozen)]
pub(crate) struct PyBaseModel {
    pub(crate) fit: BaseModel,
    pub(crate) model: Arc<Model>,
}

impl PyBaseModel {
    /// `f` of the fit and its robot at the states `q`, `qd`, `qdd` with `coulomb` (or a
    /// Recording as `q`, alone), as `predict` takes them; `name` is the Python entry point.
    fn at_states<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        q: Bound<'py, PyAny>,
        [qd, qdd, coulomb]: [Option<Bound<'py, PyAny>>; 3],
        f: impl FnOnce(&BaseModel, &Model, &States<'_>) -> Result<Vec<f64>> + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (fit, model) = (&self.fit, &self.model);
        let a = states_of(q, qd, qdd, coulomb)?;
        let columns = [&a.q, &a.qd, &a.qdd];
        at_states_with(py, model.nv, columns, a.coulomb.as_ref(), name, |s| {
            f(fit, model, s)
        })
    }
}

#[pymethods]
impl PyBaseModel {
    #[getter]
    fn theta_base<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.theta)
    }
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.stderr)
    }
    /// The correlation of the base parameters' estimates (p, p): with `stderr`,
    /// `diag(stderr) R diag(stderr)` is their covariance; None in a model saved before it was
    /// stored.
    #[getter]
    fn correlation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let r = &self.fit.correlation;
        (!r.is_empty()).then(|| mat(py, r)).transpose()
    }
    #[getter]
    fn names(&self) -> Vec<String> {
        self.fit.base.names()
    }
    #[getter]
    fn full_names(&self) -> Vec<String> {
        self.fit.base.layout.names.clone()
    }
    #[getter]
    fn kept(&self) -> Vec<usize> {
        self.fit.base.kept.clone()
    }
    #[getter]
    fn dropped(&self) -> Vec<usize> {
        self.fit.base.dropped.clone()
    }
    #[getter(K)]
    fn k<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        mat(py, &self.fit.base.k)
    }
    #[getter]
    fn residual_rms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.residual_rms)
    }
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.sigma)
    }
    /// Per joint, the long-run variance factor of the residuals (>= 1; empty for a model saved
    /// before it was computed or built from local models): the standard errors are scaled by
    /// the square root of the largest.
    #[getter]
    fn residual_correlation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.residual_correlation)
    }
    /// The data's torque columns against the robot's own model, one dict a joint (empty for
    /// a model saved before it was checked or built from local models): `joint`, `scale`
    /// (the column on its own joint's model torque: 1 where the URDF is right, negative for
    /// the opposite sign convention), `explained` (the fraction of what friction leaves that
    /// its own joint's model explains), `follows` (the joint whose model explains it best),
    /// `follows_explained`, `gravity_rms` (N m, the RMS of its joint's model gravity torque:
    /// sign and scale are judged only where it is at least a tenth of the largest joint's),
    /// `finding` (what looks wrong, or None); each finding was also a warning.
    #[getter]
    fn torque_columns<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        torque_column_dicts(py, &self.fit.torque_columns)
    }
    /// The data's torques shifted against their positions, or None (not checked: no
    /// velocities, a model saved before it was checked or built from local models): dict
    /// `samples` (the shift that fits best, in samples of the data fitted; positive where the
    /// torques were logged after the positions they belong to), `joints` (the columns judged),
    /// `unexplained` and `unexplained_at_lag` (the geometric mean of the fraction of each
    /// column its fit leaves unexplained, as logged and at that shift), `finding` (what looks
    /// wrong, or None; also a warning).
    #[getter]
    fn torque_lag<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.fit
            .torque_lag
            .as_ref()
            .map(|l| torque_lag_dict(py, l))
            .transpose()
    }
    /// The joints' zero offsets the data's torques point to, or None (no joint's offset
    /// determined by the data, or a model saved before it was checked): dict `joints` (those
    /// whose offsets the data determine: not a vertical base axis, not the chain's last joint),
    /// `offsets` (rad or m, to add to their logged positions), `stderr`, `unexplained` and
    /// `unexplained_with_offsets` (the weighted residual RMS on the samples checked, as logged
    /// and with the offsets), `left_out` (dicts `joint`, `why`: 'absorbed' by the parameters or
    /// 'undetermined' beyond 0.1 rad, `stderr` of an undetermined one or None), `finding`
    /// (what looks wrong, or None; also a warning).
    #[getter]
    fn position_offsets<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.position_offsets.as_ref())
            .map(|o| position_offsets_dict(py, o, self.fit.position_offsets_finding()))
            .transpose()
    }
    /// In a fit of several Recordings (or runs), the joints whose residuals differ in mean from
    /// run to run (a torque offset that drifted between the logs): dicts `joint`, `means` and
    /// `stderr` ((runs,) N m: each run's mean residual over its first samples and its standard
    /// error), `residual_rms` (N m) and `finding` (also a warning; None where a torque
    /// column is found wrong, which takes it up). Empty where none do.
    #[getter]
    fn run_offsets<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let names = self.fit.log_names();
        (self.fit.run_offsets.iter())
            .map(|o| {
                let e = PyDict::new(py);
                e.set_item("joint", &o.joint)?;
                e.set_item("means", PyArray1::from_slice(py, &o.means))?;
                e.set_item("stderr", PyArray1::from_slice(py, &o.stderr))?;
                e.set_item("residual_rms", o.residual_rms)?;
                let found = !self.fit.columns_found_wrong();
                e.set_item("finding", found.then(|| o.finding(&names)))?;
                Ok(e)
            })
            .collect()
    }
    /// Where an offset of each log's own was fitted (`offset_per_log`), dict `logs` (their
    /// names, in order), `deviations` and `stderr` ((logs, n) N m: each log's torque offset
    /// less the logs' mean, which is the model's offset term, and its standard error); None
    /// otherwise. A log's own offset of joint j is the model's offset term plus its deviation.
    #[getter]
    fn log_offsets<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(o) = &self.fit.log_offsets else {
            return Ok(None);
        };
        log_offsets_dict(py, o, self.fit.log_names()).map(Some)
    }
    /// In a fit of several Recordings (or runs), whether they agree with one robot (each fitted
    /// alone against the fit; a payload in some and not others makes them disagree): dict
    /// `ratio` ((n,): the fit's residual RMS over the logs, less each one's mean, over their
    /// own fits'; near 1 where they agree, NaN where not judged), `fitted_rms` and `own_rms`
    /// ((logs, n) N m; NaN for a log its samples do not determine), `finding` (also a
    /// warning, or None). None for one run.
    #[getter]
    fn log_agreement<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(a) = &self.fit.log_agreement else {
            return Ok(None);
        };
        let (logs, n) = (a.fitted_rms.len(), self.fit.joint_names.len());
        let own = |r: usize, j: usize| a.own_rms[r].as_ref().map_or(f64::NAN, |o| o[j]);
        let e = PyDict::new(py);
        let ratio: Vec<f64> = a.ratio.iter().map(|r| r.unwrap_or(f64::NAN)).collect();
        e.set_item("ratio", PyArray1::from_slice(py, &ratio))?;
        let fitted = DMatrix::from_fn(logs, n, |r, j| a.fitted_rms[r][j]);
        e.set_item("fitted_rms", mat(py, &fitted)?)?;
        e.set_item("own_rms", mat(py, &DMatrix::from_fn(logs, n, own))?)?;
        e.set_item("finding", self.fit.log_agreement_finding())?;
        Ok(Some(e))
    }
    /// In a fit of several Recordings (or runs), each run's data checked alone against the
    /// robot's model, in the runs' order: dicts `log` (its name), `samples` (fitted),
    /// `torque_columns`, `torque_lag` and `position_range` (as the model's own, of that run's
    /// samples alone) and `findings` (what looks wrong with the run, each also a warning
    /// naming it). Empty for a fit of one run; the model's `torque_lag` is then None.
    #[getter]
    fn run_checks<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let names = self.fit.log_names();
        run_check_dicts(py, &self.fit.run_checks, &names)
    }
    /// The joints whose torques show friction terms the fit lacks (the fit made again with
    /// viscous, Coulomb and offset terms): dicts `joint`, `explained` (the fraction of its
    /// residual sum of squares the terms take off), `residual_rms` and `remaining_rms` (N m,
    /// without and with them), `terms` (dicts `term`: 'viscous', 'coulomb' or 'offset',
    /// `coefficient` (N m s/rad, N m), `stderr`); their finding is also a warning. Empty where
    /// none do or the fit has every term.
    #[getter]
    fn unmodelled_friction<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        (self.fit.unmodelled_friction.iter())
            .map(|f| {
                let e = PyDict::new(py);
                e.set_item("joint", &f.joint)?;
                e.set_item("explained", f.explained)?;
                e.set_item("residual_rms", f.residual_rms)?;
                e.set_item("remaining_rms", f.remaining_rms)?;
                let terms = (f.terms.iter())
                    .map(|t| {
                        let d = PyDict::new(py);
                        d.set_item("term", &t.term)?;
                        d.set_item("coefficient", t.coefficient)?;
                        d.set_item("stderr", t.stderr)?;
                        Ok(d)
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                e.set_item("terms", terms)?;
                Ok(e)
            })
            .collect()
    }
    /// The joints' drive gains where the model was identified from logged motor currents
    /// (`identify_drive_gains`), else None: dict `gain`, `stderr`, `noise_bias` (an upper
    /// estimate of each least-squares gain's relative bias towards 0, were every residual the signal's noise),
    /// `payload_torque_rms` (N m) and `agreement` (near 1 where the runs agree with the
    /// payload as given), each (n,); `cond` of the joint fit, `runs`, `loaded_runs`,
    /// `estimator` ("least_squares" or "instrumental") and `least_squares_gain` (None, or by
    /// instrumental variables the least-squares gains, (n,)). The model's torques are
    /// `gain * signal`.
    #[getter]
    fn drive_gains<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.drive_gains.as_ref())
            .map(|g| super::findings::gains_dict(py, g))
            .transpose()
    }
    /// The fit's residuals judged against the torques' noise measured apart from it (given as
    /// `noise=`, or from a Recording's periods), else None: dict `noise` (N m a joint),
    /// `correlation` (samples an independent noise value), `noise_degrees_of_freedom` (of
    /// the levels measured, None where known exactly), `ratio` (a joint, the residual RMS over
    /// the noise), `model_error` (a joint, sqrt(max(residual^2 - noise^2, 0)), N m), `cost`
    /// (the weighted residual sum of squares over the correlation), `degrees_of_freedom`
    /// (k n / correlation - p) and `p_value` (the chance of the cost or more from noise
    /// alone; below 1e-3 a model error is warned of, above 1 - 1e-3 an overstated noise).
    #[getter]
    fn noise_fit<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.fit.noise_fit.as_ref())
            .map(|f| super::noise::noise_fit_dict(py, f))
            .transpose()
    }
    /// Where the data excite the base parameters weakly (cond beyond 2000), else None: dict
    /// `cond`, `weakest` (the least determined combination of base parameters: dicts
    /// `parameter`, the name it is kept as with ' (merged)' where others are merged into it,
    /// and `weight`, in units of its regressor column's norm; at most 6, largest first) and
    /// `motion` (dicts `joint`, `extent`: the largest position minus the smallest, `range`:
    /// the URDF's upper limit minus its lower one or None; rad or m); also a warning.
    #[getter]
    fn weak_excitation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(w) = &self.fit.weak_excitation else {
            return Ok(None);
        };
        let e = PyDict::new(py);
        e.set_item("cond", w.cond)?;
        let weakest = (w.weakest.iter()).map(|t| {
            let d = PyDict::new(py);
            d.set_item("parameter", &t.parameter)?;
            d.set_item("weight", t.weight)?;
            Ok(d)
        });
        e.set_item("weakest", weakest.collect::<PyResult<Vec<_>>>()?)?;
        let motion = (w.motion.iter()).map(|m| {
            let d = PyDict::new(py);
            d.set_item("joint", &m.joint)?;
            d.set_item("extent", m.extent)?;
            d.set_item("range", m.range)?;
            Ok(d)
        });
        e.set_item("motion", motion.collect::<PyResult<Vec<_>>>()?)?;
        Ok(Some(e))
    }
    /// The joints whose positions in the data leave their URDF limits by more than 5 % of
    /// their range: dicts `joint`, `min`, `max` (the positions logged), `lower`, `upper` (the
    /// limits; rad or m) and `degrees` (True where, read as degrees, they lie within the
    /// limits); their finding is also a warning. Empty where none do.
    #[getter]
    fn position_range<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        position_range_dicts(py, &self.fit.position_range)
    }
    /// The robot's joints the model is of, in its columns' order (as `Robot.joint_names`).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.fit.joint_names.clone()
    }
    #[getter]
    fn cond(&self) -> f64 {
        self.fit.cond
    }
    #[getter]
    fn samples(&self) -> usize {
        self.fit.samples
    }
    /// The parameter table (pandas): index `parameter` (full base-parameter names), columns
    /// `value`, `std`, `relative_std` (NaN where unknown) and `combination` (other parameters
    /// merged into it: only the combination is identifiable).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows = self.fit.parameter_table();
        let column = |f: &dyn Fn(&crate::direct::ParameterRow) -> f64| {
            PyArray1::from_iter(py, rows.iter().map(f)).into_any()
        };
        let combination = pyo3::types::PyList::new(py, rows.iter().map(|r| r.combination))?;
        super::tables::dataframe(
            py,
            vec![
                ("value", column(&|r| r.value)),
                ("std", column(&|r| r.std.unwrap_or(f64::NAN))),
                (
                    "relative_std",
                    column(&|r| r.relative_std.unwrap_or(f64::NAN)),
                ),
                ("combination", combination.into_any()),
            ],
            Some(("parameter", rows.iter().map(|r| r.name.clone()).collect())),
        )
    }
    /// Predicted torques (N m) at `q`, `qd`, `qdd`: (n,) each or (k, n). `coulomb`, shaped
    /// as `q`: the Coulomb term's column in place of sign(qd) (`Recording.coulomb` of a
    /// preprocessed log, to compare with its filtered torques). A Recording as `q`, alone:
    /// its states and Coulomb column. `signal=True`: the logged signal the model's drive
    /// gains were identified for instead (motor currents, A: each torque over its gain; the
    /// feed-forward a motion needs), for a model from `identify_drive_gains`.
    #[pyo3(signature = (q, qd=None, qdd=None, coulomb=None, signal=false))]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Option<Bound<'py, PyAny>>,
        qdd: Option<Bound<'py, PyAny>>,
        coulomb: Option<Bound<'py, PyAny>>,
        signal: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let name = "BaseParameterModel.predict";
        self.at_states(
            py,
            name,
            q,
            [qd, qdd, coulomb],
            |fit, model, s| match signal {
                true => fit.predict_signal(model, s),
                false => fit.predict(model, s),
            },
        )
    }
    /// The standard errors (N m) of the torques `predict` gives at `q`, `qd`, `qdd` (shapes as
    /// there): from the parameters' standard errors and their correlation; the uncertainty of
    /// the model's torque, not a measured one's scatter about it. `signal=True`: of the
    /// signal `predict(..., signal=True)` gives (signal units), from the covariance of the
    /// parameters and the drive gains together (fitted together, their errors are
    /// correlated). Raises InputError for a model saved before the correlation was stored.
    #[pyo3(signature = (q, qd=None, qdd=None, coulomb=None, signal=false))]
    fn predict_stderr<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Option<Bound<'py, PyAny>>,
        qdd: Option<Bound<'py, PyAny>>,
        coulomb: Option<Bound<'py, PyAny>>,
        signal: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let name = "BaseParameterModel.predict_stderr";
        self.at_states(
            py,
            name,
            q,
            [qd, qdd, coulomb],
            |fit, model, s| match signal {
                true => fit.predict_signal_stderr(model, s),
                false => fit.predict_stderr(model, s),
            },
        )
    }
    /// The model linearised exactly at `op` (an OperatingPoint): dict `torque` (n,), `D`, `H`,
    /// `G`, `G_static` (n, n; row = torque, column = joint), as a LocalModel answers it.
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        op: &PyOperatingPoint,
    ) -> PyResult<Bound<'py, PyDict>> {
        let e = self.fit.on(&self.model)?.linearize(&op.op)?;
        expansion_dict(py, &e)
    }
    /// M(q) from the identified parameters: (n, n), or (k, n, n) for q of shape (k, n).
    fn mass_matrix<'py>(&self, py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        let batch = read_batch(n, &[("q", &q)])?;
        let mut out = Vec::with_capacity(batch.k * n * n);
        self.fit.on(&self.model)?;
        for s in 0..batch.k {
            let m = self
                .fit
                .mass_matrix_checked(&self.model, &batch.columns[0][s * n..(s + 1) * n])
                .map_err(|e| batch.in_sample(s, e))?;
            out.extend(m.transpose().iter());
        }
        to_numpy(py, out, batch.k, batch.single, &[n, n])
    }
    /// The model as JSON text: the document `perturbid identify-direct` writes, read back by
    /// `from_json` (and by `perturbid predict`).
    fn to_json(&self) -> String {
        Document::to_json(&self.fit)
    }
    /// Writes the model to `path` as JSON (atomically: a temporary file renamed into place),
    /// the document `perturbid identify-direct` writes. Raises FileError when it cannot be
    /// written.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        Ok(detached(py, "BaseParameterModel.save", || {
            self.fit.save(&path)
        })?)
    }
    /// A model saved by `save` or by `perturbid identify-direct` / `identify-gains`
    /// (`base_model.json`), for `robot`, the one it was identified for (the same joints,
    /// bodies and parameter names: a URDF of the same robot with other inertias is fine).
    /// Checked as `perturbid predict` checks it: every field, its shapes and ranges. Raises
    /// FileError for a file that cannot be read, InputError naming the file and field of a
    /// document that is not such a model (another kind of document, a hand-edited value out
    /// of range), or the robot it does not fit.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf, robot: &PyRobot) -> PyResult<Self> {
        let model = Arc::new(robot.model.clone());
        let fit = detached(py, "BaseParameterModel.load", || {
            let fit = BaseModel::load(&path)?;
            fitted_to(fit, &model, &path.display().to_string())
        })?;
        Ok(Self { fit, model })
    }
    /// `load` from the JSON text `text` (of `to_json`).
    #[staticmethod]
    fn from_json(text: &str, robot: &PyRobot) -> PyResult<Self> {
        let fit = fitted_to(BaseModel::from_json(text)?, &robot.model, "the model")?;
        Ok(Self {
            fit,
            model: Arc::new(robot.model.clone()),
        })
    }
    fn __repr__(&self) -> String {
        format!(
            "BaseParameterModel(robot='{}', base parameters={}, samples={}, cond={:.4})",
            self.fit.robot,
            self.fit.theta.len(),
            self.fit.samples,
            self.fit.cond
        )
    }
}

/// Identifies the base parameters of `robot` from samples `q`, `qd`, `qdd`, `tau` (each (k, n);
/// rad, rad/s, rad/s^2, N m), or from a Recording given as `q` alone (`preprocess`'s: its
/// states, torques, time and Coulomb column; see `samples`), or from a list of them (runs
/// fitted together, one after the other; what each one's preprocessing found kept in the
/// model's `logs`; Recordings that share samples, one given twice, refused). A Recording's own
/// findings (position rounding) were warned of by `preprocess` and are not warned of again.
/// `friction`: None (default: no joint terms), 'all' (viscous, Coulomb and offset per joint,
/// and the armature where the robot has one), or names from 'viscous', 'coulomb', 'offset',
/// 'armature' (a list, or comma separated); `weighting`: 'wls' (default, weights from the residuals), 'ols'
/// or 'noise' (weights from the torques' noise measured apart, the standard errors from it);
/// `gravity`: whether `tau` includes gravity; `tolerance`: relative rank tolerance of the
/// pivoted QR. `noise` ((n,) N m a joint): the torques' noise a sample, measured apart from
/// the fit (a log held still), with `noise_correlation` samples an independent value (1 for
/// white noise); without it, a Recording averaged over its periods (`preprocess(...,
/// excitation=...)`) gives the noise its periods measured. Where there is a noise, the fit's
/// residuals are judged against it (`noise_fit`, a warning beyond or below it). `t` ((k,) s),
/// when the samples are a log: its qd and qdd columns are checked against the derivatives of
/// q and qd first (see `check_sample_derivatives`), refusing columns in other units, of
/// another joint or of the opposite sign. `coulomb` ((k, n)), for torques low-pass filtered:
/// the Coulomb friction term's column filtered as they were (`Recording.coulomb` of
/// `preprocess`), in place of sign(qd). `offset_per_log`, for a list of Recordings: a torque
/// offset of each one's own fitted beside the parameters (a sensor zeroed anew between logs),
/// whose offset terms are then the logs' mean (`log_offsets`); needs the offset term.
#[pyfunction]
#[pyo3(signature = (robot, q, qd=None, qdd=None, tau=None, friction=None, weighting="wls", gravity=true, tolerance=1e-8, seed=0, t=None, coulomb=None, offset_per_log=false, noise=None, noise_correlation=1.0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_base_parameters<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    q: Bound<'py, PyAny>,
    qd: Option<Bound<'py, PyAny>>,
    qdd: Option<Bound<'py, PyAny>>,
    tau: Option<Bound<'py, PyAny>>,
    friction: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
    #[pyo3(from_py_with = scalars::real)] tolerance: f64,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
    t: Option<Bound<'py, PyAny>>,
    coulomb: Option<Bound<'py, PyAny>>,
    offset_per_log: bool,
    noise: Option<ArrayLike<'py>>,
    #[pyo3(from_py_with = scalars::real)] noise_correlation: f64,
) -> PyResult<PyBaseModel> {
    let model = &robot.model;
    let given = Given {
        qd,
        qdd,
        tau,
        t,
        coulomb,
    };
    let listed = recordings_given(&q, &given)?;
    // a Recording's findings are kept with the model, as the command line keeps its log's
    let recording = (q.cast::<super::recording::PyRecording>().ok()).map(|r| r.get().rec.clone());
    let options = with_offset_per_log(
        fit_options(friction, weighting, gravity, tolerance, seed)?,
        offset_per_log,
        listed.as_ref().map(Vec::len),
    )?;
    let fitted = listed
        .clone()
        .unwrap_or_else(|| recording.iter().cloned().collect());
    let options = super::noise::with_noise(
        options,
        noise,
        noise_correlation,
        &fitted,
        &model.joint_names,
    )?;
    if let Some(recs) = listed {
        let fit = detached(py, "identify_base_parameters", || {
            let (set, options) = recording_set(model, &recs, &options)?;
            let (states, tau) = set.train()?;
            let fit = base_rs(model, &states, tau, &options)?;
            Ok::<_, Error>(with_logs(fit, &recs))
        })?;
        // the Recordings' own findings were warned of by the preprocessing that made them
        super::errors::warn_all(py, &fit.fit_warnings())?;
        return Ok(PyBaseModel {
            fit,
            model: Arc::new(model.clone()),
        });
    }
    let a = samples(q, given, true, true)?.arrays()?;
    let c = states(model.nv, &a.q, &a.qd, &a.qdd, a.tau.as_ref())?;
    let coulomb = coulomb_column(model.nv, a.coulomb.as_ref())?;
    let t = a.t.as_ref().map(|t| vector("t", t)).transpose()?;
    let fit = detached(py, "identify_base_parameters", || {
        check_sample_derivatives("identify_base_parameters' samples", model.nv, t, &c)?;
        let s = fit_states(model.nv, &c, coulomb.as_deref())?;
        let fit = base_rs(model, &s, &c[3], &options)?;
        Ok::<_, Error>(match &recording {
            Some(rec) => fit.with_findings_of(rec),
            None => fit,
        })
    })?;
    match recording {
        // its findings were warned of by the preprocessing that made it
        Some(_) => super::errors::warn_all(py, &fit.fit_warnings())?,
        None => super::errors::warn_all(py, &fit.warnings())?,
    }
    Ok(PyBaseModel {
        fit,
        model: Arc::new(model.clone()),
    })
}

/// Each log's offset as Python sees it: `logs` (names), `deviations` and `stderr`, each
/// (logs, n) (N m), a log's offset less the logs' mean.
pub(crate) fn log_offsets_dict<'py>(
    py: Python<'py>,
    o: &crate::direct::LogOffsets,
    names: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let e = PyDict::new(py);
    let (runs, n) = (o.runs(), o.deviations.len());
    let by_log = |m: &[Vec<f64>]| DMatrix::from_fn(runs, n, |r, j| m[j][r]);
    e.set_item("logs", names)?;
    e.set_item("deviations", mat(py, &by_log(&o.deviations))?)?;
    e.set_item("stderr", mat(py, &by_log(&o.stderr))?)?;
    Ok(e)
}
