//! Glitches in a whole log, found and replaced before preprocessing (docs/method.md, section
//! 7): a sample of one signal far off the smooth curve its neighbours follow (a corrupted or
//! dropped message read as zeros, a sensor's spike, an encoder's missed count). Without the
//! screening, one position sample of the A465's excitation log off by 0.05 rad moved the
//! direct method's base parameters by 12 of their standard errors, a row of positions read as
//! zeros by 450, and a torque of 1e300 ended the fit with an overflow, all silently; the
//! low-pass filter spreads a glitch over its neighbours rather than removing it.
//!
//! Each column (a joint's `q`, `qd`, `qdd` when logged, `tau`) is screened on its own, in two
//! passes:
//! 1. **Candidates.** A sample's difference from the straight line through its two neighbours
//!    (in time), against the column's robust level of that difference: samples beyond
//!    [`CANDIDATE_LEVELS`] of it, and their neighbours within two samples (the inner samples
//!    of a short burst sit on the line through their own kind).
//! 2. **Judgement.** Each candidate is judged in the window of [`HALF_WINDOW`] samples either
//!    side of it (shifted inside the log at its ends; never across a gap), against a cubic in
//!    time, by [`crate::logs::outliers::screen`]: it is a glitch when its studentised residual is more
//!    than [`NOISE_LEVELS`] robust noise levels off the fit of the others, and at most
//!    [`MAX_PER_WINDOW`] samples of its window are. The level is the window's own, with the
//!    candidate left out, and at least the column's median level over evenly spread windows,
//!    the rounding of a grid the column lies on, and 1e-8 of its largest value.
//!
//! A glitch is replaced by the fit of the others in its window, as if it had not been logged.
//! A step the signal really makes (Coulomb friction at a velocity reversal, an impact) puts
//! many samples of the windows around it off any cubic: their noise level rises, or more than
//! [`MAX_PER_WINDOW`] are off, and nothing is replaced. A sample is only judged in the window
//! centred on it, so a step near a window's edge is never taken for a glitch.
//!
//! **Held readings** are the bursts one sensor makes when its message is lost and its last
//! value (or zeros) is logged in its place: a run of 2 to [`MAX_HELD`] exactly repeated values
//! of one column while its joint moves is judged as a whole against the cubic through the
//! samples either side of it (`judge_run`), and replaced as a whole when off by more than
//! [`NOISE_LEVELS`] (its farthest sample, or its mean against the standard error of that
//! mean). Rows of zeros for every joint of a signal are left to [`crate::logs::log_dropouts::find_dropouts`], and rows
//! that repeat the whole row before to the rule for stale rows below.
//!
//! What is not found: other bursts of more than [`MAX_PER_WINDOW`] samples (masked: see
//! docs/limits.md), held runs longer than [`MAX_HELD`] (those that end with a jump are
//! frozen readings, removed with their rows: [`crate::logs::frozen_readings`]), and a log's repeated rows (a logger that writes its last message again:
//! the real Panda log of `../shared` repeats 6 % of its rows; replacing them moved the direct
//! method's parameters by 0.02 standard errors, so they are left as logged unless a repeated
//! position is itself far off, then it is a glitch like any other).

use nalgebra::{DMatrix, DVector};

use crate::error::{shown, Result};
pub use crate::logs::findings::log_screening::*;

/// How many evenly spread windows of a column give its median noise level (the floor of every
/// window's level).
const LEVEL_WINDOWS: usize = 400;

/// A candidate whose studentised residual from the fit of its whole window is below this
/// fraction of [`NOISE_LEVELS`] times its column's floor is not screened further: screening
/// divides by a level at least that floor, and leaving other glitches of the window out
/// could only raise the residual that far where they happened to cancel it.
const QUICK_LOOK: f64 = 0.3;
use crate::logs::outliers::{screen, Screened, MAX_PER_WINDOW, NOISE_LEVELS};
use crate::logs::recording::Recording;

/// Screens every column of `rec` for glitches (see the module documentation) and returns the
/// recording with them replaced, and the glitches in log order (by sample, then signal and
/// joint). Windows never span a gap longer than
/// [`MAX_GAP_INTERVALS`](crate::limits::MAX_GAP_INTERVALS) median sample intervals; a stretch
/// between gaps shorter than one window is not screened. Stops on Ctrl-C.
pub fn screen_recording(rec: &Recording) -> Result<(Recording, Vec<LogGlitch>)> {
    screen_log(rec, false)
}

