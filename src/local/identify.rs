//! What the local identification (docs/method.md, section 4; [`super::identify_local()`])
//! reads of each experiment: its options, the values a recording gives at the experiment's
//! crossings, and the recordings matched to the plan's experiments.

use nalgebra::DMatrix;

use super::clock::{align, check_sample_interval, lagged_half};
use super::crossing::{
    samples_needed, values_in_windows, CrossingValues, FitOptions, SignalScales, TorqueFit,
};
pub use super::crossing_values::ExperimentValues;
use super::diagnostics::{Reversal, ReversalHandling};
use super::flat_channels::flat;
pub use super::flat_channels::{flat_torques, window_torques};
use super::model::Estimator;
use super::noise::{reading_variance, sample_variance};
use super::plan::{Experiment, Plan};
use super::quantisation;
use super::reversals::narrowed_window;
use super::rounded_positions::{self};
use crate::choice::choice;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// Where the crossing times come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CrossingTimes {
    /// The plan's times, the recording's clock starting with the plan (t = 0 at the plan's
    /// start). A recording whose clock is offset reads every crossing at the wrong time: 1 ms
    /// makes H* wrong by far more than its noise.
    Planned,
    /// The plan's times shifted by the offset between plan and recording found in the
    /// recorded positions (least squares against the planned trajectory, sub-sample). An
    /// offset larger than `max_shift` s is refused: the recording is then likely not a run of
    /// the experiment, or its clock needs to be fixed first. The offsets are in the model's
    /// diagnostics.
    Detected { max_shift: f64 },
}

impl CrossingTimes {
    /// The default tolerance of [`CrossingTimes::Detected`] (s).
    pub const DEFAULT_MAX_SHIFT: f64 = 0.5;

    /// The crossing times from `source`, detected ones within `max_shift` s of the plan's.
    pub fn new(source: TimesSource, max_shift: f64) -> Self {
        match source {
            TimesSource::Planned => CrossingTimes::Planned,
            TimesSource::Detected => CrossingTimes::Detected { max_shift },
        }
    }
}

choice! {
    /// Where the crossing times come from, by name ([`CrossingTimes`] without its tolerance).
    pub enum TimesSource ("crossing_times") {
        /// The plan's times: [`CrossingTimes::Planned`].
        Planned = "planned",
        /// The plan's times shifted by the offset found in the recording:
        /// [`CrossingTimes::Detected`].
        Detected = "detected",
    }
}

/// Options of [`identify_local`](super::identify_local()).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdentifyOptions {
    pub times: CrossingTimes,
    pub fit: FitOptions,
    pub estimator: Estimator,
    /// Identify H* with the friction-aware regression (default false): the differences of
    /// the +- pairs of the H experiment, `tau(qd* + d) - tau(qd* - d) = 2 H* d + c_j s_j`,
    /// where the rigid-body terms even in `d` cancel exactly and `s_j = sign(d_j)` marks the
    /// pairs that reverse joint j (its Coulomb step, `c_j` = the sum of its two Coulomb levels).
    /// Exact for viscous and (asymmetric) Coulomb friction; needs the plan's H perturbations in
    /// pairs, at least N + 1 of them (`PlanOptions::friction_aware_h`). The Coulomb levels are
    /// in [`LocalModel::coulomb`](super::LocalModel::coulomb).
    pub friction_aware_h: bool,
}

impl Default for IdentifyOptions {
    /// Crossing times aligned with each recording's clock (offsets up to 0.5 s), the default
    /// fit, the separated estimator.
    fn default() -> Self {
        Self {
            times: CrossingTimes::Detected {
                max_shift: CrossingTimes::DEFAULT_MAX_SHIFT,
            },
            fit: FitOptions::default(),
            estimator: Estimator::Separated,
            friction_aware_h: false,
        }
    }
}

/// How to read the torque of each joint at the crossing at plan time `tp` (the recording's
/// clock: `tp + offset`) so that no velocity reversal enters the fit: the full window where no
/// joint reverses within it; a window narrowed to 0.9 of the distance to the reversal where
/// that still holds `min_half` s; else a step at the reversal (see [`TorqueFit`]). The
/// reversals are appended to `found`.
#[allow(clippy::too_many_arguments)]
fn torque_fits(
    experiment: &Experiment,
    joint_names: &[String],
    tp: f64,
    offset: f64,
    half: f64,
    min_half: f64,
    crossing: Option<usize>,
    found: &mut Vec<Reversal>,
) -> Vec<TorqueFit> {
    let traj = &experiment.trajectory;
    (0..traj.n)
        .map(|j| {
            let Some((tr, narrowed)) = narrowed_window(traj, j, tp, half, min_half) else {
                return TorqueFit::Window(half);
            };
            let (fit, handling, window) = if let Some(narrowed) = narrowed {
                (
                    TorqueFit::Window(narrowed),
                    ReversalHandling::Narrowed,
                    narrowed,
                )
            } else {
                let slope = traj.segment_at(tr).eval(j, tr).2.signum();
                let fit = TorqueFit::Step {
                    reversal: tr + offset,
                    slope,
                };
                (fit, ReversalHandling::Step, half)
            };
            found.push(Reversal {
                experiment: experiment.kind.name().to_string(),
                crossing,
                joint: joint_names
                    .get(j)
                    .cloned()
                    .unwrap_or_else(|| format!("{}", j + 1)),
                at: tr - tp,
                handling,
                window,
            });
            fit
        })
        .collect()
}

