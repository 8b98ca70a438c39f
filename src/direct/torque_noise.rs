//! The torques' noise measured apart from any fit: from the spread of an excitation's periods
//! ([`crate::logs::period_average`], [`crate::logs::period_average::PeriodAverage::torque_noise`]), or
//! given by the caller (a log of the robot held still, a sensor's data sheet). It weights the
//! rows of a [`super::Weighting::Noise`] fit, and is the yardstick a fit's residuals are
//! judged against ([`super::noise_fit`]).

use serde::{Deserialize, Serialize};

use crate::error::{shown5, Error, Result};
use crate::logs::period_average::PeriodAverage;

/// The largest noise level taken (N m): its square must stay far inside f64's range.
pub const MAX_NOISE: f64 = 1e100;

/// The most samples a joint's noise may take for one independent value.
pub const MAX_CORRELATION: f64 = 1e9;

/// The most one log's noise level may differ from another's on a joint (either way) for the
/// logs to be weighted by their pooled noise.
pub const MAX_LOG_RATIO: f64 = 1.5;

/// The torques' noise: its level per joint and how correlated it is from sample to sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueNoise {
    /// Per joint, the standard deviation of the torques' noise a sample (N m; N for a
    /// prismatic joint), positive.
    pub sigma: Vec<f64>,
    /// Samples over which a joint's noise holds one independent value, at least 1: 1 for
    /// noise white at the samples' rate; for an averaged period, its samples over the `2 H +
    /// 1` values its `H` torque harmonics hold (the noise lies in their span).
    pub correlation: f64,
    /// The degrees of freedom the levels were estimated with, summed over the joints (for an
    /// averaged period, `(periods - 1) (2 H + 1)` a joint); None for levels known exactly.
    /// The fit's residuals are then judged by an F test rather than a chi-square one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub degrees_of_freedom: Option<f64>,
}

