//! Data that excite the base parameters weakly (docs/method.md, section 8).
//!
//! A direct fit returns parameters from whatever motion it is given. Fitted to a motion that
//! moves the robot little, or its joints alike, they predict that motion well and other
//! motions badly: on the A465's test excitation scaled to +-0.05 rad about its posture,
//! cond(Phi_base) was 3.8e3 and the model was off by 0.8 N m RMS on another excitation; at
//! +-0.01 rad, 9.4e4 and 43 N m; at +-0.3 rad, 131 and 0.008 N m (the torque noise 0.05 N m in
//! each). The standard errors and `predict_stderr` say so, but nothing said it in words.
//!
//! So a fit whose condition number (the weighted base regressor, its columns scaled to unit
//! norm, [`crate::regression::LeastSquares::cond`]) exceeds [`WEAK_CONDITION`] is a finding: the
//! combination of base parameters the data determine least well is named (the right singular
//! vector of the smallest singular value), with how far each joint moved against its limits.
//! Optimised excitations reach 30 to 150 (the paper's reproduction 137, the real Panda log 30),
//! random ones of +-0.12 rad 700 to 1,000 (0.1 N m off on another excitation); beyond 2,000
//! the errors on other motion passed 7 times the torque noise.

use serde::{Deserialize, Serialize};

use super::base::BaseParameters;
use crate::model::Model;
use crate::states::States;

/// The condition number of a direct fit beyond which its data excite it weakly.
pub const WEAK_CONDITION: f64 = 2000.0;

/// The most terms of the weakest combination kept (the largest).
const TERMS: usize = 6;

/// One base parameter in the least determined combination.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeakTerm {
    /// The base parameter, by the name of the parameter it is kept as (`link3.mcx`), with
    /// ` (merged)` where others are merged into it.
    pub parameter: String,
    /// Its weight in the combination, in units of its regressor column's norm (the
    /// combination has unit norm over all base parameters).
    pub weight: f64,
}

/// How far one joint moved in the data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointMotion {
    pub joint: String,
    /// The largest position minus the smallest (rad or m).
    pub extent: f64,
    /// The URDF's upper limit minus its lower one; None for a joint without limits.
    pub range: Option<f64>,
}

/// A fit whose data excite its base parameters weakly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeakExcitation {
    /// cond(Phi_base) of the fit (as [`super::BaseModel::cond`]).
    pub cond: f64,
    /// The least determined combination: at most 6 terms, largest first, those of at least
    /// 5 % of the largest.
    pub weakest: Vec<WeakTerm>,
    /// Every joint's motion in the data.
    pub motion: Vec<JointMotion>,
}

impl WeakExcitation {
    /// What is wrong with the entry of a saved model, if anything.
    pub fn problem(&self) -> Option<String> {
        if !(self.cond.is_finite() && self.cond > WEAK_CONDITION) {
            return Some(format!(
                "cond {} is not a finite number beyond {WEAK_CONDITION}",
                crate::error::shown(self.cond)
            ));
        }
        if let Some(t) =
            (self.weakest.iter()).find(|t| !(t.weight.is_finite() && t.weight.abs() <= 1.0))
        {
            return Some(format!(
                "the weight of '{}' is {}, expected a number within [-1, 1]",
                t.parameter,
                crate::error::shown(t.weight)
            ));
        }
        let bad = |m: &JointMotion| {
            !(m.extent.is_finite() && m.extent >= 0.0)
                || m.range.is_some_and(|r| !(r.is_finite() && r > 0.0))
        };
        (self.motion.iter().find(|m| bad(m))).map(|m| {
            format!(
                "joint '{}': an extent that is not a finite number >= 0, or a range that is not positive",
                m.joint
            )
        })
    }

    /// The warning.
    pub fn finding(&self) -> String {
        let combination: Vec<String> = (self.weakest.iter().enumerate())
            .map(|(i, t)| {
                let sign = match (i, t.weight < 0.0) {
                    (0, false) => "",
                    (0, true) => "-",
                    (_, false) => " + ",
                    (_, true) => " - ",
                };
                format!("{sign}{:.2} {}", t.weight.abs(), t.parameter)
            })
            .collect();
        // the joints that moved over the least of their ranges, least first
        let mut limited: Vec<(f64, &JointMotion)> = (self.motion.iter())
            .filter_map(|m| Some((m.extent / m.range?, m)))
            .collect();
        limited.sort_by(|a, b| a.0.total_cmp(&b.0));
        let moved = if limited.is_empty() {
            String::new()
        } else {
            let each: Vec<String> = (limited.iter().take(3))
                .map(|(f, m)| format!("'{}' {:.1} %", m.joint, 100.0 * f))
                .collect();
            format!(
                "; the joints moved over as little as {} of their ranges",
                each.join(", ")
            )
        };
        format!(
            "the data excite the base parameters weakly: cond(Phi_base) is {:.3e}, beyond {WEAK_CONDITION} (an optimised excitation reaches 30 to 150); least determined: {}{moved}. The model predicts motion like the data's, and other motion with errors its standard errors show (predict_stderr, predict --stderr; on the A465 moved +-0.05 rad, 0.8 N m RMS on another excitation): for a model of the whole workspace, run an excitation over more of the joints' ranges (design_excitation, perturbid excite)",
            self.cond,
            combination.join("")
        )
    }
}

/// The finding for a fit of `cond` over `states` of `model` with base parameters `base`,
/// whose least determined combination is `weakest` (p, unit norm, in units of the scaled
/// columns: [`crate::regression::LeastSquares::weakest`]); None at or below
/// [`WEAK_CONDITION`] or where `weakest` does not have one entry per base parameter.
pub fn check_excitation(
    model: &Model,
    states: &States<'_>,
    base: &BaseParameters,
    cond: f64,
    weakest: &[f64],
) -> Option<WeakExcitation> {
    if !(cond.is_finite() && cond > WEAK_CONDITION) || weakest.len() != base.kept.len() {
        return None;
    }
    let largest = weakest.iter().fold(0.0f64, |a, w| a.max(w.abs()));
    let mut order: Vec<usize> = (0..weakest.len())
        .filter(|&i| weakest[i].abs() >= 0.05 * largest)
        .collect();
    order.sort_by(|&a, &b| weakest[b].abs().total_cmp(&weakest[a].abs()));
    let weakest = (order.into_iter().take(TERMS))
        .map(|i| {
            let merged = (0..base.dropped.len()).any(|d| base.k[(i, d)].abs() > 1e-9);
            WeakTerm {
                parameter: format!(
                    "{}{}",
                    base.layout.names[base.kept[i]],
                    if merged { " (merged)" } else { "" }
                ),
                weight: weakest[i],
            }
        })
        .collect();
    let n = model.nv;
    let q = states.q();
    let motion = (0..n)
        .map(|j| {
            let (lo, hi) = super::position_range::extent(q, n, j);
            let l = &model.limits[j];
            JointMotion {
                joint: model.joint_names[j].clone(),
                extent: if hi >= lo { hi - lo } else { 0.0 },
                range: (l.lower.is_finite() && l.upper.is_finite() && l.upper > l.lower)
                    .then_some(l.upper - l.lower),
            }
        })
        .collect();
    Some(WeakExcitation {
        cond,
        weakest,
        motion,
    })
}
