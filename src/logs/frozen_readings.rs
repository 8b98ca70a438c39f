//! Frozen readings: one joint's column of a log holds one value for longer than a held
//! reading ([`MAX_HELD`] samples) while the joint moves, and then jumps back to the signal. A
//! sensor's or driver's message stream stalled, and the logger wrote the last value it had
//! until the stream came back. On the A465's excitation log, one joint's positions frozen for
//! 50 ms moved the direct method's base parameters by 10 of their standard errors, and 30 ms in
//! every second by 21, silently.
//!
//! What the signal did during a long stall is not known (a held reading of up to
//! [`MAX_HELD`] samples is bridged by the cubic through the samples either side of it, see
//! [`crate::logs::log_screening`]; over a longer stall that would be invention), so the rows are
//! removed, as rows of zeros are ([`crate::logs::log_dropouts`]): the preprocessing bridges them as
//! it bridges irregular sampling, or splits the log at them when they are longer than a gap.
//!
//! A run of at least [`MIN_FROZEN`] exactly repeated values of one column (bit for bit) is a
//! frozen reading when
//! 1. its joint moves: for `qd`, `qdd` and `tau` the joint's position changes over each half
//!    of the run by more than [`NOISE_LEVELS`] noise levels of its own column (a joint at rest
//!    reads its velocity, acceleration and torque again legitimately, also for the part of a
//!    run before it starts off or after it arrives); for `q`, its logged velocity is not 0
//!    throughout the run (always judged where no velocity is logged);
//! 2. it ends with a jump: its last sample is more than [`NOISE_LEVELS`] noise levels off the
//!    cubic through the samples after it, extrapolated one sample back (the level at least the
//!    column's floor: its median level over the log, the rounding of a grid it lies on). A joint
//!    that really stood still, or a slow signal on a coarse grid, leaves its last repeated value
//!    smoothly: positions printed with four decimals repeat for up to 30 samples at the real
//!    Panda log's start, and are not taken for frozen; and
//! 3. the signal moved on meanwhile: the first sample after the run steps from the value held
//!    by more than [`MOVED_ON`] times the signal's own change from sample to sample after it,
//!    and by more than 2 steps of a grid the column lies on. A torque that ramps up where the
//!    run ends (a perturbation starting: a kink, which the cubic after it does not extrapolate)
//!    steps from its last value by one sample's motion, and a torque logged in steps coarser
//!    than its noise by one step.
//!
//! A run that reaches the end of its stretch between gaps (a stream that stopped before the
//! log did, its last value logged to the end) has no jump to judge. It is a frozen reading
//! where its joint moves (as in 1.; for `q`, its logged velocity integrates over the run to
//! more than [`NOISE_LEVELS`] noise levels and 2 grid steps: a joint at rest whose velocity
//! reads noise is not taken, and without logged velocities it is kept) and it is more than
//! twice as long as the column's longest run of repeated values before it in the stretch
//! (positions printed coarsely, torques on a coarse grid repeat all along). A column that
//! holds one value over its whole stretch is a flat channel, not a stall, and is kept. A column
//! whose frozen readings cover more than [`MAX_FROZEN_SHARE`] of a stretch is refused:
//! it is a signal logged at a lower rate and held on the log's grid (or a sensor that failed),
//! not a stall, and removing its rows would leave little.

use crate::error::{Error, Result};
use crate::logs::findings::log_dropouts::LogDropout;
pub use crate::logs::findings::log_dropouts::MIN_FROZEN;
use crate::logs::log_screening::{
    column_floor, end_jump, joint_called, median, segments, signals, unit, LISTED, MAX_HELD,
};
use crate::logs::outliers::NOISE_LEVELS;
use crate::logs::recording::Recording;

/// The largest share of a stretch's samples a column's frozen readings may cover; more is
/// refused (see the module documentation).
pub const MAX_FROZEN_SHARE: f64 = 0.25;

