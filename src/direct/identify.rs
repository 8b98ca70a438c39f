//! Base-parameter identification (the direct method, docs/method.md, section 8b): ordinary or
//! weighted least squares of `tau = Phi_base(q, qd, qdd) theta_base` over all samples.

use super::base_solve::{solve, Solved};
use super::streaming;
use crate::error::Result;
use crate::model::Model;
use crate::states::States;

pub use super::base_model::BaseModel;
pub use super::base_options::{BaseOptions, Weighting};

/// Identifies the base parameters of `model` from the samples of `states` (rad, rad/s,
/// rad/s^2) and the torques `tau` (row-major `k x nv`, N m).
///
/// ```
/// use perturbid_rs::direct::{identify_base_parameters, BaseOptions, FrictionTerms, Weighting};
/// use perturbid_rs::{parallel, robots, Gravity, States, TorqueModel};
/// let model = robots::builtin("a465:physical")?;
/// let n = model.nv;
/// // 500 states spread over the joint space, and the model's own torques
/// let x = |s: usize, j: usize, f: f64| ((s * 7 + j * 3) as f64 * f).sin();
/// let q: Vec<f64> = (0..500 * n).map(|i| x(i / n, i % n, 0.37)).collect();
/// let qd: Vec<f64> = (0..500 * n).map(|i| x(i / n, i % n, 0.53)).collect();
/// let qdd: Vec<f64> = (0..500 * n).map(|i| x(i / n, i % n, 0.71)).collect();
/// let states = States::new(n, &q, Some(&qd), Some(&qdd))?;
/// let mut tau = vec![0.0; q.len()];
/// parallel::rnea(&model, &mut parallel::Workspace::new(&model), &states, Gravity::Included, &mut tau)?;
/// let options = BaseOptions { friction: FrictionTerms::NONE, weighting: Weighting::Ols, ..BaseOptions::default() };
/// let fit = identify_base_parameters(&model, &states, &tau, &options)?;
/// let predicted = fit.on(&model)?.predict(&states)?;
/// let error: f64 = predicted.iter().zip(&tau).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
/// assert!(error < 1e-8);
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn identify_base_parameters(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
) -> Result<BaseModel> {
    Ok(fit_with_factors(model, states, tau, options)?.0)
}

/// [`identify_base_parameters`] with the reduced data it was computed from.
pub(super) fn fit_with_factors(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
) -> Result<(BaseModel, streaming::JointFactors)> {
    let nv = model.nv;
    crate::torque_model::check_joints(states, nv)?;
    states.check_companion("tau", tau, nv)?;
    crate::limits::check_range("tolerance", options.tolerance, 1e-15, 0.1)?;
    crate::limits::check_count("states", options.states, 1, 1_000_000)?;
    super::runs::check_runs(&options.runs, states.len())?;
    crate::torque_model::refuse_flat_torques(
        states,
        tau,
        &model.joint_names,
        crate::torque_model::FOR_A_FIT,
    )?;
    let k = states.len();
    let Solved {
        base,
        factors,
        mut ls,
        rms,
        sigma,
    } = solve(model, states, tau, options)?;
    let noise_fit = super::noise_fit::judge(&mut ls, options, &rms, k, nv)?;
    let p = base.len();
    let (coef, se) = (ls.coef.row(0), ls.stderr.row(0));
    let log_offsets = options.offset_per_run.then(|| {
        let (coef, se): (Vec<f64>, Vec<f64>) =
            (coef.iter().copied().collect(), se.iter().copied().collect());
        super::log_offsets::LogOffsets::of_fit(
            &coef,
            &se,
            &ls.correlation,
            p,
            nv,
            options.runs.len(),
        )
    });
    let mut fit = BaseModel {
        residual_rms: rms,
        sigma,
        samples: k,
        joint_term_rms: super::parameter_table::joint_term_rms(
            states,
            options.friction.for_model(model).names(),
        ),
        noise_fit,
        ..BaseModel::without_checks(model, base, options.gravity, options.weighting, &ls)
    };
    check_the_data(model, &mut fit, states, tau, options, &ls)?;
    // what follows reads the torques as the model with the runs' mean offset fits them: each
    // run's own offset taken out where one was fitted
    let adjusted = (log_offsets.as_ref()).map(|o| o.taken_out(tau, &options.runs));
    let tau = adjusted.as_deref().unwrap_or(tau);
    let options = &BaseOptions {
        offset_per_run: false,
        ..options.clone()
    };
    // residuals correlated from sample to sample (a filtered, lightly decimated log) carry less
    // information than their number says: estimated from the first samples of each run
    // (and each run's mean: a torque offset that drifted between runs)
    (fit.residual_correlation, fit.run_offsets) =
        super::runs::run_residuals(model, &fit, states, tau, &options.runs)?;
    // the noise weighting's standard errors are the noise's already, with its correlation
    // `c`; where the residuals measure a longer one (noise that is not white within its band,
    // such as a slow ripple), theirs
    let inflation = match (options.weighting, &fit.noise_fit) {
        (Weighting::Noise, Some(n)) => (fit.stderr_inflation().powi(2) / n.noise.correlation)
            .max(1.0)
            .sqrt(),
        _ => fit.stderr_inflation(),
    };
    for se in &mut fit.stderr {
        *se *= inflation;
    }
    fit.log_offsets = log_offsets.map(|mut o| {
        o.inflate(inflation);
        o
    });
    check_against_the_fit(model, &mut fit, states, tau, options)?;
    Ok((fit, factors))
}

/// The checks of the data a fit needs only its base parameters and conditioning for: the
/// torque columns against the model, their lag behind the positions (one run: over several,
/// a shift of the stacked samples reads across their joins), the joints' range, each run
/// against the model, and the excitation of every base parameter.
fn check_the_data(
    model: &Model,
    fit: &mut BaseModel,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
    ls: &crate::regression::LeastSquares,
) -> Result<()> {
    let g = options.gravity;
    fit.torque_columns = super::torque_columns::check_torque_columns(model, states, tau, g)?;
    fit.torque_lag = match options.runs.len() {
        0 | 1 => super::torque_lag::check_torque_lag(model, states, tau, g)?,
        _ => None,
    };
    fit.position_range = super::position_range::check_position_range(model, states);
    fit.run_checks =
        super::run_checks::check_runs_against_model(model, states, tau, &options.runs, g)?;
    fit.weak_excitation =
        super::weak_excitation::check_excitation(model, states, &fit.base, ls.cond, &ls.weakest);
    Ok(())
}

/// The checks that read the fitted model against the data (`tau` with each run's own offset
/// taken out where one was fitted): whether the logs agree under one model, the joints' zero
/// offsets, and joint terms the model leaves out.
fn check_against_the_fit(
    model: &Model,
    fit: &mut BaseModel,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
) -> Result<()> {
    fit.log_agreement =
        super::log_agreement::check_log_agreement(model, fit, states, tau, &options.runs)?;
    fit.position_offsets =
        super::position_offsets::check_position_offsets(model, fit, states, tau)?;
    fit.unmodelled_friction =
        super::unmodelled_friction::check_unmodelled_friction(model, fit, states, tau, options)?;
    Ok(())
}
