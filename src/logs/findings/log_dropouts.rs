//! A run of rows removed from a log: a dropout or a frozen reading, as
//! [`crate::logs::log_dropouts`] finds it.

use serde::{Deserialize, Serialize};

use crate::logs::findings::log_screening::{MAX_HELD, SIGNALS};
use crate::logs::outliers::NOISE_LEVELS;

/// The fewest rows a dropout has: a single row read as zeros is judged by the glitch screening
/// like any other sample.
pub const MIN_DROPOUT: usize = 2;

/// A run of rows of a log removed before preprocessing: rows in which every joint of one
/// signal reads exactly 0 while the robot moves (a lost message logged as zeros; `joint` is
/// None), or a frozen reading, in which one joint's column holds one value for more than
/// [`MAX_HELD`] samples while the joint moves and then jumps
/// back to the signal (`joint`, `value` and `noise_levels` say which, what and how far:
/// [`crate::logs::frozen_readings`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogDropout {
    /// The signal read as zeros, or frozen: `q`, `qd`, `qdd` or `tau`.
    pub signal: String,
    /// Index of its first row in the log (0-based: data row `first_sample + 1` of a CSV file).
    pub first_sample: usize,
    /// How many rows (at least [`MIN_DROPOUT`]; for a frozen reading, at least
    /// [`MIN_FROZEN`]).
    pub samples: usize,
    /// Times of its first and last rows (s).
    pub from: f64,
    pub to: f64,
    /// The experiment of a plan whose recording had it (local identification); absent for a
    /// log preprocessed on its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiment: Option<String>,
    /// A frozen reading's joint (0-based, in the recording's column order); absent for rows
    /// of zeros in every joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<usize>,
    /// The value a frozen reading holds (the signal's unit: rad, rad/s, rad/s^2 or N m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// How far a frozen reading's last sample is off the signal after it, in noise levels
    /// (absent for rows of zeros, and for a jump beyond any scale).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_levels: Option<f64>,
    /// A frozen reading that lasts to the end of its stretch between gaps: the stream stopped
    /// before the log did, and there is no jump to judge (`noise_levels` absent).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub to_end: bool,
}

impl LogDropout {
    /// What is wrong with a dropout read from a file, if anything: an unknown signal, fewer
    /// than [`MIN_DROPOUT`] rows (a frozen reading: [`MIN_FROZEN`]), times not finite and in
    /// order, a frozen reading's value not finite or its noise levels not beyond
    /// [`NOISE_LEVELS`] or its joint not one of the `n`, or those given for rows of zeros;
    /// `to_end` with noise levels or without a joint.
    pub fn problem(&self, n: usize) -> Option<String> {
        if !SIGNALS.contains(&self.signal.as_str()) {
            return Some(format!(
                "signal '{}' is not one of q, qd, qdd, tau",
                self.signal
            ));
        }
        let fewest = if self.joint.is_some() {
            MIN_FROZEN
        } else {
            MIN_DROPOUT
        };
        if self.samples < fewest {
            return Some(format!(
                "{} samples; {} has at least {fewest}",
                self.samples,
                self.what()
            ));
        }
        match (self.joint, self.value, self.noise_levels) {
            (None, None, None) => {}
            (None, ..) => {
                return Some("value and noise_levels belong to a frozen reading, which names its joint".into())
            }
            (Some(j), _, _) if j >= n => {
                return Some(format!("joint {j}: expected a joint index below {n}"))
            }
            (Some(_), Some(v), z) if v.is_finite() && z.is_none_or(|z| z > NOISE_LEVELS) => {}
            (Some(_), ..) => {
                return Some(format!(
                    "a frozen reading holds a finite value and is more than {NOISE_LEVELS} noise levels off (or beyond any scale: noise_levels absent)"
                ))
            }
        }
        if self.to_end && (self.joint.is_none() || self.noise_levels.is_some()) {
            return Some(
                "to_end belongs to a frozen reading that lasts to the end of its stretch, which names its joint and has no noise_levels".into(),
            );
        }
        if !(self.from.is_finite() && self.to.is_finite() && self.from <= self.to) {
            return Some("from and to must be finite times, from <= to".into());
        }
        None
    }

    /// What it is, for messages: "a dropout" or "a frozen reading".
    pub fn what(&self) -> &'static str {
        if self.joint.is_some() {
            "a frozen reading"
        } else {
            "a dropout"
        }
    }
}

/// The fewest repeated samples of a frozen reading: one more than a held reading's most.
pub const MIN_FROZEN: usize = MAX_HELD + 1;
