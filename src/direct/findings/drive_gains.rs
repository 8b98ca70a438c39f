//! The drive gains identified with a base-parameter model, how they are estimated and the limits their checks read. (the checks that find them: [`crate::direct::drive_gains`]).

use serde::{Deserialize, Serialize};

use crate::choice::choice;
use crate::document::{check_bounded, check_condition, check_magnitudes};
use crate::error::{shown, Result};
use crate::model::payload::Payload;
use crate::states::States;

/// Runs at most in one identification.
pub const MAX_RUNS: usize = crate::limits::MAX_LOGS;

/// A gain's standard error, relative to it, beyond which it is warned of as poorly determined.
pub const LOOSE_GAIN: f64 = 0.05;

/// [`DriveGains::noise_bias`] beyond which it is warned of.
pub const NOISE_BIAS: f64 = 0.01;

/// [`DriveGains::agreement`] beyond which the runs are warned of as disagreeing with the
/// payload given.
pub const AGREEMENT: f64 = 2.0;

choice! {
    /// How the gains and the base parameters are estimated ([`identify_drive_gains_with`](crate::direct::identify_drive_gains_with)).
    /// Named in files and on the command line `least_squares`, `instrumental`.
    #[derive(Default, Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum GainEstimator ("estimator") {
        /// Least squares (OLS, then WLS where the options say): the smallest variance, biased
        /// towards 0 by the signal's noise ([`DriveGains::noise_bias`] says by how much).
        #[default]
        LeastSquares = "least_squares",
        /// Instrumental variables, the signal predicted by the least-squares fit for its
        /// instrument (weighted as the least-squares fit was): consistent under the signal's
        /// noise, at a larger variance. For logs whose noise is not small against what the
        /// payload explains.
        Instrumental = "instrumental",
    }
}

/// One run of the robot: its states, the joints' logged signal and the payload it carried.
#[derive(Clone, Copy, Debug)]
pub struct GainRun<'a> {
    /// The samples (rad, rad/s, rad/s^2, or m for a prismatic joint), with velocities and
    /// accelerations; a Coulomb column where the signal was filtered ([`States::with_coulomb`]).
    pub states: States<'a>,
    /// The joints' logged signal, row-major `k x nv` (A, or whatever unit the log counts in).
    pub signal: &'a [f64],
    /// The known payload bolted onto a link during the run (None: the robot alone). Its
    /// inertial parameters are taken as exact.
    pub payload: Option<&'a Payload>,
}