/// The held readings of `rec` alone (see the module documentation), found and replaced as by
/// [`screen_recording`]: for the local method, whose crossing windows screen single glitches
/// with their own fits. Stops on Ctrl-C.
pub fn screen_held_readings(rec: &Recording) -> Result<(Recording, Vec<LogGlitch>)> {
    screen_log(rec, true)
}

/// [`screen_recording`], or with `held_only` [`screen_held_readings`].
fn screen_log(rec: &Recording, held_only: bool) -> Result<(Recording, Vec<LogGlitch>)> {
    let n = rec.n;
    let signals = signals(rec);
    let mut found = vec![];
    for (a, b) in segments(rec) {
        let columns: Vec<Vec<f64>> = signals
            .iter()
            .flat_map(|(_, v)| (0..n).map(move |j| (a..b).map(|i| v[i * n + j]).collect()))
            .collect();
        let names: Vec<&str> = signals.iter().map(|(s, _)| *s).collect();
        for (c, k, g) in screen_segment(&rec.t[a..b], &columns, &names, held_only)? {
            let (signal, values) = signals[c / n];
            let (j, i) = (c % n, a + k);
            found.push(LogGlitch {
                signal: signal.to_string(),
                joint: j,
                sample: i,
                time: rec.t[i],
                value: values[i * n + j],
                noise_levels: Some(g.noise_levels).filter(|z| z.is_finite()),
                replaced_by: g.replaced_by,
                repeats_previous: i > 0 && values[i * n + j] == values[(i - 1) * n + j],
                held: g.held,
                experiment: None,
            });
        }
    }
    let mut out = rec.clone();
    for g in &found {
        let column = match g.signal.as_str() {
            "q" => &mut out.q,
            "qd" => out.qd.as_mut().expect("screened"),
            "qdd" => out.qdd.as_mut().expect("screened"),
            _ => &mut out.tau,
        };
        column[g.sample * n + g.joint] = g.replaced_by;
    }
    Ok((out, found))
}

/// The signals `rec` has (its columns, row-major), by their column prefix.
pub(crate) fn signals(rec: &Recording) -> Vec<(&'static str, &Vec<f64>)> {
    [
        Some(&rec.q),
        rec.qd.as_ref(),
        rec.qdd.as_ref(),
        Some(&rec.tau),
    ]
    .into_iter()
    .zip(SIGNALS)
    .filter_map(|(v, s)| v.map(|v| (s, v)))
    .collect()
}

/// The stretches `[a, b)` of `rec`'s samples between gaps.
pub(crate) fn segments(rec: &Recording) -> Vec<(usize, usize)> {
    let mut bounds = vec![0];
    bounds.extend(crate::logs::gaps::gap_positions(rec).iter().map(|&i| i + 1));
    bounds.push(rec.len());
    bounds.windows(2).map(|w| (w[0], w[1])).collect()
}

/// A glitch of one column: how far off, and the value it is replaced by.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Found {
    noise_levels: f64,
    replaced_by: f64,
    held: Option<usize>,
}

