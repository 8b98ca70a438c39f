//! Python: `identify_drive_gains` (mirrors `crate::direct::drive_gains`): the joints' drive
//! gains and the base parameters from Recordings of logged motor currents, one of them with a
//! known payload.

use std::borrow::Cow;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use super::detached;
use super::direct::{check_sample_derivatives, fit_options, FrictionNames, PyBaseModel};
use super::recording::PyRecording;
use super::robot::PyRobot;
use super::scalars;
use crate::direct::drive_gains::{
    identify_drive_gains_with as gains_rs, GainEstimator, GainRun, MAX_RUNS,
};
use crate::error::{Error, Result};
use crate::logs::recording::Recording;
use crate::model::payload::Payload;
use crate::states::States;

/// The payload a caller gave for run `r`: None, or a dict with the keys of the true robot's
/// `payload` (`link`, `mass`, `com`, `inertia`); unknown keys, and values of another type or
/// length, refused by key (values out of range by [`Payload::problem`]).
fn payload_of(r: usize, value: &Bound<'_, PyAny>) -> PyResult<Option<Payload>> {
    super::payload_argument::payload_argument(&format!("payloads[{r}]"), value)
}

/// The entries of a list or tuple argument `name`, at most [`MAX_RUNS`].
fn entries<'py>(name: &str, v: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let items: Vec<Bound<'py, PyAny>> = if let Ok(l) = v.cast::<PyList>() {
        l.iter().collect()
    } else if let Ok(t) = v.cast::<PyTuple>() {
        t.iter().collect()
    } else {
        return Err(
            Error::invalid(name, format!("a {}, expected a list", v.get_type().name()?)).into(),
        );
    };
    if items.len() > MAX_RUNS {
        return Err(Error::invalid(
            name,
            format!("{} entries, expected at most {MAX_RUNS}", items.len()),
        )
        .into());
    }
    Ok(items)
}

/// A recording's arrays for a run of a robot of `nv` joints: velocities and accelerations
/// required.
fn run_arrays(r: usize, rec: &Recording, nv: usize) -> Result<(&[f64], &[f64])> {
    if rec.n != nv {
        return Err(Error::invalid(
            format!("runs[{r}]"),
            format!(
                "the Recording '{}' has {} joints, expected the robot's {nv}",
                rec.name, rec.n
            ),
        ));
    }
    match (&rec.qd, &rec.qdd) {
        (Some(qd), Some(qdd)) => Ok((qd, qdd)),
        _ => Err(Error::invalid(
            format!("runs[{r}]"),
            format!(
                "the Recording '{}' has no velocities and accelerations (a log as read): preprocess it first (perturbid_rs.preprocess)",
                rec.name
            ),
        )),
    }
}

