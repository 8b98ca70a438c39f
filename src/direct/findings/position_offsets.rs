//! The joints' zero offsets a fit finds, and the ones it leaves out. (the checks that find them: [`crate::direct::position_offsets`]).

use serde::{Deserialize, Serialize};

use crate::direct::torque_columns::TorqueColumn;
use crate::error::shown;

/// How many evenly spread samples the check uses at most.
pub const SAMPLES: usize = 600;

/// The most Gauss-Newton steps taken.
pub const STEPS: usize = 6;

/// The largest step (rad or m) in any joint's offset: a trust region, so that the linearised fit
/// does not leap where it no longer holds (6 steps reach 1.8 rad).
pub const MAX_STEP: f64 = 0.3;

/// A step below this in every joint (rad or m) ends the search.
pub const CONVERGED: f64 = 1e-5;

/// A joint whose offset's standard error exceeds this (rad or m) is taken as not determined by
/// the log and left out.
pub const MAX_STDERR: f64 = 0.1;

/// The weighted residual RMS with the offsets, as a fraction of the fit's as logged, at or
/// below which the offsets are a finding.
pub const FINDING_RATIO: f64 = 0.8;

/// A joint's derivative (per rad or m) whose norm outside the regressor's columns is below this
/// fraction of its own, or of the fitted torques', is taken as absorbed by the parameters (its
/// offset is not determined by the log).
pub const ABSORBED: f64 = 1e-4;

/// The joint offsets the log's torques point to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionOffsets {
    /// The joints whose offsets the log determines (the others' the parameters absorb).
    pub joints: Vec<String>,
    /// For each of `joints`, what to add to its logged positions (rad, or m for a prismatic
    /// joint) for the torques to fit best.
    pub offsets: Vec<f64>,
    /// Their standard errors (rad or m), from the linearised fit (inflated as the fit's are for
    /// correlated residuals).
    pub stderr: Vec<f64>,
    /// The weighted residual RMS on the samples checked as logged (in the fit's `sigma`).
    pub unexplained: f64,
    /// The same with the offsets added and the parameters refitted.
    pub unexplained_with_offsets: f64,
    /// The joints not among `joints`, and why (absent in models saved before they were
    /// reported).
    #[serde(default)]
    pub left_out: Vec<LeftOut>,
}

/// A joint whose offset the check does not estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeftOut {
    pub joint: String,
    pub why: WhyLeftOut,
    /// For [`WhyLeftOut::Undetermined`]: its standard error (rad or m, inflated as the
    /// estimates'), where it was a number.
    pub stderr: Option<f64>,
}

/// Why a joint's offset is not estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WhyLeftOut {
    /// Its offset changes nothing the fit can tell from the parameters: the torques' change
    /// lies within the regressor's columns (refitted), or there is none (a saved model's,
    /// held): a vertical base axis, the chain's last joint.
    Absorbed,
    /// Its standard error exceeds [`MAX_STDERR`] with the others estimated.
    Undetermined,
}

impl PositionOffsets {
    /// What is wrong, if the evidence is strong: the offsets leave at most [`FINDING_RATIO`]
    /// of the residual. Names the joints whose offsets exceed three standard errors, the
    /// largest first. What the library warns of is [`Self::finding_beside`].
    pub fn finding(&self) -> Option<String> {
        let (ratio, list) = self.named()?;
        Some(format!(
            "the torques fit the robot's model {:.1} times better (residual RMS) with the positions of joint(s) {list} added to them: those joints' zeros in the log are likely not the URDF's (an encoder zeroed elsewhere, another convention); check them and add the offsets to the positions before identifying, or the parameters absorb what they can of them and the rest is error",
            1.0 / ratio,
        ))
    }

    /// The same for offsets found against a saved model's parameters in a validation
    /// ([`check_position_offsets_in_validation`](crate::direct::check_position_offsets_in_validation)).
    pub fn validation_finding(&self) -> Option<String> {
        let (ratio, list) = self.named()?;
        Some(format!(
            "the torques fit the model {:.1} times better (residual RMS) with the positions of joint(s) {list} added to them: those joints' zeros in this log are likely not those of the log the model was identified from (an encoder zeroed elsewhere since, another convention); check them and add the offsets to the positions, or the validation error is partly theirs",
            1.0 / ratio,
        ))
    }

