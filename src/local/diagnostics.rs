//! What happened while a local model was identified: the clock offset found for each
//! recording, the crossings whose torque fit had to avoid a velocity reversal, the torques'
//! noise, and warnings about values the model cannot fully vouch for. Saved with the model.

use serde::{Deserialize, Serialize};

/// The clock offset found between a recording and the plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClockOffset {
    /// The experiment (`nominal`, `G_static`, `G`, `H`, `D`).
    pub experiment: String,
    /// Seconds added to the plan's crossing times to read the recording (the recording runs
    /// `offset` s behind the plan); 0 with planned times.
    pub offset: f64,
}

/// How the torque of one joint at one crossing was read because its velocity reverses near
/// the crossing (Coulomb friction steps there).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReversalHandling {
    /// The fit window was narrowed so that the reversal lies outside it: exact for any
    /// friction that depends on the velocity alone.
    Narrowed,
    /// The reversal is too close to the crossing to be left out: the fit models a step at it
    /// (exact for Coulomb friction, asymmetric or not; not for Stribeck or other friction that
    /// varies steeply near zero speed). Also a warning.
    Step,
}

/// A crossing at which a joint's velocity reverses within the fit window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reversal {
    pub experiment: String,
    /// Index of the crossing in the experiment (0-based); `None` for the reference posture.
    pub crossing: Option<usize>,
    pub joint: String,
    /// Time of the planned reversal minus the crossing time (s).
    pub at: f64,
    pub handling: ReversalHandling,
    /// Half-width (s) of the torque fit window used for this joint at this crossing.
    pub window: f64,
}

/// How one block (`D`, `H` or `G`) of the combined estimate compares with the separated one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockAgreement {
    pub block: String,
    /// `|combined - separated| / |separated|` (Frobenius norms).
    pub relative: f64,
    /// The largest entry of the difference in standard errors of the separated estimate.
    pub standard_errors: f64,
}

/// A joint whose torque read one value in every sample of an experiment that perturbs the
/// robot (a dead or saturated channel): its row of that experiment's matrix is not measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Unmeasured {
    /// The experiment (`G_static`, `G`, `H`, `D`).
    pub experiment: String,
    pub joint: String,
    /// The value every torque sample had (N m).
    pub value: f64,
}

/// The noise in one joint's torques read in one experiment (see [`super::noise`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueNoise {
    /// The experiment (`G_static`, `G`, `H`, `D`).
    pub experiment: String,
    pub joint: String,
    /// The torque samples' noise (N m): the standard deviation of one sample about its
    /// window's fit, pooled over the experiment's crossings.
    pub samples: f64,
    /// What varied from pass to pass beyond the samples' noise (N m, a standard deviation; 0
    /// when the samples' noise explains the regression's residuals): repeatability, noise
    /// slower than a window, and with symmetric pairs the even-order terms the pairs cancel from
    /// the estimate but not from the residuals (for H the velocity-squared terms; then the
    /// standard errors bound the error from above). `None` without residual degrees of freedom.
    pub passes: Option<f64>,
    /// The step (N m) the torque was logged in, where its samples lie on a grid coarser than
    /// their noise (not dithered; see [`super::quantisation`]): the standard errors of its rows
    /// include a rounding error of `step / sqrt(12)` at every crossing. `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// The encoder step (rad) the joint's positions were logged in, where the state of at
    /// least one of the experiment's crossings was read by the band of half a step about its
    /// positions (rounding without noise; see [`super::rounded_positions`]): the standard errors
    /// of every regression count the errors such positions give their regressors. `None`
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_step: Option<f64>,
}

/// A sample found far off its crossing window's fit (docs/method.md, section 7; see
/// [`super::glitches`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Glitch {
    pub experiment: String,
    /// The crossing whose window held it; `None` for the reference posture's.
    pub crossing: Option<usize>,
    /// The signal: `q`, `qd`, `qdd` or `tau`.
    pub signal: String,
    pub joint: String,
    /// Index of the sample in its recording (0-based: data row `sample + 1` of a CSV file).
    pub sample: usize,
    /// Its time in the recording's clock (s).
    pub time: f64,
    /// Its recorded value (rad, rad/s, rad/s^2 or N m).
    pub value: f64,
    /// How far off the fit of the window's other samples, in their robust noise levels;
    /// `None` beyond any scale (further than a million times the spread of the window's
    /// values from their median: set aside before any fit).
    pub noise_levels: Option<f64>,
    /// True: replaced by the fit of the others (an isolated glitch, as if not recorded).
    /// False: kept, one of more than [`super::glitches::MAX_PER_WINDOW`] such samples in its
    /// window (not isolated: something the fit does not model).
    pub replaced: bool,
}

