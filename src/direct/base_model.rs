//! An identified base-parameter model ([`super::identify_base_parameters`]): the base
//! parameters with their standard errors and correlation, the fit's residuals and what its
//! checks of the data found; saved and loaded as a JSON document, and predicting torques and
//! their standard errors with the robot whose regressor it needs.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::base::BaseParameters;
use super::base_options::Weighting;
use super::parameters::{regressor_blocks, ParameterLayout};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::regression::LeastSquares;
use crate::states::States;

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
    pub position_offsets: Option<super::findings::position_offsets::PositionOffsets>,
    /// The joints whose residuals friction terms the fit lacks explain
    /// ([`super::unmodelled_friction`]): warned of ([`BaseModel::warnings`]). Empty where
    /// none do, the fit has every friction term, or in a model saved before it was checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unmodelled_friction: Vec<super::findings::unmodelled_friction::UnmodelledFriction>,
    /// In a fit over several runs ([`BaseOptions::runs`](super::BaseOptions::runs)), the joints whose residuals differ in
    /// mean from run to run ([`super::runs`]: a torque offset that drifted between the logs),
    /// warned of ([`BaseModel::warnings`]). Empty otherwise, or in a model saved before it was
    /// checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub run_offsets: Vec<super::findings::runs::RunOffsets>,
    /// In a fit over several runs, each run's data checked alone against the robot's model
    /// ([`super::run_checks`]: its torque columns, lag and position range), in the runs'
    /// order; the top-level `torque_lag` is then None (a shift would read across the joins).
    /// Empty for one run, or in a model saved before they were checked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub run_checks: Vec<super::run_checks::RunChecks>,
    /// Where an offset a run was fitted ([`BaseOptions::offset_per_run`](super::BaseOptions::offset_per_run)), each run's offset
    /// less the runs' mean (the model's offset terms), per joint; None otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_offsets: Option<super::log_offsets::LogOffsets>,
    /// In a fit over several runs, whether they agree with one robot ([`super::log_agreement`]:
    /// each run fitted alone against the fit); None for one run, or in a model saved before it
    /// was checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_agreement: Option<super::findings::log_agreement::LogAgreement>,
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
    pub drive_gains: Option<super::findings::drive_gains::DriveGains>,
    /// Per joint and joint term of the layout (joint by joint, each joint's terms in the
    /// layout's order), the RMS over the fit's samples of that term's regressor column (`qd`,
    /// the Coulomb column, 1, `qdd`): the torque a coefficient of 1 gives, which tells a
    /// coefficient negligible against the residuals from one that matters
    /// ([`BaseModel::warnings`]). Empty in a model saved before it was stored.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_term_rms: Vec<f64>,
    /// The fit's residuals judged against the torques' noise measured apart from it
    /// ([`super::noise_fit`], [`BaseOptions::noise`](super::BaseOptions::noise); set where it was given, as it is for a
    /// log averaged over its excitation's periods): the cost, its degrees of freedom and the
    /// chance of it from noise alone, warned of ([`BaseModel::warnings`]) beyond
    /// [`super::noise_fit::FALSE_ALARM`]. For [`Weighting::Noise`] the standard errors come
    /// from it. None otherwise, or where the noise holds no more values than the unknowns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_fit: Option<super::NoiseFit>,
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
