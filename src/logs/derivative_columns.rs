//! A log's velocity columns against the derivative of its positions, and its acceleration
//! columns against the derivative of its velocities. Preprocessing takes logged velocities as
//! they are (and differentiates them into accelerations), so a column in degrees per second,
//! of the opposite sign, of another joint, or of something else entirely went into the fit
//! without a word: the A465's excitation log with its velocities in deg/s was fitted, and only
//! a position-offset warning hinted that something was off. A log with acceleration columns is
//! taken as it is, unpreprocessed (the command line without `--preprocess`; the local method's
//! `recorded_derivatives`): there one joint's velocities in deg/s moved the direct method's
//! base parameters by 2,600 of their standard errors, its accelerations in deg/s^2 by 2,600,
//! two joints' accelerations swapped by 2,200, all without a warning.
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
//! Logged accelerations are judged alike against the derivative of the logged velocities
//! ([`check_logged_derivatives`], for a log used as logged: each stretch between gaps resampled
//! at its median rate and filtered as preprocessing does, by default).

use crate::logs::preprocess_options::PreprocessOptions;
use crate::logs::recording::Recording;
use crate::signal::{butterworth_lowpass, differentiate, filtfilt, interpolate};

use crate::error::{Error, Result};

/// A cosine at least this large: the column follows that joint's positions.
pub const FOLLOWS: f64 = 0.9;

/// A cosine below this with every joint: the column follows no joint's positions.
pub const UNRELATED: f64 = 0.5;

/// The largest factor between a logged velocity and its position's derivative accepted.
pub const MAX_SCALE: f64 = 2.0;

/// A logged column and the derivative it is checked against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Derivative {
    /// Velocities against the positions' derivative.
    Velocity,
    /// Accelerations against the velocities' derivative.
    Acceleration,
}

impl Derivative {
    /// What the derivative is of ("positions").
    fn of(self) -> &'static str {
        match self {
            Self::Velocity => "positions",
            Self::Acceleration => "velocities",
        }
    }
    /// What the columns are ("velocities").
    fn columns(self) -> &'static str {
        match self {
            Self::Velocity => "velocities",
            Self::Acceleration => "accelerations",
        }
    }
    /// Their units.
    fn units(self) -> &'static str {
        match self {
            Self::Velocity => "rad/s or m/s",
            Self::Acceleration => "rad/s^2 or m/s^2",
        }
    }
    /// What a column 57.3 times the derivative looks like, and one 1/57.3 of it.
    fn in_degrees(self) -> (&'static str, &'static str) {
        match self {
            Self::Velocity => (
                "degrees per second read as rad/s",
                "the positions in degrees, the velocities in rad/s",
            ),
            Self::Acceleration => (
                "degrees per second squared read as rad/s^2",
                "the velocities in degrees per second, the accelerations in rad/s^2",
            ),
        }
    }
    /// What the user can do.
    fn remedy(self) -> &'static str {
        match self {
            Self::Velocity => "Convert or fix those columns, or remove the velocity columns to derive the velocities from the positions",
            Self::Acceleration => "Convert or fix those columns, or have the accelerations derived instead (preprocess the log: --preprocess; the local method without recorded_derivatives)",
        }
    }
}

/// Checks the logged velocities `qd` against the derivatives `dq` of the positions (per joint
/// a column on one grid, both filtered alike; rad/s or m/s) of the log `recording`. Errors: one
/// naming every joint whose column is another joint's, of the opposite sign, scaled or
/// unrelated, and what it looks like.
pub fn check_velocity_columns(recording: &str, qd: &[Vec<f64>], dq: &[Vec<f64>]) -> Result<()> {
    check_columns(Derivative::Velocity, recording, qd, dq)
}

/// Checks the logged accelerations `qdd` against the derivatives `dqd` of the logged
/// velocities (per joint a column on one grid, both filtered alike; rad/s^2 or m/s^2) of the
/// log `recording`, as [`check_velocity_columns`] checks velocities.
pub fn check_acceleration_columns(
    recording: &str,
    qdd: &[Vec<f64>],
    dqd: &[Vec<f64>],
) -> Result<()> {
    check_columns(Derivative::Acceleration, recording, qdd, dqd)
}

