//! The offset between a recording's clock and its plan's, found in the positions (docs/method.md,
//! section 7): a grid over the offsets fine enough for motion that repeats, on the plan's span
//! read the same however long the log, and its lowest minima refined by Gauss-Newton.

use super::plan::Experiment;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// The coarsest grid over the offsets (s): the nominal passes go back and forth every 0.3 s
/// at the paper's point, so a grid of `max_shift / 200` over a tolerance raised to 118 s (a
/// run 107 s into a session log) stepped 0.6 s, fell into the valley four repetitions early,
/// and the run was identified from windows 1.2 s off.
const FINE_STEP: f64 = 0.02;
/// The most offsets on the grid (a search over 4,000 s at [`FINE_STEP`]).
const MAX_OFFSETS: usize = 200_000;
/// The grid's lowest local minima refined: a repetition early or late fits nearly as well
/// as the run where its ends fall on rest, and the grid's nearest offset to the true one can
/// cost more than its nearest to a repetition's. A session log, where other experiments' runs
/// pass the same point, has twice as many refined ([`search_offset`]'s `candidates`).
pub(super) const CANDIDATES: usize = 8;

/// The time offset `d` (s, within `+-max_shift`) such that the recording at `t` follows the
/// plan at `t - d`: least squares over positions, a grid search at a resolution of
/// `max_shift / 200` or 20 ms, whichever is finer, on 256 times over the plan's span,
/// its lowest minima refined by Gauss-Newton on about 2,000 samples each and the best of them
/// on about 20,000 (sub-sample: exact on noise-free data).
pub fn detect_offset(experiment: &Experiment, rec: &Recording, max_shift: f64) -> Result<f64> {
    if !(max_shift.is_finite() && max_shift > 0.0) {
        return Err(Error::invalid(
            "max_shift",
            format!("{max_shift}; expected a positive number of seconds"),
        ));
    }
    Ok(detect_offset_in(experiment, rec, -max_shift, max_shift, 200).0)
}

/// The planned positions of `experiment` at [`SPAN_SAMPLES`] times evenly over its span, to
/// compare a log with at any offset ([`SpanGrid::cost`]).
struct SpanGrid {
    /// The plan's times (s).
    t: Vec<f64>,
    /// Row-major `t.len() x n` planned positions (rad or m).
    q: Vec<f64>,
}

/// The plan's samples in [`SpanGrid`]: every 15 ms over the A465's 3.8 s nominal (its passes
/// go back and forth every 0.3 s).
const SPAN_SAMPLES: usize = 256;

impl SpanGrid {
    fn new(experiment: &Experiment, n: usize) -> Self {
        let traj = &experiment.trajectory;
        let (start, end) = (traj.start(), traj.end());
        let step = (end - start) / (SPAN_SAMPLES - 1) as f64;
        let t: Vec<f64> = (0..SPAN_SAMPLES)
            .map(|s| (start + s as f64 * step).min(end))
            .collect();
        let q = t
            .iter()
            .flat_map(|&tp| {
                let seg = traj.segment_at(tp);
                (0..n).map(move |j| seg.eval(j, tp).0)
            })
            .collect();
        Self { t, q }
    }

