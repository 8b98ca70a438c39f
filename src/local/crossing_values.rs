//! What was read at a crossing ([`CrossingValues`]: the state, the torque, their standard
//! errors and the glitches screened in the window) and at every crossing of one experiment
//! ([`ExperimentValues`]).

use super::diagnostics::Reversal;
use super::plan::ExperimentKind;

/// The state and torque at one crossing, estimated from a recording (length N each; rad, rad/s,
/// rad/s^2, N m).
#[derive(Clone, Debug, PartialEq)]
pub struct CrossingValues {
    /// Crossing time in the recording's clock (s).
    pub time: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    /// Standard errors of `q`, `qd`, `qdd` from the scatter of the positions about their
    /// quadratic fit (measurement noise, quantisation; NaN with no residual degree of freedom).
    pub state_stderr: [Vec<f64>; 3],
    /// Per joint, the noise gain of `tau`: its standard error per unit of white noise on the
    /// torque samples (the root sum of squares of the fit's weights at the crossing; about
    /// `sqrt(4.8 / samples)` for the default fit). Windows narrowed at a velocity reversal hold
    /// fewer samples and have larger gains.
    pub tau_gain: Vec<f64>,
    /// Per joint, the scatter of the torque samples about their fit: the sum of squared
    /// residuals (N^2 m^2) and its degrees of freedom. Pooled over an experiment's crossings
    /// it estimates the torque samples' noise level.
    pub tau_scatter: Vec<(f64, usize)>,
    /// Per joint, whether `q`, `qd`, `qdd` and their standard errors were read from positions
    /// rounded to encoder counts by the band of half a count about them
    /// ([`super::rounded_positions`]) rather than by least squares.
    pub position_band: Vec<bool>,
    /// Per joint, the positions' residuals about the fit `q`, `qd`, `qdd` were read from, one
    /// per sample of the window (rad): what [`super::repeated_reading`] compares across passes.
    pub position_residuals: Vec<Vec<f64>>,
    /// The index in the window of the sample nearest the crossing time, which lines up the
    /// residuals of passes whose windows start at different samples.
    pub centre: usize,
    /// Samples of this crossing's windows found far off their fits ([`super::glitches`]):
    /// replaced by the fit of the others where isolated, left in otherwise.
    pub glitches: Vec<WindowGlitch>,
}

/// A recorded signal of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Position (rad).
    Q,
    /// Recorded velocity (rad/s).
    Qd,
    /// Recorded acceleration (rad/s^2).
    Qdd,
    /// Torque (N m).
    Tau,
}

impl Signal {
    /// The signals in the order of [`SignalScales::noise`](super::crossing::SignalScales::noise).
    pub const ALL: [Signal; 4] = [Signal::Q, Signal::Qd, Signal::Qdd, Signal::Tau];

    /// The signal's place in [`Signal::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The column prefix of the signal in recordings (`q`, `qd`, `qdd`, `tau`).
    pub fn name(self) -> &'static str {
        match self {
            Signal::Q => "q",
            Signal::Qd => "qd",
            Signal::Qdd => "qdd",
            Signal::Tau => "tau",
        }
    }

    /// The signal's unit.
    pub fn unit(self) -> &'static str {
        match self {
            Signal::Q => "rad",
            Signal::Qd => "rad/s",
            Signal::Qdd => "rad/s^2",
            Signal::Tau => "N m",
        }
    }
}

/// A sample found far off its window's fit (see [`super::glitches`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowGlitch {
    pub signal: Signal,
    /// Joint index (0-based).
    pub joint: usize,
    /// Index of the sample in the recording (0-based).
    pub sample: usize,
    /// Its time in the recording's clock (s).
    pub time: f64,
    /// Its recorded value (the signal's unit).
    pub value: f64,
    /// How far off the fit of the others, in the window's robust noise levels.
    pub noise_levels: f64,
    /// Whether it was replaced by the fit of the others (an isolated glitch) or left in (one
    /// of more than [`super::glitches::MAX_PER_WINDOW`] such samples in the window).
    pub replaced: bool,
}

/// The values read at every crossing of one experiment (and its reference posture).
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentValues {
    pub kind: ExperimentKind,
    /// Offset (s) added to the planned times.
    pub offset: f64,
    pub crossings: Vec<CrossingValues>,
    pub reference: Option<CrossingValues>,
    /// The crossings at which a joint's velocity reverses within the fit window, and how its
    /// torque was read there.
    pub reversals: Vec<Reversal>,
    /// Per joint, the value (N m) every torque sample read for this experiment had, when all
    /// of them (every crossing's window and the reference posture's) had the same one: a torque
    /// signal that did not change (see [`flat_torques`](super::identify::flat_torques)).
    pub flat_torque: Vec<Option<f64>>,
    /// Per joint, the step (N m) of the grid the torque samples read for this experiment lie
    /// on, if any (see [`super::quantisation::torque_steps`]).
    pub torque_step: Vec<Option<f64>>,
    /// Per joint, the encoder step (rad) of the recording's positions where the state of at
    /// least one crossing (or the reference posture) was read by the band of half a step
    /// ([`super::rounded_positions`]); None otherwise.
    pub position_step: Vec<Option<f64>>,
}
