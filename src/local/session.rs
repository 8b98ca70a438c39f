//! One log of a whole session split into a recording per experiment (docs/method.md, section
//! 7). A controller that runs the plan's trajectories one after the other, with pauses and
//! moves of any length between them, logs one file; the identification wants each experiment's
//! run on the plan's clock. The runs are found in the plan's order, each after the previous
//! one, where the log's positions follow the experiment's planned ones best.

use super::clock::{follows_plan, misfit_shown, position_misfit};
use super::offset_search::{search_offset, span_cost};
use super::plan::{Experiment, Plan};
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// How a session log is split ([`split_session`]).
#[derive(Clone, Debug)]
pub struct SplitOptions {
    /// Seconds of log kept before each run's planned start and after its planned end (default
    /// 0.2): room for the identification's own clock search, which refines each run's offset
    /// below a sample.
    pub margin: f64,
}

impl Default for SplitOptions {
    fn default() -> Self {
        Self { margin: 0.2 }
    }
}

/// The grid's lowest minima refined for each run: other experiments' runs pass the same point,
/// so twice as many as for one experiment's recording.
const CANDIDATES: usize = 2 * super::offset_search::CANDIDATES;

/// The offset `d` in `[lo, hi]` (s) at which `e`'s plan fits the log best, with its cost (see
/// [`span_cost`]): the clock search of one recording (a grid of 20 ms or finer, its lowest
/// minima refined), over the stretch of log where the run can lie.
fn best_offset(e: &Experiment, log: &Recording, lo: f64, hi: f64) -> Result<(f64, f64)> {
    search_offset(e, log, (lo, hi), 1, CANDIDATES, || {
        crate::interrupt::check("splitting the session log")
    })
}

