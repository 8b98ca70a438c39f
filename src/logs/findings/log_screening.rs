//! A sample of a log taken for a glitch and replaced, as [`crate::logs::log_screening`] finds it.

use serde::{Deserialize, Serialize};

/// Samples each side of a judged sample in its window (the window has `2 HALF_WINDOW + 1`).
pub const HALF_WINDOW: usize = 10;

/// Degree of the polynomial in time each window is fitted with.
pub const DEGREE: usize = 3;

/// A sample whose difference from the line through its neighbours exceeds this many robust
/// levels of that difference (over its column) is a candidate, judged in its window.
pub const CANDIDATE_LEVELS: f64 = 5.0;

/// A sample of a log taken for a glitch and replaced before preprocessing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogGlitch {
    /// The signal: `q`, `qd`, `qdd` or `tau`.
    pub signal: String,
    /// The joint's index (0-based, in the recording's column order).
    pub joint: usize,
    /// Index of the sample in the log (0-based: data row `sample + 1` of a CSV file).
    pub sample: usize,
    /// Its time in the log's clock (s).
    pub time: f64,
    /// Its logged value (rad, rad/s, rad/s^2 or N m).
    pub value: f64,
    /// How far off the fit of the others in its window, in their robust noise levels; `None`
    /// beyond any scale (further than a million times the spread of the window's values).
    pub noise_levels: Option<f64>,
    /// The value it was replaced by: the fit of the others at its time.
    pub replaced_by: f64,
    /// Whether it repeats the sample before it exactly: a logger that wrote its last message
    /// again, with a new time stamp (a stale sample rather than a reading).
    pub repeats_previous: bool,
    /// For a sample of a held reading (a run of this many exactly repeated readings of its
    /// column while its joint moved, judged together and all replaced): the run's length;
    /// its `noise_levels` are then the larger of its farthest sample's and its mean
    /// deviation's (against the standard error of that mean). Absent for a single glitch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<usize>,
    /// The experiment of a plan whose recording had it (local identification, which screens
    /// held readings alone); absent for a log preprocessed on its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiment: Option<String>,
}

impl LogGlitch {
    /// What is wrong with a glitch read from a file, if anything: an unknown signal, a joint
    /// index not below `joints`, a non-finite time, value or replacement, noise levels that
    /// are not positive.
    pub fn problem(&self, joints: usize) -> Option<String> {
        if !SIGNALS.contains(&self.signal.as_str()) {
            return Some(format!(
                "signal '{}' is not one of q, qd, qdd, tau",
                self.signal
            ));
        }
        if self.joint >= joints {
            return Some(format!(
                "joint {} is not a joint index below {joints}",
                self.joint
            ));
        }
        if !(self.time.is_finite() && self.value.is_finite() && self.replaced_by.is_finite()) {
            return Some("time, value and replaced_by must be finite".into());
        }
        if self.noise_levels.is_some_and(|z| z.is_nan() || z <= 0.0) {
            return Some("noise_levels must be a positive number or null".into());
        }
        if self.held.is_some_and(|l| !(2..=MAX_HELD).contains(&l)) {
            return Some(format!(
                "held {}: a held reading is a run of 2 to {MAX_HELD} samples",
                self.held.unwrap_or(0)
            ));
        }
        None
    }
}

/// The signals a log may have, by their column prefix (`q`, `qd`, `qdd`, `tau`).
pub const SIGNALS: [&str; 4] = ["q", "qd", "qdd", "tau"];

/// The longest run of exactly repeated readings of one column that is judged as a held
/// reading: a sensor or logger that wrote its last value again (or zeros) for up to 10 ms at
/// 1 kHz. Longer runs are not bridged: those that end with a jump are frozen readings, removed
/// with their rows ([`crate::logs::frozen_readings`]).
pub const MAX_HELD: usize = HALF_WINDOW;
