//! The options of the direct method's fits ([`super::identify_base_parameters`] and the
//! fits built on it): the joint terms, the weighting, gravity, the base parameters' rank
//! tolerance, the runs the samples come in and an offset of each run's own.

use serde::{Deserialize, Serialize};

use super::base::BASE_TOLERANCE;
use super::parameters::FrictionTerms;
use super::torque_noise::TorqueNoise;
use crate::choice::choice;
use crate::error::{Error, Result};
use crate::gravity::Gravity;

choice! {
    /// Ordinary or weighted least squares.
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum Weighting ("weighting") {
        /// Ordinary least squares: every row weighs the same.
        Ols = "ols",
        /// Rows of joint `j` divided by `sigma_j`, the RMS of joint `j`'s OLS residuals (Swevers
        /// et al.: the maximum-likelihood estimate for independent per-joint noise).
        Wls = "wls",
        /// Rows of joint `j` divided by `sigma_j`, the noise measured apart from the fit
        /// ([`BaseOptions::noise`]: from the spread of an excitation's periods, or given):
        /// the maximum-likelihood estimate whose weights no model error biases, its standard
        /// errors from the noise ([`super::noise_fit`]).
        Noise = "noise",
    }
}

/// Options of [`super::identify_base_parameters`].
#[derive(Clone, Debug, PartialEq)]
pub struct BaseOptions {
    /// Joint terms identified with the inertial parameters (default viscous, Coulomb and
    /// offset); the armature is added when the robot model has one
    /// ([`FrictionTerms::for_model`]).
    pub friction: FrictionTerms,
    pub weighting: Weighting,
    /// Whether the torques include gravity (default true).
    pub gravity: Gravity,
    /// Relative rank tolerance of the pivoted QR (default 1e-8).
    pub tolerance: f64,
    /// Random states used to find the base parameters (default 200) and their seed.
    pub states: usize,
    pub seed: u64,
    /// The samples as several runs one after the other (logs of other excitations, other
    /// days): the number of samples of each, adding up to all of them
    /// ([`crate::logs::stacked_states::StackedStates::runs`]). Each run's residuals are a time
    /// series of their own: their correlation from sample to sample is estimated within each
    /// run, not across the joins, where two logs' residuals may differ in mean (a torque
    /// offset that drifted between them read as correlation at every lag, and inflated the
    /// standard errors six times for 0.02 N m). Empty (default): one run. At most
    /// [`super::drive_gains::MAX_RUNS`].
    pub runs: Vec<usize>,
    /// An offset a run beside the base parameters, whose offset terms are then the runs'
    /// mean ([`super::log_offsets`], [`super::BaseModel::log_offsets`]): for logs between which a
    /// torque sensor was zeroed anew or a drive warmed up. Needs 2 to
    /// [`super::streaming::MAX_OFFSET_RUNS`] `runs` and the offset among `friction`. Default
    /// false.
    pub offset_per_run: bool,
    /// The torques' noise measured apart from the fit ([`super::TorqueNoise`]): the weights
    /// of [`Weighting::Noise`] (which needs it), and for any weighting the yardstick the
    /// fit's residuals are judged against ([`super::NoiseFit`], [`super::BaseModel::noise_fit`]).
    /// Default None.
    pub noise: Option<TorqueNoise>,
}

impl Default for BaseOptions {
    fn default() -> Self {
        Self {
            friction: FrictionTerms::ALL,
            weighting: Weighting::Wls,
            gravity: Gravity::Included,
            tolerance: BASE_TOLERANCE,
            states: 200,
            seed: 0,
            runs: vec![],
            offset_per_run: false,
            noise: None,
        }
    }
}

impl BaseOptions {
    /// The noise levels a joint (N m) that weight the rows of a fit with these options:
    /// [`BaseOptions::noise`]'s for [`Weighting::Noise`], None for the other weightings (OLS,
    /// or WLS weighted from its residuals). Errors: the noise weighting without a noise, or a
    /// noise that is not one positive level a joint of `joints`.
    pub fn noise_weights(&self, joints: &[String]) -> crate::error::Result<Option<Vec<f64>>> {
        weights(self.weighting, self.noise.as_ref(), joints)
    }
}

/// The noise levels a joint (N m) that weight a fit's rows: `noise`'s for
/// [`Weighting::Noise`], None for the other weightings (OLS, or WLS weighted from its
/// residuals). Errors: the noise weighting without a noise, or a noise that is not one
/// positive level a joint of `joints`.
pub fn weights(
    weighting: Weighting,
    noise: Option<&TorqueNoise>,
    joints: &[String],
) -> Result<Option<Vec<f64>>> {
    if let Some(noise) = noise {
        noise.check(joints)?;
    }
    match (weighting, noise) {
        (Weighting::Noise, Some(noise)) => Ok(Some(noise.sigma.clone())),
        (Weighting::Noise, None) => Err(Error::invalid(
            "weighting",
            "the noise weighting needs the torques' noise measured apart from the fit: average the log over its excitation's periods (--average-periods, --period; preprocess(excitation=..., period=...)), or give the noise a joint (noise=)",
        )),
        _ => Ok(None),
    }
}