/// The held-out prediction errors of both estimators.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimatorEvidence {
    /// Crossings predicted (each once, by fits made without its fold).
    pub crossings: usize,
    /// RMS prediction error of the separated and the combined estimates, each joint's error in
    /// units of the RMS of its torque changes.
    pub separated: f64,
    pub combined: f64,
    /// Two-sided p value of the paired difference of the crossings' error norms (Student's t).
    pub p_value: f64,
}

/// p value below which one estimator counts as the better predictor.
pub const EVIDENCE_LEVEL: f64 = 0.01;

impl EstimatorEvidence {
    /// The estimator the evidence favours at [`EVIDENCE_LEVEL`]: `Some(true)` combined,
    /// `Some(false)` separated, `None` no difference.
    pub fn favours_combined(&self) -> Option<bool> {
        (self.p_value < EVIDENCE_LEVEL).then_some(self.combined < self.separated)
    }
}

/// Diagnostics of a local identification; see the module documentation.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Diagnostics {
    /// One per experiment, in the plan's order.
    #[serde(default)]
    pub offsets: Vec<ClockOffset>,
    /// Crossings whose torque fit avoided or modelled a velocity reversal.
    #[serde(default)]
    pub reversals: Vec<Reversal>,
    /// How far the variables an experiment did not perturb stray from the operating point at
    /// the crossings, in standard errors of their measurement (RMS): about 1 when that is
    /// measurement noise, far above when the robot did not follow its plan.
    #[serde(default)]
    pub unperturbed_deviation: Option<f64>,
    /// The combined estimate against the separated one, block by block (when both exist).
    #[serde(default)]
    pub combined: Vec<BlockAgreement>,
    /// How well each estimator predicts the crossings left out of its fit: the evidence the
    /// advice between them rests on ([`super::estimator_evidence`]). `None` without the
    /// nominal, G, H and D experiments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimator_evidence: Option<EstimatorEvidence>,
    /// The torque delay estimated from the recordings and read past
    /// ([`super::identify_local_with_delay`]); `None` where it was given or left at 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_delay: Option<crate::direct::torque_delay::TorqueDelay>,
    /// The rows not measured (their standard errors NaN), with a warning: a torque that did
    /// not change. [`super::identify_parameters_from_local`] leaves them out.
    #[serde(default)]
    pub unmeasured: Vec<Unmeasured>,
    /// The torque noise of every joint in the nominal passes (first: their `passes` is the
    /// noise from pass to pass the planner's prediction takes,
    /// [`super::PlanOptions::torque_pass_noise`]) and in each separated regression (G_static,
    /// G, H, D), in the plan's order.
    #[serde(default)]
    pub noise: Vec<TorqueNoise>,
    /// Torques of an experiment (D, G, G_static) that do not return to the base they are
    /// measured against (`T*`, or G-static's reference) between its perturbations, with a
    /// warning ([`super::torque_offsets`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_offsets: Vec<super::torque_offsets::TorqueOffset>,
    /// Samples found far off their crossing windows' fits: glitches of the log, replaced, or
    /// not isolated and kept (with a warning).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub glitches: Vec<Glitch>,
    /// Rows of the recordings removed before their windows were read: every joint of a
    /// signal read exactly 0 while the robot moved, or one joint's column frozen
    /// ([`crate::logs::log_dropouts::find_removed_rows`]; each names its experiment).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropouts: Vec<crate::logs::log_dropouts::LogDropout>,
    /// Samples of the recordings replaced before their windows were read: one joint's reading
    /// held (a run of one repeated value while it moved, off the curve either side; see
    /// [`crate::logs::log_screening::screen_held_readings`]; each names its experiment).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_readings: Vec<crate::logs::log_screening::LogGlitch>,
    /// What the user should know: each is also given as a Python warning and printed by the
    /// command line.
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl Diagnostics {
    /// True when nothing needs the user's attention.
    pub fn is_clean(&self) -> bool {
        self.warnings.is_empty()
    }
}
