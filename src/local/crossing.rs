//! Values at a crossing from sampled data (docs/method.md, section 7): local polynomial fits over a
//! window around the crossing time, and detection of the time offset between a plan and a
//! recording.

use nalgebra::DMatrix;

use super::plan::Experiment;
use crate::error::{Error, Result};
use crate::recording::Recording;

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

/// Least-squares weights of a polynomial fit of degree `degree` over the samples `t[lo..hi]`
/// with `u = (t - tc) / half`: row `d` of the result maps the samples onto coefficient `d`.
fn fit_weights(t: &[f64], tc: f64, half: f64, degree: usize) -> Result<DMatrix<f64>> {
    let v = DMatrix::from_fn(t.len(), degree + 1, |i, d| {
        ((t[i] - tc) / half).powi(d as i32)
    });
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
    let n = rec.n;
    let (first, last) = (rec.t[0], rec.t[rec.len() - 1]);
    let eps = 1e-9 * half;
    if tc - half < first - eps || tc + half > last + eps {
        return Err(Error::Recording {
            recording: rec.name.clone(),
            message: format!(
                "{what} at t = {tc:.4} s needs data from {:.4} to {:.4} s; the recording covers {first:.4} to {last:.4} s (too short, or shifted: try detected crossing times)",
                tc - half,
                tc + half
            ),
        });
    }
    let lo = rec.t.partition_point(|&t| t < tc - half - eps);
    let hi = rec.t.partition_point(|&t| t <= tc + half + eps);
    let count = hi - lo;
    let degree_max = 2.max(options.torque_degree);
    let needed = degree_max + 3;
    if count < needed {
        return Err(Error::Recording {
            recording: rec.name.clone(),
            message: format!(
                "{what} at t = {tc:.4} s: {count} samples in the +-{half} s window, need at least {needed}"
            ),
        });
    }
    let t = &rec.t[lo..hi];
    let wq = fit_weights(t, tc, half, 2)?;
    let wt = if options.torque_degree == 2 {
        wq.clone()
    } else {
        fit_weights(t, tc, half, options.torque_degree)?
    };
    let mut out = CrossingValues {
        time: tc,
        q: vec![0.0; n],
        qd: vec![0.0; n],
        qdd: vec![0.0; n],
        tau: vec![0.0; n],
    };
    for j in 0..n {
        out.q[j] = apply(&wq, 0, &rec.q, lo, count, n, j);
        out.qd[j] = apply(&wq, 1, &rec.q, lo, count, n, j) / half;
        out.qdd[j] = 2.0 * apply(&wq, 2, &rec.q, lo, count, n, j) / (half * half);
        out.tau[j] = apply(&wt, 0, &rec.tau, lo, count, n, j);
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

/// The time offset `d` (s, within `+-max_shift`) such that the recording at `t` follows the
/// plan at `t - d`: least squares over positions, a grid search at a resolution of
/// `max_shift / 200` on about 1000 samples, refined by golden-section search on all samples.
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
    let stride = (rec.len() / 1000).max(1);
    let step = max_shift / 200.0;
    let mut best = (f64::INFINITY, 0.0);
    for g in -200..=200 {
        let d = g as f64 * step;
        let c = cost(d, stride);
        if c < best.0 {
            best = (c, d);
        }
    }
    // golden-section refinement in [d - step, d + step]
    let (mut a, mut b) = (best.1 - step, best.1 + step);
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (b - r * (b - a), a + r * (b - a));
    let (mut f1, mut f2) = (cost(x1, 1), cost(x2, 1));
    for _ in 0..60 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - r * (b - a);
            f1 = cost(x1, 1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + r * (b - a);
            f2 = cost(x2, 1);
        }
    }
    Ok(0.5 * (a + b))
}