/// The check of `logged` columns of `kind` against the `derived` ones (see the module
/// documentation).
fn check_columns(
    kind: Derivative,
    recording: &str,
    logged: &[Vec<f64>],
    derived: &[Vec<f64>],
) -> Result<()> {
    let (qd, dq) = (logged, derived);
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
        if moving[j] && vn == 0.0 {
            problems.push((
                j + 1,
                format!("reads 0 throughout while its {} change", kind.of()),
            ));
            continue;
        }
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
                "follows the {} of joint {} (cosine {c:.3}, its own {own:.3}): columns swapped or mislabelled",
                kind.of(),
                k + 1
            )));
        } else if own.abs().max(best.map_or(0.0, |b| b.1.abs())) < UNRELATED {
            problems.push((
                joint,
                format!(
                    "follows no joint's {} (cosine {own:.3} with its own): not {} of this log",
                    kind.of(),
                    kind.columns()
                ),
            ));
        } else if own <= -FOLLOWS {
            problems.push((
                joint,
                format!(
                    "the opposite sign of its {}' derivative (scale {scale:.3})",
                    kind.of()
                ),
            ));
        } else if own >= FOLLOWS && !(1.0 / MAX_SCALE..=MAX_SCALE).contains(&scale) {
            let (degrees, radians) = kind.in_degrees();
            let looks = if (scale / 57.2958 - 1.0).abs() < 0.05 {
                format!(": {degrees}")
            } else if (scale * 57.2958 - 1.0).abs() < 0.05 {
                format!(": {radians}")
            } else {
                ": other units, or a motor-side reading before the gear".to_string()
            };
            problems.push((
                joint,
                format!("{scale:.3} times its {}' derivative{looks}", kind.of()),
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
    Err(Error::recording(
        recording.to_string(),
        format!(
            "logged {} that are not their {}' derivative ({}), {}. {}",
            kind.columns(),
            kind.of(),
            kind.units(),
            problems.join("; "),
            kind.remedy()
        ),
    ))
}

/// Checks the logged velocities and accelerations of `rec`, a log used as logged (not
/// preprocessed), against the derivatives of its positions (steps of whole turns taken out:
/// [`crate::logs::position_wraps`]) and of its logged velocities: each
/// stretch between gaps (longer than 20 median sample intervals) resampled at its median rate,
/// both sides filtered alike by the default preprocessing's low-pass
/// ([`PreprocessOptions::default`]) and trimmed by its trim; stretches too short or sampled too
/// slowly to filter are not judged. Nothing to check without velocity columns. Errors: those
/// of [`check_velocity_columns`] and [`check_acceleration_columns`], naming `rec`; a log too
/// large to resample ([`crate::limits`]). Stops on Ctrl-C.
pub fn check_logged_derivatives(rec: &Recording) -> Result<()> {
    let Some(qd) = rec.qd.as_ref() else {
        return Ok(());
    };
    // a joint angle logged within one turn steps by a turn where it wraps: not motion
    let (unwrapped, _) = crate::logs::position_wraps::unwrap_positions(rec);
    let rec = &unwrapped;
    let options = PreprocessOptions::default();
    let n = rec.n;
    'parts: for (first, end) in crate::logs::log_screening::segments(rec) {
        crate::interrupt::check("checking the log's velocity and acceleration columns")?;
        let t = &rec.t[first..end];
        if t.len() < 3 {
            continue;
        }
        let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = steps.len() / 2;
        let dt = *steps.select_nth_unstable_by(mid, f64::total_cmp).1;
        let Some(cutoff) = options.cutoff.filter(|&c| dt > 0.0 && c < 0.4 / dt) else {
            continue;
        };
        let (t0, t1) = (t[0], t[t.len() - 1]);
        let count = crate::limits::sample_count(
            "checking the velocity and acceleration columns",
            t1 - t0,
            1.0 / dt,
            1 + 4 * n,
        )?;
        let skip = (options.trim / dt).round() as usize;
        if count <= 2 * skip + 10 {
            continue;
        }
        let filter = butterworth_lowpass(options.order, cutoff, 1.0 / dt)?;
        let grid: Vec<f64> = (0..count).map(|i| t0 + i as f64 * dt).collect();
        let column = |x: &[f64], j: usize| -> Vec<f64> {
            let values: Vec<f64> = (first..end).map(|i| x[i * n + j]).collect();
            interpolate(t, &values, &grid)
        };
        // both sides filtered once, and trimmed of the filter's transients
        let smooth = |x: Vec<f64>| -> Option<Vec<f64>> {
            filtfilt(&filter, &x)
                .ok()
                .map(|y| y[skip..count - skip].to_vec())
        };
        let (mut v, mut dq, mut a, mut dv) = (vec![], vec![], vec![], vec![]);
        for j in 0..n {
            let velocity = column(qd, j);
            let (Some(x), Some(y)) = (
                smooth(velocity.clone()),
                smooth(differentiate(&column(&rec.q, j), dt)),
            ) else {
                continue 'parts;
            };
            v.push(x);
            dq.push(y);
            if let Some(qdd) = &rec.qdd {
                let (Some(x), Some(y)) =
                    (smooth(column(qdd, j)), smooth(differentiate(&velocity, dt)))
                else {
                    continue 'parts;
                };
                a.push(x);
                dv.push(y);
            }
        }
        check_velocity_columns(&rec.name, &v, &dq)?;
        if !a.is_empty() {
            check_acceleration_columns(&rec.name, &a, &dv)?;
        }
    }
    Ok(())
}
