//! Torques that do not return to the operating point's: an experiment whose torque changes
//! `tau_k - T*` hold a constant part its perturbations do not explain.
//!
//! Each experiment's crossings pass the operating point perturbed in +- pairs, so the torque
//! changes average to about zero: the linear terms cancel, and what is left are the even-order
//! terms of the perturbation (for H the velocity-squared terms, for G the curvature of gravity;
//! D has none), small beside the torque. A recording whose torques are offset against the
//! nominal recording's (torque columns swapped between the recordings, a torque sensor
//! re-zeroed or drifting between runs, a changed payload, friction that changed as the robot
//! warmed, or in H a joint whose velocity reverses between passes so that its Coulomb friction
//! changes sign) shows as the intercept of the fit `tau_k - T* = c + X b`: with +- pairs it
//! leaves the estimate unbiased but its standard errors large; without, it biases the estimate.
//! Swapped columns also swap the rows of the estimate: the rows are the other joint's.
//!
//! The intercept is fitted by ordinary least squares beside the experiment's regressors (its
//! standard error counts the base's own noise, common to every row). A joint's is a finding
//! where it exceeds [`STANDARD_ERRORS`] of its standard errors and a fraction of the largest
//! torque of the base (`T*`, or G-static's reference; [`fraction`]). D, G and G-static are
//! judged so: D's torques are linear in the accelerations, and gravity's curvature over G's
//! position perturbations is a small fraction of it. In H only swaps are findings: its
//! velocity-squared terms give an intercept of their own, which can exceed `T*` itself in a
//! gravity-compensated log, but not two joints each off by the other's `T*`.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::ExperimentKind;
use crate::error::shown;

/// How many of its standard errors an intercept must exceed to be a finding (the fits have
/// few residual degrees of freedom: 5 for 12 crossings of 6 joints).
pub const STANDARD_ERRORS: f64 = 10.0;

/// The fraction of the base's largest torque an intercept of experiment `kind` must exceed to
/// be a finding on its own, or None where only swaps are (H, whose velocity-squared terms give
/// an intercept of their own; the nominal experiment has none): above the rounding of D's
/// exactly linear torques (1e-3), above the curvature of gravity over G's and G-static's
/// position perturbations (0.02; 1e-3 of the torque at the Panda's).
pub fn fraction(kind: ExperimentKind) -> Option<f64> {
    match kind {
        ExperimentKind::D => Some(1e-3),
        ExperimentKind::GDynamic | ExperimentKind::GStatic => Some(0.02),
        ExperimentKind::Nominal | ExperimentKind::H => None,
    }
}

/// An experiment's torques of one joint offset from the base they are measured against.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueOffset {
    /// The experiment (`G_static`, `G`, `H`, `D`).
    pub experiment: String,
    pub joint: String,
    /// The intercept (N m): the torque changes' part the perturbations do not explain.
    pub offset: f64,
    /// Its standard error (N m).
    pub stderr: f64,
}

/// The intercepts of `y` (`K x N` torque changes from a base, N m) fitted beside the
/// regressors `x` (`K x N` perturbations), with their standard errors: the residuals' scatter,
/// and the base's own variance `base_var` (N^2 m^2 per joint: an error of the base is common to
/// every row, so the residuals cannot show it). `None` for every joint where there are not two
/// residual degrees of freedom or the fit fails (values not finite).
pub fn intercepts(x: &DMatrix<f64>, y: &DMatrix<f64>, base_var: &[f64]) -> Vec<Option<(f64, f64)>> {
    let (k, p) = (x.nrows(), x.ncols() + 1);
    let none = vec![None; y.ncols()];
    if k != y.nrows() || base_var.len() != y.ncols() || k < p + 2 {
        return none;
    }
    // the perturbations scaled to unit columns, so that the threshold is scale-free
    let norms: Vec<f64> = x.column_iter().map(|c| c.norm()).collect();
    let z = DMatrix::from_fn(k, p, |i, c| match c {
        0 => 1.0,
        _ if norms[c - 1] > 0.0 => x[(i, c - 1)] / norms[c - 1],
        _ => 0.0,
    });
    let Some(pinv) = crate::decomposition::pseudo_inverse(z.clone(), 1e-10) else {
        return none;
    };
    let gain: f64 = pinv.row(0).iter().map(|w| w * w).sum();
    let rank = crate::decomposition::svd(z.clone(), false, false)
        .map_or(p, |s| s.rank(1e-10 * s.singular_values.max()));
    let dof = k.saturating_sub(rank);
    if dof < 2 {
        return none;
    }
    y.column_iter()
        .zip(base_var)
        .map(|(col, v)| {
            let b = &pinv * col;
            let r = col - &z * &b;
            let s2 = r.norm_squared() / dof as f64;
            let se = (s2 * gain + v.max(0.0)).sqrt();
            (b[0].is_finite() && se.is_finite()).then_some((b[0], se))
        })
        .collect()
}

