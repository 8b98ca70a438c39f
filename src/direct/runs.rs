//! The runs of a fit over several logs ([`super::BaseOptions::runs`]): each run's residuals
//! read as a time series of their own, for their correlation from sample to sample
//! ([`super::residual_correlation`]) and for their mean, which tells a torque offset that
//! drifted between the runs ([`RunOffsets`]).
//!
//! One offset term a joint fits the runs' offsets' mean. Where a sensor was zeroed anew or a
//! drive warmed up between two logs, each log's residuals keep their share of the difference:
//! a step at the join that no parameter can take, which bends the others and widens their
//! standard errors (docs/method.md, "Several logs").

use serde::{Deserialize, Serialize};

use super::identify::BaseModel;
use super::residual_correlation::{combine, long_run_factors, SAMPLES, SAMPLES_A_RUN};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::states::States;

/// A run's mean residual this many of its standard errors from the runs' weighted mean is a
/// finding (with [`RELATIVE`]); among 1,000 runs of white residuals one is that far with a
/// chance below 1e-3.
pub const STANDARD_ERRORS: f64 = 5.0;

/// ... where the runs' means also spread over at least this fraction of the joint's residual
/// RMS (an offset too small to matter is not named).
pub const RELATIVE: f64 = 0.1;

/// A joint whose residuals differ in mean from run to run: a torque offset that drifted
/// between the logs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunOffsets {
    pub joint: String,
    /// Per run, in the fit's order, its residuals' mean (N m or N) over its first samples.
    pub means: Vec<f64>,
    /// Per run, that mean's standard error (N m or N), counting the residuals' correlation
    /// from sample to sample.
    pub stderr: Vec<f64>,
    /// The joint's residual RMS over those samples of every run (N m or N).
    pub residual_rms: f64,
}

impl RunOffsets {
    /// What is wrong with the finding for a model of joints `joint_names` and `runs` runs
    /// (0 where the model names none); None where nothing is.
    pub(crate) fn problem(&self, joint_names: &[String], runs: usize) -> Option<String> {
        let count = self.means.len();
        if !joint_names.contains(&self.joint) {
            Some(format!("joint '{}' is not one of the model's", self.joint))
        } else if !(2..=super::drive_gains::MAX_RUNS).contains(&count)
            || self.stderr.len() != count
            || (runs > 0 && runs != count)
        {
            Some(format!(
                "{count} means and {} standard errors, expected one of each a run (2 to {}{})",
                self.stderr.len(),
                super::drive_gains::MAX_RUNS,
                if runs > 0 {
                    format!("; the model has {runs} logs")
                } else {
                    String::new()
                }
            ))
        } else if let Some(i) = self.means.iter().position(|m| m.is_nan() || m.abs() > 1e9) {
            Some(format!(
                "means[{i}] is {}, expected a torque",
                crate::error::shown(self.means[i])
            ))
        } else if let Some(i) = self
            .stderr
            .iter()
            .position(|s| s.is_nan() || *s <= 0.0 || *s > 1e9)
        {
            Some(format!(
                "stderr[{i}] is {}, expected a positive standard error",
                crate::error::shown(self.stderr[i])
            ))
        } else if self.residual_rms.is_nan() || self.residual_rms < 0.0 || self.residual_rms > 1e9 {
            Some(format!(
                "residual_rms is {}, expected a magnitude",
                crate::error::shown(self.residual_rms)
            ))
        } else {
            None
        }
    }

    /// The finding, runs named by `names` (a log's path; `run i` where none is given).
    pub fn finding(&self, names: &[String]) -> String {
        let name = |i: usize| crate::logs::stacked_states::run_name(names, i);
        let (lo, hi) = extremes(&self.means);
        let apart = (self.means[hi] - self.means[lo])
            / (self.stderr[hi].powi(2) + self.stderr[lo].powi(2)).sqrt();
        format!(
            "the residuals of joint '{}' differ in mean from log to log, from {:.4} ('{}') to {:.4} ('{}'), {:.0} standard errors apart, {:.0} % of its residual RMS {:.4}: a torque offset that drifted between the logs (a sensor zeroed anew, a drive warmed up), which one offset a joint cannot fit, or an effect the model lacks that the logs' motions excite unlike; it bends the other parameters and widens their standard errors. Fit an offset of each log's own (identify-direct --offset-per-log, Python offset_per_log=True), or compare the logs fitted one by one",
            self.joint,
            self.means[lo],
            name(lo),
            self.means[hi],
            name(hi),
            apart,
            100.0 * (self.means[hi] - self.means[lo]) / self.residual_rms,
            self.residual_rms
        )
    }
}

