//! Base-parameter identification (the direct method, docs/method.md, section 8b): ordinary or
//! weighted least squares of `tau = Phi_base(q, qd, qdd) theta_base` over all samples.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::base::BaseParameters;
use super::base_model_on::BaseModelOn;
use super::parameters::{regressor_blocks, ParameterLayout};
use super::streaming;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::regression::LeastSquares;
use crate::states::States;

pub use super::base_options::{BaseOptions, Weighting};

/// An identified base-parameter model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseModel {
    /// `perturbid-base-model/1`.
    pub format: String,
    pub robot: String,
    pub joint_names: Vec<String>,
    pub base: BaseParameters,
    pub gravity: Gravity,
    pub weighting: Weighting,
    /// The identified base parameters (SI units of each combination).
    pub theta: Vec<f64>,
    /// Their standard errors; NaN (`null` in JSON) without a residual degree of freedom.
    #[serde(with = "crate::json::stderr_vec")]
    pub stderr: Vec<f64>,
    /// Per joint, the RMS of the torque residuals of the fit (N m).
    pub residual_rms: Vec<f64>,
    /// Per joint, the noise level used as weight (N m; 1 for OLS; the residual RMS of the OLS
    /// fit for WLS; the noise measured apart for [`Weighting::Noise`]).
    pub sigma: Vec<f64>,
    /// cond(Phi_base) of the (weighted) fit, columns scaled to unit norm.
    pub cond: f64,
    /// Samples used.
    pub samples: usize,
    /// Per joint, the long-run variance factor of the fit's residuals (at least 1; see
    /// [`super::residual_correlation`]): how many correlated samples count as one independent
    /// one. `stderr` is scaled by the square root of the largest. Empty in a model saved before
    /// it was computed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub residual_correlation: Vec<f64>,
    /// Samples of the log the data were preprocessed from that were taken for glitches and
    /// replaced first ([`crate::logs::log_screening`]; set by the caller that preprocessed them,
    /// such as the command line); empty when none were, or the data came otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub log_glitches: Vec<crate::logs::log_screening::LogGlitch>,
    /// Rows of that log removed first: dropouts (every joint of a signal read exactly 0 while
    /// the robot moved) and frozen readings (one joint's column held one value too long;
    /// [`crate::logs::log_dropouts::find_removed_rows`]), set likewise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub log_dropouts: Vec<crate::logs::log_dropouts::LogDropout>,
    /// The torques of that log that read clipped ([`crate::logs::torque_saturation`]; set likewise):
    /// the fit took them for the robot's, and was warned of them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub log_torque_saturation: Vec<crate::logs::torque_saturation::TorqueSaturation>,
    /// Steps of whole turns in that log's positions, taken back out first
    /// ([`crate::logs::position_wraps`]; set likewise).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub log_position_wraps: Vec<crate::logs::position_wraps::PositionWrap>,
    /// Columns of that log logged at a lower rate and held on its grid, read again at their
    /// values' arrivals first ([`crate::logs::held_columns`]; set likewise).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub log_held_columns: Vec<crate::logs::held_columns::HeldColumn>,
    /// That log's time stamps, found jittering over the regular clock its samples were taken
    /// on ([`crate::logs::stamp_jitter`]; set likewise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_stamp_jitter: Option<crate::logs::stamp_jitter::StampJitter>,
    /// What averaging that log over its excitation's periods found, where it was averaged
    /// (`--period`, `--excitation`; [`crate::logs::period_average`]; set likewise): the periods
    /// averaged and left out, and each signal's noise from their spread.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_period_average: Option<crate::logs::period_average::PeriodAverage>,
    /// Per joint of that log whose positions lie on a grid and whose velocity was derived
    /// from them, the noise their rounding left in qd and qdd ([`crate::logs::position_rounding`];
    /// set likewise): ratios of [`crate::logs::position_rounding::NOISE_RATIO`] or more are warned
    /// of ([`BaseModel::warnings`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_rounding: Vec<crate::logs::position_rounding::PositionRounding>,
    /// Where the model was fitted to several logs (excitation runs, or drive-gain runs), what
    /// the preprocessing found in each, named by the log ([`super::log_findings`]); the
    /// `log_*` fields and `position_rounding` are then empty. Empty for a model of one log.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub logs: Vec<super::log_findings::LogFindings>,
    /// The data's torque columns against the robot's own model, one a joint
    /// ([`super::torque_columns`]): swapped columns, the opposite sign convention or other
    /// units are warned of ([`BaseModel::warnings`]). Empty in a model saved before it was
    /// checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_columns: Vec<super::torque_columns::TorqueColumn>,
    /// The data's torques shifted against their positions ([`super::torque_lag`]): a lag
    /// that fits far better is warned of ([`BaseModel::warnings`]). None where it was not
    /// checked (no gravity in the data, a model saved before it was checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_lag: Option<super::torque_lag::TorqueLag>,
    /// The joints whose positions in the data leave their URDF limits
    /// ([`super::position_range`]): warned of ([`BaseModel::warnings`]), with positions in
    /// degrees named as such. Empty where none do (or in a model saved before it was checked).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_range: Vec<super::position_range::JointRange>,
    /// The joints' zero offsets the data's torques point to ([`super::position_offsets`]):
    /// offsets that fit far better are warned of ([`BaseModel::warnings`]). None where no
    /// joint's offset is determined (or in a model saved before it was checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_offsets: Option<super::position_offsets::PositionOffsets>,
    /// The joints whose residuals friction terms the fit lacks explain
    /// ([`super::unmodelled_friction`]): warned of ([`BaseModel::warnings`]). Empty where
    /// none do, the fit has every friction term, or in a model saved before it was checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unmodelled_friction: Vec<super::unmodelled_friction::UnmodelledFriction>,
    /// In a fit over several runs ([`BaseOptions::runs`]), the joints whose residuals differ in
    /// mean from run to run ([`super::runs`]: a torque offset that drifted between the logs),
    /// warned of ([`BaseModel::warnings`]). Empty otherwise, or in a model saved before it was
    /// checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub run_offsets: Vec<super::runs::RunOffsets>,
    /// In a fit over several runs, each run's data checked alone against the robot's model
    /// ([`super::run_checks`]: its torque columns, lag and position range), in the runs'
    /// order; the top-level `torque_lag` is then None (a shift would read across the joins).
    /// Empty for one run, or in a model saved before they were checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub run_checks: Vec<super::run_checks::RunChecks>,
    /// Where an offset a run was fitted ([`BaseOptions::offset_per_run`]), each run's offset
    /// less the runs' mean (the model's offset terms), per joint; None otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_offsets: Option<super::log_offsets::LogOffsets>,
    /// In a fit over several runs, whether they agree with one robot ([`super::log_agreement`]:
    /// each run fitted alone against the fit); None for one run, or in a model saved before it
    /// was checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_agreement: Option<super::log_agreement::LogAgreement>,
    /// Where the data excite the base parameters weakly (`cond` beyond
    /// [`super::weak_excitation::WEAK_CONDITION`]): the least determined combination and how
    /// far each joint moved ([`super::weak_excitation`]), warned of ([`BaseModel::warnings`]).
    /// None otherwise, or in a model saved before it was checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_excitation: Option<super::weak_excitation::WeakExcitation>,
    /// The correlation of the estimates in `theta` (p x p, unit diagonal): with `stderr`,
    /// `diag(stderr) R diag(stderr)` is their covariance, which [`BaseModel::predict_stderr`]
    /// needs. In a physically consistent model, the unconstrained fit's (with its standard
    /// errors). Empty (0 x 0) in a model saved before it was stored.
    #[serde(
        default = "crate::json::empty_matrix",
        skip_serializing_if = "crate::json::is_empty_matrix",
        with = "crate::json::rows"
    )]
    pub correlation: DMatrix<f64>,
    /// The joints' drive gains where the model was identified from logged motor currents with
    /// them ([`super::drive_gains`]): the model's torques are the gains times the signal.
    /// None for a model identified from torques.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_gains: Option<super::drive_gains::DriveGains>,
    /// Per joint and joint term of the layout (joint by joint, each joint's terms in the
    /// layout's order), the RMS over the fit's samples of that term's regressor column (`qd`,
    /// the Coulomb column, 1, `qdd`): the torque a coefficient of 1 gives, which tells a
    /// coefficient negligible against the residuals from one that matters
    /// ([`BaseModel::warnings`]). Empty in a model saved before it was stored.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_term_rms: Vec<f64>,
    /// The fit's residuals judged against the torques' noise measured apart from it
    /// ([`super::noise_fit`], [`BaseOptions::noise`]; set where it was given, as it is for a
    /// log averaged over its excitation's periods): the cost, its degrees of freedom and the
    /// chance of it from noise alone, warned of ([`BaseModel::warnings`]) beyond
    /// [`super::noise_fit::FALSE_ALARM`]. For [`Weighting::Noise`] the standard errors come
    /// from it. None otherwise, or where the noise holds no more values than the unknowns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_fit: Option<super::NoiseFit>,
}

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
        torque_columns: super::torque_columns::check_torque_columns(
            model,
            states,
            tau,
            options.gravity,
        )?,
        // over several runs each run's lag (a shift of the stacked samples reads across joins)
        torque_lag: match options.runs.len() {
            0 | 1 => super::torque_lag::check_torque_lag(model, states, tau, options.gravity)?,
            _ => None,
        },
        position_range: super::position_range::check_position_range(model, states),
        run_checks: super::run_checks::check_runs_against_model(
            model,
            states,
            tau,
            &options.runs,
            options.gravity,
        )?,
        joint_term_rms: super::parameter_table::joint_term_rms(
            states,
            options.friction.for_model(model).names(),
        ),
        noise_fit,
        ..BaseModel::without_checks(model, base, options.gravity, options.weighting, &ls)
    };
    fit.weak_excitation =
        super::weak_excitation::check_excitation(model, states, &fit.base, ls.cond, &ls.weakest);
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
    fit.log_agreement =
        super::log_agreement::check_log_agreement(model, &fit, states, tau, &options.runs)?;
    fit.position_offsets =
        super::position_offsets::check_position_offsets(model, &fit, states, tau)?;
    fit.unmodelled_friction =
        super::unmodelled_friction::check_unmodelled_friction(model, &fit, states, tau, options)?;
    Ok((fit, factors))
}

