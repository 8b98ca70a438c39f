//! The noise positions rounded to encoder counts leave in qd and qdd, as
//! [`crate::logs::position_rounding`] finds it.

use serde::{Deserialize, Serialize};

/// The ratio of rounding noise to signal (RMS) in qd or qdd warned of: a bias of about 1 %
/// (`0.1^2`) toward zero of the parameters that term carries.
pub const NOISE_RATIO: f64 = 0.1;

/// One joint whose positions are logged in counts coarse enough to show in its derived qd or
/// qdd.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionRounding {
    /// The joint's index (0-based, in the recording's column order).
    pub joint: usize,
    /// The step of the grid its positions lie on (rad or m).
    pub step: f64,
    /// RMS of the rounding's noise in the preprocessed qd over the RMS of that qd.
    pub qd_ratio: f64,
    /// RMS of the rounding's noise in the preprocessed qdd over the RMS of that qdd.
    pub qdd_ratio: f64,
}

impl PositionRounding {
    /// What is wrong with a finding read from a file, for a recording of `n` joints: None
    /// when nothing is.
    pub fn problem(&self, n: usize) -> Option<String> {
        if self.joint >= n {
            return Some(format!("joint {} of a model of {n} joints", self.joint));
        }
        let ok = |x: f64| (0.0..=crate::limits::MAX_MODEL_VALUE).contains(&x);
        if !(ok(self.step) && self.step > 0.0 && ok(self.qd_ratio) && ok(self.qdd_ratio)) {
            return Some(format!(
                "step {}, qd_ratio {}, qdd_ratio {}: expected a positive step and ratios >= 0, each at most {:e}",
                crate::error::shown(self.step),
                crate::error::shown(self.qd_ratio),
                crate::error::shown(self.qdd_ratio),
                crate::limits::MAX_MODEL_VALUE
            ));
        }
        None
    }

    /// The larger of the two ratios.
    pub fn ratio(&self) -> f64 {
        self.qd_ratio.max(self.qdd_ratio)
    }
}