/// The median of the finite values of `x` (None for none).
pub(crate) fn median(mut x: Vec<f64>) -> Option<f64> {
    x.retain(|v| v.is_finite());
    if x.is_empty() {
        return None;
    }
    let mid = x.len() / 2;
    Some(*x.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// The candidates of one column `y` sampled at `t` (see the module documentation).
pub(crate) fn candidates(t: &[f64], y: &[f64]) -> Vec<bool> {
    let k = y.len();
    let mut e = vec![0.0; k];
    for i in 1..k - 1 {
        let s = (t[i] - t[i - 1]) / (t[i + 1] - t[i - 1]);
        e[i] = y[i] - (y[i - 1] + s * (y[i + 1] - y[i - 1]));
    }
    e[0] = e[1];
    e[k - 1] = e[k - 2];
    let level = median(e.iter().map(|x| x.abs()).collect()).unwrap_or(0.0) * 1.4826;
    let far = |x: f64| !x.is_finite() || x.abs() > CANDIDATE_LEVELS * level;
    let mut candidate = vec![false; k];
    for i in (0..k).filter(|&i| far(e[i])) {
        for c in &mut candidate[i.saturating_sub(2)..(i + 3).min(k)] {
            *c = true;
        }
    }
    candidate
}

/// The glitches of the `columns` (each sampled at `t`: one stretch between gaps; the joints of
/// each of the `signals` in turn, `q` first) as (column, index, glitch), in index order; with
/// `held_only`, the held readings alone. Each window's basis is built once for all columns.
fn screen_segment(
    t: &[f64],
    columns: &[Vec<f64>],
    signals: &[&str],
    held_only: bool,
) -> Result<Vec<(usize, usize, Found)>> {
    let k = t.len();
    let width = 2 * HALF_WINDOW + 1;
    if k < width {
        return Ok(vec![]);
    }
    let candidate: Vec<Vec<bool>> = columns.iter().map(|y| candidates(t, y)).collect();
    let judged: Vec<usize> = if held_only {
        vec![]
    } else {
        (0..k).filter(|&i| candidate.iter().any(|c| c[i])).collect()
    };
    let runs = held_runs(columns, signals);
    if judged.is_empty() && runs.is_empty() {
        return Ok(vec![]);
    }
    let window = |i: usize| {
        let a = i.saturating_sub(HALF_WINDOW).min(k - width);
        a..a + width
    };
    let floors = floors(t, columns, &candidate);
    // each candidate judged in its own window
    let mut found = vec![];
    for (done, &i) in judged.iter().enumerate() {
        if done % 1000 == 999 {
            crate::interrupt::check("screening the log for glitches")?;
        }
        let r = window(i);
        let Some((v, w)) = basis(&t[r.clone()], t[i]) else {
            continue;
        };
        let at = i - r.start;
        // the sample's leverage in its window, for the quick look below
        let h: f64 = (0..=DEGREE).map(|d| v[(at, d)] * w[(d, at)]).sum();
        for (c, y) in columns.iter().enumerate().filter(|(c, _)| candidate[*c][i]) {
            let y = &y[r.clone()];
            // a quick look: the sample's residual from the fit of the whole window, studentised;
            // screening cannot find it a glitch unless this is far above the level's floor
            let fit: f64 = (0..=DEGREE)
                .map(|d| v[(at, d)] * (0..width).map(|m| w[(d, m)] * y[m]).sum::<f64>())
                .sum();
            let studentised = (y[at] - fit).abs() / (1.0 - h).max(1e-12).sqrt();
            if studentised < QUICK_LOOK * NOISE_LEVELS * floors[c] {
                continue;
            }
            let s: Screened = screen(&v, &w, y, floors[c]);
            if !s.isolated {
                continue;
            }
            if let Some(f) = s.flagged.iter().find(|f| f.index == at) {
                let g = Found {
                    noise_levels: f.noise_levels,
                    replaced_by: s.values[at],
                    held: None,
                };
                found.push((c, i, g));
            }
        }
    }
    let single: std::collections::HashSet<(usize, usize)> =
        found.iter().map(|f| (f.0, f.1)).collect();
    for (c, run) in runs {
        crate::interrupt::check("screening the log for held readings")?;
        for (i, g) in judge_run(t, &columns[c], run, floors[c]) {
            if !single.contains(&(c, i)) {
                found.push((c, i, g));
            }
        }
    }
    found.sort_by_key(|f| f.1);
    Ok(found)
}

/// Per column of `columns` (each sampled at `t`, one stretch between gaps, of at least one
/// window), the floor of its windows' noise levels: the rounding of a grid it lies on, 1e-8 of
/// its largest value, and its median level over [`LEVEL_WINDOWS`] evenly spread windows (each
/// against its cubic). `candidate` marks, per column, the samples [`candidates`] found, left
/// out of the grid and the size.
pub(crate) fn floors(t: &[f64], columns: &[Vec<f64>], candidate: &[Vec<bool>]) -> Vec<f64> {
    let k = t.len();
    let width = 2 * HALF_WINDOW + 1;
    if k < width {
        return vec![f64::MIN_POSITIVE; columns.len()];
    }
    let window = |i: usize| {
        let a = i.saturating_sub(HALF_WINDOW).min(k - width);
        a..a + width
    };
    // the floor of every window's level: the rounding of a grid, a tiny fraction of the
    // column's size, and its median level over evenly spread windows
    let spread = (k / LEVEL_WINDOWS).max(1);
    let mut levels: Vec<Vec<f64>> = vec![vec![]; columns.len()];
    for i in (HALF_WINDOW..k - HALF_WINDOW).step_by(spread) {
        let r = window(i);
        if let Some((v, w)) = basis(&t[r.clone()], t[i]) {
            for (c, y) in columns.iter().enumerate() {
                levels[c].push(crate::logs::outliers::level(&v, &w, &y[r.clone()]));
            }
        }
    }
    columns
        .iter()
        .zip(candidate)
        .zip(levels)
        .map(|((y, cand), levels)| {
            let ordinary: Vec<f64> = (0..k).filter(|&i| !cand[i]).map(|i| y[i]).collect();
            let size = ordinary.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let step = crate::signal::grid_step(&ordinary).unwrap_or(0.0);
            median(levels)
                .unwrap_or(0.0)
                .max(step / 12f64.sqrt())
                .max(1e-8 * size)
                .max(f64::MIN_POSITIVE)
        })
        .collect()
}

/// The floor of one column `y` sampled at `t` ([`floors`], its candidates found first).
pub(crate) fn column_floor(t: &[f64], y: &[f64]) -> f64 {
    floors(t, &[y.to_vec()], &[candidates(t, y)])[0]
}

/// Fewest samples of the others on each side of a held run for its judgement: the cubic
/// through them interpolates the run and never extrapolates (and twice as many after it, whose
/// own cubic tells whether the run ends with a jump).
pub(crate) const HELD_SIDE: usize = DEGREE + 1;

/// The runs of 2 to [`MAX_HELD`] exactly repeated readings in each column (as (column, first
/// index..end)) while its joint moves: for `qd`, `qdd` and `tau` the joint's position changes
/// within the run (a joint at rest reads its velocity, acceleration and torque again
/// legitimately); for `q`, its logged velocity is not 0 throughout the run (always judged
/// where no velocity is logged; the others' fit shows a real stop).
fn held_runs(columns: &[Vec<f64>], signals: &[&str]) -> Vec<(usize, std::ops::Range<usize>)> {
    let n = columns.len() / signals.len().max(1);
    let qd = signals.iter().position(|&s| s == "qd");
    // rows that repeat the row before in every column: a logger's stale rows (see the module
    // documentation), not one sensor's held reading
    let len = columns.first().map_or(0, Vec::len);
    let stale: Vec<bool> = (0..len)
        .map(|i| i > 0 && columns.iter().all(|y| y[i].to_bits() == y[i - 1].to_bits()))
        .collect();
    let mut runs = vec![];
    for (c, y) in columns.iter().enumerate() {
        let j = c % n;
        let mut next = 0;
        while next < y.len() {
            let a = next;
            while next < y.len() && y[next].to_bits() == y[a].to_bits() {
                next += 1;
            }
            let b = next;
            if !(2..=MAX_HELD).contains(&(b - a)) {
                continue;
            }
            let moves = match signals[c / n] {
                "q" => qd.is_none_or(|s| columns[s * n + j][a..b].iter().any(|&v| v != 0.0)),
                _ => columns[j][a] != columns[j][b - 1],
            };
            // rows in which every joint of the signal reads 0 are a dropout's, removed
            let signal = (c / n) * n..(c / n + 1) * n;
            let dropout = y[a] == 0.0
                && columns[signal]
                    .iter()
                    .all(|z| z[a..b].iter().all(|&x| x == 0.0));
            let repeated_rows = stale[a + 1..b].iter().all(|&s| s);
            if moves && !dropout && !repeated_rows {
                runs.push((c, a..b));
            }
        }
    }
    runs
}

/// The samples of the held `run` of `y` (sampled at `t`) that are glitches: judged against the
/// cubic through up to [`HALF_WINDOW`] samples either side of it (at least [`HELD_SIDE`] on
/// each), by [`NOISE_LEVELS`] of their noise level (at least `floor`) with the prediction's own
/// uncertainty. The others must be smooth themselves (at most [`MAX_PER_WINDOW`] glitches of
/// their own, left out of the fit): a step the signal really makes near the run leaves it
/// alone. And the run must end with a jump: its last sample beyond [`NOISE_LEVELS`] of the
/// cubic through the samples after it, extrapolated one sample back (a signal levelling off,
/// as a joint's torque does when it arrives at rest, continues from its last sample).
fn judge_run(t: &[f64], y: &[f64], run: std::ops::Range<usize>, floor: f64) -> Vec<(usize, Found)> {
    let before = run.start.saturating_sub(HALF_WINDOW)..run.start;
    let after = run.end..(run.end + HALF_WINDOW).min(y.len());
    if before.len() < HELD_SIDE || after.len() < HELD_SIDE {
        return vec![];
    }
    let others: Vec<usize> = before.chain(after).collect();
    let tc = 0.5 * (t[run.start] + t[run.end - 1]);
    let times: Vec<f64> = others.iter().map(|&i| t[i]).collect();
    let Some((v, w)) = basis(&times, tc) else {
        return vec![];
    };
    let values: Vec<f64> = others.iter().map(|&i| y[i]).collect();
    let s = screen(&v, &w, &values, floor);
    if !s.isolated {
        return vec![];
    }
    let level = crate::logs::outliers::level(&v, &w, &s.values).max(floor);
    let coef = &w * DVector::from_column_slice(&s.values);
    let half = times.iter().fold(0.0f64, |m, x| m.max((x - tc).abs()));
    // (V^T V)^-1 = W W^T: the fit's variance at new times, in units of the noise's
    let covariance = &w * w.transpose();
    let row = |i: usize| DVector::from_fn(DEGREE + 1, |d, _| ((t[i] - tc) / half).powi(d as i32));
    let fits: Vec<f64> = run.clone().map(|i| row(i).dot(&coef)).collect();
    if !fits.iter().all(|f| f.is_finite()) {
        return vec![];
    }
    // each sample against the fit, and the run's mean deviation against its own spread
    let farthest = run
        .clone()
        .zip(&fits)
        .map(|(i, fit)| {
            let x = row(i);
            (y[i] - fit).abs() / (level * (1.0 + (x.transpose() * &covariance * &x)[0]).sqrt())
        })
        .fold(
            0.0,
            |m: f64, z| if z.is_nan() { f64::INFINITY } else { m.max(z) },
        );
    let length = run.len() as f64;
    let mean_row = run.clone().map(row).sum::<DVector<f64>>() / length;
    let mean = run
        .clone()
        .zip(&fits)
        .map(|(i, fit)| y[i] - fit)
        .sum::<f64>()
        / length;
    let spread =
        level * (1.0 / length + (mean_row.transpose() * &covariance * &mean_row)[0]).sqrt();
    // NaN where the deviations overflow: beyond any scale
    let z = match mean.abs() / spread {
        by_mean if by_mean.is_nan() => f64::INFINITY,
        by_mean => farthest.max(by_mean),
    };
    if z <= NOISE_LEVELS {
        return vec![];
    }
    // a held reading ends with a jump back to the signal when the sensor reads again: its last
    // sample is off the cubic through the samples after it, extrapolated one sample back. A
    // signal that really levels off (a joint arriving at rest: a kink the two-sided cubic
    // cannot follow) continues from its last sample and is left alone.
    if end_jump(t, y, run.end - 1, level).is_none_or(|jump| jump <= NOISE_LEVELS) {
        return vec![];
    }
    let held = Some(run.len());
    run.zip(fits)
        .map(|(i, fit)| {
            let found = Found {
                noise_levels: z,
                replaced_by: fit,
                held,
            };
            (i, found)
        })
        .collect()
}

/// How far the sample `y[last]` (sampled at `t`) is off the cubic through the samples after
/// it (up to [`HALF_WINDOW`], at least `2 HELD_SIDE`), extrapolated one sample back: in noise
/// levels (the fit's own, at least `level`), with the extrapolation's uncertainty; infinite
/// where the difference overflows. None where fewer samples follow, or their times do not
/// span a cubic. The last sample of a held or frozen reading is far off: the signal jumps
/// back when the sensor reads again.
pub(crate) fn end_jump(t: &[f64], y: &[f64], last: usize, level: f64) -> Option<f64> {
    let after: Vec<usize> = (last + 1..(last + 1 + HALF_WINDOW).min(y.len())).collect();
    if after.len() < 2 * HELD_SIDE {
        return None;
    }
    let t_after: Vec<f64> = after.iter().map(|&i| t[i]).collect();
    let y_after: Vec<f64> = after.iter().map(|&i| y[i]).collect();
    let (va, wa) = basis(&t_after, t[last])?;
    // the basis is in powers of the time from t[last]: there the fit is the constant's
    // coefficient, and its variance (in units of the noise's) that coefficient's
    let back: f64 = (0..after.len()).map(|m| wa[(0, m)] * y_after[m]).sum();
    let variance: f64 = (0..after.len()).map(|m| wa[(0, m)].powi(2)).sum();
    let level_after = crate::logs::outliers::level(&va, &wa, &y_after).max(level);
    let jump = (y[last] - back).abs() / (level_after * (1.0 + variance).sqrt());
    Some(if jump.is_nan() { f64::INFINITY } else { jump })
}

/// The cubic basis of a window at times `t` about `tc`, scaled to [-1, 1], and its
/// least-squares weights (`(V^T V)^-1 V^T` by Cholesky: the scaled cubic is well
/// conditioned); None where the times do not span a cubic.
pub(crate) fn basis(t: &[f64], tc: f64) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let half = t.iter().fold(0.0f64, |m, x| m.max((x - tc).abs()));
    if !(half > 0.0 && half.is_finite()) {
        return None;
    }
    let v = DMatrix::from_fn(t.len(), DEGREE + 1, |r, d| {
        ((t[r] - tc) / half).powi(d as i32)
    });
    let w = v.tr_mul(&v).cholesky()?.solve(&v.transpose());
    w.iter().all(|x| x.is_finite()).then_some((v, w))
}

/// A joint in a warning: its name quoted, or `joint 3` for index 2 where `joint_names` has none.
pub(crate) fn joint_called(joint_names: &[String], joint: usize) -> String {
    joint_names
        .get(joint)
        .map_or_else(|| format!("joint {}", joint + 1), |j| format!("'{j}'"))
}

/// The unit of a signal in messages.
pub(crate) fn unit(signal: &str) -> &'static str {
    match signal {
        "q" => "rad",
        "qd" => "rad/s",
        "qdd" => "rad/s^2",
        _ => "N m",
    }
}

