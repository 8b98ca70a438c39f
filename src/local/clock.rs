//! The recording's clock against the plan's (docs/method.md, section 7): whether a recording can
//! be a run of an experiment as it stands (its time stamps, its sample interval, its positions
//! against the planned ones), and the offset between the two clocks found in the positions.

use super::crossing::samples_needed;
use super::offset_search::{search_offset, span_rows, CANDIDATES};
use super::plan::Experiment;
use super::FitOptions;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// The offset (s) between `rec`'s clock and `experiment`'s plan, found in the positions within
/// `+-max_shift` s (see [`detect_offset_in`](super::detect_offset_in)) and checked: the positions must follow the plan
/// there (`steps`: the encoder steps of the positions, per joint, or empty), and where the best
/// offset is refused the error says where over the recording's whole span the run is.
/// `joint_names` name the joints in errors.
pub(super) fn align(
    experiment: &Experiment,
    rec: &Recording,
    joint_names: &[String],
    steps: &[Option<f64>],
    max_shift: f64,
) -> Result<f64> {
    if !(max_shift.is_finite() && max_shift > 0.0) {
        return Err(Error::invalid(
            "max_shift",
            format!(
                "{}; expected a positive number of seconds",
                crate::error::shown(max_shift)
            ),
        ));
    }
    check_clock(experiment, rec, max_shift)?;
    // the offsets within 1.25 times the tolerance at which the recording holds every
    // window, or else (to say later which window it misses) that leave some overlap:
    // one that leaves the plan's motion mostly outside the recording compares rest
    // with rest, and fits trivially
    let searched = 1.25 * max_shift;
    let covering =
        covering_offsets(experiment, rec).filter(|(a, b)| a.max(-searched) <= b.min(searched));
    let (first, last) = covering.unwrap_or_else(|| overlap_offsets(experiment, rec));
    let (lo, hi) = (first.max(-searched), last.min(searched));
    let check = || crate::interrupt::check("aligning the recordings with the plan");
    let (offset, cost) = search_offset(experiment, rec, (lo, hi), 200, CANDIDATES, check)?;
    let positions = check_positions(experiment, rec, joint_names, steps, (offset, searched));
    // beyond the tolerance, not following the plan there, or a log long enough for the run
    // to lie further in: the run may start later in the log; look over the whole overlap, at
    // about the same resolution (bounded), and say where it fits. A motion that repeats (the
    // nominal passes, back and forth every few tenths of a second) also fits one repetition
    // off: a run 0.7 s late in its log matched at +0.4 s and was identified from the wrong
    // windows (T* off by 65 of its standard errors)
    let beyond = first < lo || last > hi;
    if positions.is_err() || offset.abs() > max_shift || beyond {
        let step = (hi - lo) / 400.0;
        let points = (((last - first) / step.max(1e-3)) as usize / 2).clamp(200, 20_000);
        let (first, last) = covering_offsets(experiment, rec).unwrap_or((first, last));
        let (wide, wide_cost) =
            search_offset(experiment, rec, (first, last), points, CANDIDATES, check)?;
        let fits = check_positions(experiment, rec, joint_names, steps, (wide, searched)).is_ok();
        if wide.abs() > max_shift && wide_cost < 0.25 * cost && fits {
            // a log more than twice the run's length may hold the whole session
            let span = experiment.trajectory.end() - experiment.trajectory.start();
            let session = if rec.t[rec.len() - 1] - rec.t[0] > 2.0 * span {
                "; if it is a log of the whole session, split it into one recording per experiment first (perturbid split, Plan.split_session)"
            } else {
                ""
            };
            return Err(Error::recording(
                rec.name.clone(),
                format!(
                    "its positions follow the plan of experiment '{}' best with its clock {wide:+.3} s ahead of the plan's (found over its whole span), more than the {} s of clock offset accepted: if the run starts that late in the log, raise max_shift (--max-shift) to at least {}{session}",
                    experiment.kind.name(),
                    crate::error::shown(max_shift),
                    crate::error::shown((wide.abs() * 1.1 * 10.0).ceil() / 10.0),
                ),
            ));
        }
    }
    positions?;
    if offset.abs() > max_shift {
        return Err(Error::recording(
            rec.name.clone(),
            format!(
                "its clock is {offset:+.4} s off the plan of experiment '{}' (found in its positions), more than the {} s accepted: check that it is a run of this experiment, or raise max_shift (--max-shift)",
                experiment.kind.name(),
                crate::error::shown(max_shift)
            ),
        ));
    }
    Ok(offset)
}

