//! The weighted least-squares solve of a robot's base parameters from states and torques:
//! OLS, WLS weighted by the OLS residuals, or weighted by the noise measured apart. What a fit
//! ([`super::identify_base_parameters`]) and the refits of its checks share.

use super::base::BaseParameters;
use super::base_options::{BaseOptions, Weighting};
use super::parameters::ParameterLayout;
use super::streaming;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::states::States;

/// A least-squares fit of the base parameters: OLS, WLS weighted by the OLS residuals, or
/// weighted by the noise measured apart.
pub(super) struct Solved {
    pub base: BaseParameters,
    pub factors: streaming::JointFactors,
    pub ls: crate::regression::LeastSquares,
    /// Per joint, the residual RMS (N m or N) and the weight's noise level.
    pub rms: Vec<f64>,
    pub sigma: Vec<f64>,
}

/// The base parameters of `model` with `options`' joint terms, found from its random states.
pub(super) fn base_parameters(model: &Model, options: &BaseOptions) -> Result<BaseParameters> {
    let layout = ParameterLayout::new(model, options.friction.for_model(model));
    BaseParameters::from_random_states(
        model,
        &layout,
        options.gravity,
        options.states.max(layout.len() / model.nv + 1),
        options.tolerance,
        options.seed,
    )
}

/// The base parameters of `model` with `options`' terms fitted to `tau` (row-major `k x nv`,
/// N m) at `states`, checked already: one pass over the samples gives the OLS fit, the WLS
/// weights (each joint's OLS residual RMS) and the WLS fit, or the fit weighted by
/// [`BaseOptions::noise`]. Errors: residuals that overflow, the noise weighting without a
/// noise of one positive level a joint.
pub(super) fn solve(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
) -> Result<Solved> {
    let fixed = options.noise_weights(&model.joint_names)?;
    let base = base_parameters(model, options)?;
    let mut names = base.names();
    let mut sigma = vec![1.0; model.nv];
    let runs: &[usize] = match options.offset_per_run {
        true => {
            super::log_offsets::check_options(options)?;
            for j in &model.joint_names {
                names.extend((1..options.runs.len()).map(|r| format!("{j}.offset of run {r}")));
            }
            &options.runs
        }
        false => &[],
    };
    let factors =
        streaming::JointFactors::with_runs(model, &base, states, tau, &[], runs, options.gravity)?;
    let mut ls = factors.solve(&sigma, &names)?;
    let mut rms = factors.residual_rms(ls.coef.as_slice())?;
    // residuals past f64's range (torques or states near 1e300) can be neither weighted nor
    // vouched for
    if let Some(j) = rms.iter().position(|r| !r.is_finite()) {
        return Err(Error::numerical(
            "base-parameter identification",
            format!(
                "the residuals of joint '{}' overflow (RMS {}): the torques or states are too large for f64 arithmetic (near 1e300?); rescale the log to SI units",
                model.joint_names[j], rms[j]
            ),
        ));
    }
    let weights = match (options.weighting, fixed) {
        (Weighting::Wls, _) => Some(rms.iter().map(|&s| if s > 0.0 { s } else { 1.0 }).collect()),
        (_, fixed) => fixed,
    };
    if let Some(weights) = weights {
        sigma = weights;
        ls = factors.solve(&sigma, &names)?;
        rms = factors.residual_rms(ls.coef.as_slice())?;
    }
    Ok(Solved {
        base,
        factors,
        ls,
        rms,
        sigma,
    })
}
