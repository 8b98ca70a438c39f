//! A log's velocity columns against the derivative of its positions. Preprocessing takes
//! logged velocities as they are (and differentiates them into accelerations), so a column in
//! degrees per second, of the opposite sign, of another joint, or of something else entirely
//! went into the fit without a word: the A465's excitation log with its velocities in deg/s
//! was fitted, and only a position-offset warning hinted that something was off.
//!
//! Each joint's logged velocity `v_j` (resampled and filtered as preprocessing does) is
//! compared with every moving joint's derivative of position `d_k` (filtered alike) by the
//! cosine of the angle between them, `<v_j, d_k> / (|v_j| |d_k|)`, and the scale `<v_j, d_j> /
//! <d_j, d_j>`. Refused, naming the joint: a column that follows another joint's positions far
//! better than its own ([`FOLLOWS`] against less), one of the opposite sign, one whose scale is
//! outside [1/[`MAX_SCALE`], [`MAX_SCALE`]] (deg/s read as rad/s is 57.3; a motor-side velocity
//! before the gear), and one that follows no joint's positions (cosine below [`UNRELATED`] with
//! every one). A joint that does not move (its derivative's RMS below 1e-3 of the fastest
//! joint's) is not judged. Small scale errors and lags of a filtered velocity estimate pass.

use crate::error::{Error, Result};

/// A cosine at least this large: the column follows that joint's positions.
pub const FOLLOWS: f64 = 0.9;

/// A cosine below this with every joint: the column follows no joint's positions.
pub const UNRELATED: f64 = 0.5;

/// The largest factor between a logged velocity and its position's derivative accepted.
pub const MAX_SCALE: f64 = 2.0;

/// Checks the logged velocities `qd` against the derivatives `dq` of the positions (per joint
/// a column on one grid, both filtered alike; rad/s or m/s) of the log `recording`. Errors: one
/// naming every joint whose column is another joint's, of the opposite sign, scaled or
/// unrelated, and what it looks like.
pub fn check_velocity_columns(recording: &str, qd: &[Vec<f64>], dq: &[Vec<f64>]) -> Result<()> {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let norms: Vec<f64> = dq.iter().map(|d| dot(d, d).sqrt()).collect();
    let fastest = norms.iter().copied().fold(0.0, f64::max);
    let moving: Vec<bool> = norms
        .iter()
        .map(|&r| r.is_finite() && r > 1e-3 * fastest && r > 0.0)
        .collect();
    let mut problems = vec![];
    for (j, v) in qd.iter().enumerate() {
        let vn = dot(v, v).sqrt();
        if !(moving[j] && vn.is_finite() && vn > 0.0) {
            continue;
        }
        let cosine = |k: usize| dot(v, &dq[k]) / (vn * norms[k]);
        let own = cosine(j);
        let best = (0..dq.len())
            .filter(|&k| moving[k] && k != j)
            .map(|k| (k, cosine(k)))
            .fold(None, |a: Option<(usize, f64)>, b| match a {
                Some(a) if a.1.abs() >= b.1.abs() => Some(a),
                _ => Some(b),
            });
        let scale = dot(v, &dq[j]) / (norms[j] * norms[j]);
        let joint = j + 1;
        if let Some((k, c)) = best.filter(|(_, c)| c.abs() >= FOLLOWS && own.abs() < FOLLOWS) {
            problems.push((joint, format!(
                "follows the positions of joint {} (cosine {c:.3}, its own {own:.3}): columns swapped or mislabelled",
                k + 1
            )));
        } else if own.abs().max(best.map_or(0.0, |b| b.1.abs())) < UNRELATED {
            problems.push((joint, format!(
                "follows no joint's positions (cosine {own:.3} with its own): not a velocity of this log"
            )));
        } else if own <= -FOLLOWS {
            problems.push((
                joint,
                format!("the opposite sign of its positions' derivative (scale {scale:.3})"),
            ));
        } else if own >= FOLLOWS && !(1.0 / MAX_SCALE..=MAX_SCALE).contains(&scale) {
            let looks = if (scale / 57.2958 - 1.0).abs() < 0.05 {
                ": degrees per second read as rad/s"
            } else if (scale * 57.2958 - 1.0).abs() < 0.05 {
                ": the positions in degrees, the velocities in rad/s"
            } else {
                ": other units, or a motor-side velocity before the gear"
            };
            problems.push((
                joint,
                format!("{scale:.3} times its positions' derivative{looks}"),
            ));
        }
    }
    if problems.is_empty() {
        return Ok(());
    }
    // joints with one diagnosis named together: "joints 1, 2, 3: ..."
    let mut grouped: Vec<(Vec<usize>, String)> = vec![];
    for (joint, what) in problems {
        match grouped.iter_mut().find(|(_, w)| *w == what) {
            Some((joints, _)) => joints.push(joint),
            None => grouped.push((vec![joint], what)),
        }
    }
    let problems: Vec<String> = grouped
        .into_iter()
        .map(|(joints, what)| {
            let names: Vec<String> = joints.iter().map(usize::to_string).collect();
            let plural = if joints.len() > 1 { "s" } else { "" };
            format!("joint{plural} {}: {what}", names.join(", "))
        })
        .collect();
    Err(Error::Recording {
        recording: recording.to_string(),
        message: format!(
            "logged velocities that are not their positions' derivative (rad/s or m/s), {}. Convert or fix those columns, or remove the velocity columns to derive the velocities from the positions",
            problems.join("; ")
        ),
    })
}
