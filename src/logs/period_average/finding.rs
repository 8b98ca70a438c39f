//! What averaging over periods found: kept with the recording it made and with a model
//! fitted to it.

use serde::{Deserialize, Serialize};

use super::options::PERIOD_RANGE;
use crate::error::shown;

/// A period of the log left out of the average, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeftOutPeriod {
    /// The period's place among the log's whole periods from the start (0-based, `skip`
    /// counted).
    pub period: usize,
    /// Its start and end in the log's time (s).
    pub t0: f64,
    pub t1: f64,
    /// Why: a gap, or the signal and joint far off the other periods.
    pub reason: String,
}

/// What averaging over the periods found, kept with the recording it made
/// ([`crate::Recording::period_average`]) and with a model fitted to it.
///
/// Noise levels are per joint, of one period's samples within the band kept (rad, rad/s,
/// rad/s^2, N m; m and N for a prismatic joint); the averaged recording's are these over
/// `sqrt(periods)` ([`PeriodAverage::averaged_torque_noise`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodAverage {
    /// The period (s).
    pub period: f64,
    /// The log's time (s) at which the first period used starts (after `skip`).
    pub start: f64,
    /// The periods averaged.
    pub periods: usize,
    /// Harmonics kept in the positions (and so in the velocities and accelerations).
    pub harmonics: usize,
    /// Harmonics kept in the torques (and the Coulomb column).
    pub torque_harmonics: usize,
    /// Samples of the averaged period (before decimation).
    pub samples: usize,
    /// Samples of the averaged recording: every `decimate`-th of `samples` (0 in a finding
    /// saved before it was kept).
    #[serde(default)]
    pub kept_samples: usize,
    pub position_noise: Vec<f64>,
    pub velocity_noise: Vec<f64>,
    pub acceleration_noise: Vec<f64>,
    pub torque_noise: Vec<f64>,
    /// Per joint, the RMS of the averaged positions' content between harmonic `L + 1` and
    /// the torques' band (rad): motion the harmonics kept leave out (tracking errors at
    /// higher frequencies), which the regressor then does not see.
    pub position_beyond: Vec<f64>,
    /// Per joint, the F ratio of a linear trend of its torques over the periods against the
    /// spread it leaves (near 1 for noise alone; beyond [`super::DRIFT_RATIO`] the torques
    /// drift, as a warming joint's friction does, and the noise measured holds the drift);
    /// None where not judged (fewer than 3 periods, or fewer than
    /// [`super::MIN_COEFFICIENTS`] coefficients in the torques' band).
    #[serde(default)]
    pub torque_drift: Vec<Option<f64>>,
    /// Per joint, the torques' noise in the band's lower half of harmonics over its upper
    /// half, a value each ([`super::noise_colour`]: 1 for white noise); None where not judged
    /// (fewer than [`super::noise_colour::MIN_HARMONICS`] torque harmonics). Empty in a
    /// finding saved before it was measured.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_noise_tilt: Vec<Option<f64>>,
    /// Periods left out, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out: Vec<LeftOutPeriod>,
}

impl PeriodAverage {
    /// The noise of the averaged torques a sample (N m a joint): one period's over
    /// `sqrt(periods)`.
    pub fn averaged_torque_noise(&self) -> Vec<f64> {
        let s = (self.periods as f64).sqrt();
        self.torque_noise.iter().map(|x| x / s).collect()
    }

    /// Per joint, a fit's residual RMS (N m, of the averaged torques) against the averaged
    /// torques' noise: their ratio (1 where the fit leaves only noise), and the model's own
    /// error `sqrt(max(residual^2 - noise^2, 0))` (N m). The fit's parameters take up a small
    /// share of the noise (their count over the `2 H + 1` values a period and joint holds), so
    /// a ratio a little below 1 is noise too.
    pub fn model_error(&self, residual_rms: &[f64]) -> Vec<(f64, f64)> {
        (residual_rms.iter().zip(self.averaged_torque_noise()))
            .map(|(r, n)| (r / n, (r * r - n * n).max(0.0).sqrt()))
            .collect()
    }

    /// [`Self::model_error`] of the RMS `rms` (N m a joint, of a fit's residuals or a
    /// validation's errors: `what`) in words, a joint each.
    pub fn model_error_line(&self, rms: &[f64], what: &str) -> String {
        let errors = self.model_error(rms);
        let list = |f: &dyn Fn(&(f64, f64)) -> f64| -> String {
            (errors.iter().map(|e| crate::error::shown5(f(e))))
                .collect::<Vec<_>>()
                .join(", ")
        };
        format!(
            "{what} over the averaged torques' noise, a joint: {} (1: the model leaves only noise); the model's own error (N m): {}",
            list(&|e| e.0),
            list(&|e| e.1)
        )
    }

    /// What is wrong with it for `n` joints (a document edited by hand); None where nothing.
    pub(crate) fn problem(&self, n: usize) -> Option<String> {
        let lists = [
            ("position_noise", &self.position_noise),
            ("velocity_noise", &self.velocity_noise),
            ("acceleration_noise", &self.acceleration_noise),
            ("torque_noise", &self.torque_noise),
            ("position_beyond", &self.position_beyond),
        ];
        if let Some((name, v)) = lists.iter().find(|(_, v)| v.len() != n) {
            return Some(format!(
                "{name}: {} values, expected one a joint ({n})",
                v.len()
            ));
        }
        if let Some((name, x)) = lists.iter().find_map(|(name, v)| {
            v.iter()
                .find(|x| !(x.is_finite() && **x >= 0.0))
                .map(|x| (name, x))
        }) {
            return Some(format!("{name}: {x}, expected finite and >= 0"));
        }
        let (low, high) = PERIOD_RANGE;
        if !(self.period.is_finite()
            && (low..=high).contains(&self.period)
            && self.start.is_finite())
        {
            return Some(format!(
                "period {} s from t = {} s; expected a period of {low} to {high} s, a finite start",
                shown(self.period),
                shown(self.start)
            ));
        }
        if self.periods < 2
            || self.harmonics == 0
            || self.torque_harmonics < self.harmonics
            || self.samples <= 2 * self.torque_harmonics
            || self.kept_samples > self.samples
        {
            return Some(format!(
                "{} periods, {} and {} harmonics over {} samples, {} kept; expected at least 2 periods, harmonics >= 1 and torque harmonics no fewer, below half the samples, and no more kept than there are",
                self.periods, self.harmonics, self.torque_harmonics, self.samples, self.kept_samples
            ));
        }
        if !(self.torque_noise_tilt.is_empty() || self.torque_noise_tilt.len() == n)
            || (self.torque_noise_tilt.iter().flatten()).any(|f| !(f.is_finite() && *f >= 0.0))
        {
            return Some(format!(
                "torque_noise_tilt: {} values, expected one a joint ({n}), each finite and >= 0 or null",
                self.torque_noise_tilt.len()
            ));
        }
        if !(self.torque_drift.is_empty() || self.torque_drift.len() == n)
            || (self.torque_drift.iter().flatten()).any(|f| !(f.is_finite() && *f >= 0.0))
        {
            return Some(format!(
                "torque_drift: {} values, expected one a joint ({n}), each finite and >= 0 or null",
                self.torque_drift.len()
            ));
        }
        (self.left_out.iter().enumerate())
            .find(|(_, p)| !(p.t0.is_finite() && p.t1 > p.t0) || p.reason.len() > 4096)
            .map(|(i, _)| format!("left_out[{i}]: expected t0 < t1, finite, and a short reason"))
    }
}
