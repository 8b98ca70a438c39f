//! The log's torques against the robot's own model (its URDF), column by column, before any
//! parameter is trusted: a real log's torque columns may be swapped or mislabelled, read with
//! the opposite sign convention, or in other units (mN m, a motor's current, a torque before
//! the gear). The direct method fits any of them without a word (the parameters are linear in
//! the torques, and the fit only gets worse), so each column is compared with what the model
//! predicts for every joint (docs/method.md, section 8).
//!
//! For a column `j` and a joint `k`, the column is fitted by least squares with the model's
//! torque of joint `k` (scaled) and joint `k`'s own terms that a URDF lacks: viscous and
//! Coulomb friction, an offset, and a rotor's inertia (`qdd_k`; a geared robot's motors can
//! outweigh its links about a vertical axis, and the A465's do). What the model adds is
//! measured on what those terms alone leave: `gain = (R^2 - R^2_own) / (1 - R^2_own)`, the
//! fraction of the variance they cannot explain that the model's torque does. A column is only
//! judged where some joint's model explains at least [`JUDGED`] of it; a joint whose torque is
//! mostly friction (the Panda's wrist) or its rotor's inertia (the A465's vertical axes) is
//! not. On the real Panda log each judged column follows its own joint's model with gains of
//! 0.73 to 0.998 and scales 0.60 to 0.91 (the vertical first joint and the friction-bound
//! last one unjudged).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::{parallel, Gravity, Model, States};

/// Fewest gain a column's best joint must reach for the column to be judged.
pub const JUDGED: f64 = 0.5;

/// How many times less of a column another joint's model must leave unexplained than its
/// own for the column to be taken for that joint's (the shoulder's and the elbow's gravity
/// torques are alike: swapped, each column's own model still explained 77-80 % of it, the
/// other's 99 %).
pub const SWAPPED_RATIO: f64 = 5.0;

/// A column's scale on its own joint's model beyond `[1 / SCALE_LIMIT, SCALE_LIMIT]` is taken
/// for other units (mN m, a torque before a gear, a current), not for parameters the URDF has
/// wrong.
pub const SCALE_LIMIT: f64 = 10.0;

/// A column's sign and scale are judged only where its joint's model gravity torque is at
/// least this fraction of the largest joint's (RMS over the samples): where the links' own
/// weight dominates (the A465's elbow has a quarter of its shoulder's, its wrist under 1 %). A wrist's small gravity torque is easily outweighed by a payload or a
/// tool the URDF lacks (the A465 with a 1 kg tool read 21 times its model's at the wrist, and
/// 1.4 and 1.7 times at the shoulder and elbow).
pub const LOADED: f64 = 0.1;

/// How many evenly spread samples the check uses at most (its cost is one inverse dynamics
/// call and a few 4-column fits per sample and joint).
pub const SAMPLES: usize = 5000;

/// What looks wrong with the torque `columns` of a log (one a joint, from
/// [`check_torque_columns`]): each column's [`TorqueColumn::finding`], in joint order; where
/// none has one, the whole log's ([`unmatched`]).
pub fn findings(columns: &[TorqueColumn]) -> Vec<String> {
    let each: Vec<String> = columns.iter().filter_map(|c| c.finding(columns)).collect();
    if each.is_empty() {
        unmatched(columns).into_iter().collect()
    } else {
        each
    }
}

