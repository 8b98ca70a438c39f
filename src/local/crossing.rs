//! Values at a crossing from sampled data (docs/method.md, section 7): local polynomial fits over a
//! window around the crossing time, and detection of the time offset between a plan and a
//! recording.

use nalgebra::DMatrix;

use super::plan::Experiment;
use super::rounded_positions::band_state;
use crate::error::{Error, Result};
use crate::recording::Recording;
use crate::trajectory::Trajectory;

/// The state and torque at one crossing, estimated from a recording (length N each; rad, rad/s,
/// rad/s^2, N m).
#[derive(Clone, Debug, PartialEq)]
pub struct CrossingValues {
    /// Crossing time in the recording's clock (s).
    pub time: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    /// Standard errors of `q`, `qd`, `qdd` from the scatter of the positions about their
    /// quadratic fit (measurement noise, quantisation; NaN with no residual degree of freedom).
    pub state_stderr: [Vec<f64>; 3],
    /// Per joint, the noise gain of `tau`: its standard error per unit of white noise on the
    /// torque samples (the root sum of squares of the fit's weights at the crossing; about
    /// `sqrt(4.8 / samples)` for the default fit). Windows narrowed at a velocity reversal hold
    /// fewer samples and have larger gains.
    pub tau_gain: Vec<f64>,
    /// Per joint, the scatter of the torque samples about their fit: the sum of squared
    /// residuals (N^2 m^2) and its degrees of freedom. Pooled over an experiment's crossings
    /// it estimates the torque samples' noise level.
    pub tau_scatter: Vec<(f64, usize)>,
    /// Per joint, whether `q`, `qd`, `qdd` and their standard errors were read from positions
    /// rounded to encoder counts by the band of half a count about them
    /// ([`super::rounded_positions`]) rather than by least squares.
    pub position_band: Vec<bool>,
}

/// How to read crossing values from a recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Half-width of the fit window (s); `None`: the plan's window for the experiment.
    pub window: Option<f64>,
    /// Degree of the polynomial fitted to the torque (default 6). The torque along a crossing
    /// window is smooth but not polynomial; the bias of the fit is O((window * rate of change)^
    /// (degree + 2)), below 1e-9 relative on the A465 with the default window. Against white
    /// noise of n samples its standard error at the centre is about sqrt(4.8 / n) sigma (degree
    /// 2: sqrt(2.25 / n), degree 4: sqrt(3.5 / n)). Positions are always fitted with a
    /// quadratic, exact on a crossing segment.
    pub torque_degree: usize,
    /// Take qd (and qdd) from the recording's own columns, fitted like the torque, instead of
    /// differentiating the position fit (default false).
    pub recorded_derivatives: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            window: None,
            torque_degree: 6,
            recorded_derivatives: false,
        }
    }
}

/// Basis function `d` of a polynomial fit of degree `degree` about `tc` with `u = (t - tc) /
/// half`: `u^d`, and with `step = Some((reversal, slope))` a last one (`d = degree + 1`),
/// `sign(slope (t - reversal))`, modelling a Coulomb step.
fn basis(t: f64, tc: f64, half: f64, degree: usize, step: Option<(f64, f64)>, d: usize) -> f64 {
    match step {
        Some((reversal, slope)) if d == degree + 1 => {
            let x = slope * (t - reversal);
            if x == 0.0 {
                0.0
            } else {
                x.signum()
            }
        }
        _ => ((t - tc) / half).powi(d as i32),
    }
}

/// Least-squares weights of a polynomial fit of degree `degree` (and a step, see [`basis`])
/// over the samples `t[lo..hi]`: row `d` of the result maps the samples onto coefficient `d`.
fn fit_weights(
    t: &[f64],
    tc: f64,
    half: f64,
    degree: usize,
    step: Option<(f64, f64)>,
) -> Result<DMatrix<f64>> {
    let cols = degree + 1 + usize::from(step.is_some());
    let v = DMatrix::from_fn(t.len(), cols, |i, d| basis(t[i], tc, half, degree, step, d));
    v.pseudo_inverse(1e-12).map_err(|m| Error::Numerical {
        operation: "crossing fit".into(),
        message: m.into(),
    })
}