/// Splits `log`, a session in which the robot ran `plan`'s experiments one after the other in
/// the plan's order (pauses and moves of any length between them, anything before the first
/// and after the last), into one recording per experiment, in the plan's order: each marked
/// with its experiment, named `<log name> [<experiment>]`, its time on the plan's clock (the
/// log's minus the offset found), holding the run and [`SplitOptions::margin`] s either side.
/// Its columns are the log's (`q` in rad or m, `tau` in N m or N, `qd`, `qdd` when logged).
/// Each comes with the offset `d` (s) found: the log's time is the plan's plus `d`.
///
/// Each run is sought after the previous one's end, where the log's positions follow the
/// experiment's plan best (the squared differences about each joint's mean, so an encoder's
/// zero does not matter); a stretch that a later experiment's plan fits better is that
/// experiment's, and the run is sought before it. Errors: a log of other joints, one that ends
/// before an experiment could have run, or whose best stretch does not follow the plan (as the
/// identification's position check: within 0.05 rad on average and half the planned motion
/// about that), named with the experiment, the time in the log and the joints.
pub fn split_session(
    plan: &Plan,
    log: &Recording,
    o: &SplitOptions,
) -> Result<Vec<(Recording, f64)>> {
    if log.n != plan.n() {
        return Err(Error::recording(
            log.name.clone(),
            format!(
                "{} joint columns; the plan is of {} joints ({})",
                log.n,
                plan.n(),
                plan.joint_names.join(", ")
            ),
        ));
    }
    if !(o.margin.is_finite() && (0.0..=60.0).contains(&o.margin)) {
        return Err(Error::invalid(
            "margin",
            format!("{}; expected 0 to 60 s", crate::error::shown(o.margin)),
        ));
    }
    let (first, last) = (log.t[0], log.t[log.len() - 1]);
    let mut cursor = first;
    let mut runs = Vec::with_capacity(plan.experiments.len());
    for (k, e) in plan.experiments.iter().enumerate() {
        let (start, end) = (e.trajectory.start(), e.trajectory.end());
        let lo = cursor - start;
        let mut hi = last - end;
        let refuse = |message: String| {
            Error::recording(
                log.name.clone(),
                format!("experiment '{}': {message}", e.kind.name()),
            )
        };
        // the later experiment whose run the search was kept before, and where it starts
        let mut before: Option<(&str, f64)> = None;
        let (d, cost) = loop {
            if hi < lo {
                let until = match before {
                    Some((kind, at)) => format!(
                        "{} s, where experiment '{kind}' fits better",
                        shown_time(at)
                    ),
                    None => format!("{} s (the log's end)", shown_time(last)),
                };
                return Err(refuse(format!(
                    "its run ({:.2} s) does not fit in the log between {} s (the end of the previous run, or the log's start) and {until}: check that the log holds the whole session and that its experiments ran in the plan's order ({})",
                    end - start,
                    shown_time(cursor),
                    plan.kinds()
                )));
            }
            let (d, cost) = best_offset(e, log, lo, hi)?;
            // a stretch a later experiment fits better, started at the same time, is its run
            let later = plan.experiments[k + 1..].iter().find(|l| {
                let dl = d + start - l.trajectory.start();
                dl + l.trajectory.end() <= last && span_cost(l, log, dl) < cost
            });
            match later {
                Some(l) => {
                    before = Some((l.kind.name(), d + start));
                    hi = d - (end - start);
                }
                None => break (d, cost),
            }
        };
        let misfit = position_misfit(e, log, d).unwrap_or_default();
        let off: Vec<String> = (misfit.iter().enumerate())
            .filter(|(_, m)| !follows_plan(m, 0.0))
            .map(|(j, m)| misfit_shown(&plan.joint_names[j], m, 0.0))
            .collect();
        if !off.is_empty() || !cost.is_finite() {
            return Err(refuse(format!(
                "no stretch of the log after {} s follows its plan: at the best, from {} s, the joints {} (rad or m): check that the log holds the whole session, its experiments in the plan's order ({}), its columns the plan's joints, in radians",
                shown_time(cursor),
                shown_time(d + start),
                off.join(", "),
                plan.kinds()
            )));
        }
        let (from, to) = (d + start - o.margin, d + end + o.margin);
        let i0 = log.t.partition_point(|&t| t < from);
        let i1 = log.t.partition_point(|&t| t <= to);
        let n = log.n;
        let rows = |v: &[f64]| v[i0 * n..i1 * n].to_vec();
        let mut run = Recording::new(
            format!("{} [{}]", log.name, e.kind.name()),
            n,
            log.t[i0..i1].iter().map(|t| t - d).collect(),
            rows(&log.q),
            rows(&log.tau),
            log.qd.as_deref().map(rows),
            log.qdd.as_deref().map(rows),
        )?;
        run.experiment = Some(e.kind.name().to_string());
        log::info!(
            target: "perturbid_rs::session",
            "experiment '{}': from {} s in {}",
            e.kind.name(),
            shown_time(d + start),
            log.name
        );
        runs.push((run, d));
        cursor = d + end;
    }
    Ok(runs)
}

