//! Each run's torque offset against the others. (the checks that find them: [`crate::direct::runs`]).

use serde::{Deserialize, Serialize};

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
        } else if !(2..=crate::limits::MAX_LOGS).contains(&count)
            || self.stderr.len() != count
            || (runs > 0 && runs != count)
        {
            Some(format!(
                "{count} means and {} standard errors, expected one of each a run (2 to {}{})",
                self.stderr.len(),
                crate::limits::MAX_LOGS,
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
pub(in crate::direct) fn extremes(v: &[f64]) -> (usize, usize) {
    let by = |a: &&f64, b: &&f64| a.total_cmp(b);
    let lo = (v.iter().enumerate())
        .min_by(|a, b| by(&a.1, &b.1))
        .map_or(0, |x| x.0);
    let hi = (v.iter().enumerate())
        .max_by(|a, b| by(&a.1, &b.1))
        .map_or(0, |x| x.0);
    (lo, hi)
}
