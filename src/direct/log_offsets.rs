//! An offset a log, fitted ([`super::BaseOptions::offset_per_run`]): where a torque sensor was
//! zeroed anew or a drive warmed up between two logs, one offset a joint cannot fit both
//! (the drift [`super::runs::RunOffsets`] names). Fitted with a torque offset of its own for
//! every log, each joint's offset term in the base parameters is the logs' mean offset, and each
//! log's offset less that mean is an unknown of the fit beside them
//! ([`super::streaming::JointFactors::with_runs`]): the parameters are fitted to what the logs
//! share, not bent to their differences (docs/method.md, "Several logs").
//!
//! The model predicts with the mean offset (a new log's offset is not known); each log's own is
//! the mean plus its deviation. The checks after the fit (the residuals' correlation and means,
//! the joints' zero offsets, friction the fit leaves out) read the torques with each log's
//! deviation taken out ([`LogOffsets::taken_out`]).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::error::shown;

/// Each log's torque offset less the logs' mean, per joint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogOffsets {
    /// Per joint (the model's order), per run (the fit's order): the run's torque offset less
    /// the runs' mean (N m, or N for a prismatic joint). Each joint's sum to 0 over the runs.
    pub deviations: Vec<Vec<f64>>,
    /// Their standard errors (N m or N), counting the residuals' correlation from sample to
    /// sample as the parameters' do.
    pub stderr: Vec<Vec<f64>>,
}

impl LogOffsets {
    /// From a fit's unknowns `coef` (`p` base parameters, then per joint its `runs - 1`
    /// deviations of runs `1 ..`, [`super::streaming::JointFactors::with_runs`]), their
    /// standard errors `stderr` and correlation `correlation`, for `nv` joints.
    pub(super) fn of_fit(
        coef: &[f64],
        stderr: &[f64],
        correlation: &DMatrix<f64>,
        p: usize,
        nv: usize,
        runs: usize,
    ) -> Self {
        let e = runs - 1;
        let at = |j: usize, c: usize| p + j * e + c;
        let cov = |a: usize, b: usize| correlation[(a, b)] * stderr[a] * stderr[b];
        let errors = (0..nv)
            .map(|j| {
                // the first run's is minus the others' sum: its variance their covariances' sum
                let first: f64 = (0..e)
                    .flat_map(|a| (0..e).map(move |b| (a, b)))
                    .map(|(a, b)| cov(at(j, a), at(j, b)))
                    .sum();
                [first.max(0.0).sqrt()]
                    .into_iter()
                    .chain((0..e).map(|c| stderr[at(j, c)]))
                    .collect()
            })
            .collect();
        Self {
            deviations: Self::deviations_of(coef, p, nv, runs),
            stderr: errors,
        }
    }

    /// Per joint and run, the deviations that a fit's unknowns `coef` (as [`Self::of_fit`]
    /// reads them) hold.
    pub(super) fn deviations_of(coef: &[f64], p: usize, nv: usize, runs: usize) -> Vec<Vec<f64>> {
        let e = runs - 1;
        (0..nv)
            .map(|j| {
                let own = &coef[p + j * e..p + (j + 1) * e];
                [-own.iter().sum::<f64>()]
                    .into_iter()
                    .chain(own.iter().copied())
                    .collect()
            })
            .collect()
    }

    /// The number of runs.
    pub fn runs(&self) -> usize {
        self.deviations.first().map_or(0, Vec::len)
    }

    /// The torques `tau` (row-major `k x nv`, in runs of `runs` samples) with each run's
    /// deviation taken out: what the model with the mean offset fits as the fit with each
    /// run's own offset fits `tau`.
    pub fn taken_out(&self, tau: &[f64], runs: &[usize]) -> Vec<f64> {
        self.shifted(tau, runs, -1.0)
    }

    /// The model's torques `predicted` (row-major `k x nv`, in runs of `runs` samples of the
    /// runs fitted, in their order) with each run's own offset: each run's deviation added.
    pub fn added(&self, predicted: &[f64], runs: &[usize]) -> Vec<f64> {
        self.shifted(predicted, runs, 1.0)
    }