    /// The squared differences between `rec`'s positions at the plan's times plus `d` s
    /// (linearly interpolated between samples; its first or last sample's outside the log)
    /// and the planned ones, taken about each joint's mean difference, averaged over the times
    /// and summed over the joints (rad^2 or m^2). Centred, because a constant offset (an
    /// encoder's zero, or a joint held off the plan, which is checked after) carries no timing
    /// and would otherwise pull the offset towards where the difference's mean is smallest.
    /// The plan's span is read
    /// the same however long the log: a run in a session log of minutes was compared on the
    /// few of 250 samples spread over the whole log that fell within it, and an offset that
    /// leaves the plan's motion outside the log compares that motion with the log's end, not
    /// rest with rest.
    fn cost(&self, rec: &Recording, d: f64) -> f64 {
        let n = rec.n;
        let (mut sum, mut sq) = (vec![0.0; n], vec![0.0; n]);
        let last = rec.len() - 1;
        let mut i = 0;
        for (s, &tp) in self.t.iter().enumerate() {
            let at = tp + d;
            // a galloping search on from the previous time's sample: a few steps between
            // neighbouring times however densely the log is sampled, log2 of the log's
            // length to the first
            let rest = &rec.t[i..];
            let mut bound = 1;
            while bound < rest.len() && rest[bound] <= at {
                bound *= 2;
            }
            i += rest[..bound.min(rest.len())].partition_point(|&t| t <= at);
            // rec.t[i - 1] <= at < rec.t[i], or beyond either end
            let (a, b, w) = if i == 0 {
                (0, 0, 0.0)
            } else if i > last {
                (last, last, 0.0)
            } else {
                let span = rec.t[i] - rec.t[i - 1];
                (i - 1, i, (at - rec.t[i - 1]) / span)
            };
            for j in 0..n {
                let (qa, qb) = (rec.q[a * n + j], rec.q[b * n + j]);
                let e = qa + w * (qb - qa) - self.q[s * n + j];
                sum[j] += e;
                sq[j] += e * e;
            }
        }
        let count = self.t.len() as f64;
        (0..n).map(|j| sq[j] - sum[j] * sum[j] / count).sum::<f64>() / count
    }
}

/// The mean squared difference between `rec`'s positions and `experiment`'s planned ones with
/// the plan placed `d` s into the log, about each joint's mean difference, summed over the
/// joints (rad^2 or m^2), on 256 times over the plan's span: the cost [`detect_offset_in`]
/// minimises, comparable between experiments.
pub(super) fn span_cost(experiment: &Experiment, rec: &Recording, d: f64) -> f64 {
    SpanGrid::new(experiment, rec.n).cost(rec, d)
}

/// [`detect_offset`] over `[lo, hi]` (s, `lo <= hi`), with a grid of at least
/// `2 half_points + 1` offsets and at most 20 ms apart (at most 200,001) before the refinement
/// of its 8 lowest local minima; also returns the cost at the offset found (the positions'
/// squared differences about each joint's mean, averaged over 256 times evenly over the plan's
/// span and summed over the joints, rad^2 or m^2), to compare searches.
pub fn detect_offset_in(
    experiment: &Experiment,
    rec: &Recording,
    lo: f64,
    hi: f64,
    half_points: usize,
) -> (f64, f64) {
    let unchecked = || Ok::<(), std::convert::Infallible>(());
    match search_offset(
        experiment,
        rec,
        (lo, hi),
        half_points,
        CANDIDATES,
        unchecked,
    ) {
        Ok(found) => found,
        Err(never) => match never {},
    }
}

/// [`detect_offset_in`] over `lo..hi` (s), its grid's `candidates` lowest minima refined, the
/// cost divided by the plan times compared (the mean squared difference per sample, summed over
/// the joints: rad^2 or m^2, comparable between experiments); `check` is called every 1,024
/// offsets on the grid and before each refinement, and its error ends the search (Ctrl-C).
pub(super) fn search_offset<E>(
    experiment: &Experiment,
    rec: &Recording,
    (lo, hi): (f64, f64),
    half_points: usize,
    candidates: usize,
    mut check: impl FnMut() -> std::result::Result<(), E>,
) -> std::result::Result<(f64, f64), E> {
    let grid = SpanGrid::new(experiment, rec.n);
    let width = hi - lo;
    if width.is_nan() || width <= 0.0 {
        let d = 0.5 * (lo + hi);
        return Ok((d, grid.cost(rec, d)));
    }
    let points =
        (2 * half_points.max(1)).max((width / FINE_STEP).ceil().min(MAX_OFFSETS as f64) as usize);
    let step = width / points as f64;
    let mut costs = Vec::with_capacity(points + 1);
    for g in 0..=points {
        if g % 1024 == 0 {
            check()?;
        }
        costs.push(grid.cost(rec, lo + g as f64 * step));
    }
    // the local minima, lowest first (a plateau's first point)
    let mut minima: Vec<usize> = (0..=points)
        .filter(|&g| {
            (g == 0 || costs[g] < costs[g - 1]) && (g == points || costs[g] <= costs[g + 1])
        })
        .collect();
    minima.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
    // each candidate refined on fewer samples to rank them, the best one then on more
    let bounds = |d0: f64| ((d0 - step).max(lo), (d0 + step).min(hi));
    let mut best = (
        lo + minima.first().copied().unwrap_or(0) as f64 * step,
        f64::INFINITY,
    );
    for &g in minima.iter().take(candidates) {
        check()?;
        let d0 = lo + g as f64 * step;
        let d = refine(experiment, rec, d0, bounds(d0), RANK_SAMPLES);
        let c = grid.cost(rec, d);
        if c < best.1 {
            best = (d, c);
        }
    }
    let (d0, c0) = best;
    let d = refine(experiment, rec, d0, bounds(d0), REFINE_SAMPLES);
    let c = grid.cost(rec, d);
    Ok(if c <= c0 { (d, c) } else { (d0, c0) })
}

