//! Rows removed from a log before preprocessing: runs of rows in which every joint of one
//! signal reads exactly 0 while the robot moves (a lost message logged as zeros: a dropout),
//! and runs in which one joint's reading holds one value too long to be replaced
//! ([`crate::logs::frozen_readings`]). What was logged there is not known, so the rows go; the
//! preprocessing bridges them as it bridges irregular sampling, and a crossing window's fit
//! uses the samples left.

use crate::error::{Error, Result};
pub use crate::logs::findings::log_dropouts::*;
use crate::logs::log_screening::{column_floor, signals, LISTED};
use crate::logs::outliers::NOISE_LEVELS;
use crate::logs::recording::Recording;

/// The dropouts of `rec`: runs of at least [`MIN_DROPOUT`] rows in which every joint of a
/// signal reads exactly 0, with a row on either side in which some joint of it does not. For
/// `qd`, `qdd` and `tau` the positions must change within the run (from its first row to its
/// last, some joint's by more than [`NOISE_LEVELS`] noise levels of its column): a robot holding
/// a posture reads zero velocities and accelerations (and noisy positions), and with no
/// gravity may read zero torques. In log order.
pub fn find_dropouts(rec: &Recording) -> Vec<LogDropout> {
    let n = rec.n;
    let k = rec.len();
    let mut found = vec![];
    // each joint's position noise floor, computed where a run asks for it
    let mut position_floors: Option<Vec<f64>> = None;
    for (signal, values) in signals(rec) {
        let zero = |i: usize| values[i * n..(i + 1) * n].iter().all(|&x| x == 0.0);
        let mut i = 1;
        while i < k {
            if !zero(i) {
                i += 1;
                continue;
            }
            let a = i;
            while i < k && zero(i) {
                i += 1;
            }
            // rows a..i read zeros; a - 1 does not (a >= 1 and the run starts there)
            if i == k || zero(a - 1) || i - a < MIN_DROPOUT {
                continue;
            }
            // the robot moves during the run: some joint's position changes from its first row
            // to its last by more than 10 noise levels of its column (a hold between two
            // postures reads zero velocities and accelerations, and noisy positions)
            let moves = signal == "q" || {
                let floors = position_floors.get_or_insert_with(|| {
                    (0..n)
                        .map(|j| {
                            let y: Vec<f64> = (0..k).map(|r| rec.q[r * n + j]).collect();
                            column_floor(&rec.t, &y)
                        })
                        .collect()
                });
                (0..n).any(|j| {
                    (rec.q[(i - 1) * n + j] - rec.q[a * n + j]).abs() > NOISE_LEVELS * floors[j]
                })
            };
            if moves {
                found.push(LogDropout {
                    signal: signal.to_string(),
                    first_sample: a,
                    samples: i - a,
                    from: rec.t[a],
                    to: rec.t[i - 1],
                    experiment: None,
                    joint: None,
                    value: None,
                    noise_levels: None,
                    to_end: false,
                });
            }
        }
    }
    found.sort_by_key(|d| d.first_sample);
    found
}

/// The rows to remove from a log before preprocessing: the frozen readings of `logged` (the
/// log as logged: [`crate::logs::frozen_readings::find_frozen_readings`]) and the dropouts of
/// `screened` (the same log with its glitches or held readings replaced: [`find_dropouts`]),
/// in log order. A frozen reading within a dropout of its signal (zeros held by every joint)
/// is told of as the dropout.
///
/// Errors: those of [`crate::logs::frozen_readings::find_frozen_readings`].
pub fn find_removed_rows(logged: &Recording, screened: &Recording) -> Result<Vec<LogDropout>> {
    let dropouts = find_dropouts(screened);
    let mut rows: Vec<LogDropout> = crate::logs::frozen_readings::find_frozen_readings(logged)?
        .into_iter()
        .filter(|f| {
            !dropouts.iter().any(|d| {
                d.signal == f.signal
                    && d.first_sample <= f.first_sample
                    && f.first_sample + f.samples <= d.first_sample + d.samples
            })
        })
        .collect();
    rows.extend(dropouts);
    rows.sort_by_key(|d| d.first_sample);
    Ok(rows)
}