/// The frozen readings of `rec` (see the module documentation), in log order (by first
/// sample, then signal and joint). Each names its signal, joint, rows (`first_sample`,
/// `samples`: indices into `rec`), times, the value held and how far its end jumps.
///
/// Errors: [`Error::Recording`] naming the column where frozen readings cover more than
/// [`MAX_FROZEN_SHARE`] of a stretch between gaps; [`Error::Interrupted`] on Ctrl-C.
pub fn find_frozen_readings(rec: &Recording) -> Result<Vec<LogDropout>> {
    let n = rec.n;
    let all = signals(rec);
    let mut found = vec![];
    for (a, b) in segments(rec) {
        crate::interrupt::check("looking for frozen readings in the log")?;
        let t = &rec.t[a..b];
        let column =
            |values: &[f64], j: usize| -> Vec<f64> { (a..b).map(|i| values[i * n + j]).collect() };
        let floor = |y: &Vec<f64>| column_floor(t, y);
        // the frozen reading of `signal`'s column `j` holding `value` over the stretch's rows `run`
        let reading =
            |signal: &str, j: usize, run: std::ops::Range<usize>, value, jump, to_end| LogDropout {
                signal: signal.to_string(),
                first_sample: a + run.start,
                samples: run.len(),
                from: rec.t[a + run.start],
                to: rec.t[a + run.end - 1],
                experiment: None,
                joint: Some(j),
                value: Some(value),
                noise_levels: jump,
                to_end,
            };
        // each joint's position floor, computed where a run asks for it
        let mut position_floor: Vec<Option<f64>> = vec![None; n];
        for &(signal, values) in &all {
            for j in 0..n {
                let y = column(values, j);
                let runs = long_runs(&y);
                if runs.is_empty() {
                    continue;
                }
                let level = floor(&y);
                let grid = crate::signal::grid_step(&y).unwrap_or(0.0);
                let mut covered = 0;
                for run in runs {
                    let moves = if signal == "q" {
                        rec.qd
                            .as_ref()
                            .is_none_or(|qd| run.clone().any(|i| qd[(a + i) * n + j] != 0.0))
                    } else {
                        // in both halves of the run: a joint that stands still for part of
                        // it (arriving at rest, or starting off) reads its torque again there
                        let q = |i: usize| rec.q[(a + i) * n + j];
                        let level_q =
                            *position_floor[j].get_or_insert_with(|| floor(&column(&rec.q, j)));
                        let mid = (run.start + run.end) / 2;
                        [(run.start, mid), (mid, run.end - 1)]
                            .iter()
                            .all(|&(x, y)| (q(y) - q(x)).abs() > NOISE_LEVELS * level_q)
                    };
                    if !moves {
                        continue;
                    }
                    // a column that never changes in the stretch is a flat channel, not a stall
                    // (crate::local::flat_channels warns of it)
                    if run.start == 0 && run.end == y.len() {
                        continue;
                    }
                    if run.end == y.len() {
                        // a stream that stopped before the log did: no jump to judge, so the
                        // run must stand out from the column's runs before it, and a position
                        // must have moved by what its logged velocity says
                        let moved = signal != "q" || {
                            let travel = match &rec.qd {
                                Some(qd) => run
                                    .clone()
                                    .skip(1)
                                    .fold(0.0, |s, i| s + qd[(a + i) * n + j] * (t[i] - t[i - 1])),
                                None => 0.0,
                            };
                            travel.abs() > NOISE_LEVELS * level + 2.0 * grid
                        };
                        if moved && run.len() > 2 * longest_run(&y[..run.start]) {
                            covered += run.len();
                            found.push(reading(signal, j, run.clone(), y[run.start], None, true));
                        }
                        continue;
                    }
                    let Some(jump) = end_jump(t, &y, run.end - 1, level) else {
                        continue;
                    };
                    if jump <= NOISE_LEVELS || !moved_on(&y, run.clone(), grid) {
                        continue;
                    }
                    covered += run.len();
                    let jump = Some(jump).filter(|z| z.is_finite());
                    found.push(reading(signal, j, run.clone(), y[run.start], jump, false));
                }
                if covered as f64 > MAX_FROZEN_SHARE * (b - a) as f64 {
                    return Err(Error::recording(
                        rec.name.clone(),
                        format!(
                            "column {signal}{} holds one value for more than {MAX_HELD} samples and then jumps, while the joint moves, over {covered} of the {} samples from t = {} s to {} s (more than {:.0} %): a signal logged at a lower rate and held on the log's grid, or a sensor that failed, rather than a stalled message stream. Resample the column at the instants its values change, or log it at the log's rate",
                            j + 1,
                            b - a,
                            crate::error::shown(rec.t[a]),
                            crate::error::shown(rec.t[b - 1]),
                            100.0 * MAX_FROZEN_SHARE
                        ),
                    ));
                }
            }
        }
    }
    found.sort_by(|x, y| {
        (x.first_sample, &x.signal, x.joint).cmp(&(y.first_sample, &y.signal, y.joint))
    });
    Ok(found)
}