/// The drive gains identified with a base-parameter model ([`BaseModel::drive_gains`](crate::direct::BaseModel::drive_gains)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveGains {
    /// Per joint, `K_j`: the joint's torque (N m, or N) per unit of its logged signal.
    /// Negative for a signal that counts the other way from the torque.
    pub gain: Vec<f64>,
    /// Their standard errors (inflated for residuals correlated from sample to sample, as the
    /// model's are).
    pub stderr: Vec<f64>,
    /// Per joint, the least-squares gain's relative bias towards 0 were every residual noise
    /// of the logged signal (an upper estimate; 0 where the estimate points away from 0): the
    /// errors in the signal's columns bias least squares by `-(X^T W^2 X)^-1 Sigma_uu theta`,
    /// `Sigma_uu` holding `k (rms_j / (K_j sigma_j))^2` at joint `j`'s signal column. The
    /// gains share one scale with each other and the parameters, so every joint's noise
    /// biases every gain.
    pub noise_bias: Vec<f64>,
    /// Per joint, the RMS (N m, or N) of the payloads' torques over the runs that carried one:
    /// what determined the gain's scale.
    pub payload_torque_rms: Vec<f64>,
    /// Per joint, the joint fit's residual RMS over the RMS each run's signal leaves when that
    /// joint's row of the model is fitted to it alone, run by run (every coefficient free):
    /// near 1 where the runs agree with one robot and the payload as given; far above where
    /// a run did not carry the payload given, the payload's centre of mass or inertia is not
    /// its own, or the robot changed between the runs. (A payload's mass off by a factor
    /// scales the gains and the parameters by it, and no data can show that.)
    pub agreement: Vec<f64>,
    /// cond of the (weighted) regressor of base parameters and gains, columns scaled to unit
    /// norm.
    pub cond: f64,
    /// Runs and samples identified from, and the runs that carried a payload.
    pub runs: usize,
    pub loaded_runs: usize,
    /// How the gains were estimated (models saved before it: least squares).
    #[serde(default)]
    pub estimator: GainEstimator,
    /// The correlation of each gain's estimate with the base parameters' and the gains'
    /// (`nv x (p + nv)`: row `j` gain `j`'s, columns the base parameters in the model's order
    /// and then the gains): with [`BaseModel::correlation`](crate::direct::BaseModel::correlation), the correlation of every estimate
    /// of the joint fit, which the predicted signal's standard errors need
    /// ([`BaseModel::predict_signal_stderr`](crate::direct::BaseModel::predict_signal_stderr)). Empty (0 x 0) in a model saved before it was
    /// stored.
    #[serde(
        default = "crate::json::empty_matrix",
        skip_serializing_if = "crate::json::is_empty_matrix",
        with = "crate::json::rows"
    )]
    pub correlation: nalgebra::DMatrix<f64>,
    /// The least-squares gains, where the gains are by instrumental variables (else empty):
    /// `1 - least_squares_gain / gain` is the bias the signal's noise gave least squares,
    /// [`DriveGains::noise_bias`] its estimate.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub least_squares_gain: Vec<f64>,
}

impl DriveGains {
    /// What is wrong with saved gains for `n` joints beside the parameters' correlation
    /// `theta` ([`BaseModel::correlation`](crate::direct::BaseModel::correlation)); None where nothing is.
    pub(crate) fn problem(
        &self,
        what: &str,
        n: usize,
        theta: &nalgebra::DMatrix<f64>,
    ) -> Option<String> {
        let lens = [
            ("gain", self.gain.len()),
            ("stderr", self.stderr.len()),
            ("noise_bias", self.noise_bias.len()),
            ("payload_torque_rms", self.payload_torque_rms.len()),
            ("agreement", self.agreement.len()),
        ];
        let least_squares = self.least_squares_gain.len();
        match self.estimator {
            GainEstimator::LeastSquares if least_squares != 0 => {
                return Some(format!(
                    "drive_gains.least_squares_gain has {least_squares} entries for gains by least squares, expected none"
                ))
            }
            GainEstimator::Instrumental if least_squares != n => {
                return Some(format!(
                    "drive_gains.least_squares_gain has {least_squares} entries, expected one per joint ({n}) for gains by instrumental variables"
                ))
            }
            _ => {}
        }
        if let Some((field, len)) = lens.iter().find(|(_, l)| *l != n) {
            return Some(format!(
                "drive_gains.{field} has {len} entries, expected one per joint ({n})"
            ));
        }
        if let Some(j) = self.gain.iter().position(|g| !(g.is_finite() && *g != 0.0)) {
            return Some(format!(
                "drive_gains.gain[{j}] is {}, expected a finite gain other than 0",
                shown(self.gain[j])
            ));
        }
        if !(self.loaded_runs >= 1 && self.loaded_runs <= self.runs && self.runs <= MAX_RUNS) {
            return Some(format!(
                "drive_gains: {} runs of which {} loaded, expected 2 to {MAX_RUNS} runs and at least one loaded",
                self.runs, self.loaded_runs
            ));
        }
        let checks = [
            check_bounded(what, "drive gains", "drive_gains.gain", &self.gain),
            check_bounded(
                what,
                "drive gains",
                "drive_gains.least_squares_gain",
                &self.least_squares_gain,
            ),
            check_magnitudes(what, "drive_gains.stderr", &self.stderr, false),
            check_magnitudes(what, "drive_gains.noise_bias", &self.noise_bias, false),
            check_magnitudes(
                what,
                "drive_gains.payload_torque_rms",
                &self.payload_torque_rms,
                false,
            ),
            check_magnitudes(what, "drive_gains.agreement", &self.agreement, false),
            check_condition(what, "drive_gains.cond", self.cond),
            self.check_correlation(what, n, theta),
        ];
        checks
            .into_iter()
            .find_map(|c| c.err())
            .map(|e| e.to_string())
    }