/// `error` (a recording's, from the rows left after `removed`'s were removed) with what was
/// removed appended: a gap or a window short of samples may be of the removal's making. Other
/// errors, and any where nothing was removed, are returned as they are.
pub fn after_removing(error: Error, removed: &[LogDropout]) -> Error {
    match (error, removed.first()) {
        (Error::Recording { recording, message }, Some(first)) => {
            let frozen = removed.iter().filter(|d| d.joint.is_some()).count();
            let zeros = removed.len() - frozen;
            let mut what = vec![];
            if zeros > 0 {
                what.push(format!(
                    "{zeros} dropout(s), rows that read 0 for every joint of a signal"
                ));
            }
            if frozen > 0 {
                what.push(format!(
                    "{frozen} frozen reading(s), rows in which a joint's column held one value"
                ));
            }
            Error::Recording {
                recording,
                message: format!(
                    "{message} (after removing {}, the first {} rows from t = {:.6} s)",
                    what.join(", and "),
                    first.samples,
                    first.from
                ),
            }
        }
        (other, _) => other,
    }
}

/// The indices of the rows of a log of `len` rows that `dropouts` leave.
pub fn kept_rows(len: usize, dropouts: &[LogDropout]) -> Vec<usize> {
    let mut keep = vec![true; len];
    for d in dropouts {
        for k in keep.iter_mut().skip(d.first_sample).take(d.samples) {
            *k = false;
        }
    }
    (0..len).filter(|&i| keep[i]).collect()
}

/// `rec` without the rows of `dropouts` (a row in several is removed once).
pub fn without_dropouts(rec: &Recording, dropouts: &[LogDropout]) -> Result<Recording> {
    if dropouts.is_empty() {
        return Ok(rec.clone());
    }
    let n = rec.n;
    let keep = kept_rows(rec.len(), dropouts);
    let rows = |x: &[f64]| -> Vec<f64> {
        keep.iter()
            .flat_map(|&i| x[i * n..(i + 1) * n].iter().copied())
            .collect()
    };
    let out = Recording::new(
        rec.name.clone(),
        n,
        keep.iter().map(|&i| rec.t[i]).collect(),
        rows(&rec.q),
        rows(&rec.tau),
        rec.qd.as_deref().map(rows),
        rec.qdd.as_deref().map(rows),
    )?;
    Ok(Recording {
        experiment: rec.experiment.clone(),
        glitches: rec.glitches.clone(),
        dropouts: dropouts.to_vec(),
        ..out
    })
}

/// What [`dropout_warning`] says became of the rows removed before preprocessing.
pub const BRIDGED_BY_PREPROCESSING: &str = "before preprocessing, which bridges them as it bridges irregular sampling (a stretch longer than 20 median sample intervals is a gap)";

/// The warning that tells of the `dropouts` removed from the log `recording` (None for none):
/// rows of zeros, and frozen readings ([`crate::logs::frozen_readings::describe`]); `removed` says
/// when and with what consequence (such as [`BRIDGED_BY_PREPROCESSING`]); `joint_names` name
/// the joints by index (where it has none, `joint 3` names index 2).
pub fn dropout_warning(
    dropouts: &[LogDropout],
    recording: &str,
    joint_names: &[String],
    removed: &str,
) -> Option<String> {
    let (frozen, zeros): (Vec<&LogDropout>, Vec<&LogDropout>) =
        dropouts.iter().partition(|d| d.joint.is_some());
    let mut parts = vec![];
    if !zeros.is_empty() {
        let mut listed: Vec<String> = zeros
            .iter()
            .take(LISTED)
            .map(|d| {
                format!(
                    "{} rows from sample {} (t = {:.4} s to {:.4} s) read 0 for every joint's {}",
                    d.samples, d.first_sample, d.from, d.to, d.signal
                )
            })
            .collect();
        if zeros.len() > LISTED {
            listed.push(format!("and {} more", zeros.len() - LISTED));
        }
        parts.push(format!(
            "{} dropout(s), rows in which every joint of a signal reads exactly 0 while the robot moves (a lost message logged as zeros), were removed {removed}: {}",
            zeros.len(),
            listed.join("; ")
        ));
    }
    if !frozen.is_empty() {
        parts.push(crate::logs::frozen_readings::describe(
            &frozen,
            joint_names,
            removed,
        ));
    }
    if parts.is_empty() {
        return None;
    }
    Some(format!("log '{recording}': {}", parts.join("; and ")))
}
