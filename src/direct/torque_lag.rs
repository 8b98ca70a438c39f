//! The log's torques out of step with its positions: a torque logged some samples after (or
//! before) the positions it belongs to, as two topics of a ROS log stamped by different
//! clocks, or a logger that buffers one channel, give. The direct method fits such a log
//! without a word, and each sample's error grows with the lag times how fast the torque
//! changes: the A465 example's torques 0.1 s late left 11 to 20 times its residual RMS per
//! joint, 1 s late 20 to 94 times (docs/method.md, section 8).
//!
//! The check shifts each torque column against the robot's model torques at the positions
//! and fits it as [`super::torque_columns`] does (its model's gravity torque and the rest of
//! its inverse dynamics, each scaled, beside its friction, an offset and a rotor's inertia).
//! The columns judged are those such a fit explains at least half of at some shift; the shift
//! that leaves the least of them unexplained (the geometric mean of each one's unexplained
//! fraction, so that each joint counts alike) is the log's lag. It is a finding where it
//! leaves [`LAG_RATIO`] times less unexplained than no shift: a small lag that changes little
//! (a torque sensor's filter) is none. On the A465 example (preprocessed to 100 Hz) the clean
//! log's best shift is none; torques 10 samples late fit 26 times better shifted back, 100
//! samples late 500 times; positions in degrees or a joint's zero 1 rad off fit no shift
//! better (1.0 to 1.04 times).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::findings::position_offsets::PositionOffsets;
use super::position_range::JointRange;
use super::torque_columns::{joint_regressors, model_torques, TorqueColumn, JUDGED};
use crate::error::Result;
use crate::{Gravity, Model, States};

/// The largest shift searched, in samples (and at most a quarter of the log either way).
pub const MAX_LAG: usize = 500;

/// How many times less of the loaded columns a lag must leave unexplained than no shift for
/// it to be a finding.
pub const LAG_RATIO: f64 = 4.0;

/// How many evenly spread samples the check uses at most.
pub const SAMPLES: usize = 2000;

/// The least fraction of a column counted as unexplained (an exact fit's rounding).
pub const EXACT: f64 = 1e-15;

/// The log's torque columns shifted against its positions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueLag {
    /// The shift, in samples of the data checked, that fits the torques best: positive where
    /// the torques are logged after the positions they belong to (they lag), negative where
    /// before; 0 where none fits better than the log as it is.
    pub samples: i64,
    /// The joints whose columns were judged (their fit explains at least half of the column
    /// at some shift).
    pub joints: Vec<String>,
    /// What their fits leave unexplained as logged: the geometric mean over those columns of
    /// each one's residual sum of squares as a fraction of its variance (at least [`EXACT`]).
    pub unexplained: f64,
    /// The same at the shift `samples`.
    pub unexplained_at_lag: f64,
}

impl TorqueLag {
    /// What is wrong, if the evidence is strong: the torques fit the positions
    /// [`LAG_RATIO`] times better shifted by `samples`.
    pub fn finding(&self) -> Option<String> {
        let strong = self.unexplained >= LAG_RATIO * self.unexplained_at_lag;
        if self.samples == 0 || !strong || !self.unexplained_at_lag.is_finite() {
            return None;
        }
        let (how, by) = if self.samples > 0 {
            ("after", self.samples)
        } else {
            ("before", -self.samples)
        };
        Some(format!(
            "the torques of {} fit the robot's model {:.0} times better shifted by {by} sample(s): they were logged {by} sample(s) {how} the positions they belong to (two clocks, a buffered channel); align the columns before identifying, or each sample's torque is compared with another moment's motion",
            self.joints
                .iter()
                .map(|j| format!("'{j}'"))
                .collect::<Vec<_>>()
                .join(", "),
            self.unexplained / self.unexplained_at_lag.max(f64::MIN_POSITIVE),
        ))
    }

    /// What is wrong with a lag read from a file, if anything: a joint not among
    /// `joint_names`, a shift beyond [`MAX_LAG`], a fraction that is not finite or negative.
    pub fn problem(&self, joint_names: &[String]) -> Option<String> {
        if let Some(j) = self.joints.iter().find(|j| !joint_names.contains(j)) {
            return Some(format!("joint '{j}' is not one of the model's joints"));
        }
        if self.samples.unsigned_abs() > MAX_LAG as u64 {
            return Some(format!(
                "samples is {}, beyond the {MAX_LAG} searched",
                self.samples
            ));
        }
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !ok(self.unexplained) || !ok(self.unexplained_at_lag) {
            return Some("unexplained and unexplained_at_lag must be finite and >= 0".into());
        }
        None
    }
}

/// What looks wrong with a log against the robot's model: its positions beyond the joint
/// limits (`ranges`, [`super::position_range::finding`]), the torque `columns`' findings
/// ([`super::torque_columns::findings`]) and then the `lag`'s, if any.
pub fn log_findings(
    ranges: &[JointRange],
    columns: &[TorqueColumn],
    lag: Option<&TorqueLag>,
) -> Vec<String> {
    let mut out: Vec<String> = super::position_range::finding(ranges).into_iter().collect();
    out.extend(super::torque_columns::findings(columns));
    out.extend(lag.and_then(TorqueLag::finding));
    out
}

/// What looks wrong with a new log against a saved base-parameter model: its
/// [`log_findings`], then the joints' zero offsets against the model's parameters
/// ([`PositionOffsets::finding_beside`]: none where a torque column is found wrong).
pub fn validation_findings(
    ranges: &[JointRange],
    columns: &[TorqueColumn],
    lag: Option<&TorqueLag>,
    offsets: Option<&PositionOffsets>,
) -> Vec<String> {
    let mut out = log_findings(ranges, columns, lag);
    out.extend(offsets.and_then(|o| o.finding_beside(columns, true)));
    out
}