    /// [`DriveGains::correlation`], where saved, against the parameters' `theta`: with it, a
    /// correlation of `p + n` estimates.
    fn check_correlation(
        &self,
        what: &str,
        n: usize,
        theta: &nalgebra::DMatrix<f64>,
    ) -> Result<()> {
        let r = &self.correlation;
        if r.is_empty() {
            return Ok(());
        }
        let p = theta.nrows();
        if theta.is_empty() || r.shape() != (n, p + n) {
            return Err(crate::document::invalid(
                what,
                format!(
                    "drive_gains.correlation is {} x {}, expected one row per joint ({n}) and a column for each of the model's {p} parameters (its correlation) and {n} gains",
                    r.nrows(),
                    r.ncols()
                ),
            ));
        }
        crate::document::check_correlation(
            what,
            "correlation with drive_gains.correlation",
            &joint_correlation(theta, r),
            p + n,
        )
    }

    /// The findings about the gains, naming the joints (`names`): gains determined to worse
    /// than [`LOOSE_GAIN`] of themselves, noise biases beyond [`NOISE_BIAS`], negative gains.
    pub fn warnings(&self, names: &[String]) -> Vec<String> {
        let mut out = Vec::new();
        let apart: Vec<String> = (names.iter().zip(&self.agreement))
            .filter(|(_, a)| **a > AGREEMENT)
            .map(|(n, a)| format!("'{n}' {a:.1} times"))
            .collect();
        if !apart.is_empty() {
            out.push(format!(
                "the runs do not agree with the payload as given: one robot with it leaves residuals larger than each run's signal fitted alone ({}); a run logged without the payload given, a payload's centre of mass or inertia not its own, or a robot that changed between the runs; the gains are not to be trusted",
                apart.join(", ")
            ));
        }
        for (j, name) in names.iter().enumerate().take(self.gain.len()) {
            let (g, se) = (self.gain[j], self.stderr[j]);
            if g < 0.0 {
                out.push(format!(
                    "the drive gain of joint '{name}' is negative ({g:.5} +- {se:.5}): its logged signal counts the other way from its torque (the model takes it so)"
                ));
            }
            if se > LOOSE_GAIN * g.abs() {
                out.push(format!(
                    "the drive gain of joint '{name}' is determined to +-{:.1} % only ({g:.5} +- {se:.5}): the payload's torque on it is {} RMS; bolt on a heavier payload, or move the joint more in the loaded run",
                    100.0 * se / g.abs(),
                    shown(self.payload_torque_rms[j])
                ));
            }
            if self.noise_bias[j] > NOISE_BIAS && self.estimator == GainEstimator::LeastSquares {
                out.push(format!(
                    "the drive gain of joint '{name}' may be biased towards 0 by up to {:.1} %: its logged signal's noise is large against the part of it the rest of the model does not explain (estimate by instrumental variables, filter the signal, or use a heavier payload)",
                    100.0 * self.noise_bias[j]
                ));
            }
        }
        out
    }
}

/// The correlation of the joint fit's estimates, `(p + nv)` square: the parameters' (`theta`,
/// `p x p`) and the gains' rows (`gains`, `nv x (p + nv)`).
fn joint_correlation(
    theta: &nalgebra::DMatrix<f64>,
    gains: &nalgebra::DMatrix<f64>,
) -> nalgebra::DMatrix<f64> {
    let p = theta.nrows();
    let n = gains.ncols();
    nalgebra::DMatrix::from_fn(n, n, |a, b| match (a < p, b < p) {
        (true, true) => theta[(a, b)],
        (false, _) => gains[(a - p, b)],
        (true, false) => gains[(b - p, a)],
    })
}
