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

use serde::{Deserialize, Serialize};

use super::identify::BaseModel;
use super::residual_correlation::{combine, long_run_factors};
use super::streaming::JointFactors;
use crate::error::{shown, Result};
use crate::{Model, States};

/// [`LogAgreement::ratio`] beyond which the logs are warned of as disagreeing.
pub const AGREEMENT: f64 = 2.0;

/// The least number of independent samples (the samples over the residuals' long-run
/// factor) a joint needs per log and base parameter to be judged: with as many, a log's own
/// fit takes up at most about half the noise, and agreeing logs stay below a ratio of 1.5.
pub const JUDGED_SAMPLES: f64 = 2.0;

/// Per joint and log, one model's residuals against each log's own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogAgreement {
    /// Per joint, the RMS over the logs of the fit's residuals (less their mean on each log)
    /// over the RMS of each log's own fit's residuals; None where not judged (too few
    /// independent samples, or a log whose own fit its samples do not determine).
    pub ratio: Vec<Option<f64>>,
    /// Per log (the fit's order), per joint: the fit's residual RMS on it, less their mean
    /// (N m or N).
    pub fitted_rms: Vec<Vec<f64>>,
    /// Per log, per joint: its own fit's residual RMS (N m or N); None for a log whose samples
    /// do not determine the parameters.
    pub own_rms: Vec<Option<Vec<f64>>>,
}

impl LogAgreement {
    /// The finding, logs named by `names` (`run r` where none is given), joints by
    /// `joint_names`: the joints whose ratio is [`AGREEMENT`] or more, the log where the fit
    /// leaves most over its own named; a drift of the logs' offsets named among the causes
    /// unless `offsets_fitted` (an offset of each log's own). None where none is.
    pub fn finding(
        &self,
        names: &[String],
        joint_names: &[String],
        offsets_fitted: bool,
    ) -> Option<String> {
        let name = |r: usize| crate::logs::stacked_states::run_name(names, r);
        let own = |r: usize, j: usize| self.own_rms[r].as_ref().map_or(f64::NAN, |o| o[j]);
        let apart: Vec<String> = (self.ratio.iter().enumerate())
            .filter_map(|(j, r)| r.filter(|r| *r >= AGREEMENT).map(|r| (j, r)))
            .map(|(j, ratio)| {
                let worst = (0..self.own_rms.len())
                    .max_by(|&a, &b| {
                        let at = |r: usize| self.fitted_rms[r][j] / own(r, j);
                        at(a).total_cmp(&at(b))
                    })
                    .unwrap_or(0);
                format!(
                    "'{}' {:.1} times (most on '{}': {:.4} against its own {:.4} N m)",
                    joint_names.get(j).map_or("?", String::as_str),
                    ratio,
                    name(worst),
                    self.fitted_rms[worst][j],
                    own(worst, j)
                )
            })
            .collect();
        (!apart.is_empty()).then(|| {
            format!(
                "the logs do not agree with one robot: one model over all of them leaves residuals (less each log's mean) larger than each log's own fit leaves at {} (near 1 expected): a payload or tool mounted in some logs and not in others, a robot changed between them, or another robot's log{}; the model describes none of them. Fit the logs one by one to find the odd one",
                apart.join(", "),
                match offsets_fitted {
                    true => "",
                    false => " (or torque offsets that drifted between them, which bend the parameters: with an offset of each log's own, --offset-per-log or offset_per_log=True, logs that differ only so agree)",
                }
            )
        })
    }

    /// What is wrong with the entry of a model read from a file, for `nv` joints and `runs`
    /// runs (0 where the model names none): other shapes, values negative or beyond 1e9.
    pub(crate) fn problem(&self, nv: usize, runs: usize) -> Option<String> {
        let logs = self.own_rms.len();
        let shaped = self.fitted_rms.len() == logs
            && self.fitted_rms.iter().all(|r| r.len() == nv)
            && self.own_rms.iter().flatten().all(|r| r.len() == nv);
        if self.ratio.len() != nv
            || !shaped
            || !(2..=super::drive_gains::MAX_RUNS).contains(&logs)
            || (runs > 0 && runs != logs)
        {
            return Some(format!(
                "log_agreement: expected a ratio a joint ({nv}) and two RMS a joint and log (2 to {} logs{})",
                super::drive_gains::MAX_RUNS,
                if runs > 0 { format!(", as the model's {runs}") } else { String::new() }
            ));
        }
        let bad = |v: f64| v.is_nan() || !(0.0..=1e9).contains(&v);
        let all = (self.ratio.iter().flatten())
            .chain(self.own_rms.iter().flatten().flatten())
            .chain(self.fitted_rms.iter().flatten());
        all.copied().find(|v| bad(*v)).map(|v| {
            format!(
                "log_agreement: {}, expected a magnitude (or null where not judged)",
                shown(v)
            )
        })
    }
}

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