/// The lag of the torque columns `tau` (row-major `k x nv`, N m) behind the positions of
/// `states` (rad, rad/s, rad/s^2; velocities and accelerations required), against `model`'s
/// inverse dynamics (with or without gravity, as the log was recorded), searched within
/// [`MAX_LAG`] samples and a quarter of the log either way, over at most [`SAMPLES`] evenly
/// spread samples. None where the log has no velocities or accelerations, is shorter than 40
/// samples, or no column is judged.
pub fn check_torque_lag(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    gravity: Gravity,
) -> Result<Option<TorqueLag>> {
    let n = model.nv;
    let k = states.len();
    let (Some(qd_all), Some(qdd_all)) = (states.qd(), states.qdd()) else {
        return Ok(None);
    };
    if k < 40 {
        return Ok(None);
    }
    states.check_companion("tau", tau, n)?;
    // the rows checked stay clear of both ends by the largest shift, so that every shift is
    // judged on the same samples
    let reach = MAX_LAG.min(k / 4);
    let span = k - 2 * reach;
    let m = span.min(SAMPLES);
    let rows: Vec<usize> = (0..m).map(|i| reach + i * span / m).collect();
    let pick = |x: &[f64]| -> Vec<f64> {
        rows.iter()
            .flat_map(|&i| x[i * n..(i + 1) * n].iter().copied())
            .collect()
    };
    let (q, qd, qdd) = (pick(states.q()), pick(qd_all), pick(qdd_all));
    let (weight, inertial) = model_torques(model, &q, &qd, &qdd, gravity)?;
    // per joint: its model's torques and its own terms, and the pseudo-inverse that fits any
    // shifted column by them (6 x m)
    let fitters: Vec<(DMatrix<f64>, DMatrix<f64>)> = (0..n)
        .map(|j| {
            let x = joint_regressors(&weight, &inertial, &qd, &qdd, n, j);
            // the pseudo-inverse of the tall matrix itself (its singular values, not their
            // squares), so that nearly dependent columns (a rotor's inertia beside the model's
            // inertial torque) are kept as a least-squares solver keeps them
            // a matrix that is not finite fits nothing (the column is then unjudged)
            let solve = crate::decomposition::svd(x.clone(), true, true)
                .and_then(|svd| {
                    let largest = svd.singular_values.max();
                    svd.pseudo_inverse(1e-12 * largest).ok()
                })
                .unwrap_or_else(|| DMatrix::zeros(6, m));
            (solve, x)
        })
        .collect();
    // the fraction of joint j's column its fit leaves unexplained at shift `lag` (floored
    // where a fit is exact); None where the column does not vary or the fit is not finite
    let unexplained = |j: usize, lag: i64| -> Option<f64> {
        let (solve, x) = &fitters[j];
        let y = DVector::from_fn(m, |r, _| {
            let i = (rows[r] as i64 + lag) as usize;
            tau[i * n + j]
        });
        let mean = y.mean();
        let variance: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
        if !(variance > 0.0 && variance.is_finite()) {
            return None;
        }
        let residual = (&y - x * (solve * &y)).norm_squared();
        let fraction = (residual / variance).max(EXACT);
        fraction.is_finite().then_some(fraction)
    };
    // a coarse pass over every `step`-th shift for every joint: the joints it judges (their
    // fit explains at least half of the column at some shift) and the best of those shifts
    let reach = reach as i64;
    let step = (reach / 50).max(1);
    let coarse: Vec<i64> = (0..)
        .map(|i| -reach + i * step)
        .take_while(|&l| l <= reach)
        .chain([0])
        .collect();
    let mut table = vec![vec![None; coarse.len()]; n];
    for (c, &lag) in coarse.iter().enumerate() {
        crate::interrupt::check("checking the torques' lag")?;
        for (j, row) in table.iter_mut().enumerate() {
            row[c] = unexplained(j, lag);
        }
    }
    let judged: Vec<usize> = (0..n)
        .filter(|&j| {
            table[j].iter().all(Option::is_some)
                && table[j].iter().flatten().any(|&u| u <= 1.0 - JUDGED)
        })
        .collect();
    if judged.is_empty() {
        return Ok(None);
    }
    // the mean over the judged joints of the log of what each leaves unexplained
    let pooled = |lag: i64| -> Option<f64> {
        judged
            .iter()
            .map(|&j| unexplained(j, lag).map(f64::ln))
            .sum::<Option<f64>>()
            .map(|s| s / judged.len() as f64)
    };
    let Some(at_zero) = pooled(0) else {
        return Ok(None);
    };
    let mut best = (0i64, at_zero);
    let consider = |best: &mut (i64, f64), lag: i64, u: Option<f64>| {
        if let Some(u) = u {
            if u < best.1 || (u == best.1 && lag.abs() < best.0.abs()) {
                *best = (lag, u);
            }
        }
    };
    for (c, &lag) in coarse.iter().enumerate() {
        let u = judged
            .iter()
            .map(|&j| table[j][c].map(f64::ln))
            .sum::<Option<f64>>()
            .map(|s| s / judged.len() as f64);
        consider(&mut best, lag, u);
    }
    // then every shift around the best of them
    let centre = best.0;
    for lag in (centre - step + 1).max(-reach)..=(centre + step - 1).min(reach) {
        crate::interrupt::check("checking the torques' lag")?;
        consider(&mut best, lag, pooled(lag));
    }
    Ok(Some(TorqueLag {
        samples: best.0,
        joints: judged
            .iter()
            .map(|&j| model.joint_names[j].clone())
            .collect(),
        unexplained: at_zero.exp(),
        unexplained_at_lag: best.1.exp(),
    }))
}
