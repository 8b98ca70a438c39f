//! The runs of a fit over several logs ([`super::BaseOptions::runs`]): each run's residuals
//! read as a time series of their own, for their correlation from sample to sample
//! ([`super::residual_correlation`]) and for their mean, which tells a torque offset that
//! drifted between the runs ([`RunOffsets`]).
//!
//! One offset term a joint fits the runs' offsets' mean. Where a sensor was zeroed anew or a
//! drive warmed up between two logs, each log's residuals keep their share of the difference:
//! a step at the join that no parameter can take, which bends the others and widens their
//! standard errors (docs/method.md, "Several logs").

use super::base_model::BaseModel;
pub use super::findings::runs::*;
use super::residual_correlation::{combine, long_run_factors, SAMPLES, SAMPLES_A_RUN};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::states::States;

/// Refuses `runs` ([`super::BaseOptions::runs`]) that are not the lengths of consecutive runs
/// of `k` samples: none of 0, adding up to `k`, at most [`super::findings::drive_gains::MAX_RUNS`].
pub(super) fn check_runs(runs: &[usize], k: usize) -> Result<()> {
    let most = super::findings::drive_gains::MAX_RUNS;
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