impl BaseModel {
    /// A model of `base` for `robot`'s joints fitted from `ls` (its first column; `p` base
    /// parameters first), with none of the checks of a log: every finding empty, for the fit
    /// to fill in.
    pub(crate) fn without_checks(
        robot: &Model,
        base: BaseParameters,
        gravity: Gravity,
        weighting: Weighting,
        ls: &LeastSquares,
    ) -> BaseModel {
        let p = base.len();
        BaseModel {
            format: BaseModel::tag(),
            robot: robot.name.clone(),
            joint_names: robot.joint_names.clone(),
            base,
            gravity,
            weighting,
            theta: ls.coef.row(0).iter().take(p).copied().collect(),
            stderr: ls.stderr.row(0).iter().take(p).copied().collect(),
            correlation: ls.correlation.view((0, 0), (p, p)).into_owned(),
            residual_rms: vec![],
            sigma: vec![1.0; robot.nv],
            cond: ls.cond,
            samples: ls.rows,
            residual_correlation: vec![],
            log_glitches: vec![],
            log_dropouts: vec![],
            log_torque_saturation: vec![],
            log_position_wraps: vec![],
            log_held_columns: vec![],
            log_stamp_jitter: None,
            log_period_average: None,
            noise_fit: None,
            position_rounding: vec![],
            logs: vec![],
            torque_columns: vec![],
            torque_lag: None,
            position_range: vec![],
            position_offsets: None,
            unmodelled_friction: vec![],
            run_offsets: vec![],
            run_checks: vec![],
            log_offsets: None,
            log_agreement: None,
            weak_excitation: None,
            drive_gains: None,
            joint_term_rms: vec![],
        }
    }

