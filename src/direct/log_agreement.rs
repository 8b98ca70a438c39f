//! Whether the logs of a fit over several ([`super::BaseOptions::runs`]) agree with one robot:
//! a payload or a tool mounted in some logs and not in others, a robot changed between them (a
//! joint repaired, a cable rerouted) or another robot's log are fitted by one model without a
//! word, and the model describes none of them.
//!
//! Each log is fitted alone with the same base parameters and weights, and per joint the
//! residuals the fit over all the logs leaves on each log (less their mean there: an offset
//! that drifted is [`super::runs::RunOffsets`]' and [`super::log_offsets`]' to tell) are
//! compared with those the log's own fit leaves: [`LogAgreement::ratio`], the RMS of the one
//! over the RMS of the other, summed over the logs. Where the logs agree, each own fit only
//! takes up a little more of the noise: the ratio is near 1 (two simulated A465 logs of one
//! robot, 1.002-1.03; two halves of the real Panda log, 1.02-1.07). A payload of 0.1 kg at the
//! A465's flange in one of two logs made it 1.5 to 7.3, of 1 kg 10 to 71. A joint is judged
//! where the logs' samples, counted as independent ones by the own fits' residuals'
//! correlation ([`super::residual_correlation`]), are at least [`JUDGED_SAMPLES`] times the
//! logs' parameters: under that the own fits take up much
//! of the noise and the ratio says little (the real Panda log in thirds leaves its wrist unjudged). Beyond [`AGREEMENT`] it is a finding.

use super::base_model::BaseModel;
pub use super::findings::log_agreement::*;
use super::residual_correlation::{combine, long_run_factors};
use super::streaming::JointFactors;
use crate::error::Result;
use crate::{Model, States};

/// The agreement of the `runs` (two or more; the samples of each, in order) of `fit`, whose
/// samples are `states` (rad, rad/s, rad/s^2) and torques `tau` (row-major `k x nv`, N m;
/// with each run's own offset taken out where one was fitted): each run fitted alone with the
/// fit's base parameters, weights and gravity ([`JointFactors`]), one pass over its samples
/// and two predictions (the fit's and its own). None for fewer than two runs.
pub(super) fn check_log_agreement(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
    runs: &[usize],
) -> Result<Option<LogAgreement>> {
    if runs.len() < 2 {
        return Ok(None);
    }
    let (nv, p) = (model.nv, fit.theta.len());
    let names = fit.base.names();
    let (mut fitted_rms, mut own_rms) = (Vec::new(), Vec::new());
    let (mut fitted_sum, mut own_sum) = (vec![0.0; nv], vec![0.0; nv]);
    let mut determined = true;
    // each own fit's residuals' long-run factors: the noise's correlation where the logs
    // agree (the fit's own residuals are correlated by any disagreement too)
    let mut factors = Vec::with_capacity(runs.len());
    let mut start = 0;
    for &len in runs {
        crate::interrupt::check("fitting each log alone")?;
        let rows = start..start + len;
        let (run, measured) = (
            states.slice(rows.clone()),
            &tau[rows.start * nv..rows.end * nv],
        );
        start += len;
        // the fit's residuals on the run, less their mean there
        let predicted = fit.predict(model, &run)?;
        let fitted: Vec<f64> = (0..nv)
            .map(|j| {
                let r = |s: usize| measured[s * nv + j] - predicted[s * nv + j];
                let mean = (0..len).map(r).sum::<f64>() / len as f64;
                ((0..len).map(|s| (r(s) - mean).powi(2)).sum::<f64>() / len as f64).sqrt()
            })
            .collect();
        // its own fit: none where its samples do not determine the parameters
        let own = match JointFactors::new(model, &fit.base, &run, measured, fit.gravity)
            .and_then(|f| f.solve(&fit.sigma, &names).map(|ls| (f, ls)))
        {
            Ok((f, ls)) if len * nv > p => {
                let theta: Vec<f64> = ls.coef.iter().copied().collect();
                let alone = BaseModel {
                    theta: theta.clone(),
                    ..fit.clone()
                };
                let residuals: Vec<f64> = (measured.iter())
                    .zip(alone.predict(model, &run)?)
                    .map(|(t, p)| t - p)
                    .collect();
                factors.push((long_run_factors(&residuals, nv), len));
                Some(f.residual_rms(&theta)?)
            }
            Err(e @ crate::error::Error::Interrupted { .. }) => return Err(e),
            _ => None,
        }
        .filter(|o| o.iter().all(|v| v.is_finite()));
        determined &= own.is_some();
        for j in 0..nv {
            fitted_sum[j] += fitted[j].powi(2) * len as f64;
            own_sum[j] += own.as_ref().map_or(0.0, |o| o[j].powi(2)) * len as f64;
        }
        fitted_rms.push(fitted);
        own_rms.push(own);
    }
    let k: usize = runs.iter().sum();
    let factor = combine(&factors, nv);
    let ratio = (0..nv)
        .map(|j| {
            let independent = k as f64 / factor.get(j).copied().unwrap_or(1.0).max(1.0);
            let judged = determined
                && independent >= JUDGED_SAMPLES * (runs.len() * p) as f64
                && own_sum[j] > 0.0;
            judged.then(|| (fitted_sum[j] / own_sum[j]).sqrt())
        })
        .collect();
    Ok(Some(LogAgreement {
        ratio,
        fitted_rms,
        own_rms,
    }))
}