/// Refuses a recording whose samples are too sparse for a window of `+-half` s to hold the
/// samples the fits need at its median sample interval (over at most 10,000 intervals),
/// with a word on the time's unit: a log stamped in milliseconds or nanoseconds reads as one
/// sample every second or every 10^6 s.
pub(super) fn check_sample_interval(rec: &Recording, half: f64, fit: &FitOptions) -> Result<()> {
    let stride = (rec.len() / 10_000).max(1);
    let mut dt: Vec<f64> = (stride..rec.len())
        .step_by(stride)
        .map(|i| rec.t[i] - rec.t[i - 1])
        .collect();
    if dt.is_empty() {
        return Ok(());
    }
    let mid = dt.len() / 2;
    let median = *dt.select_nth_unstable_by(mid, f64::total_cmp).1;
    let held = (2.0 * half / median).floor() + 1.0;
    let needed = samples_needed(fit);
    if held >= needed as f64 {
        return Ok(());
    }
    Err(Error::recording(
        rec.name.clone(),
        format!(
            "its median sample interval is {} s, so a crossing window of +-{} s holds at most {held} samples where the fits need {needed}: check that its times are in seconds (a log stamped in milliseconds or nanoseconds reads as a sample every second or every 10^6 s), or record faster, or widen the window",
            crate::error::shown(format!("{median:.3e}").parse().unwrap_or(median)),
            crate::error::shown(half),
        ),
    ))
}

/// How far a joint's recorded positions may stray from the plan on average once aligned (rad
/// or m). A robot that tracks its encoders stays far below (its tracking errors); positions in
/// degrees or columns in another order are far above.
const POSITION_MISFIT: f64 = 0.05;

/// How far the recorded motion may differ in shape from the planned one (the RMS of the
/// difference about its mean, rad or m): half the planned motion's RMS, or this, or two encoder
/// steps, whichever is more. A recording of another experiment, or of the robot at rest where
/// the plan moves it, differs by about the whole motion; a joint the plan barely moves must
/// still follow it to within its tracking errors.
const SHAPE_MISFIT: f64 = 0.01;

/// A joint the plan moves by at least this (RMS, rad or m) must move in its recording by at
/// least [`STILL_FRACTION`] of it: a slow plan's motion lies within [`SHAPE_MISFIT`], so a
/// recording of the robot standing still (or a dead encoder's constant reading) passed as a
/// run of the nominal passes at the paper's point, and T* came from wherever the clock search
/// placed the windows (32.9 N m for -1.19 at the base).
const STILL_MOTION: f64 = 1e-3;
/// See [`STILL_MOTION`]; a robot that tracks its plan moves about as much as planned.
const STILL_FRACTION: f64 = 0.25;

/// Whether a joint the plan moves stood still in the recording (`m`; `step` its encoder's
/// step, rad or m, or 0): see [`STILL_MOTION`].
fn still(m: &PositionMisfit, step: f64) -> bool {
    m.motion >= STILL_MOTION.max(4.0 * step) && m.recorded < STILL_FRACTION * m.motion
}

/// Whether a joint's recorded positions, `m` against the plan, are what a run of the plan shows
/// (its encoder's `step`, rad or m, or 0): within [`POSITION_MISFIT`] on average and within
/// [`SHAPE_MISFIT`], half the planned motion or two encoder steps (whichever is most) about
/// that, and moving where the plan moves it ([`STILL_MOTION`]).
pub(super) fn follows_plan(m: &PositionMisfit, step: f64) -> bool {
    let shape = SHAPE_MISFIT.max(0.5 * m.motion).max(2.0 * step);
    m.mean.abs() <= POSITION_MISFIT && m.shape <= shape && !still(m, step)
}

