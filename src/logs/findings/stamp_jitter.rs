//! Time stamps that jitter over a regular clock, as [`crate::logs::stamp_jitter`] finds it.

use serde::{Deserialize, Serialize};

/// How many times farther from their neighbours' line a joint's positions must lie against
/// the stamps than against the sample count, on average, for the stamps to be found jittering.
/// The real Panda log's, whose positions' noise hides its stamps' scatter, reach 1.19.
pub const ROUGHER: f64 = 2.0;

/// Stamps found jittering about the regular clock the samples were taken on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StampJitter {
    /// The median interval between stamps (s).
    pub interval: f64,
    /// How far the intervals scatter about it (s; 1.4826 times their median absolute
    /// deviation): about 1.4 times the stamps' own scatter where it is white.
    pub scatter: f64,
    /// The joint whose positions tell it most clearly (0-based).
    pub joint: usize,
    /// How many times farther from their neighbours' line its positions lie against the stamps
    /// than against the sample count, on average.
    pub rougher: f64,
}

impl StampJitter {
    /// What is wrong with a finding read from a file, if anything: a joint not one of the `n`,
    /// an interval that is not a positive time, a scatter that is not a finite time of 0 or
    /// more, a ratio below [`ROUGHER`] (no finding) or not finite.
    pub fn problem(&self, n: usize) -> Option<String> {
        if self.joint >= n {
            return Some(format!(
                "joint {}: expected a joint index below {n}",
                self.joint
            ));
        }
        if !(self.interval > 0.0 && self.interval.is_finite()) {
            return Some(format!(
                "interval {}: expected a positive time (s)",
                self.interval
            ));
        }
        if !(self.scatter >= 0.0 && self.scatter.is_finite()) {
            return Some(format!(
                "scatter {}: expected a finite time of 0 or more (s)",
                self.scatter
            ));
        }
        if !(self.rougher >= ROUGHER && self.rougher.is_finite()) {
            return Some(format!(
                "rougher {}: expected a finite ratio of {ROUGHER} or more (a finding)",
                self.rougher
            ));
        }
        None
    }
}
