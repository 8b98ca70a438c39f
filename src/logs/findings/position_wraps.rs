//! A step of whole turns in a joint's logged positions, as [`crate::logs::position_wraps`] finds
//! it.

use serde::{Deserialize, Serialize};

/// The largest part of a wrap's step taken for the joint's own motion in one sample interval
/// (rad): an eighth of a turn.
pub const MAX_MOTION_AT_WRAP: f64 = std::f64::consts::FRAC_PI_4;

/// A wrap of one joint's positions in a log, taken back out before preprocessing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionWrap {
    /// The joint (0-based, in the recording's column order).
    pub joint: usize,
    /// The first sample after the step (0-based row of the log).
    pub sample: usize,
    /// Its time (s).
    pub time: f64,
    /// Whole turns added to the joint's positions from this sample on to undo the step: -1
    /// where the log stepped up by a turn, +1 where it stepped down.
    pub turns: i64,
}

impl PositionWrap {
    /// What is wrong with a wrap read from a file, if anything: a joint not one of the `n`,
    /// no turns, a time that is not finite.
    pub fn problem(&self, n: usize) -> Option<String> {
        if self.joint >= n {
            return Some(format!(
                "joint {}: expected a joint index below {n}",
                self.joint
            ));
        }
        if self.turns == 0 {
            return Some("turns 0: a wrap undoes a whole, nonzero number of turns".into());
        }
        if !self.time.is_finite() {
            return Some("time: expected a finite time (s)".into());
        }
        None
    }
}