/// What a joint's misfit `m` says, for an error naming joint `name`.
pub(super) fn misfit_shown(name: &str, m: &PositionMisfit, step: f64) -> String {
    if still(m, step) {
        return format!(
            "'{name}' moved {:.4} RMS where the plan moves it {:.4} RMS (less than a quarter: not this run, or the robot standing still)",
            m.recorded, m.motion
        );
    }
    format!(
        "'{name}' {:+.3} off on average and {:.3} RMS about that, where the plan moves it {:.3} RMS",
        m.mean, m.shape, m.motion
    )
}

/// Refuses a recording whose positions do not follow `experiment`'s plan at the clock offset
/// found (`offset` s, the best within `+-searched` s), naming the joints.
fn check_positions(
    experiment: &Experiment,
    rec: &Recording,
    joint_names: &[String],
    steps: &[Option<f64>],
    (offset, searched): (f64, f64),
) -> Result<()> {
    let Some(misfit) = position_misfit(experiment, rec, offset) else {
        return Ok(());
    };
    let off: Vec<String> = misfit
        .iter()
        .enumerate()
        .filter(|(j, m)| !follows_plan(m, steps.get(*j).copied().flatten().unwrap_or(0.0)))
        .map(|(j, m)| {
            let name = joint_names
                .get(j)
                .cloned()
                .unwrap_or_else(|| format!("{}", j + 1));
            misfit_shown(&name, m, steps.get(j).copied().flatten().unwrap_or(0.0))
        })
        .collect();
    if off.is_empty() {
        return Ok(());
    }
    Err(Error::recording(
        rec.name.clone(),
        format!(
            "its positions do not follow the plan of experiment '{}' at any clock offset within +-{} s: at the best ({offset:+.4} s) the joints {} (rad or m), where a robot that tracks its encoders stays within {POSITION_MISFIT} on average and within half the planned motion about that, and moves about as much as planned: check that it is a run of this experiment (not of the robot standing still), that its columns follow the plan's joints ({}) and that its positions are in radians (metres for prismatic joints)",
            experiment.kind.name(),
            crate::error::shown(searched),
            off.join(", "),
            joint_names.join(", "),
        ),
    ))
}

/// Checks that `rec` can be a run of `experiment` with its clock within `max_shift` s of the
/// plan's (before the offset is sought): its time stamps must reach the plan's span, shifted
/// by at most `max_shift`. A log stamped in seconds since 1970 or since a controller booted
/// does not, and the error says how far apart they are.
pub fn check_clock(experiment: &Experiment, rec: &Recording, max_shift: f64) -> Result<()> {
    let (start, end) = (experiment.trajectory.start(), experiment.trajectory.end());
    let (first, last) = (rec.t[0], rec.t[rec.len() - 1]);
    if first - max_shift <= end && last + max_shift >= start {
        return Ok(());
    }
    let rounded = |v: f64| crate::error::shown((v * 1e3).round() / 1e3);
    Err(Error::recording(
        rec.name.clone(),
        format!(
            "its time stamps run from {} to {} s and experiment '{}' from {} to {} s of the plan's clock, {} s apart, more than the {} s of clock offset accepted: its time must count from the start of the experiment (subtract the time of the run's start, as for a log stamped in seconds since 1970 or since the controller started)",
            rounded(first),
            rounded(last),
            experiment.kind.name(),
            rounded(start),
            rounded(end),
            rounded(if first > end { first - end } else { start - last }),
            crate::error::shown(max_shift),
        ),
    ))
}

/// How far one joint's recorded positions stray from the planned ones (rad or m; see
/// [`position_misfit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionMisfit {
    /// The mean difference, recorded minus planned: where the joint was held off the plan.
    pub mean: f64,
    /// The RMS of the difference about its mean: how the recorded motion differs in shape.
    pub shape: f64,
    /// The RMS of the planned motion about its mean over the same samples.
    pub motion: f64,
    /// The RMS of the recorded positions about their mean over the same samples: how much the
    /// joint moved.
    pub recorded: f64,
}