/// The findings among `intercepts` (per joint) of experiment `kind`, whose base torques (`T*`,
/// or G-static's reference) are `base` (N m): beyond [`STANDARD_ERRORS`] and the experiment's
/// [`fraction`]; in H only the pairs of joints each off by the other's `T*` (a swap of their
/// columns, [`swapped_pairs`]), whose pattern its velocity-squared terms do not mimic. None
/// for the nominal experiment.
pub fn findings(
    kind: ExperimentKind,
    joint_names: &[String],
    intercepts: &[Option<(f64, f64)>],
    base: &[f64],
) -> Vec<TorqueOffset> {
    if kind == ExperimentKind::Nominal {
        return vec![];
    }
    let lone = fraction(kind);
    let scale = base.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let found: Vec<TorqueOffset> = joint_names
        .iter()
        .zip(intercepts)
        .filter_map(|(joint, found)| {
            let (offset, stderr) = (*found)?;
            let beyond = offset.abs() > lone.unwrap_or(0.0) * scale;
            (offset.abs() > STANDARD_ERRORS * stderr && beyond).then(|| TorqueOffset {
                experiment: kind.name().to_string(),
                joint: joint.clone(),
                offset,
                stderr,
            })
        })
        .collect();
    if lone.is_some() {
        return found;
    }
    let swapped: Vec<&String> = swapped_pairs(kind, &found, joint_names, base)
        .into_iter()
        .flat_map(|(a, b)| [&a.joint, &b.joint])
        .collect();
    let keep: Vec<bool> = found.iter().map(|t| swapped.contains(&&t.joint)).collect();
    found
        .into_iter()
        .zip(keep)
        .filter_map(|(t, k)| k.then_some(t))
        .collect()
}