    /// The factor the standard errors are inflated by for residuals correlated from sample to
    /// sample: the square root of the largest joint's [`Self::residual_correlation`] (at
    /// least 1).
    pub fn stderr_inflation(&self) -> f64 {
        self.residual_correlation
            .iter()
            .copied()
            .fold(1.0, f64::max)
            .sqrt()
    }
}

impl Document for BaseModel {
    const FORMAT: &'static str = "perturbid-base-model";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "base-parameter model";

    /// Checks that the base parameters, their map and the layout agree in size, that the
    /// per-joint fields have one value a joint, and that standard errors, residuals and noise
    /// levels are magnitudes (the noise levels positive) and the condition number at least 1.
    fn validate(&self) -> Result<()> {
        self.validate_base()?;
        self.validate_numbers()?;
        self.validate_logs()?;
        self.validate_findings()
    }
}

impl BaseModel {
    /// The model bound to the robot it was identified for, as a [`crate::TorqueModel`]; fails when
    /// `robot` has other joints.
    pub fn on<'a>(&'a self, robot: &'a Model) -> Result<BaseModelOn<'a>> {
        self.check(robot)?;
        Ok(BaseModelOn { fit: self, robot })
    }

    pub(super) fn check(&self, model: &Model) -> Result<()> {
        if model.joint_names != self.joint_names || model.nbodies() != self.base.layout.nbodies {
            return Err(Error::invalid(
                "robot",
                format!(
                    "the model was identified for '{}' with joints [{}]",
                    self.robot,
                    self.joint_names.join(", ")
                ),
            ));
        }
        // the parameters are named after the robot's links and joints, in its order
        let own = ParameterLayout::new(model, self.base.layout.friction);
        if let Some((saved, robot)) = self
            .base
            .layout
            .names
            .iter()
            .zip(&own.names)
            .find(|(a, b)| a != b)
        {
            return Err(Error::invalid(
                "robot",
                format!(
                    "the model's parameters are not the robot's: '{saved}' where '{}' has '{robot}' (the model was identified for '{}')",
                    model.name, self.robot
                ),
            ));
        }
        // and its base parameters are the robot's combinations
        self.base.check_on(model, self.gravity)
    }