    /// The residual's ratio and the joints beyond three standard errors, listed with their
    /// offsets (the largest first), where the offsets leave at most [`FINDING_RATIO`] of it.
    /// [`Self::finding`] (`validation` false) or [`Self::validation_finding`] (true), unless
    /// one of the log's torque `columns` is found wrong ([`crate::direct::torque_columns::findings`]):
    /// offsets fitted to a negated, swapped or rescaled column take up part of its error and
    /// would be named for it (the A465's shoulder column negated read as offsets of 1.7 rad of
    /// the shoulder and the elbow against a saved model). What the fit and a validation warn
    /// of, and their `finding`.
    pub fn finding_beside(&self, columns: &[TorqueColumn], validation: bool) -> Option<String> {
        if !crate::direct::torque_columns::findings(columns).is_empty() {
            return None;
        }
        if validation {
            self.validation_finding()
        } else {
            self.finding()
        }
    }

    fn named(&self) -> Option<(f64, String)> {
        let ratio = self.unexplained_with_offsets / self.unexplained;
        if !(ratio.is_finite() && ratio <= FINDING_RATIO) {
            return None;
        }
        let mut named: Vec<usize> = (0..self.joints.len())
            .filter(|&i| self.offsets[i].abs() > 3.0 * self.stderr[i])
            .collect();
        if named.is_empty() {
            return None;
        }
        named.sort_by(|&a, &b| self.offsets[b].abs().total_cmp(&self.offsets[a].abs()));
        let list: Vec<String> = named
            .iter()
            .map(|&i| {
                format!(
                    "'{}' {:+.4} rad (standard error {:.1e})",
                    self.joints[i], self.offsets[i], self.stderr[i]
                )
            })
            .collect();
        Some((ratio, list.join(", ")))
    }

    /// What is wrong with offsets read from a file, if anything: a joint not among
    /// `joint_names` or named twice, lengths that differ, numbers that are not finite or
    /// negative where they cannot be.
    pub fn problem(&self, joint_names: &[String]) -> Option<String> {
        if let Some(j) = self.joints.iter().find(|j| !joint_names.contains(j)) {
            return Some(format!("joint '{j}' is not one of the model's joints"));
        }
        if let Some(j) =
            (1..self.joints.len()).find(|&i| self.joints[..i].contains(&self.joints[i]))
        {
            return Some(format!("joint '{}' is named twice", self.joints[j]));
        }
        let m = self.joints.len();
        if self.offsets.len() != m || self.stderr.len() != m {
            return Some(format!(
                "{} offsets and {} standard errors for {m} joints",
                self.offsets.len(),
                self.stderr.len()
            ));
        }
        for (i, l) in self.left_out.iter().enumerate() {
            let problem = if !joint_names.contains(&l.joint) {
                "is not one of the model's joints".to_string()
            } else if self.joints.contains(&l.joint) {
                "is also estimated".to_string()
            } else if self.left_out[..i].iter().any(|o| o.joint == l.joint) {
                "is named twice".to_string()
            } else if let Some(s) = l.stderr.filter(|s| !(s.is_finite() && *s >= 0.0)) {
                format!("has stderr {}; expected a finite number >= 0", shown(s))
            } else {
                continue;
            };
            return Some(format!("left_out: joint '{}' {problem}", l.joint));
        }
        if let Some(v) = self.offsets.iter().find(|v| !v.is_finite()) {
            return Some(format!(
                "an offset is {}; expected a finite number",
                shown(*v)
            ));
        }
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !self.stderr.iter().all(|s| ok(*s))
            || !ok(self.unexplained)
            || !ok(self.unexplained_with_offsets)
        {
            return Some(
                "stderr, unexplained and unexplained_with_offsets must be finite and >= 0".into(),
            );
        }
        None
    }
}