/// The pairs of `found` (one experiment's findings) that read each other's base: each offset
/// within a tenth of the difference of the two joints' base torques (and three standard
/// errors) of that difference, as torque columns swapped between the recording and the
/// nominal one. None for G-static, whose base is in its own recording.
pub fn swapped_pairs<'a>(
    kind: ExperimentKind,
    found: &'a [TorqueOffset],
    joint_names: &[String],
    base: &[f64],
) -> Vec<(&'a TorqueOffset, &'a TorqueOffset)> {
    if kind == ExperimentKind::GStatic {
        return vec![];
    }
    let base_of = |t: &TorqueOffset| {
        joint_names
            .iter()
            .position(|j| *j == t.joint)
            .map(|j| base[j])
    };
    let mut pairs = vec![];
    for (i, a) in found.iter().enumerate() {
        for b in &found[i + 1..] {
            let (Some(ta), Some(tb)) = (base_of(a), base_of(b)) else {
                continue;
            };
            let gap = tb - ta;
            let near = |t: &TorqueOffset, expected: f64| {
                (t.offset - expected).abs() <= 0.1 * gap.abs() + 3.0 * t.stderr
            };
            if near(a, gap) && near(b, -gap) {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// The findings of `found` (one experiment's) that read the opposite of their joint's base:
/// each offset within a tenth (and three standard errors) of `-2 T*_j`, as a torque column
/// negated in the recording or in the nominal one (another sign convention), and not in a
/// swapped pair (`swapped`). None for G-static, whose base is in its own recording.
pub fn negated<'a>(
    kind: ExperimentKind,
    found: &'a [TorqueOffset],
    swapped: &[(&TorqueOffset, &TorqueOffset)],
    joint_names: &[String],
    base: &[f64],
) -> Vec<&'a TorqueOffset> {
    if kind == ExperimentKind::GStatic {
        return vec![];
    }
    let paired = |t: &TorqueOffset| swapped.iter().any(|(a, b)| *a == t || *b == t);
    (found.iter())
        .filter(|t| !paired(t))
        .filter(|t| {
            let Some(j) = joint_names.iter().position(|n| *n == t.joint) else {
                return false;
            };
            let opposite = -2.0 * base[j];
            opposite != 0.0 && (t.offset - opposite).abs() <= 0.1 * opposite.abs() + 3.0 * t.stderr
        })
        .collect()
}

/// The warning for `found`, the findings of experiment `kind` (one or more joints), with the
/// pairs among them that read each other's base and those that read the opposite of their
/// own ([`negated`]); `symmetric` when the perturbations come in +- pairs (then the offset
/// does not bias the estimate).
pub fn warning(
    kind: ExperimentKind,
    found: &[TorqueOffset],
    swapped: &[(&TorqueOffset, &TorqueOffset)],
    negated: &[&TorqueOffset],
    symmetric: bool,
) -> Option<String> {
    if found.is_empty() {
        return None;
    }
    let base = if kind == ExperimentKind::GStatic {
        "their torques at the reference posture"
    } else {
        "T*"
    };
    let joints: Vec<String> = found
        .iter()
        .map(|t| {
            format!(
                "'{}' ({} N m off, {:.0} standard errors)",
                t.joint,
                shown(format!("{:.3e}", t.offset).parse().unwrap_or(t.offset)),
                (t.offset / t.stderr).abs()
            )
        })
        .collect();
    let mut text = format!(
        "experiment '{}': the torques of {} do not return to {base} between its perturbations: the fit leaves a constant part they do not explain",
        kind.name(),
        joints.join(", ")
    );
    for (a, b) in swapped {
        text.push_str(&format!(
            ". '{}' and '{}' are off by each other's T*: their torque columns look swapped in the {} recording or in the nominal one, and then their rows of {} are each other's",
            a.joint,
            b.joint,
            kind.name(),
            kind.estimate_name()
        ));
    }
    for t in negated {
        text.push_str(&format!(
            ". '{}' is off by minus twice its T*: its torque column looks negated in the {} recording or in the nominal one (another sign convention), and then its row of {} is negated too",
            t.joint,
            kind.name(),
            kind.estimate_name()
        ));
    }
    text.push_str(&format!(
        ". {} offset from each other (a torque sensor re-zeroed or drifting between the runs, a changed payload, friction changed as the robot warmed): the rows' standard errors include the offset, which {}",
        if swapped.is_empty() && negated.is_empty() {
            "The recordings' torques look"
        } else {
            "If not so, the recordings' torques are"
        },
        if symmetric {
            "does not bias them (the perturbations come in +- pairs)"
        } else {
            "biases them (the perturbations do not come in +- pairs)"
        }
    ));
    Some(text)
}

/// The warning where two or more of G, H and D (each measured against `T*`) find the same
/// offset of the same joints (within a tenth and three standard errors each): then the
/// nominal recording, whose torques give `T*`, is the one that differs.
pub fn nominal_warning(found: &[TorqueOffset]) -> Option<String> {
    let moving = [
        ExperimentKind::GDynamic,
        ExperimentKind::H,
        ExperimentKind::D,
    ]
    .map(|k| k.name());
    let agree = |a: &TorqueOffset, b: &TorqueOffset| {
        a.joint == b.joint
            && (a.offset - b.offset).abs()
                <= 0.1 * a.offset.abs().max(b.offset.abs()) + 3.0 * (a.stderr + b.stderr)
    };
    let mut joints: Vec<String> = vec![];
    let mut experiments: Vec<&str> = vec![];
    for t in found
        .iter()
        .filter(|t| moving.contains(&t.experiment.as_str()))
    {
        let alike: Vec<&str> = found
            .iter()
            .filter(|o| moving.contains(&o.experiment.as_str()) && agree(t, o))
            .map(|o| o.experiment.as_str())
            .collect();
        let joint = format!("'{}'", t.joint);
        if alike.len() >= 2 && !joints.contains(&joint) {
            joints.push(joint);
            experiments.extend(
                alike
                    .iter()
                    .filter(|e| !experiments.contains(e))
                    .collect::<Vec<_>>(),
            );
        }
    }
    if joints.is_empty() {
        return None;
    }
    // in the plan's order of kinds
    let named: Vec<String> = moving
        .iter()
        .filter(|k| experiments.contains(k))
        .map(|k| format!("'{k}'"))
        .collect();
    let (last, rest) = named.split_last()?;
    Some(format!(
        "experiments {} and {last} find the same torque offsets of {} against T*: the nominal recording, whose torques give T*, is the one that differs from the others (and with it T*)",
        rest.join(", "),
        joints.join(", ")
    ))
}
