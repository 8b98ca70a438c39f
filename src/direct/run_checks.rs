//! Each run of a fit over several logs ([`super::BaseOptions::runs`]) against the robot's own
//! model, as a fit of one log is checked: its torque columns ([`super::torque_columns`]), its
//! torques' lag behind its positions ([`super::torque_lag`]) and its positions against the
//! joint limits ([`super::position_range`]).
//!
//! Checked over the stacked samples only, one wrong log among right ones hides: the A465's
//! shoulder torque logged in mN m in one of two logs fitted with residuals of 13,000 N m and
//! no warning (the column's scale read over both logs is neither 1 nor 1,000, and its gain
//! below the check's threshold), a log with its first two torque columns swapped read as a
//! negative Coulomb coefficient, and a log whose positions froze at their first sample while its
//! torques went on, beside a right one, as a lag of 315 samples.
//! Each log is therefore checked alone, and its findings are warned of naming it
//! (docs/method.md, "Several logs").

use serde::{Deserialize, Serialize};

use super::position_range::{check_position_range, JointRange};
use super::torque_columns::{check_torque_columns, TorqueColumn};
use super::torque_lag::{check_torque_lag, log_findings, TorqueLag};
use crate::error::Result;
use crate::{Gravity, Model, States};

/// One run's data against the robot's model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunChecks {
    /// The run's samples (as fitted).
    pub samples: usize,
    /// Its torque columns against the model, one a joint (empty for a run under 20 samples).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_columns: Vec<TorqueColumn>,
    /// Its torques' shift against its positions (None where not judged: a run under 40
    /// samples, or no column its model explains).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_lag: Option<TorqueLag>,
    /// Its joints whose positions leave their URDF limits.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_range: Vec<JointRange>,
}

impl RunChecks {
    /// What looks wrong with the run (its [`log_findings`]), each named as the run `name`'s.
    pub fn findings(&self, name: &str) -> Vec<String> {
        log_findings(
            &self.position_range,
            &self.torque_columns,
            self.torque_lag.as_ref(),
        )
        .into_iter()
        .map(|f| format!("log '{name}': {f}"))
        .collect()
    }

    /// Whether a torque column of the run is found wrong.
    pub fn columns_wrong(&self) -> bool {
        !super::torque_columns::findings(&self.torque_columns).is_empty()
    }
}

/// Each of the `runs` (run lengths, in order, adding up to the samples of `states`) of the
/// samples `states` (rad, rad/s, rad/s^2; velocities and accelerations required) and torques
/// `tau` (row-major `k x nv`, N m) checked alone against `model`'s inverse dynamics, with or
/// without gravity as the logs were recorded; empty for fewer than two runs (a single run is
/// the fit's own checks). Each run's checks read at most their own sample counts
/// ([`super::torque_columns::SAMPLES`], [`super::torque_lag::SAMPLES`]): about 1 ms a run
/// of a 6-joint arm. The caller checks `runs` first.
pub fn check_runs_against_model(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    runs: &[usize],
    gravity: Gravity,
) -> Result<Vec<RunChecks>> {
    if runs.len() < 2 {
        return Ok(vec![]);
    }
    let nv = model.nv;
    let mut start = 0;
    let mut out = Vec::with_capacity(runs.len());
    for &len in runs {
        crate::interrupt::check("checking each log against the model")?;
        let (rows, values) = (start..start + len, start * nv..(start + len) * nv);
        let run = states.slice(rows);
        let tau = &tau[values];
        out.push(RunChecks {
            samples: len,
            torque_columns: check_torque_columns(model, &run, tau, gravity)?,
            torque_lag: check_torque_lag(model, &run, tau, gravity)?,
            position_range: check_position_range(model, &run),
        });
        start += len;
    }
    Ok(out)
}

/// The findings of every run of `checks`, each named by `names` (a log's path or a
/// Recording's name; `run r` where none is given).
pub fn findings(checks: &[RunChecks], names: &[String]) -> Vec<String> {
    (checks.iter().enumerate())
        .flat_map(|(r, c)| {
            let name = crate::logs::stacked_states::run_name(names, r);
            c.findings(&name)
        })
        .collect()
}

/// What is wrong with a log's checks read from a file, for a model of `joint_names`: torque
/// columns neither one a joint nor none, or any entry's own problem
/// ([`TorqueColumn::problem`], [`TorqueLag::problem`], [`JointRange::problem`], joints not
/// the model's). `field` names the checks' place in the document (`torque_columns` at the
/// top, or `run_checks[3].torque_columns`).
pub(crate) fn data_checks_problem(
    columns: &[TorqueColumn],
    lag: Option<&TorqueLag>,
    ranges: &[JointRange],
    joint_names: &[String],
    field: impl Fn(&str) -> String,
) -> Option<String> {
    let n = joint_names.len();
    if !columns.is_empty() && columns.len() != n {
        return Some(format!(
            "{}: {} entries, expected one per joint ({n}) or none",
            field("torque_columns"),
            columns.len()
        ));
    }
    if let Some((i, p)) =
        (columns.iter().enumerate()).find_map(|(i, c)| c.problem(joint_names).map(|p| (i, p)))
    {
        return Some(format!("{}[{i}]: {p}", field("torque_columns")));
    }
    if let Some(p) = lag.and_then(|l| l.problem(joint_names)) {
        return Some(format!("{}: {p}", field("torque_lag")));
    }
    (ranges.iter().enumerate()).find_map(|(i, r)| {
        let unknown = (!joint_names.contains(&r.joint))
            .then(|| format!("joint '{}' is not one of the model's", r.joint));
        unknown
            .or_else(|| r.problem())
            .map(|p| format!("{}[{i}]: {p}", field("position_range")))
    })
}

/// What is wrong with a model's `checks` read from a file, for a model of `joint_names` fitted
/// to `samples` samples of `logs` logs (0 where it names none): none, or one a run, at most
/// [`super::findings::drive_gains::MAX_RUNS`], two or more, their samples adding up to the model's,
/// each run's checks as [`data_checks_problem`] reads them.
pub(crate) fn problem(
    checks: &[RunChecks],
    joint_names: &[String],
    samples: usize,
    logs: usize,
) -> Option<String> {
    if checks.is_empty() {
        return None;
    }
    let most = super::findings::drive_gains::MAX_RUNS;
    let total = checks
        .iter()
        .try_fold(0usize, |t, c| t.checked_add(c.samples));
    if checks.len() < 2 || checks.len() > most || (logs > 0 && logs != checks.len()) {
        return Some(format!(
            "run_checks: {} runs' checks, expected none or one a run (2 to {most}{})",
            checks.len(),
            if logs > 0 {
                format!("; the model has {logs} logs")
            } else {
                String::new()
            }
        ));
    }
    if let Some(r) = checks.iter().position(|c| c.samples == 0) {
        return Some(format!("run_checks[{r}]: a run of 0 samples"));
    }
    if total != Some(samples) {
        return Some(format!(
            "run_checks: runs of {} samples in all, for a model of {samples} samples",
            total.map_or_else(|| "too many".to_string(), |t| t.to_string())
        ));
    }
    (checks.iter().enumerate()).find_map(|(r, c)| {
        data_checks_problem(
            &c.torque_columns,
            c.torque_lag.as_ref(),
            &c.position_range,
            joint_names,
            |f| format!("run_checks[{r}].{f}"),
        )
    })
}
