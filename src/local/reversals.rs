//! The planned velocity reversals near a crossing and the torque windows narrowed before them
//! (docs/method.md, section 7: friction steps near a crossing). A joint whose velocity changes
//! sign within a crossing's window has its torque read over a window narrowed to 0.9 of the
//! distance to the reversal (its friction step left out), or, where that would hold too few
//! samples, over the full window with the step modelled. The identification reads the torques
//! so, and the planner's prediction takes the noise of the narrowed readings from the same rule.

use super::crossing::{torque_reading_gain, FitOptions};
use super::plan::Experiment;
use crate::error::Result;
use crate::trajectory::Trajectory;

/// The fraction of the distance to a reversal a narrowed torque window keeps.
pub const NARROWED: f64 = 0.9;

/// Joint `j`'s planned velocity reversal nearest to plan time `tp` within `+-half` s, and the
/// half-width (s) of the torque window narrowed before it where that is at least `min_half`
/// (None: too close, the step is modelled over the full window). None without a reversal.
pub fn narrowed_window(
    traj: &Trajectory,
    j: usize,
    tp: f64,
    half: f64,
    min_half: f64,
) -> Option<(f64, Option<f64>)> {
    let tr = velocity_reversals(traj, j, tp - half, tp + half)
        .into_iter()
        .min_by(|a, b| (a - tp).abs().total_cmp(&(b - tp).abs()))?;
    let narrowed = NARROWED * (tr - tp).abs();
    Some((tr, (narrowed >= min_half).then_some(narrowed)))
}

/// Per joint, the root mean square over `experiment`'s crossings of the torque reading's noise
/// gain ([`torque_reading_gain`]) at `rate` Hz with `options`' fit, each crossing's window
/// narrowed before a planned velocity reversal as the identification narrows it (a window
/// with the step modelled counts as the full one). None where the full window holds too few
/// samples for the fit.
pub fn reading_gains(
    experiment: &Experiment,
    rate: f64,
    options: &FitOptions,
) -> Result<Option<Vec<f64>>> {
    let half = experiment.window;
    let Some(full) = torque_reading_gain(half, rate, options)? else {
        return Ok(None);
    };
    let min_half = 0.5 * super::crossing::samples_needed(options) as f64 / rate;
    let traj = &experiment.trajectory;
    let k = experiment.crossings.len().max(1) as f64;
    let mut gains = Vec::with_capacity(traj.n);
    for j in 0..traj.n {
        let mut sum = 0.0;
        for c in &experiment.crossings {
            let narrowed = narrowed_window(traj, j, c.time, half, min_half).and_then(|w| w.1);
            let g = match narrowed {
                Some(h) => torque_reading_gain(h, rate, options)?.unwrap_or(full),
                None => full,
            };
            sum += g * g;
        }
        gains.push((sum / k).sqrt());
    }
    Ok(Some(gains))
}

/// The times in `[a, b]` at which joint `j`'s planned velocity changes sign, in order (exact
/// on the quadratic crossing segments, by bisection to 1e-12 s on the quintic transitions).
pub fn velocity_reversals(traj: &Trajectory, j: usize, a: f64, b: f64) -> Vec<f64> {
    let mut out = vec![];
    let first = traj.segments.partition_point(|s| s.t1 < a);
    for seg in traj.segments[first..].iter().take_while(|s| s.t0 <= b) {
        let (lo, hi) = (a.max(seg.t0), b.min(seg.t1));
        if lo > hi {
            continue;
        }
        let c = &seg.coeffs[j];
        let v = |t: f64| seg.eval(j, t).1;
        if c[3] == 0.0 && c[4] == 0.0 && c[5] == 0.0 {
            // v = c1 + 2 c2 s: one root at most
            if c[2] != 0.0 {
                let root = seg.t_ref - c[1] / (2.0 * c[2]);
                if (lo..=hi).contains(&root) && v(lo).signum() != v(hi).signum() {
                    out.push(root);
                }
            }
            continue;
        }
        let m = 64;
        let mut prev = (lo, v(lo));
        for i in 1..=m {
            let t = lo + (hi - lo) * i as f64 / m as f64;
            let vt = v(t);
            if prev.1 != 0.0 && vt != 0.0 && prev.1.signum() != vt.signum() {
                let (mut x0, mut x1) = (prev.0, t);
                while x1 - x0 > 1e-12 {
                    let mid = 0.5 * (x0 + x1);
                    if v(mid).signum() == prev.1.signum() {
                        x0 = mid;
                    } else {
                        x1 = mid;
                    }
                }
                out.push(0.5 * (x0 + x1));
            }
            if vt != 0.0 {
                prev = (t, vt);
            }
        }
    }
    out.dedup_by(|x, y| (*x - *y).abs() < 1e-9);
    out
}