/// The whole log against the robot: where the links' weight loads at least two joints
/// ([`LOADED`]) and not one of their columns follows its own joint's model (each gain below
/// [`JUDGED`]), the log does not match the robot at all. Positions in degrees, position
/// columns swapped, another robot's URDF and torques far out of step with the positions each
/// do that (the A465 logged in degrees: gains of 1 % and 0 % at the shoulder and elbow,
/// against 100 % in radians), and so does a motion too small to change the gravity torques
/// beyond the noise (the test excitation at +-0.002 rad: 44 % and 6 %, and a fit that erred by
/// 129 N m on another excitation), which is named among the causes. Two loaded joints, since a single one may be a vertical axis
/// whose constant weight an offset takes (a SCARA's). None otherwise.
pub fn unmatched(columns: &[TorqueColumn]) -> Option<String> {
    let heaviest = columns.iter().fold(0.0f64, |m, c| m.max(c.gravity_rms));
    let loaded: Vec<&TorqueColumn> = columns
        .iter()
        .filter(|c| heaviest > 0.0 && c.gravity_rms >= LOADED * heaviest)
        .collect();
    // NaN (a model loaded unchecked) says nothing
    if loaded.len() < 2
        || loaded
            .iter()
            .any(|c| c.explained.is_nan() || c.explained >= JUDGED)
    {
        return None;
    }
    let gains: Vec<String> = loaded
        .iter()
        .map(|c| format!("'{}' {:.0} %", c.joint, 100.0 * c.explained.max(0.0)))
        .collect();
    Some(format!(
        "no torque column of a joint the links' weight loads follows its own joint's model ({} of what the rest of its model torque, friction, an offset and a rotor's inertia leave explained by its gravity torque; at least {:.0} % expected): the log does not match the robot (positions in degrees, swapped, or from another zero or direction; another robot's URDF; torques out of step with the positions; gravity compensated in a log fitted with it; or joints moved too little for their gravity torque to change beyond the torque noise, which no fit can identify from), and no parameters fitted to it describe the robot",
        gains.join(", "),
        100.0 * JUDGED
    ))
}

/// One torque column of a log against the robot's model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueColumn {
    /// The joint whose column it is (as logged).
    pub joint: String,
    /// The column's scale on its own joint's model torque (1 where the URDF is right; the
    /// sign of the log's convention against the model's).
    pub scale: f64,
    /// The gain of its own joint's model (see the module documentation; at most 1).
    pub explained: f64,
    /// The joint whose model explains the column best.
    pub follows: String,
    /// That joint's gain.
    pub follows_explained: f64,
    /// RMS of the model's gravity torque of its joint over the samples (N m; 0 where the log
    /// excludes gravity).
    pub gravity_rms: f64,
}

impl TorqueColumn {
    /// What is wrong with the column, if the evidence is strong, among `all` the log's
    /// columns: it follows another joint's model (which leaves [`SWAPPED_RATIO`] times less of
    /// it unexplained) whose own column follows a third joint's or this one's in turn (a swap
    /// or a shift of columns; a likeness to a joint whose column reads as its own is the
    /// model's shortfall, no swap: the A465's wrist roll, whose URDF has no gravity torque,
    /// follows the wrist pitch's where the robot has one); or, for a joint its links' weight
    /// loads ([`LOADED`]), it reads its own joint's model with the opposite sign, or at a
    /// scale beyond [`SCALE_LIMIT`]. None where it is unjudged (below [`JUDGED`]) or fine.
    pub fn finding(&self, all: &[TorqueColumn]) -> Option<String> {
        // NaN (a model loaded unchecked) is unjudged too
        if self.follows_explained.is_nan() || self.follows_explained < JUDGED {
            return None;
        }
        let percent = |g: f64| format!("{:.0} %", 100.0 * g.max(0.0));
        let displaced = all
            .iter()
            .find(|c| c.joint == self.follows)
            .is_some_and(|c| c.follows != c.joint && c.follows_explained >= JUDGED);
        if self.follows != self.joint
            && (1.0 - self.follows_explained) * SWAPPED_RATIO <= 1.0 - self.explained
            && displaced
        {
            return Some(format!(
                "the torque column of joint '{}' follows the model of joint '{}' ({} of what the rest of its model torque, friction, an offset and a rotor's inertia leave explained by its gravity torque, against {} by its own joint's): are the torque columns (or the position columns) swapped or mislabelled?",
                self.joint,
                self.follows,
                percent(self.follows_explained),
                percent(self.explained)
            ));
        }
        let heaviest = all.iter().fold(0.0f64, |m, c| m.max(c.gravity_rms));
        if self.follows != self.joint
            || self.explained < JUDGED
            || !(self.gravity_rms >= LOADED * heaviest && self.gravity_rms > 0.0)
        {
            return None;
        }
        if self.scale < 0.0 {
            return Some(format!(
                "the torque of joint '{}' reads {} times the robot's model torque ({} of what the rest of its model torque, friction, an offset and a rotor's inertia leave explained by its gravity torque): the log's sign convention is the opposite of the model's; negate the column",
                self.joint,
                scale_shown(self.scale, 3),
                percent(self.explained)
            ));
        }
        if !(1.0 / SCALE_LIMIT..=SCALE_LIMIT).contains(&self.scale) {
            return Some(format!(
                "the torque of joint '{}' reads {} times the robot's model torque ({} of what the rest of its model torque, friction, an offset and a rotor's inertia leave explained by its gravity torque): torques are expected in N m (N for a prismatic joint) at the joint, after any gear; check the column's units (mN m, a current) and the URDF's masses",
                self.joint,
                scale_shown(self.scale, 4),
                percent(self.explained)
            ));
        }
        None
    }