/// Identifies the joints' drive gains with the base parameters (docs/method.md, section 8c)
/// from `runs`, Recordings of the robot whose `tau` holds each joint's logged signal (motor
/// currents, A, or torques computed with nominal gains), preprocessed (with `qd` and `qdd`),
/// and `payloads`, one a run: None for the robot alone, or the known payload bolted on during
/// it, a dict `link` (a link of `robot` that moves: a body's own, or a flange or tool frame behind fixed joints), `mass` (kg), `com` (m) and `inertia`
/// (`[ixx, ixy, ixz, iyy, iyz, izz]` about the centre of mass, kg m^2), all in the link's
/// frame. Not every run may carry the same payload: the payload fixes the gains' scale.
///
/// Returns a BaseParameterModel of the robot alone in SI units (its predictions are torques),
/// with `drive_gains`: `gain` (n,) N m (or N) per unit of the signal, `stderr`, `noise_bias`
/// (each least-squares gain's relative bias towards 0 were every residual the signal's noise),
/// `payload_torque_rms` (N m), `agreement` (the fit's residual over each run's signal fitted
/// alone: near 1 where the runs agree with the payload as given), `cond`, `runs`,
/// `loaded_runs`, `estimator` and `least_squares_gain` (None, or by instrumental variables
/// the least-squares gains). `estimator`: "least_squares" (the smallest variance, biased
/// towards 0 by the signal's noise as `noise_bias` says) or "instrumental" (instrumental
/// variables, the signal predicted by the least-squares fit for instrument: consistent under
/// the signal's noise). `friction`, `weighting`, `gravity`, `tolerance`, `seed` as for
/// `identify_base_parameters`. Findings are warned of. What each run's preprocessing found
/// (glitches, dropouts, position rounding, ...) is kept in the model's `logs`, named by the
/// Recording, as `perturbid identify-gains` keeps its logs'.
#[pyfunction]
#[pyo3(signature = (robot, runs, payloads, friction=None, weighting="wls", gravity=true, tolerance=1e-8, seed=0, estimator="least_squares"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_drive_gains(
    py: Python<'_>,
    robot: &PyRobot,
    runs: Bound<'_, PyAny>,
    payloads: Bound<'_, PyAny>,
    friction: Option<FrictionNames<'_>>,
    weighting: &str,
    gravity: bool,
    #[pyo3(from_py_with = scalars::real)] tolerance: f64,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
    estimator: &str,
) -> PyResult<PyBaseModel> {
    let options = fit_options(friction, weighting, gravity, tolerance, seed)?;
    let estimator: GainEstimator = estimator.parse()?;
    let model = &robot.model;
    let (runs, payloads) = (entries("runs", &runs)?, entries("payloads", &payloads)?);
    if runs.len() != payloads.len() {
        return Err(Error::invalid(
            "payloads",
            format!(
                "{} payloads for {} runs, expected one a run (None for a run without)",
                payloads.len(),
                runs.len()
            ),
        )
        .into());
    }
    let mut recordings: Vec<Arc<Recording>> = Vec::with_capacity(runs.len());
    for (r, run) in runs.iter().enumerate() {
        let Ok(rec) = run.cast::<PyRecording>() else {
            return Err(Error::invalid(
                format!("runs[{r}]"),
                format!(
                    "a {}, expected a Recording (perturbid_rs.Recording, preprocessed)",
                    run.get_type().name()?
                ),
            )
            .into());
        };
        recordings.push(rec.get().rec.clone());
    }
    let payloads = (payloads.iter().enumerate())
        .map(|(r, p)| payload_of(r, p))
        .collect::<PyResult<Vec<_>>>()?;
    let fit = detached(py, "identify_drive_gains", || {
        let mut gain_runs = Vec::with_capacity(recordings.len());
        for (r, (rec, payload)) in recordings.iter().zip(&payloads).enumerate() {
            let (qd, qdd) = run_arrays(r, rec, model.nv)?;
            let columns = [
                Cow::Borrowed(&rec.q[..]),
                Cow::Borrowed(qd),
                Cow::Borrowed(qdd),
                Cow::Borrowed(&rec.tau[..]),
            ];
            check_sample_derivatives(
                &format!("runs[{r}] ('{}')", rec.name),
                model.nv,
                Some(rec.t.clone()),
                &columns,
            )?;
            let states = States::new(rec.n, &rec.q, Some(qd), Some(qdd))?;
            let states = match &rec.coulomb {
                Some(c) => states.with_coulomb(c)?,
                None => states,
            };
            gain_runs.push(GainRun {
                states,
                signal: &rec.tau,
                payload: payload.as_ref(),
            });
        }
        let fit = gains_rs(model, &gain_runs, &options, estimator)?.model;
        // what each run's preprocessing found, kept with the model as the command line keeps
        // its logs'
        Ok::<_, Error>(crate::direct::BaseModel {
            logs: (recordings.iter())
                .map(|r| crate::direct::LogFindings::of(&r.name, r))
                .collect(),
            ..fit
        })
    })?;
    // the runs' own findings were warned of by the preprocessing that made them
    super::errors::warn_all(py, &fit.fit_warnings())?;
    Ok(PyBaseModel {
        fit,
        model: Arc::new(model.clone()),
    })
}
