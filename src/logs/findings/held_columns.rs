//! A column logged at a lower rate and held on the log's grid, as [`crate::logs::held_columns`]
//! finds it.

use serde::{Deserialize, Serialize};

/// Samples either side over which a joint's position must change for it to move.
pub const MOTION_SPAN: usize = 50;

/// The least share of a moving joint's samples that repeat the one before, for a held column.
pub const MIN_REPEATED: f64 = 0.5;

/// How many steps of its grid a held column's values change by where they change (the median):
/// more than this.
pub const MIN_GRID_STEPS: f64 = 3.0;

/// A column of a log found held at a lower rate, and read again at its values' arrivals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldColumn {
    /// The signal: `q`, `qd`, `qdd` or `tau`.
    pub signal: String,
    /// The joint (0-based, in the recording's column order).
    pub joint: usize,
    /// The share of its samples, where its joint moves, that repeat the one before.
    pub repeated: f64,
    /// The median number of samples each value is held for.
    pub held_for: f64,
}

impl HeldColumn {
    /// What is wrong with a held column read from a file, if anything: an unknown signal, a
    /// joint not one of the `n`, a share outside [0, 1] or a hold shorter than 1 sample.
    pub fn problem(&self, n: usize) -> Option<String> {
        if !crate::logs::findings::log_screening::SIGNALS.contains(&self.signal.as_str()) {
            return Some(format!(
                "signal '{}' is not one of q, qd, qdd, tau",
                self.signal
            ));
        }
        if self.joint >= n {
            return Some(format!(
                "joint {}: expected a joint index below {n}",
                self.joint
            ));
        }
        if !(0.0..=1.0).contains(&self.repeated) {
            return Some(format!(
                "repeated {}: expected a share in [0, 1]",
                self.repeated
            ));
        }
        if !(self.held_for >= 1.0 && self.held_for.is_finite()) {
            return Some(format!(
                "held_for {}: expected a number of samples of at least 1",
                self.held_for
            ));
        }
        None
    }
}
