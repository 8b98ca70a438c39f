//! Torques clipped in a log: a drive, sensor or controller that cannot read or give more than
//! some torque logs that value while the true torque goes beyond it. A least-squares fit takes
//! the clipped readings for torques, and the parameters bend to fit them, silently.
//!
//! A clipped stretch is a run of samples reading exactly the column's largest (or smallest)
//! value, which the samples either side of it approach and leave as if they went on beyond it.
//! Runs at that value at most [`MAX_BREAK`] samples apart are one stretch (noise about the
//! clipped level breaks its runs). Each stretch of at least [`MIN_RUN`] samples is judged by
//! the straight lines through the samples either side of it (as many as it has, from
//! [`MIN_FLANK`] to [`MAX_FLANK`] a side, within the stretch between gaps): clipped when both
//! head beyond the value by more than [`SLOPE_LEVELS`] standard errors of their slopes (from
//! the larger of their scatter and the column's noise, the robust scale of its second
//! differences), and the parabola through the stretch's ends at the gentler slope goes beyond
//! it by more than 2 grid steps (a torque logged in steps) and 1e-9 of the value.
//!
//! A torque that really peaks there, read in steps, keeps its top step for a while: the
//! parabola through its sides goes beyond it by about one step. A torque held still (the
//! robot at rest) has flat sides; one that jumps to its peak (Coulomb friction at a velocity
//! reversal) leaves it gently, and the gentler side decides. Stretches at the log's ends or a
//! gap's, with a side of fewer than [`MIN_FLANK`] samples, are not judged.

pub use crate::logs::findings::torque_saturation::*;
use crate::logs::recording::Recording;

/// The clipped torques of `rec` (as logged, before any preprocessing), per joint and side.
pub fn find_torque_saturation(rec: &Recording) -> Vec<TorqueSaturation> {
    let (n, k) = (rec.n, rec.len());
    let mut found = vec![];
    if n == 0 || k < 2 * MIN_FLANK + MIN_RUN {
        return found;
    }
    let mut bounds = vec![0];
    bounds.extend(crate::logs::gaps::gap_positions(rec).iter().map(|&i| i + 1));
    bounds.push(k);
    for j in 0..n {
        let y: Vec<f64> = (0..k).map(|s| rec.tau[s * n + j]).collect();
        let (noise, step) = noise_and_step(&y);
        for upper in [true, false] {
            let level = if upper {
                y.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            } else {
                y.iter().copied().fold(f64::INFINITY, f64::min)
            };
            let sign = if upper { 1.0 } else { -1.0 };
            let mut hit: Option<TorqueSaturation> = None;
            for segment in bounds.windows(2) {
                for run in stretches(&y[segment[0]..segment[1]], level) {
                    let run = segment[0] + run.start..segment[0] + run.end;
                    let flank = run.len().clamp(MIN_FLANK, MAX_FLANK);
                    if run.len() < MIN_RUN
                        || run.start < segment[0] + flank
                        || run.end + flank > segment[1]
                    {
                        continue;
                    }
                    let side = |r: std::ops::Range<usize>| line(&rec.t[r.clone()], &y[r], noise);
                    let (Some(before), Some(after)) = (
                        side(run.start - flank..run.start),
                        side(run.end..run.end + flank),
                    ) else {
                        continue;
                    };
                    // the slopes heading beyond the level on the way in and coming back out,
                    // each read at its side's middle
                    let (s_in, s_out) = (sign * before.0, -sign * after.0);
                    let heading = (s_in / before.1).min(s_out / after.1) > SLOPE_LEVELS;
                    // a parabola through the run's ends at the gentler slope, taken at the
                    // ends (a parabola's slope grows linearly: L / (L + w) of the side's)
                    let duration = rec.t[run.end] - rec.t[run.start - 1];
                    let at_ends = run.len() as f64 / (run.len() + flank) as f64;
                    let beyond = duration * s_in.min(s_out) / 4.0 * at_ends;
                    if !(heading && beyond > 2.0 * step + 1e-9 * level.abs()) {
                        continue;
                    }
                    let h = hit.get_or_insert(TorqueSaturation {
                        joint: j,
                        level,
                        upper,
                        runs: 0,
                        samples: 0,
                        longest: 0,
                        first_at: rec.t[run.start],
                        beyond: 0.0,
                        spans: vec![],
                    });
                    h.spans.push((rec.t[run.start], rec.t[run.end - 1]));
                    h.runs += 1;
                    h.samples += run.len();
                    h.longest = h.longest.max(run.len());
                    h.beyond = h.beyond.max(beyond);
                }
            }
            found.extend(hit);
        }
    }
    found
}