/// How many glitches a warning lists before "and N more".
pub(crate) const LISTED: usize = 5;

/// What [`warning`] says the glitches were replaced before, for a whole log.
pub const BEFORE_PREPROCESSING: &str = "before preprocessing";

/// The warning that tells of the glitches `found` in the log `recording` (None for none),
/// replaced `before` what (such as [`BEFORE_PREPROCESSING`]); `joint_names` name the joints by
/// index (where it has none, `joint 3` names index 2).
pub fn warning(
    found: &[LogGlitch],
    recording: &str,
    joint_names: &[String],
    before: &str,
) -> Option<String> {
    if found.is_empty() {
        return None;
    }
    // a held reading is listed once, by its first sample
    let first_of_run = |g: &LogGlitch| {
        g.held.is_none()
            || !found.iter().any(|h| {
                h.held.is_some()
                    && (&h.signal, h.joint) == (&g.signal, g.joint)
                    && h.sample + 1 == g.sample
            })
    };
    let items: Vec<&LogGlitch> = found.iter().filter(|g| first_of_run(g)).collect();
    let mut listed: Vec<String> = items
        .iter()
        .take(LISTED)
        .map(|g| {
            let joint = joint_called(joint_names, g.joint);
            let off = g
                .noise_levels
                .map_or("off beyond any scale".to_string(), |z| {
                    format!("{z:.0} noise levels off")
                });
            let (read, samples) = match g.held {
                Some(l) => (
                    "held",
                    format!("samples {} to {}", g.sample, g.sample + l - 1),
                ),
                None => ("read", format!("sample {}", g.sample)),
            };
            format!(
                "{} of {joint} at t = {:.4} s ({samples}) {read} {} {}, {off}",
                g.signal,
                g.time,
                shown(g.value),
                unit(&g.signal)
            )
        })
        .collect();
    if items.len() > LISTED {
        listed.push(format!("and {} more", items.len() - LISTED));
    }
    let single = found.iter().filter(|g| g.held.is_none()).count();
    let runs = items.len() - single;
    let mut kinds = vec![];
    if single > 0 {
        let repeated = found
            .iter()
            .filter(|g| g.held.is_none() && g.repeats_previous)
            .count();
        let stale = if repeated > 0 {
            format!(" ({repeated} of them repeat the sample before exactly: stale samples of a logger that wrote its last message again with a new time stamp; such repeats that stay near the curve are kept as logged)")
        } else {
            String::new()
        };
        kinds.push(format!(
            "{single} sample(s) each alone in its window of {} samples beyond {NOISE_LEVELS} noise levels of the cubic through the others (at most {MAX_PER_WINDOW} such in a window){stale}",
            2 * HALF_WINDOW + 1
        ));
    }
    if runs > 0 {
        kinds.push(format!(
            "{} sample(s) of {runs} held reading(s), a column that repeats one value for 2 to {MAX_HELD} samples while its joint moves, beyond {NOISE_LEVELS} noise levels of the cubic through up to {HALF_WINDOW} samples either side (a sensor's message lost and its last value or zeros logged in its place)",
            found.len() - single
        ));
    }
    Some(format!(
        "log '{recording}': {} were taken for glitches of the log and replaced by that fit {before}: {}",
        kinds.join(", and "),
        listed.join("; ")
    ))
}