fn apply(
    w: &DMatrix<f64>,
    row: usize,
    values: &[f64],
    lo: usize,
    count: usize,
    n: usize,
    j: usize,
) -> f64 {
    (0..count)
        .map(|i| w[(row, i)] * values[(lo + i) * n + j])
        .sum()
}

/// One joint's torque read at a crossing: the value (N m), its noise gain and the samples'
/// scatter about the fit (see [`CrossingValues::tau_gain`] and [`CrossingValues::tau_scatter`]).
struct TorqueReading {
    value: f64,
    gain: f64,
    scatter: (f64, usize),
}

/// Reads joint `j`'s torque at `tc` from the samples `lo..lo + count` of `rec` with the fit
/// weights `w` of degree `degree` about `tc` with half-width `half` (and the step `step`: its
/// height counts on the crossing's side, none exactly at the reversal).
#[allow(clippy::too_many_arguments)]
fn read_torque(
    rec: &Recording,
    w: &DMatrix<f64>,
    (lo, count): (usize, usize),
    tc: f64,
    half: f64,
    degree: usize,
    step: Option<(f64, f64)>,
    j: usize,
) -> TorqueReading {
    let n = rec.n;
    let cols = w.nrows();
    let c: Vec<f64> = (0..cols)
        .map(|d| apply(w, d, &rec.tau, lo, count, n, j))
        .collect();
    // the value at tc: the constant term, and the step's height on tc's side of it
    let side = match step {
        Some((reversal, slope)) if tc != reversal => (slope * (tc - reversal)).signum(),
        _ => 0.0,
    };
    let at = |i: usize| {
        w[(0, i)]
            + if side != 0.0 {
                side * w[(cols - 1, i)]
            } else {
                0.0
            }
    };
    let value = c[0] + if side != 0.0 { side * c[cols - 1] } else { 0.0 };
    let gain = (0..count).map(|i| at(i).powi(2)).sum::<f64>().sqrt();
    let ss = (0..count)
        .map(|i| {
            let t = rec.t[lo + i];
            let fit: f64 = (0..cols)
                .map(|d| c[d] * basis(t, tc, half, degree, step, d))
                .sum();
            (rec.tau[(lo + i) * n + j] - fit).powi(2)
        })
        .sum();
    TorqueReading {
        value,
        gain,
        scatter: (ss, count.saturating_sub(cols)),
    }
}

/// How the torque of one joint is read at a crossing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TorqueFit {
    /// A polynomial over the samples within `+-half` s of the crossing.
    Window(f64),
    /// A polynomial plus a step `sign(slope * (t - reversal))` over the whole window: the
    /// Coulomb step where the joint's velocity reverses at `reversal` (the recording's clock;
    /// `slope` is the sign of the acceleration there). The value at the crossing includes the
    /// step on the crossing's side of it (none exactly at it, as friction at zero speed).
    Step { reversal: f64, slope: f64 },
}

/// Estimates the values at time `tc` (the recording's clock) from the samples within `+-half`
/// s: a quadratic fit of q gives q, qd and qdd; a fit of degree `options.torque_degree` gives
/// tau. Fails when the window is not inside the recording or holds too few samples.
pub fn values_at(
    rec: &Recording,
    tc: f64,
    half: f64,
    options: &FitOptions,
    what: &str,
) -> Result<CrossingValues> {
    values_at_with(
        rec,
        tc,
        half,
        &vec![TorqueFit::Window(half); rec.n],
        &[],
        options,
        what,
    )
}

/// The fewest samples a fit window must hold for `options`.
pub(crate) fn samples_needed(options: &FitOptions) -> usize {
    2.max(options.torque_degree) + 3
}