/// The indices of the smallest and the largest value.
fn extremes(v: &[f64]) -> (usize, usize) {
    let by = |a: &&f64, b: &&f64| a.total_cmp(b);
    let lo = (v.iter().enumerate())
        .min_by(|a, b| by(&a.1, &b.1))
        .map_or(0, |x| x.0);
    let hi = (v.iter().enumerate())
        .max_by(|a, b| by(&a.1, &b.1))
        .map_or(0, |x| x.0);
    (lo, hi)
}

/// Refuses `runs` ([`super::BaseOptions::runs`]) that are not the lengths of consecutive runs
/// of `k` samples: none of 0, adding up to `k`, at most [`super::drive_gains::MAX_RUNS`].
pub(super) fn check_runs(runs: &[usize], k: usize) -> Result<()> {
    let most = super::drive_gains::MAX_RUNS;
    let problem = if runs.len() > most {
        Some(format!("{} runs, expected at most {most}", runs.len()))
    } else if let Some(r) = runs.iter().position(|&len| len == 0) {
        Some(format!("run {r} has no samples"))
    } else if !runs.is_empty() && runs.iter().sum::<usize>() != k {
        Some(format!(
            "runs of {} samples in all, for {k} samples",
            runs.iter().sum::<usize>()
        ))
    } else {
        None
    };
    match problem {
        Some(message) => Err(Error::InvalidArgument {
            argument: "runs".into(),
            message,
        }),
        None => Ok(()),
    }
}

/// What the runs' residuals say of `fit` on the samples `states`, `tau` (row-major `k x nv`)
/// in runs of `runs` samples (empty: one run), each read from its first samples
/// ([`SAMPLES`] shared among the runs, at least [`SAMPLES_A_RUN`] each): per joint the
/// long-run variance factor, the runs' combined as their information is; and the joints whose
/// runs differ in mean ([`RunOffsets`]: a run's mean [`STANDARD_ERRORS`] or more from their
/// weighted mean, the means spread over [`RELATIVE`] of the residual RMS or more).
pub(super) fn run_residuals(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
    runs: &[usize],
) -> Result<(Vec<f64>, Vec<RunOffsets>)> {
    let (nv, k) = (model.nv, states.len());
    let whole = [k];
    let runs = if runs.is_empty() { &whole[..] } else { runs };
    let head = (SAMPLES / runs.len()).max(SAMPLES_A_RUN);
    let mut start = 0;
    let mut factors = Vec::with_capacity(runs.len());
    // per run and joint: the mean, its variance, and the sum of squares, over the run's head
    let mut stats = Vec::with_capacity(runs.len());
    for &len in runs {
        let rows = start..start + len.min(head);
        let predicted = fit.predict(model, &states.slice(rows.clone()))?;
        let residuals: Vec<f64> = (tau[rows.start * nv..rows.end * nv].iter())
            .zip(&predicted)
            .map(|(t, p)| t - p)
            .collect();
        let f = long_run_factors(&residuals, nv);
        let m = rows.len() as f64;
        stats.push(
            (0..nv)
                .map(|j| {
                    let x = || residuals.iter().skip(j).step_by(nv);
                    let mean = x().sum::<f64>() / m;
                    let squares = x().map(|r| r * r).sum::<f64>();
                    let variance = (squares / m - mean * mean).max(0.0);
                    (mean, variance * f[j] / m, squares)
                })
                .collect::<Vec<_>>(),
        );
        factors.push((f, len));
        start += len;
    }
    let mut offsets = vec![];
    if runs.len() > 1 {
        let used: f64 = runs.iter().map(|&len| len.min(head) as f64).sum();
        for (j, joint) in model.joint_names.iter().enumerate() {
            let at = |r: usize| stats[r][j];
            // runs whose residuals are exactly constant (noise-free) have no standard error
            if (0..runs.len()).any(|r| at(r).1.is_nan() || at(r).1 <= 0.0) {
                continue;
            }
            let weights: f64 = (0..runs.len()).map(|r| 1.0 / at(r).1).sum();
            let mean = (0..runs.len()).map(|r| at(r).0 / at(r).1).sum::<f64>() / weights;
            let rms = ((0..runs.len()).map(|r| at(r).2).sum::<f64>() / used).sqrt();
            let means: Vec<f64> = (0..runs.len()).map(|r| at(r).0).collect();
            let stderr: Vec<f64> = (0..runs.len()).map(|r| at(r).1.sqrt()).collect();
            let (lo, hi) = extremes(&means);
            let far =
                (0..runs.len()).any(|r| (means[r] - mean).abs() >= STANDARD_ERRORS * stderr[r]);
            let spread = means[hi] - means[lo];
            if far && spread >= RELATIVE * rms && spread.is_finite() && rms > 0.0 {
                offsets.push(RunOffsets {
                    joint: joint.clone(),
                    means,
                    stderr,
                    residual_rms: rms,
                });
            }
        }
    }
    Ok((combine(&factors, nv), offsets))
}
