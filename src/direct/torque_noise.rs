//! The torques' noise measured apart from any fit: from the spread of an excitation's periods
//! ([`crate::period_average`], [`crate::period_average::PeriodAverage::torque_noise`]), or
//! given by the caller (a log of the robot held still, a sensor's data sheet). It weights the
//! rows of a [`super::Weighting::Noise`] fit, and is the yardstick a fit's residuals are
//! judged against ([`super::noise_fit`]).

use serde::{Deserialize, Serialize};

use crate::error::{shown5, Error, Result};

/// The largest noise level taken (N m): its square must stay far inside f64's range.
pub const MAX_NOISE: f64 = 1e100;

/// The most samples a joint's noise may take for one independent value.
pub const MAX_CORRELATION: f64 = 1e9;

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