/// The log's samples the Gauss-Newton refinement of each candidate offset reads, to rank them.
const RANK_SAMPLES: usize = 2_000;
/// ... and of the best one.
const REFINE_SAMPLES: usize = 20_000;

/// Gauss-Newton refinement of the offset `d` within `[lo, hi]` (s): the residual
/// `q_rec(t) - q_plan(t - d)` changes with `d` at the planned speed; on about `samples` of
/// the log's samples within the plan's span, each joint's mean difference taken off.
fn refine(
    experiment: &Experiment,
    rec: &Recording,
    mut d: f64,
    (lo, hi): (f64, f64),
    samples: usize,
) -> f64 {
    let n = rec.n;
    let traj = &experiment.trajectory;
    let (start, end) = (traj.start(), traj.end());
    for _ in 0..20 {
        // per joint, the sums of e, v, e v and v^2 (e the difference, v the planned speed):
        // the step of the centred problem, each joint's mean difference taken off
        let mut sums = vec![[0.0; 4]; n];
        let mut count = 0.0;
        for i in span_rows(experiment, rec, d, samples) {
            let tp = (rec.t[i] - d).clamp(start, end);
            let seg = traj.segment_at(tp);
            for (j, s) in sums.iter_mut().enumerate() {
                let (q, v, _) = seg.eval(j, tp);
                let e = rec.q[i * n + j] - q;
                s[0] += e;
                s[1] += v;
                s[2] += e * v;
                s[3] += v * v;
            }
            count += 1.0;
        }
        if count < 2.0 {
            break;
        }
        let (num, den) = sums.iter().fold((0.0, 0.0), |(num, den), s| {
            (
                num + s[2] - s[0] * s[1] / count,
                den + s[3] - s[1] * s[1] / count,
            )
        });
        if den.is_nan() || den <= 0.0 {
            break;
        }
        let next = (d - num / den).clamp(lo, hi);
        let done = (next - d).abs() < 1e-13;
        d = next;
        if done {
            break;
        }
    }
    d
}

/// The rows of `rec` whose times lie within `experiment`'s planned span placed `d` s later (log
/// time = plan time + `d`), every so many so as to take at most about `samples` of them: the
/// same rows however much else the log holds (a run's check in a 10-minute session read a
/// dozen samples when they were spread over the whole log).
pub(super) fn span_rows(
    experiment: &Experiment,
    rec: &Recording,
    d: f64,
    samples: usize,
) -> std::iter::StepBy<std::ops::Range<usize>> {
    let traj = &experiment.trajectory;
    let i0 = rec.t.partition_point(|&t| t < traj.start() + d);
    let i1 = rec.t.partition_point(|&t| t <= traj.end() + d).max(i0);
    (i0..i1).step_by(((i1 - i0) / samples.max(1)).max(1))
}