/// The stretches of `y` at exactly `level`: runs of such samples, those apart by at most
/// [`MAX_BREAK`] samples merged (noise about a clipped level breaks its runs).
fn stretches(y: &[f64], level: f64) -> Vec<std::ops::Range<usize>> {
    let mut out: Vec<std::ops::Range<usize>> = vec![];
    let mut s = 0;
    while s < y.len() {
        if y[s] != level {
            s += 1;
            continue;
        }
        let start = s;
        while s < y.len() && y[s] == level {
            s += 1;
        }
        match out.last_mut() {
            Some(last) if start - last.end <= MAX_BREAK => last.end = s,
            _ => out.push(start..s),
        }
    }
    out
}

/// The column's noise level, the robust scale of its second differences (`1.4826 * median /
/// sqrt(6)`, the standard deviation of white noise), and its grid step (0 for none).
fn noise_and_step(y: &[f64]) -> (f64, f64) {
    let mut d: Vec<f64> = y
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect();
    let scale = if d.is_empty() {
        0.0
    } else {
        let mid = d.len() / 2;
        1.4826 * *d.select_nth_unstable_by(mid, f64::total_cmp).1 / 6f64.sqrt()
    };
    (scale, crate::signal::grid_step(y).unwrap_or(0.0))
}

/// The slope of the straight line through `(t, y)` and its standard error, from the larger of
/// the line's residual scatter and the column's `noise`; None for a degenerate time span.
fn line(t: &[f64], y: &[f64], noise: f64) -> Option<(f64, f64)> {
    let m = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
    let stt: f64 = t.iter().map(|x| (x - tm).powi(2)).sum();
    if !(stt > 0.0 && stt.is_finite()) {
        return None;
    }
    let slope = t
        .iter()
        .zip(y)
        .map(|(x, v)| (x - tm) * (v - ym))
        .sum::<f64>()
        / stt;
    let residual = t
        .iter()
        .zip(y)
        .map(|(x, v)| (v - ym - slope * (x - tm)).powi(2))
        .sum::<f64>();
    let scatter = (residual / (m - 2.0).max(1.0)).sqrt().max(noise);
    let se = scatter / stt.sqrt();
    (slope.is_finite() && se.is_finite()).then_some((slope, se))
}

/// The warning for `found` in the log `log`, its joints named by `joint_names`; None for none.
pub fn warning(found: &[TorqueSaturation], joint_names: &[String], log: &str) -> Option<String> {
    if found.is_empty() {
        return None;
    }
    let each: Vec<String> = found
        .iter()
        .map(|s| {
            let name = joint_names
                .get(s.joint)
                .map_or(format!("joint {}", s.joint + 1), |n| format!("'{n}'"));
            format!(
                "{name} reads exactly {:.4} N m, its {} value, in {} run(s) of up to {} samples from t = {:.3} s, where the samples either side head beyond it (by up to about {:.4} N m)",
                s.level,
                if s.upper { "largest" } else { "smallest" },
                s.runs,
                s.longest,
                s.first_at,
                s.beyond
            )
        })
        .collect();
    Some(format!(
        "log '{log}': the torque of {}: clipped (a saturated sensor or drive, or a torque limit of the controller). The fit takes the clipped readings for the robot's torques and its parameters bend to them: log with a wider range, or excite the robot less",
        each.join("; ")
    ))
}

/// The warning for the clipped runs of `found` (in one experiment's recording) that reach into
/// a crossing's window: `times`, the crossings' times in the recording's clock (s), `window`
/// the windows' half-width (s). None where none does: clipping between the crossings leaves
/// the fits alone.
pub fn crossing_warning(
    found: &[TorqueSaturation],
    times: &[f64],
    window: f64,
    joint_names: &[String],
) -> Option<String> {
    let each: Vec<String> = found
        .iter()
        .filter_map(|s| {
            let hit: Vec<String> = (times.iter().enumerate())
                .filter(|(_, t)| (s.spans.iter()).any(|&(a, b)| a <= *t + window && b >= *t - window))
                .map(|(i, _)| i.to_string())
                .collect();
            let name = joint_names
                .get(s.joint)
                .map_or(format!("joint {}", s.joint + 1), |n| format!("'{n}'"));
            (!hit.is_empty()).then(|| {
                format!(
                    "{name} reads exactly {:.4} N m, its {} value, in the window(s) of crossing(s) {}",
                    s.level,
                    if s.upper { "largest" } else { "smallest" },
                    hit.join(", ")
                )
            })
        })
        .collect();
    (!each.is_empty()).then(|| {
        format!(
            "the torque of {}: clipped (a saturated sensor or drive, or a torque limit of the controller), so those crossings' torques are the clip's, not the robot's, and the fits bend to them: record with a wider range, or perturb less",
            each.join("; ")
        )
    })
}