impl TorqueNoise {
    /// The noise of a log's torques averaged over the periods of its excitation, for the noise
    /// weighting and the judgement of a fit's residuals ([`crate::direct::noise_fit`]):
    /// [`PeriodAverage::averaged_torque_noise`] a joint (N m), correlated over
    /// `kept_samples / (2 H + 1)` samples (at least 1; `H` the torque harmonics: the noise lies in their span), its
    /// levels estimated with `(periods - 1) (2 H + 1)` degrees of freedom a joint. Errors
    /// naming the joint whose torques' noise measured 0 (a log without noise, such as a
    /// simulated one), or a finding saved without `kept_samples`.
    pub fn from_period_average(
        average: &PeriodAverage,
        joints: &[String],
    ) -> crate::error::Result<TorqueNoise> {
        let bad = |message: String| crate::error::Error::InvalidArgument {
            argument: "noise".into(),
            message,
        };
        if average.kept_samples == 0 {
            return Err(bad("the log's period average was kept without its samples (saved by an older version): average the log anew".into()));
        }
        let sigma = average.averaged_torque_noise();
        if let Some(j) = sigma.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            let name = joints
                .get(j)
                .cloned()
                .unwrap_or_else(|| format!("joint {}", j + 1));
            return Err(bad(format!(
                "the {} periods averaged measured no noise in {name}'s torques ({}): identical periods (a simulated log without noise) give no noise to weight by or judge against",
                average.periods,
                crate::error::shown(sigma[j])
            )));
        }
        let values = (2 * average.torque_harmonics + 1) as f64;
        Ok(TorqueNoise {
            sigma,
            correlation: (average.kept_samples as f64 / values).max(1.0),
            degrees_of_freedom: Some(
                (average.periods - 1) as f64 * values * average.torque_noise.len() as f64,
            ),
        })
    }

    /// Noise white at the samples' rate, `sigma` a joint (N m).
    pub fn white(sigma: Vec<f64>) -> Self {
        Self {
            sigma,
            correlation: 1.0,
            degrees_of_freedom: None,
        }
    }

    /// What is wrong with it for the joints `joints`; None where nothing.
    pub fn problem(&self, joints: &[String]) -> Option<String> {
        if self.sigma.len() != joints.len() {
            return Some(format!(
                "{} noise levels, expected one a joint ({})",
                self.sigma.len(),
                joints.len()
            ));
        }
        if let Some(j) =
            (self.sigma.iter()).position(|s| !(s.is_finite() && *s > 0.0 && *s <= MAX_NOISE))
        {
            return Some(format!(
                "joint '{}': a noise level of {}, expected a positive finite standard deviation (N m) of at most {MAX_NOISE:e}",
                joints[j],
                shown5(self.sigma[j])
            ));
        }
        if !(self.correlation.is_finite() && (1.0..=MAX_CORRELATION).contains(&self.correlation)) {
            return Some(format!(
                "a correlation of {} samples an independent noise value, expected 1 (white noise) to {MAX_CORRELATION:e}",
                shown5(self.correlation)
            ));
        }
        if let Some(d) = self
            .degrees_of_freedom
            .filter(|d| !(d.is_finite() && *d >= 1.0))
        {
            return Some(format!(
                "noise levels estimated with {} degrees of freedom, expected at least 1 (or none given: known exactly)",
                shown5(d)
            ));
        }
        None
    }

    /// The noise of several logs fitted together as runs one after the other, `logs` each
    /// log's name, noise and samples: per joint the samples-weighted mean of their variances,
    /// a correlation that keeps the independent values they hold (`sum K / sum (K / c)`), and
    /// their degrees of freedom summed (None where one's levels are known exactly). Errors
    /// naming the joint and the two logs: levels that differ by more than [`MAX_LOG_RATIO`],
    /// which one weight a joint cannot hold.
    pub fn pooled(logs: &[(&str, &TorqueNoise, usize)], joints: &[String]) -> Result<Self> {
        let bad = |message: String| Error::InvalidArgument {
            argument: "noise".into(),
            message,
        };
        let Some(first) = logs.first() else {
            return Err(bad("no logs to pool the noise of".into()));
        };
        for (name, noise, _) in logs {
            noise
                .check(joints)
                .map_err(|e| bad(format!("{name}: {e}")))?;
        }
        for (j, joint) in joints.iter().enumerate() {
            let level = |l: &(&str, &TorqueNoise, usize)| l.1.sigma[j];
            let low = (logs.iter())
                .min_by(|a, b| level(a).total_cmp(&level(b)))
                .unwrap_or(first);
            let high = (logs.iter())
                .max_by(|a, b| level(a).total_cmp(&level(b)))
                .unwrap_or(first);
            if level(high) > MAX_LOG_RATIO * level(low) {
                return Err(bad(format!(
                    "the torques' noise of joint '{joint}' differs between the logs: {} N m in {}, {} N m in {} ({} times), beyond the {MAX_LOG_RATIO} one weight a joint may take for both; weight from the residuals (wls), or fit the logs apart",
                    shown5(level(high)),
                    high.0,
                    shown5(level(low)),
                    low.0,
                    shown5(level(high) / level(low))
                )));
            }
        }
        let samples: f64 = logs.iter().map(|l| l.2 as f64).sum();
        let values: f64 = logs.iter().map(|l| l.2 as f64 / l.1.correlation).sum();
        if samples <= 0.0 {
            return Err(bad("logs of no samples to pool the noise of".into()));
        }
        let sigma = (0..joints.len())
            .map(|j| {
                let v: f64 = logs.iter().map(|l| l.2 as f64 * l.1.sigma[j].powi(2)).sum();
                (v / samples).sqrt()
            })
            .collect();
        let degrees_of_freedom = logs
            .iter()
            .map(|l| l.1.degrees_of_freedom)
            .sum::<Option<f64>>();
        let pooled = Self {
            sigma,
            correlation: (samples / values).max(1.0),
            degrees_of_freedom,
        };
        pooled.check(joints)?;
        Ok(pooled)
    }

    /// The noise of logs fitted together, as each log's own was found (`logs`: its name, its
    /// noise or why it has none, its samples): one log's, several logs' [`Self::pooled`].
    /// Where `required` (the noise weighting), a log without a noise is an error in its name,
    /// as are noises too far apart to pool; otherwise either gives None.
    pub fn of_logs(
        logs: Vec<(String, Result<TorqueNoise>, usize)>,
        joints: &[String],
        required: bool,
    ) -> Result<Option<Self>> {
        let several = logs.len() > 1;
        let mut each = Vec::with_capacity(logs.len());
        for (name, noise, samples) in logs {
            match (noise, required) {
                (Ok(n), _) => each.push((name, n, samples)),
                (Err(e), true) if several => {
                    return Err(Error::invalid("noise", format!("{name}: {e}")))
                }
                (Err(e), true) => return Err(e),
                (Err(_), false) => return Ok(None),
            }
        }
        match each.as_slice() {
            [] => Ok(None),
            [(_, noise, _)] => Ok(Some(noise.clone())),
            _ => {
                let logs: Vec<(&str, &TorqueNoise, usize)> =
                    (each.iter()).map(|(p, n, k)| (p.as_str(), n, *k)).collect();
                match Self::pooled(&logs, joints) {
                    Ok(n) => Ok(Some(n)),
                    Err(e) if required => Err(e),
                    Err(_) => Ok(None),
                }
            }
        }
    }

    /// [`Self::problem`] as an error of the argument `noise`.
    pub fn check(&self, joints: &[String]) -> Result<()> {
        match self.problem(joints) {
            Some(message) => Err(Error::InvalidArgument {
                argument: "noise".into(),
                message,
            }),
            None => Ok(()),
        }
    }
}