    /// `x` with `sign` times each run's deviation added to its rows.
    fn shifted(&self, x: &[f64], runs: &[usize], sign: f64) -> Vec<f64> {
        let nv = self.deviations.len();
        let mut out = x.to_vec();
        let mut start = 0;
        for (r, &len) in runs.iter().enumerate() {
            for row in out[start * nv..(start + len) * nv].chunks_exact_mut(nv) {
                for (j, t) in row.iter_mut().enumerate() {
                    *t += sign * self.deviations[j][r];
                }
            }
            start += len;
        }
        out
    }

    /// The standard errors scaled by `factor` (the residuals' correlation).
    pub(super) fn inflate(&mut self, factor: f64) {
        for se in self.stderr.iter_mut().flatten() {
            *se *= factor;
        }
    }

    /// What is wrong with the offsets of a model read from a file, for `nv` joints and `logs`
    /// runs (its logs or its runs' checks; 0 where the model names none), whose layout has the offset term (`has_offset`):
    /// a model without it, other shapes, runs beyond
    /// [`super::streaming::MAX_OFFSET_RUNS`], values not finite or beyond 1e9, standard errors
    /// not positive, a joint's deviations that do not sum to 0.
    pub(crate) fn problem(&self, nv: usize, logs: usize, has_offset: bool) -> Option<String> {
        let runs = self.runs();
        let most = super::streaming::MAX_OFFSET_RUNS;
        if !has_offset {
            return Some("log_offsets: the model has no offset term; offsets a log are the deviations from it".into());
        }
        let shaped = |m: &[Vec<f64>]| m.len() == nv && m.iter().all(|r| r.len() == runs);
        if !(2..=most).contains(&runs)
            || !shaped(&self.deviations)
            || !shaped(&self.stderr)
            || (logs > 0 && logs != runs)
        {
            return Some(format!(
                "log_offsets: expected deviations and stderr of {nv} joints x one a run (2 to {most}{})",
                if logs > 0 { format!("; the model has {logs} logs") } else { String::new() }
            ));
        }
        for (j, (d, s)) in self.deviations.iter().zip(&self.stderr).enumerate() {
            if let Some(r) = d.iter().position(|v| v.is_nan() || v.abs() > 1e9) {
                return Some(format!(
                    "log_offsets.deviations[{j}][{r}] is {}, expected a torque",
                    shown(d[r])
                ));
            }
            if let Some(r) = s.iter().position(|v| !(*v > 0.0 && *v <= 1e9)) {
                return Some(format!(
                    "log_offsets.stderr[{j}][{r}] is {}, expected a positive standard error",
                    shown(s[r])
                ));
            }
            let (sum, size) = (
                d.iter().sum::<f64>(),
                d.iter().map(|v| v.abs()).sum::<f64>(),
            );
            if sum.abs() > 1e-9 * size.max(1e-12) {
                return Some(format!(
                    "log_offsets.deviations[{j}] sum to {}, expected 0 (each log's offset less the logs' mean)",
                    shown(sum)
                ));
            }
        }
        None
    }
}

/// `e` with the argument `offset_per_run` named as a front end calls it (`--offset-per-log`,
/// `offset_per_log`); other errors as they are.
pub fn as_argument(e: crate::error::Error, name: &str) -> crate::error::Error {
    match e {
        crate::error::Error::InvalidArgument { argument, message }
            if argument == "offset_per_run" =>
        {
            crate::error::Error::InvalidArgument {
                argument: name.into(),
                message,
            }
        }
        other => other,
    }
}

/// Refuses an offset a run ([`super::BaseOptions::offset_per_run`]) that `options` cannot
/// take: fewer than two runs or more than [`super::streaming::MAX_OFFSET_RUNS`], or joint
/// terms without the offset (the runs' offsets are deviations from it).
pub(super) fn check_options(options: &super::BaseOptions) -> crate::error::Result<()> {
    let most = super::streaming::MAX_OFFSET_RUNS;
    let problem = if !(2..=most).contains(&options.runs.len()) {
        Some(format!(
            "an offset a log needs 2 to {most} logs (runs), got {}",
            options.runs.len().max(1)
        ))
    } else if !options.friction.offset {
        Some("an offset a log needs the offset among the joint terms (friction), whose deviations they are".to_string())
    } else {
        None
    };
    match problem {
        Some(message) => Err(crate::error::Error::InvalidArgument {
            argument: "offset_per_run".into(),
            message,
        }),
        None => Ok(()),
    }
}