/// Per joint, how far the recorded positions stray from `experiment`'s planned ones with the
/// recording's clock `offset` s ahead of the plan's, over the samples within the plan's span
/// (about 2,000 of them: however long the log, the run's own samples). `None`
/// when no sample lies within the plan's span.
pub fn position_misfit(
    experiment: &Experiment,
    rec: &Recording,
    offset: f64,
) -> Option<Vec<PositionMisfit>> {
    let n = rec.n;
    let traj = &experiment.trajectory;
    let (start, end) = (traj.start(), traj.end());
    let mut diff: Vec<Vec<f64>> = vec![vec![]; n];
    let mut planned: Vec<Vec<f64>> = vec![vec![]; n];
    let mut recorded: Vec<Vec<f64>> = vec![vec![]; n];
    for i in span_rows(experiment, rec, offset, 2_000) {
        let tp = (rec.t[i] - offset).clamp(start, end);
        let seg = traj.segment_at(tp);
        for j in 0..n {
            let q = seg.eval(j, tp).0;
            diff[j].push(rec.q[i * n + j] - q);
            planned[j].push(q);
            recorded[j].push(rec.q[i * n + j]);
        }
    }
    if diff[0].is_empty() {
        return None;
    }
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let spread = |x: &[f64]| {
        let m = mean(x);
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
    };
    Some(
        (0..n)
            .map(|j| PositionMisfit {
                mean: mean(&diff[j]),
                shape: spread(&diff[j]),
                motion: spread(&planned[j]),
                recorded: spread(&recorded[j]),
            })
            .collect(),
    )
}

/// The offsets `d` (s) at which some sample of `rec` falls within `experiment`'s plan
/// (`rec.t - d` meets its span): the widest range worth searching.
pub fn overlap_offsets(experiment: &Experiment, rec: &Recording) -> (f64, f64) {
    let traj = &experiment.trajectory;
    (rec.t[0] - traj.end(), rec.t[rec.len() - 1] - traj.start())
}

/// The offsets `d` (s) at which `rec` holds every window of `experiment` (its crossings' and
/// reference posture's, `+-window` s about their planned times plus `d`): where a run could be
/// read whole. `None` when the recording is too short for any.
pub fn covering_offsets(experiment: &Experiment, rec: &Recording) -> Option<(f64, f64)> {
    let times = experiment
        .crossings
        .iter()
        .chain(&experiment.reference)
        .map(|c| c.time);
    let lo = times.clone().fold(f64::INFINITY, f64::min) - experiment.window;
    let hi = times.fold(f64::NEG_INFINITY, f64::max) + experiment.window;
    let range = (rec.t[0] - lo, rec.t[rec.len() - 1] - hi);
    (range.0 <= range.1).then_some(range)
}

/// The largest clock offset, as a fraction of the reading window's half-width, taken for a
/// closed-loop controller's lag behind its reference ([`lagged_half`]).
pub const LAG_FRACTION: f64 = 0.1;

/// The half-width (s) of the reading windows of a recording whose positions follow the plan
/// `offset` s late (or early), at sample interval `dt` s: `half` less the offset in whole
/// samples where it is at most [`LAG_FRACTION`] of `half`, `half` otherwise. A robot in closed
/// loop lags its reference by a few milliseconds, but its commanded torque, and so its
/// acceleration, turns into the next transition at the planned segment's end: a window centred
/// on the lagged crossing would reach past that kink (on the A465 at 400 N m/rad, 2 ms in: its
/// last samples taken for glitches in 11 windows of 12). A larger offset is the log's clock,
/// which shifts torques and positions alike.
pub fn lagged_half(half: f64, offset: f64, dt: f64) -> f64 {
    let lag = offset.abs();
    if !(lag <= LAG_FRACTION * half && dt > 0.0) {
        return half;
    }
    half - (lag / dt).floor() * dt
}