/// Reads the values at every crossing of `experiment` from `rec`. `joint_names` name the
/// joints in diagnostics.
pub fn experiment_values(
    experiment: &Experiment,
    rec: &Recording,
    joint_names: &[String],
    options: &IdentifyOptions,
) -> Result<ExperimentValues> {
    let half = options.fit.window.unwrap_or(experiment.window);
    crate::limits::check_range("window", half, 0.0, 60.0)?;
    if !(half.is_finite() && half > 0.0) {
        return Err(Error::invalid(
            "window",
            format!("{half}; expected a positive number of seconds"),
        ));
    }
    check_sample_interval(rec, half, &options.fit)?;
    let steps = rounded_positions::position_steps(rec);
    let offset = match options.times {
        CrossingTimes::Planned => 0.0,
        CrossingTimes::Detected { max_shift } => {
            align(experiment, rec, joint_names, &steps, max_shift)?
        }
    };
    // the narrowest torque window that still holds enough samples at the recording's rate
    let dt = (rec.t[rec.len() - 1] - rec.t[0]) / (rec.len() - 1) as f64;
    let half = match options.fit.window {
        None => lagged_half(half, offset, dt),
        Some(_) => half,
    };
    let min_half = 0.5 * samples_needed(&options.fit) as f64 * dt;
    let name = experiment.kind.name();
    let mut reversals = vec![];
    // every window: the crossings' in order, then the reference posture's, each with its
    // joints' torque fits
    let windows: Vec<(f64, Option<usize>, String, Vec<TorqueFit>)> = experiment
        .crossings
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                c.time,
                Some(k),
                format!("experiment '{name}', crossing {k}"),
            )
        })
        .chain(experiment.reference.iter().map(|c| {
            let what = format!("experiment '{name}', reference posture");
            (c.time, None, what)
        }))
        .map(|(tp, crossing, what)| {
            let fits = torque_fits(
                experiment,
                joint_names,
                tp,
                offset,
                half,
                min_half,
                crossing,
                &mut reversals,
            );
            (tp, crossing, what, fits)
        })
        .collect();
    let centres: Vec<f64> = windows.iter().map(|w| w.0 + offset).collect();
    let torques = window_torques(rec, &centres, half);
    let in_clock: Vec<(f64, Vec<TorqueFit>, String)> = windows
        .into_iter()
        .map(|(tp, _, what, fits)| (tp + offset, fits, what))
        .collect();
    let scales = SignalScales {
        position_step: steps,
        torque_step: quantisation::torque_steps(&torques),
        noise: vec![],
    };
    let (mut values, scales) = values_in_windows(rec, &in_clock, half, scales, &options.fit)?;
    let reference = match experiment.reference {
        Some(_) => values.pop(),
        None => None,
    };
    let crossings = values;
    let position_step = (0..rec.n)
        .map(|j| {
            let banded = crossings
                .iter()
                .chain(&reference)
                .any(|c| c.position_band[j]);
            scales.position_step[j].filter(|_| banded)
        })
        .collect();
    Ok(ExperimentValues {
        kind: experiment.kind,
        offset,
        crossings,
        reference,
        reversals,
        flat_torque: flat(&torques),
        torque_step: scales.torque_step,
        position_step,
    })
}

pub(super) fn state(c: &CrossingValues, v: usize) -> &[f64] {
    match v {
        0 => &c.q,
        1 => &c.qd,
        _ => &c.qdd,
    }
}

/// The variances (N^2 m^2, one row per crossing of `experiments` in order, one column per
/// joint) that the torque samples' noise gives the torques read at the crossings, and the
/// samples' noise variance of each experiment, pooled within it, per joint (see
/// [`super::noise`]).
pub(super) fn reading_variances(
    experiments: &[&ExperimentValues],
    n: usize,
) -> (DMatrix<f64>, Vec<Vec<f64>>) {
    let samples: Vec<Vec<f64>> = experiments
        .iter()
        .map(|v| sample_variance(&v.crossings, n))
        .collect();
    let rows: Vec<Vec<f64>> = experiments
        .iter()
        .zip(&samples)
        .flat_map(|(v, s2)| v.crossings.iter().map(|c| reading_variance(c, s2)))
        .collect();
    (DMatrix::from_fn(rows.len(), n, |i, j| rows[i][j]), samples)
}

/// Pairs each experiment of `plan` with its recording, by identity: each recording says which
/// experiment it is a run of ([`Recording::experiment`]: its mark, or a name such as `D.csv`).
/// A recording that names no experiment of the plan, two for one experiment, or an experiment
/// without one is an error naming them: the order of `recordings` does not matter.
pub(super) fn match_recordings<'a>(
    plan: &Plan,
    recordings: &'a [Recording],
) -> Result<Vec<&'a Recording>> {
    let kinds: Vec<&str> = plan.experiments.iter().map(|e| e.kind.name()).collect();
    let mut found: Vec<Option<&Recording>> = vec![None; kinds.len()];
    let refuse = |message: String| Error::InvalidArgument {
        argument: "recordings".into(),
        message,
    };
    for r in recordings {
        let Some(kind) = r.experiment(&kinds) else {
            return Err(refuse(format!(
                "recording '{}' does not say which experiment it is a run of (the plan has {}): mark it (Python: Recording(..., experiment='D')) or name its file after the experiment (D.csv)",
                r.name,
                plan.kinds()
            )));
        };
        let Some(i) = kinds.iter().position(|k| *k == kind) else {
            return Err(refuse(format!(
                "recording '{}' is a run of experiment '{kind}', which the plan does not have (it has {})",
                r.name,
                plan.kinds()
            )));
        };
        if let Some(first) = found[i] {
            return Err(refuse(format!(
                "recordings '{}' and '{}' are both runs of experiment '{kind}'; give one",
                first.name, r.name
            )));
        }
        found[i] = Some(r);
    }
    kinds
        .iter()
        .zip(found)
        .map(|(kind, r)| {
            r.ok_or_else(|| refuse(format!("experiment '{kind}' of the plan has no recording")))
        })
        .collect()
}
