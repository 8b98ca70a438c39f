//! A torque column that reads clipped, as [`crate::logs::torque_saturation`] finds it.

use serde::{Deserialize, Serialize};

/// The fewest samples reading exactly the extreme that make a run worth judging.
pub const MIN_RUN: usize = 3;

/// The fewest and the most samples each side of a stretch its slopes are read from.
pub const MIN_FLANK: usize = 8;
pub const MAX_FLANK: usize = 50;

/// How many standard errors each side's slope must head beyond the level by.
pub const SLOPE_LEVELS: f64 = 5.0;

/// Runs at the level apart by at most this many samples are one stretch.
pub const MAX_BREAK: usize = 10;

/// A joint's torque clipped at one value in a log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueSaturation {
    /// The joint's index (0-based, in the log's column order).
    pub joint: usize,
    /// The value the clipped samples read (N m, or N for a prismatic joint).
    pub level: f64,
    /// Whether it is the column's largest value (else its smallest).
    pub upper: bool,
    /// The runs judged clipped, the samples in them and the longest's.
    pub runs: usize,
    pub samples: usize,
    pub longest: usize,
    /// The log's time (s) where the first clipped run starts.
    pub first_at: f64,
    /// How far beyond `level` the torque went in a clipped run, at most, as the parabola
    /// through the run's ends at its sides' gentler slope estimates it (N m or N).
    pub beyond: f64,
    /// Each clipped run's first and last sample's times (s, the log's clock); not saved.
    #[serde(skip)]
    pub spans: Vec<(f64, f64)>,
}

impl TorqueSaturation {
    /// What is wrong with a finding read from a file of a robot with `joints` joints, if
    /// anything: a joint index out of range, values that are not finite, counts that disagree.
    pub fn problem(&self, joints: usize) -> Option<String> {
        if self.joint >= joints {
            return Some(format!(
                "joint {} is not a joint index below {joints}",
                self.joint
            ));
        }
        if !(self.level.is_finite() && self.first_at.is_finite() && self.beyond.is_finite())
            || self.beyond <= 0.0
        {
            return Some("level and first_at must be finite, beyond positive".into());
        }
        if self.runs == 0
            || self.longest < MIN_RUN
            || self.samples < self.runs.saturating_mul(MIN_RUN)
            || self.longest > self.samples
        {
            return Some(format!(
                "runs {}, samples {}, longest {}: expected runs of at least {MIN_RUN} samples each",
                self.runs, self.samples, self.longest
            ));
        }
        None
    }
}