/// A warning for each run of `runs` (from [`split_session`] of `plan` on `log`: a recording
/// per experiment with its offset, s) whose experiment's plan is also followed, as the position
/// check accepts a run, by a stretch of the log between the runs next to it: the experiment ran
/// twice (rerun after a fault, or sent twice), and the split took the stretch that follows the
/// plan more closely without a word of the other. Errors: Ctrl-C.
pub fn repeated_runs(
    plan: &Plan,
    log: &Recording,
    runs: &[(Recording, f64)],
) -> Result<Vec<String>> {
    if runs.len() != plan.experiments.len() {
        return Err(Error::invalid(
            "runs",
            format!(
                "{} runs for the plan's {} experiments ({}); expected split_session's, one each",
                runs.len(),
                plan.experiments.len(),
                plan.kinds()
            ),
        ));
    }
    let (first, last) = (log.t[0], log.t[log.len() - 1]);
    let mut out = vec![];
    for (k, (e, (_, d))) in plan.experiments.iter().zip(runs).enumerate() {
        let (start, end) = (e.trajectory.start(), e.trajectory.end());
        let before = match k.checked_sub(1) {
            Some(p) => runs[p].1 + plan.experiments[p].trajectory.end(),
            None => first,
        };
        let after = match runs.get(k + 1) {
            Some((_, dn)) => dn + plan.experiments[k + 1].trajectory.start(),
            None => last,
        };
        // the stretches between the neighbouring runs and this one, as offsets of its plan
        for (lo, hi) in [
            (before - start, d - (end - start)),
            (d + (end - start), after - end),
        ] {
            if hi < lo {
                continue;
            }
            let (other, cost) = search_offset(e, log, (lo, hi), 1, CANDIDATES, || {
                crate::interrupt::check("looking for repeated runs in the session log")
            })?;
            let follows = position_misfit(e, log, other)
                .is_some_and(|m| m.iter().all(|m| follows_plan(m, 0.0)));
            // a stretch another experiment's plan fits better, started at the same time, is a
            // run of that one that looks alike (H's passes follow D's plan within the check)
            let alike = (plan.experiments.iter()).any(|l| {
                l.kind != e.kind && span_cost(l, log, other + start - l.trajectory.start()) < cost
            });
            if follows && !alike {
                let closer = if span_cost(e, log, *d) <= cost {
                    "more"
                } else {
                    "less"
                };
                out.push(format!(
                    "experiment '{}' seems to have run twice in {}: its plan is followed also from {} s of the log, and the run from {} s was taken, which follows it {closer} closely than the other; if the other is the one to use, cut the log to leave it alone between the runs before and after",
                    e.kind.name(),
                    log.name,
                    shown_time(other + start),
                    shown_time(d + start)
                ));
            }
        }
    }
    Ok(out)
}

/// A warning for each run of `runs` (from [`split_session`] of `plan` on `log`) inside whose
/// planned span the log has no sample for longer than
/// [`MAX_GAP_INTERVALS`](crate::limits::MAX_GAP_INTERVALS) times its median interval: samples
/// lost there (the identification names a crossing whose window they leave empty), or a step
/// of the log's clock, after which the run is off the plan's clock by the step (and the
/// recording ends early). Named with the experiment, the gap's length and where it lies in
/// the log and on the plan's clock.
pub fn gaps_in_runs(plan: &Plan, log: &Recording, runs: &[(Recording, f64)]) -> Vec<String> {
    let intervals: Vec<f64> = log.t.windows(2).map(|w| w[1] - w[0]).collect();
    let Some(median) = crate::logs::log_screening::median(intervals) else {
        return vec![];
    };
    let longest = crate::limits::MAX_GAP_INTERVALS * median;
    let mut out = vec![];
    for (e, (_, d)) in plan.experiments.iter().zip(runs) {
        let (from, to) = (d + e.trajectory.start(), d + e.trajectory.end());
        let i0 = log.t.partition_point(|&t| t < from).saturating_sub(1);
        let i1 = log.t.partition_point(|&t| t <= to).min(log.len() - 1);
        let gaps: Vec<(f64, f64)> = (i0..i1)
            .map(|i| (log.t[i], log.t[i + 1]))
            .filter(|(a, b)| b - a > longest && *b > from && *a < to)
            .collect();
        if let Some(&(a, b)) = gaps
            .iter()
            .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        {
            out.push(format!(
                "experiment '{}': {} has no sample for {} s inside its run, from {} to {} s of the log ({} to {} s on the plan's clock; {} such gap(s) in the run, the median interval {} s): samples were lost there, or the log's clock stepped, and then the rest of the run is off the plan's clock by the step; the identification needs the samples around each crossing",
                e.kind.name(),
                log.name,
                shown_time(b - a),
                shown_time(a),
                shown_time(b),
                shown_time(a - d),
                shown_time(b - d),
                gaps.len(),
                crate::error::shown5(median)
            ));
        }
    }
    out
}

/// A time in the log (s), to the millisecond.
fn shown_time(t: f64) -> String {
    crate::error::shown((t * 1e3).round() / 1e3)
}