/// [`values_at`] with the torque of each joint read as `torque[j]` says (a narrower window, or
/// a step at a velocity reversal; see [`TorqueFit`]); the positions are always fitted over
/// `+-half`. `position_steps` (one per joint, or empty for none) gives the encoder step (rad)
/// of each joint's positions where they lie on a grid
/// ([`super::rounded_positions::position_steps`]): such a joint's state is read by the band of
/// half a step where every reading of the window lies in it
/// ([`super::rounded_positions::band_state`]), by least squares otherwise.
pub fn values_at_with(
    rec: &Recording,
    tc: f64,
    half: f64,
    torque: &[TorqueFit],
    position_steps: &[Option<f64>],
    options: &FitOptions,
    what: &str,
) -> Result<CrossingValues> {
    let n = rec.n;
    if torque.len() != n {
        return Err(Error::Shape {
            argument: "torque fits".into(),
            expected: format!("{n} (one per joint)"),
            got: torque.len().to_string(),
        });
    }
    if !(position_steps.is_empty() || position_steps.len() == n) {
        return Err(Error::Shape {
            argument: "position steps".into(),
            expected: format!("{n} (one per joint) or none"),
            got: position_steps.len().to_string(),
        });
    }
    let (first, last) = (rec.t[0], rec.t[rec.len() - 1]);
    let eps = 1e-9 * half;
    if tc - half < first - eps || tc + half > last + eps {
        return Err(Error::Recording {
            recording: rec.name.clone(),
            message: format!(
                "{what} at t = {tc:.4} s needs data from {:.4} to {:.4} s; the recording covers {first:.4} to {last:.4} s (too short, or its clock is offset from the plan's: align it with detected crossing times)",
                tc - half,
                tc + half
            ),
        });
    }
    let span = |h: f64| {
        let e = 1e-9 * h;
        let lo = rec.t.partition_point(|&t| t < tc - h - e);
        let hi = rec.t.partition_point(|&t| t <= tc + h + e);
        (lo, hi)
    };
    let (lo, hi) = span(half);
    let count = hi - lo;
    let needed = samples_needed(options);
    let too_few = |count: usize, h: f64| Error::Recording {
        recording: rec.name.clone(),
        message: format!(
            "{what} at t = {tc:.4} s: {count} samples in the +-{h} s window, need at least {needed}"
        ),
    };
    if count < needed {
        return Err(too_few(count, half));
    }
    let t = &rec.t[lo..hi];
    let wq = fit_weights(t, tc, half, 2, None)?;
    let wt = if options.torque_degree == 2 {
        wq.clone()
    } else {
        fit_weights(t, tc, half, options.torque_degree, None)?
    };
    let mut out = CrossingValues {
        time: tc,
        q: vec![0.0; n],
        qd: vec![0.0; n],
        qdd: vec![0.0; n],
        tau: vec![0.0; n],
        state_stderr: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
        tau_gain: vec![0.0; n],
        tau_scatter: vec![(0.0, 0); n],
        position_band: vec![false; n],
    };
    // sum of squared weights per coefficient: the variance factor of each estimate
    let gain: Vec<f64> = (0..3)
        .map(|d| (0..count).map(|i| wq[(d, i)].powi(2)).sum::<f64>().sqrt())
        .collect();
    for (j, fit) in torque.iter().enumerate() {
        let c = [
            apply(&wq, 0, &rec.q, lo, count, n, j),
            apply(&wq, 1, &rec.q, lo, count, n, j),
            apply(&wq, 2, &rec.q, lo, count, n, j),
        ];
        out.q[j] = c[0];
        out.qd[j] = c[1] / half;
        out.qdd[j] = 2.0 * c[2] / (half * half);
        let ss: f64 = (0..count)
            .map(|i| {
                let u = (t[i] - tc) / half;
                (rec.q[(lo + i) * n + j] - (c[0] + u * (c[1] + u * c[2]))).powi(2)
            })
            .sum();
        let sigma = if count > 3 {
            (ss / (count - 3) as f64).sqrt()
        } else {
            f64::NAN
        };
        out.state_stderr[0][j] = sigma * gain[0];
        out.state_stderr[1][j] = sigma * gain[1] / half;
        out.state_stderr[2][j] = 2.0 * sigma * gain[2] / (half * half);
        if let Some(step) = position_steps.get(j).copied().flatten() {
            let q: Vec<f64> = (0..count).map(|i| rec.q[(lo + i) * n + j]).collect();
            if let Some(b) = band_state(t, &q, tc, half, step) {
                out.q[j] = b.values[0];
                out.qd[j] = b.values[1];
                out.qdd[j] = b.values[2];
                for (v, se) in b.stderr.iter().enumerate() {
                    out.state_stderr[v][j] = *se;
                }
                out.position_band[j] = true;
            }
        }
        let reading = match *fit {
            TorqueFit::Window(h) if h >= half => read_torque(
                rec,
                &wt,
                (lo, count),
                tc,
                half,
                options.torque_degree,
                None,
                j,
            ),
            TorqueFit::Window(h) => {
                let (lo_j, hi_j) = span(h);
                if hi_j - lo_j < needed {
                    return Err(too_few(hi_j - lo_j, h));
                }
                let w = fit_weights(&rec.t[lo_j..hi_j], tc, h, options.torque_degree, None)?;
                read_torque(
                    rec,
                    &w,
                    (lo_j, hi_j - lo_j),
                    tc,
                    h,
                    options.torque_degree,
                    None,
                    j,
                )
            }
            TorqueFit::Step { reversal, slope } => {
                let step = Some((reversal, slope));
                let w = fit_weights(t, tc, half, options.torque_degree, step)?;
                read_torque(
                    rec,
                    &w,
                    (lo, count),
                    tc,
                    half,
                    options.torque_degree,
                    step,
                    j,
                )
            }
        };
        out.tau[j] = reading.value;
        out.tau_gain[j] = reading.gain;
        out.tau_scatter[j] = reading.scatter;
        if options.recorded_derivatives {
            if let Some(qd) = &rec.qd {
                out.qd[j] = apply(&wt, 0, qd, lo, count, n, j);
                if options.torque_degree >= 1 && rec.qdd.is_none() {
                    out.qdd[j] = apply(&wt, 1, qd, lo, count, n, j) / half;
                }
            }
            if let Some(qdd) = &rec.qdd {
                out.qdd[j] = apply(&wt, 0, qdd, lo, count, n, j);
            }
        }
    }
    Ok(out)
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

/// The time offset `d` (s, within `+-max_shift`) such that the recording at `t` follows the
/// plan at `t - d`: least squares over positions, a grid search at a resolution of
/// `max_shift / 200` on about 250 samples, refined by Gauss-Newton on about 20,000
/// (sub-sample: exact on noise-free data).
pub fn detect_offset(experiment: &Experiment, rec: &Recording, max_shift: f64) -> Result<f64> {
    if !(max_shift.is_finite() && max_shift > 0.0) {
        return Err(Error::InvalidArgument {
            argument: "max_shift".into(),
            message: format!("{max_shift}; expected a positive number of seconds"),
        });
    }
    let n = rec.n;
    let traj = &experiment.trajectory;
    let (start, end) = (traj.start(), traj.end());
    let cost = |d: f64, stride: usize| -> f64 {
        let mut acc = 0.0;
        for i in (0..rec.len()).step_by(stride) {
            let tp = (rec.t[i] - d).clamp(start, end);
            let seg = traj.segment_at(tp);
            for j in 0..n {
                let e = rec.q[i * n + j] - seg.eval(j, tp).0;
                acc += e * e;
            }
        }
        acc
    };
    let stride = (rec.len() / 250).max(1);
    let step = max_shift / 200.0;
    let mut best = (f64::INFINITY, 0.0);
    for g in -200..=200 {
        let d = g as f64 * step;
        let c = cost(d, stride);
        if c < best.0 {
            best = (c, d);
        }
    }
    // Gauss-Newton refinement in [d - step, d + step]: the residual q_rec(t) - q_plan(t - d)
    // changes with d at the planned speed
    let fine = (rec.len() / 20_000).max(1);
    let (lo, hi) = (best.1 - step, best.1 + step);
    let mut d = best.1;
    for _ in 0..20 {
        let (mut num, mut den) = (0.0, 0.0);
        for i in (0..rec.len()).step_by(fine) {
            let tp = rec.t[i] - d;
            if tp < start || tp > end {
                continue;
            }
            let seg = traj.segment_at(tp);
            for j in 0..n {
                let (q, v, _) = seg.eval(j, tp);
                num += (rec.q[i * n + j] - q) * v;
                den += v * v;
            }
        }
        if den <= 0.0 {
            break;
        }
        let next = (d - num / den).clamp(lo, hi);
        let done = (next - d).abs() < 1e-13;
        d = next;
        if done {
            break;
        }
    }
    Ok(d)
}