/// Whether the first sample after the held `run` of `y` steps from the value held by more
/// than [`MOVED_ON`] times the signal's own change from sample to sample after it (the median
/// over up to [`MAX_HELD`] samples) and by more than 2 steps of the `grid` it lies on (0 for
/// none): the signal moved on while its reading was held. A signal that only bends where the
/// run ends (a torque that ramps up as a perturbation starts) steps from its last value by no
/// more than its own motion, and one on a coarse grid by one step.
fn moved_on(y: &[f64], run: std::ops::Range<usize>, grid: f64) -> bool {
    let Some(&first) = y.get(run.end) else {
        return false;
    };
    let step = (first - y[run.end - 1]).abs();
    let after = &y[run.end..(run.end + MAX_HELD + 1).min(y.len())];
    let own = median(after.windows(2).map(|w| (w[1] - w[0]).abs()).collect()).unwrap_or(0.0);
    step > MOVED_ON * own && step > 2.0 * grid
}

/// How many samples' worth of the signal's own motion the first sample after a frozen
/// reading must step from the value held (see the module documentation).
pub const MOVED_ON: f64 = 3.0;

/// The length of the longest run of bit-for-bit repeated values of `y` (0 if empty).
fn longest_run(y: &[f64]) -> usize {
    let mut longest = 0;
    let mut a = 0;
    while a < y.len() {
        let b = a + y[a..]
            .iter()
            .take_while(|v| v.to_bits() == y[a].to_bits())
            .count();
        longest = longest.max(b - a);
        a = b;
    }
    longest
}

/// The runs of at least [`MIN_FROZEN`] bit-for-bit repeated values of `y` (index ranges).
fn long_runs(y: &[f64]) -> Vec<std::ops::Range<usize>> {
    let mut runs = vec![];
    let mut a = 0;
    while a < y.len() {
        let mut b = a + 1;
        while b < y.len() && y[b].to_bits() == y[a].to_bits() {
            b += 1;
        }
        if b - a >= MIN_FROZEN {
            runs.push(a..b);
        }
        a = b;
    }
    runs
}

/// The words of a warning that tell of `frozen` readings (each with a joint), removed
/// `removed` (such as [`BRIDGED_BY_PREPROCESSING`](crate::logs::log_dropouts::BRIDGED_BY_PREPROCESSING));
/// `joint_names` name the joints by index. Readings of several joints of one signal over the
/// same rows (a whole message stalled) are listed together.
pub fn describe(frozen: &[&LogDropout], joint_names: &[String], removed: &str) -> String {
    let mut groups: Vec<Vec<&LogDropout>> = vec![];
    for d in frozen {
        match groups.iter_mut().find(|g| {
            (&g[0].signal, g[0].first_sample, g[0].samples)
                == (&d.signal, d.first_sample, d.samples)
        }) {
            Some(g) => g.push(d),
            None => groups.push(vec![d]),
        }
    }
    let mut listed: Vec<String> = groups
        .iter()
        .take(LISTED)
        .map(|g| {
            let d = g[0];
            let joints: Vec<String> = g
                .iter()
                .map(|d| joint_called(joint_names, d.joint.unwrap_or(0)))
                .collect();
            let held = if g.len() == 1 {
                format!(
                    "{} of {} held {} {}",
                    d.signal,
                    joints[0],
                    crate::error::shown(d.value.unwrap_or(f64::NAN)),
                    unit(&d.signal)
                )
            } else {
                format!("{} of {} held their values", d.signal, joints.join(", "))
            };
            let off = g
                .iter()
                .map(|d| d.noise_levels.unwrap_or(f64::INFINITY))
                .fold(0.0f64, f64::max);
            let off = if off.is_finite() {
                format!("{off:.0} noise levels")
            } else {
                "beyond any scale".into()
            };
            let then = if g.iter().all(|d| d.to_end) {
                "to the end of its stretch of the log (the stream stopped before the log did)"
                    .to_string()
            } else {
                format!("and then jumped {off} back to the signal")
            };
            format!(
                "{held} for {} rows from sample {} (t = {:.4} s to {:.4} s) {then}",
                d.samples, d.first_sample, d.from, d.to
            )
        })
        .collect();
    if groups.len() > LISTED {
        listed.push(format!("and {} more", groups.len() - LISTED));
    }
    format!(
        "{} frozen reading(s), a column that holds one value for more than {MAX_HELD} samples while its joint moves and then jumps back to the signal (a stalled message stream whose last value was logged in its place: what the signal did there is not known), were removed with their rows {removed}: {}",
        groups.len(),
        listed.join("; ")
    )
}
