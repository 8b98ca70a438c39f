//! Columns logged at a lower rate and held on the log's grid: a logger that merges a slower
//! stream into a faster one (a torque or current read at 100 Hz beside positions at 1 kHz, a
//! ROS topic resampled to another's stamps) writes the slower signal's last value again until
//! the next arrives. The column is a staircase that lags its signal by half a step on average:
//! one joint's torque of the A465's excitation log held for 10 samples at a time moved the
//! direct method's base parameters by 1.7 of their standard errors, its position by 1.3, both
//! silently (runs of 11 samples or more ended as frozen readings here and there, which
//! misnamed the cause).
//!
//! A column is held when, at the samples where its joint moves (its position changes over
//! [`MOTION_SPAN`] samples either side by more than [`NOISE_LEVELS`] noise levels), at least
//! [`MIN_REPEATED`] of its samples repeat the one before exactly, and its values change by
//! more than [`MIN_GRID_STEPS`] steps of a grid it lies on where they change (positions in
//! coarse encoder counts, or a torque in steps coarser than its noise, repeat as often but
//! change by one step). Such a column is read again as the signal it samples: each value at
//! the sample where it first appears (its arrival), joined by straight lines; the samples
//! before the first change and after the last keep their values. What is left is a lag of at
//! most one sample interval. The log is not refused: the values are the sensor's own.

pub use crate::logs::findings::held_columns::*;
use crate::logs::log_screening::{column_floor, joint_called, median, segments, signals};
use crate::logs::outliers::NOISE_LEVELS;
use crate::logs::recording::Recording;

/// `rec` with its held columns read again at their values' arrivals (see the module
/// documentation), and those columns, in order of signal (`q`, `qd`, `qdd`, `tau`) then joint.
/// Each stretch between gaps is judged and read on its own; a column is listed once, with the
/// figures of the first stretch it was found held in. Stops on Ctrl-C.
pub fn find_held_columns(rec: &Recording) -> crate::error::Result<(Recording, Vec<HeldColumn>)> {
    let n = rec.n;
    let mut out = rec.clone();
    let mut found: Vec<HeldColumn> = vec![];
    for (a, b) in segments(rec) {
        crate::interrupt::check("looking for columns held at a lower rate")?;
        let t = &rec.t[a..b];
        let k = b - a;
        if k < 2 * MOTION_SPAN {
            continue;
        }
        let column =
            |values: &[f64], j: usize| -> Vec<f64> { (a..b).map(|i| values[i * n + j]).collect() };
        // per joint, whether it moves at each sample: computed where a column asks
        let mut moving: Vec<Option<Vec<bool>>> = vec![None; n];
        for (signal, values) in signals(rec) {
            for j in 0..n {
                let y = column(values, j);
                let repeats = (1..k)
                    .filter(|&i| y[i].to_bits() == y[i - 1].to_bits())
                    .count();
                if (repeats as f64) < 0.05 * k as f64 {
                    continue;
                }
                let moves = moving[j].get_or_insert_with(|| {
                    let q = column(&rec.q, j);
                    let floor = column_floor(t, &q);
                    (0..k)
                        .map(|i| {
                            let (lo, hi) =
                                (i.saturating_sub(MOTION_SPAN), (i + MOTION_SPAN).min(k - 1));
                            (q[hi] - q[lo]).abs() > NOISE_LEVELS * floor
                        })
                        .collect()
                });
                let judged: Vec<usize> = (1..k).filter(|&i| moves[i]).collect();
                if judged.len() < (k / 10).max(2 * MOTION_SPAN) {
                    continue;
                }
                let same = judged
                    .iter()
                    .filter(|&&i| y[i].to_bits() == y[i - 1].to_bits())
                    .count();
                let repeated = same as f64 / judged.len() as f64;
                if repeated < MIN_REPEATED {
                    continue;
                }
                let changes: Vec<f64> = judged
                    .iter()
                    .filter(|&&i| y[i] != y[i - 1])
                    .map(|&i| (y[i] - y[i - 1]).abs())
                    .collect();
                let grid = crate::signal::grid_step(&y).unwrap_or(0.0);
                match median(changes) {
                    Some(m) if m > MIN_GRID_STEPS * grid => {}
                    _ => continue,
                }
                // each value at its arrival, joined by straight lines
                let arrivals: Vec<usize> = std::iter::once(0)
                    .chain((1..k).filter(|&i| y[i].to_bits() != y[i - 1].to_bits()))
                    .collect();
                let holds: Vec<f64> = arrivals.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
                let Some(held_for) = median(holds) else {
                    continue;
                };
                let target = match signal {
                    "q" => &mut out.q,
                    "qd" => out.qd.as_mut().expect("a column of it"),
                    "qdd" => out.qdd.as_mut().expect("a column of it"),
                    _ => &mut out.tau,
                };
                for w in arrivals.windows(2) {
                    let (p, r) = (w[0], w[1]);
                    let span = t[r] - t[p];
                    for i in p + 1..r {
                        let s = (t[i] - t[p]) / span;
                        target[(a + i) * n + j] = y[p] + s * (y[r] - y[p]);
                    }
                }
                if !found.iter().any(|h| h.signal == signal && h.joint == j) {
                    found.push(HeldColumn {
                        signal: signal.to_string(),
                        joint: j,
                        repeated,
                        held_for,
                    });
                }
            }
        }
    }
    found.sort_by_key(|h| {
        (
            crate::logs::log_screening::SIGNALS
                .iter()
                .position(|s| *s == h.signal),
            h.joint,
        )
    });
    Ok((out, found))
}

/// The warning that tells of the `held` columns of the log `recording` (None for none);
/// `joint_names` name the joints by index (where it has none, `joint 3` names index 2).
pub fn warning(held: &[HeldColumn], recording: &str, joint_names: &[String]) -> Option<String> {
    if held.is_empty() {
        return None;
    }
    let listed: Vec<String> = held
        .iter()
        .map(|h| {
            format!(
                "{} of {} repeats {:.0} % of its samples where the joint moves, each value held for {} samples",
                h.signal,
                joint_called(joint_names, h.joint),
                100.0 * h.repeated,
                h.held_for
            )
        })
        .collect();
    Some(format!(
        "log '{recording}': {} column(s) logged at a lower rate and held on the log's grid (a slower stream merged into a faster one), which lag their signals by half a hold on average: {}. Each was read again as the signal it samples, every value at the sample it arrived in and joined to the next by a straight line (a lag of at most one sample interval)",
        held.len(),
        listed.join("; ")
    ))
}