    /// Predicted torques (row-major `k x nv`, N m) at a batch of states of `model` (the robot it
    /// was identified for).
    pub fn predict(&self, model: &Model, states: &States<'_>) -> Result<Vec<f64>> {
        self.check(model)?;
        self.predict_checked(model, states)
    }

    /// The standard errors (row-major `k x nv`, N m, or N for a prismatic joint) of the torques
    /// [`Self::predict`] gives at the samples of `states`: `sqrt(phi^T diag(se) R diag(se)
    /// phi)` for each joint's row `phi` of the base regressor, with the parameters' standard
    /// errors `se` ([`Self::stderr`]) and their correlation `R` ([`Self::correlation`]): the
    /// uncertainty of the model's torque, not the scatter of a measured one about it. NaN for a
    /// joint whose row weights a parameter of unknown standard error. Refused on a robot
    /// [`Self::on`] refuses, for a model saved before the correlation was stored, and where
    /// the arithmetic overflows.
    pub fn predict_stderr(&self, model: &Model, states: &States<'_>) -> Result<Vec<f64>> {
        use crate::regression::root;
        self.check(model)?;
        let p = self.theta.len();
        if self.correlation.shape() != (p, p) {
            return Err(Error::invalid(
                "predict_stderr",
                "the model holds no correlation of its parameters' estimates (a model saved before it was stored): identify it again from its log",
            ));
        }
        let mut out = Vec::with_capacity(states.len() * model.nv);
        regressor_blocks(model, &self.base.layout, states, self.gravity, |_, phi| {
            let rows = self.base.select(phi);
            // a parameter of unknown standard error counts only where the row weights it, and
            // apart from the sums, so that a sum which overflows is told from it
            let z = DMatrix::from_fn(rows.nrows(), p, |r, a| match self.stderr[a] {
                se if se.is_nan() => 0.0,
                se => rows[(r, a)] * se,
            });
            let unknown = |r: usize| (0..p).any(|a| self.stderr[a].is_nan() && rows[(r, a)] != 0.0);
            // every row's z^T R z at once: one product for the block
            let w = &z * &self.correlation;
            out.extend((0..z.nrows()).map(|r| match unknown(r) {
                true => f64::NAN,
                false => root(z.row(r).dot(&w.row(r))),
            }));
            Ok(())
        })?;
        crate::regression::refuse_overflow(out, model.nv, "prediction's standard error")
    }

    /// [`Self::predict`] on a robot [`Self::check`] accepted.
    fn predict_checked(&self, model: &Model, states: &States<'_>) -> Result<Vec<f64>> {
        let theta = DVector::from_column_slice(&self.theta);
        let mut tau = Vec::with_capacity(states.len() * model.nv);
        regressor_blocks(model, &self.base.layout, states, self.gravity, |_, phi| {
            tau.extend_from_slice((self.base.select(phi) * &theta).as_slice());
            Ok(())
        })?;
        crate::torque_model::check_prediction(&tau, model.nv)?;
        Ok(tau)
    }

    /// The mass matrix `M(q)` (`nv x nv`) of the identified parameters at `q`: column `j` is
    /// `Phi(q, 0, e_j) theta - Phi(q, 0, 0) theta` (docs/method.md, section 8b).
    pub fn mass_matrix(&self, model: &Model, q: &[f64]) -> Result<DMatrix<f64>> {
        self.check(model)?;
        self.mass_matrix_checked(model, q)
    }

    /// [`Self::mass_matrix`] on a robot [`Self::on`] accepted (for loops over many `q`).
    pub(crate) fn mass_matrix_checked(&self, model: &Model, q: &[f64]) -> Result<DMatrix<f64>> {
        let nv = model.nv;
        crate::model::check_finite_vector("q", q, nv)?;
        let mut qs = Vec::with_capacity((nv + 1) * nv);
        let mut qdd = vec![0.0; (nv + 1) * nv];
        for s in 0..=nv {
            qs.extend_from_slice(q);
            if s > 0 {
                qdd[s * nv + s - 1] = 1.0;
            }
        }
        let zeros = vec![0.0; (nv + 1) * nv];
        let tau = self.predict_checked(
            model,
            &States::new(model.nv, &qs, Some(&zeros), Some(&qdd))?,
        )?;
        Ok(DMatrix::from_fn(nv, nv, |i, j| {
            tau[(j + 1) * nv + i] - tau[i]
        }))
    }
}