    /// What is wrong with a column read from a file, if anything: a joint not among
    /// `joint_names`, a scale or gain that is not finite, a gain above 1.
    pub fn problem(&self, joint_names: &[String]) -> Option<String> {
        for name in [&self.joint, &self.follows] {
            if !joint_names.contains(name) {
                return Some(format!("joint '{name}' is not one of the model's joints"));
            }
        }
        let finite = [
            self.scale,
            self.explained,
            self.follows_explained,
            self.gravity_rms,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite || self.explained > 1.0 || self.follows_explained > 1.0 || self.gravity_rms < 0.0
        {
            return Some("scale must be finite, explained and follows_explained finite and at most 1, gravity_rms finite and >= 0".into());
        }
        None
    }
}

/// Each torque column of `tau` (row-major `k x nv`, N m) against `model`'s inverse dynamics
/// at `states` (rad, rad/s, rad/s^2; velocities and accelerations required), with or without
/// gravity as the log was recorded, over at most [`SAMPLES`] evenly spread samples. One
/// [`TorqueColumn`] a joint, in the model's order; empty for fewer than 20 samples.
pub fn check_torque_columns(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    gravity: Gravity,
) -> Result<Vec<TorqueColumn>> {
    let n = model.nv;
    let k = states.len();
    if k < 20 || states.qd().is_none() || states.qdd().is_none() {
        return Ok(vec![]);
    }
    states.check_companion("tau", tau, n)?;
    let rows = crate::states::SpreadRows::new(k, SAMPLES, n);
    let pick = |x: &[f64]| rows.pick(x);
    let (q, qd, qdd) = (
        pick(states.q()),
        pick(states.qd().unwrap_or_default()),
        pick(states.qdd().unwrap_or_default()),
    );
    let measured = pick(tau);
    let (weight, inertial) = model_torques(model, &q, &qd, &qdd, gravity)?;
    let m = rows.len();
    let column = |x: &[f64], j: usize| DVector::from_fn(m, |r, _| x[r * n + j]);
    // joint kk's regressors, from its model's gravity torque when `with_model`
    let regressors = |kk: usize, with_model: bool| {
        let all = joint_regressors(&weight, &inertial, &qd, &qdd, n, kk);
        let first = usize::from(!with_model);
        all.columns(first, 6 - first).into_owned()
    };
    let mut out = Vec::with_capacity(n);
    for j in 0..n {
        crate::interrupt::check("checking the torque columns against the model")?;
        let y = column(&measured, j);
        // per joint k: the gain of its model's torque on column j, and its scale
        let fits: Vec<(f64, f64)> = (0..n)
            .map(|kk| {
                let base = residual_fraction(&regressors(kk, false), &y).map(|(r, _)| r);
                match (base, residual_fraction(&regressors(kk, true), &y)) {
                    (Some(rf), Some((r, coef))) if rf > 0.0 => ((rf - r) / rf, coef[0]),
                    _ => (0.0, 0.0),
                }
            })
            .collect();
        let best = (0..n)
            .max_by(|&a, &b| fits[a].0.total_cmp(&fits[b].0))
            .unwrap_or(j);
        out.push(TorqueColumn {
            joint: model.joint_names[j].clone(),
            scale: fits[j].1,
            explained: fits[j].0,
            follows: model.joint_names[best].clone(),
            follows_explained: fits[best].0,
            gravity_rms: ((0..m).map(|r| weight[r * n + j].powi(2)).sum::<f64>() / m as f64).sqrt(),
        });
    }
    Ok(out)
}

/// The model's gravity torque (what a URDF's masses and centres of mass, usually close,
/// predict; zeros where the log excludes gravity) and the rest of its inverse dynamics
/// (inertias, often far off: a CAD model without its motors) at the states `q`, `qd`, `qdd`
/// (row-major `m x nv`; rad, rad/s, rad/s^2), each row-major `m x nv` (N m): the two parts of
/// the model's torque that the checks of the torque columns scale separately.
pub(crate) fn model_torques(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let n = model.nv;
    let mut ws = parallel::Workspace::new(model);
    let mut weight = vec![0.0; q.len()];
    let mut inertial = vec![0.0; q.len()];
    if gravity == Gravity::Included {
        parallel::rnea(
            model,
            &mut ws,
            &States::new(n, q, None, None)?,
            Gravity::Included,
            &mut weight,
        )?;
    }
    parallel::rnea(
        model,
        &mut ws,
        &States::new(n, q, Some(qd), Some(qdd))?,
        Gravity::Excluded,
        &mut inertial,
    )?;
    Ok((weight, inertial))
}

/// Joint `j`'s regressors over `m` samples (`m x 6`): its model's gravity torque and the rest
/// of its inverse dynamics (from [`model_torques`]), then its own terms a URDF lacks: viscous
/// and Coulomb friction (`qd_j`, `sign(qd_j)`), a rotor's inertia (`qdd_j`) and an offset (1).
pub(crate) fn joint_regressors(
    weight: &[f64],
    inertial: &[f64],
    qd: &[f64],
    qdd: &[f64],
    n: usize,
    j: usize,
) -> DMatrix<f64> {
    DMatrix::from_fn(qd.len() / n, 6, |r, c| match c {
        0 => weight[r * n + j],
        1 => inertial[r * n + j],
        2 => qd[r * n + j],
        3 => crate::parameters::sign0(qd[r * n + j]),
        4 => qdd[r * n + j],
        _ => 1.0,
    })
}

/// `x` with `decimals` decimals where it is between 1e-3 and 1e4 in size, in scientific
/// notation with as many otherwise (a torque logged 1e150 times too large is no 150-digit
/// number).
fn scale_shown(x: f64, decimals: usize) -> String {
    if (1e-3..1e4).contains(&x.abs()) {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.decimals$e}")
    }
}

/// The least-squares fit of `y` by the columns of `x`: its residual sum of squares as a
/// fraction of `y`'s variance about its mean, and its coefficients. None where `y` does not
/// vary or the fit is not finite.
fn residual_fraction(x: &DMatrix<f64>, y: &DVector<f64>) -> Option<(f64, DVector<f64>)> {
    let mean = y.mean();
    let variance: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    if !(variance > 0.0 && variance.is_finite()) {
        return None;
    }
    // the normal equations: a few columns of very different sizes, well enough conditioned
    // for a diagnostic; the SVD of the small Gram matrix drops what the data do not span
    let gram = x.tr_mul(x);
    let largest = gram.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let coef = crate::decomposition::svd(gram, true, true)?
        .solve(&x.tr_mul(y), 1e-12 * largest)
        .ok()?;
    let residual = (y - x * &coef).norm_squared();
    let fraction = residual / variance;
    (fraction.is_finite() && coef.iter().all(|c| c.is_finite())).then_some((fraction, coef))
}
