//! A log's positions against the robot's joint limits: a joint logged far beyond the range its
//! URDF allows is not the robot the model describes, or not in its units.
//!
//! Real robots pass their URDF's limits a little (limits set conservatively, an encoder's
//! offset), so a joint is only a finding beyond [`MARGIN`] of its range (and 0.01 rad or m)
//! outside it. Where two or more joints leave their limits and every one lies within them once
//! divided by 180/pi, the log's positions are named as degrees: the commonest way a log leaves
//! the range (the A465's shoulder at 22.5 "rad" for 0.39 rad). A single joint is not enough:
//! most positions a little beyond the limits fit within them divided by 57.3, and degrees
//! change every joint. Continuous joints (no limits) are never
//! findings. The direct fit keeps the findings (`BaseModel.position_range`), validation
//! reports them, and both warn.

use serde::{Deserialize, Serialize};

use crate::error::shown;
use crate::model::{JointKind, Model};
use crate::states::States;

/// How far beyond its limits, as a fraction of its range, a joint's positions may go before
/// they are a finding.
pub const MARGIN: f64 = 0.05;

/// Degrees per radian.
const DEGREES: f64 = 180.0 / std::f64::consts::PI;

/// A joint whose logged positions leave its limits by more than [`MARGIN`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointRange {
    pub joint: String,
    /// The smallest and largest position logged (rad or m).
    pub min: f64,
    pub max: f64,
    /// The URDF's limits (rad or m).
    pub lower: f64,
    pub upper: f64,
    /// True where the positions, read as degrees and converted to rad, lie within the limits
    /// (revolute joints only).
    pub degrees: bool,
}

impl JointRange {
    /// What is wrong with the entry of a saved model, if anything: not finite, or limits in
    /// the wrong order.
    pub fn problem(&self) -> Option<String> {
        let all = [self.min, self.max, self.lower, self.upper];
        if all.iter().any(|v| !v.is_finite()) {
            return Some(format!(
                "joint '{}': a position or limit that is not finite",
                self.joint
            ));
        }
        (self.min > self.max || self.lower >= self.upper).then(|| {
            format!(
                "joint '{}': min above max or lower not below upper",
                self.joint
            )
        })
    }
}

/// Whether positions from `min` to `max` lie within `[lower, upper]` but for the margin.
fn within(min: f64, max: f64, lower: f64, upper: f64) -> bool {
    let slack = MARGIN * (upper - lower) + 0.01;
    min >= lower - slack && max <= upper + slack
}

/// The joints of `model` whose positions in `states` (rad or m, one row a sample) leave their
/// limits by more than [`MARGIN`] of their range; joints without limits are skipped. A
/// position that is not finite is the caller's to refuse: it is skipped here.
pub fn check_position_range(model: &Model, states: &States<'_>) -> Vec<JointRange> {
    let n = model.nv;
    let q = states.q();
    (0..n)
        .filter_map(|j| {
            let l = &model.limits[j];
            if !(l.lower.is_finite() && l.upper.is_finite()) {
                return None;
            }
            let (min, max) = extent(q, n, j);
            if min > max || within(min, max, l.lower, l.upper) {
                return None;
            }
            let revolute = model.joint_kinds[j] == JointKind::Revolute;
            Some(JointRange {
                joint: model.joint_names[j].clone(),
                min,
                max,
                lower: l.lower,
                upper: l.upper,
                degrees: revolute && within(min / DEGREES, max / DEGREES, l.lower, l.upper),
            })
        })
        .collect()
}

/// The smallest and largest finite value of joint `j` in `q` (row-major, `n` joints a row);
/// `(inf, -inf)` where it has none.
pub(crate) fn extent(q: &[f64], n: usize, j: usize) -> (f64, f64) {
    (q.iter().skip(j).step_by(n))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        })
}

/// The warning for `ranges` (from [`check_position_range`]), or None where there are none.
pub fn finding(ranges: &[JointRange]) -> Option<String> {
    if ranges.is_empty() {
        return None;
    }
    let short = |v: f64| shown(format!("{v:.3e}").parse().unwrap_or(v));
    let each: Vec<String> = ranges
        .iter()
        .map(|r| {
            format!(
                "'{}' from {} to {} (its limits {} to {})",
                r.joint,
                short(r.min),
                short(r.max),
                short(r.lower),
                short(r.upper)
            )
        })
        .collect();
    let in_degrees: Vec<String> = ranges
        .iter()
        .filter(|r| r.degrees)
        .map(|r| format!("'{}'", r.joint))
        .collect();
    // degrees change every joint: two or more joints, all fitting, say so; one alone may as
    // well be another zero
    let cause = if ranges.len() >= 2 && in_degrees.len() == ranges.len() {
        "read as degrees, every one lies within its limits: the log's positions look like degrees (convert them to rad)".to_string()
    } else {
        let hint = if in_degrees.is_empty() {
            String::new()
        } else {
            format!(
                " (read as degrees, {} would lie within the limits)",
                in_degrees.join(", ")
            )
        };
        format!("the log is of another robot or another zero, or its position columns are swapped or in other units{hint}")
    };
    Some(format!(
        "the log's positions leave the URDF's joint limits: {}; {cause}, and a model fitted to it does not describe this robot",
        each.join(", ")
    ))
}
