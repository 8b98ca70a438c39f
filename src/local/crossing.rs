//! Values at a crossing from sampled data (docs/method.md, section 7): local polynomial fits over a
//! window around the crossing time, each signal screened for glitches first; the velocity
//! reversals a window meets. The clock alignment is in [`super::clock`].

use nalgebra::DMatrix;

pub use super::crossing_values::{CrossingValues, Signal, WindowGlitch};
use super::glitches::{self, Screened};
use super::rounded_positions::band_state;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// What is known of a recording's signals before its crossings are read, per joint (empty
/// vectors: nothing known): the grids (steps) they lie on, found over the whole recording or
/// the experiment's windows, and their noise levels over the experiment's windows. The steps
/// select the band read of rounded positions; all of it sets the least noise level the
/// glitch screening of one window assumes ([`super::glitches`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SignalScales {
    /// Encoder steps of the positions (rad; [`super::rounded_positions::position_steps`]).
    pub position_step: Vec<Option<f64>>,
    /// Steps of the torques (N m; [`super::quantisation::torque_steps`]).
    pub torque_step: Vec<Option<f64>>,
    /// The noise level of each signal (indexed by [`Signal::index`]: q, qd, qdd, tau; the
    /// signal's unit) over the experiment's windows ([`noise_levels`]).
    pub noise: Vec<[f64; 4]>,
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
    /// How long after the positions the torque channel logs what belongs with them (s;
    /// default 0): each crossing's torque is read at its time plus this, over a window moved
    /// with it. A sensor's or filter's delay is positive.
    pub torque_delay: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            window: None,
            torque_degree: 6,
            recorded_derivatives: false,
            torque_delay: 0.0,
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

/// A polynomial fit of degree `degree` (and a step, see [`basis`]) over the samples at `t`:
/// the basis functions at the samples (K x C) and the least-squares weights (C x K, row `d`
/// maps the samples onto coefficient `d`).
struct WindowFit {
    basis: DMatrix<f64>,
    weights: DMatrix<f64>,
}

impl WindowFit {
    fn new(t: &[f64], tc: f64, half: f64, degree: usize, step: Option<(f64, f64)>) -> Result<Self> {
        let cols = degree + 1 + usize::from(step.is_some());
        let v = DMatrix::from_fn(t.len(), cols, |i, d| basis(t[i], tc, half, degree, step, d));
        let weights = crate::decomposition::pseudo_inverse(v.clone(), 1e-12).ok_or_else(|| {
            Error::numerical(
                "crossing fit",
                "the window's basis is not finite, or its SVD did not converge",
            )
        })?;
        Ok(Self { basis: v, weights })
    }

    /// Coefficient `d` of the fit of the window's samples `y`.
    fn coefficient(&self, d: usize, y: &[f64]) -> f64 {
        y.iter()
            .enumerate()
            .map(|(i, v)| self.weights[(d, i)] * v)
            .sum()
    }

    /// The residuals of `y` about its fit.
    fn residuals(&self, y: &[f64]) -> Vec<f64> {
        let c: Vec<f64> = (0..self.weights.nrows())
            .map(|d| self.coefficient(d, y))
            .collect();
        y.iter()
            .enumerate()
            .map(|(i, v)| {
                v - c
                    .iter()
                    .enumerate()
                    .map(|(d, c)| c * self.basis[(i, d)])
                    .sum::<f64>()
            })
            .collect()
    }

    /// The sum of squared residuals of `y` about its fit.
    fn scatter(&self, y: &[f64]) -> f64 {
        self.residuals(y).iter().map(|r| r * r).sum()
    }

    /// Screens `y` for glitches ([`super::glitches`]), with a noise level of at least the
    /// signal's over the experiment's windows, the rounding of its grid (when it lies on one)
    /// and 1e-8 of the window's largest value.
    fn screen(&self, y: &[f64], floor: Floor) -> Screened {
        let size = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let floor = floor
            .step
            .map_or(0.0, |s| s / 12f64.sqrt())
            .max(floor.noise)
            .max(1e-8 * size)
            .max(f64::MIN_POSITIVE);
        glitches::screen(&self.basis, &self.weights, y, floor)
    }
}

/// Joint `j`'s samples `lo..lo + count` of the row-major `values` (N per sample).
fn samples(values: &[f64], (lo, count): (usize, usize), n: usize, j: usize) -> Vec<f64> {
    (lo..lo + count).map(|i| values[i * n + j]).collect()
}

/// The least noise level a window's screening assumes for one signal: its level over the
/// experiment's windows (0 unknown) and the step of a grid it lies on.
struct Floor {
    noise: f64,
    step: Option<f64>,
}

/// One signal's samples in a window after screening, with what was found recorded in `out`.
#[allow(clippy::too_many_arguments)]
fn screened(
    fit: &WindowFit,
    rec: &Recording,
    values: &[f64],
    range: (usize, usize),
    floor: Floor,
    signal: Signal,
    j: usize,
    out: &mut Vec<WindowGlitch>,
) -> Screened {
    let y = samples(values, range, rec.n, j);
    let s = fit.screen(&y, floor);
    for f in &s.flagged {
        let sample = range.0 + f.index;
        out.push(WindowGlitch {
            signal,
            joint: j,
            sample,
            time: rec.t[sample],
            value: f.value,
            noise_levels: f.noise_levels,
            replaced: s.isolated,
        });
    }
    s
}

/// One joint's torque read at a crossing: the value (N m), its noise gain and the samples'
/// scatter about the fit (see [`CrossingValues::tau_gain`] and [`CrossingValues::tau_scatter`]).
struct TorqueReading {
    value: f64,
    gain: f64,
    scatter: (f64, usize),
}

/// Reads a torque at `tc` from its window's samples `y` (glitches replaced) with `fit` (and
/// the step `step`: its height counts on the crossing's side, none exactly at the reversal);
/// `replaced` samples count as left out of the scatter's degrees of freedom.
fn read_torque(
    fit: &WindowFit,
    y: &[f64],
    tc: f64,
    step: Option<(f64, f64)>,
    replaced: usize,
) -> TorqueReading {
    let w = &fit.weights;
    let cols = w.nrows();
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
    let value = fit.coefficient(0, y)
        + if side != 0.0 {
            side * fit.coefficient(cols - 1, y)
        } else {
            0.0
        };
    let gain = (0..y.len()).map(|i| at(i).powi(2)).sum::<f64>().sqrt();
    TorqueReading {
        value,
        gain,
        scatter: (fit.scatter(y), y.len().saturating_sub(cols + replaced)),
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
        &SignalScales::default(),
        options,
        what,
    )
}

/// The fewest samples a fit window must hold for `options`.
pub(crate) fn samples_needed(options: &FitOptions) -> usize {
    2.max(options.torque_degree) + 3
}

/// How a crossing's torque reading scales the noise of one torque sample: the standard error
/// at the centre of the torque fit of `options` over a window of half-width `half` (s) sampled
/// at `rate` (Hz) in white noise of unit standard deviation (about `sqrt(4.8 / samples)` at
/// degree 6). None when the window holds fewer samples than the fit needs. Windows of more
/// than [`GAIN_SAMPLES`] samples are computed on that many and scaled as `1 / sqrt(samples)`
/// (within 1e-3 of the exact gain there).
pub fn torque_reading_gain(half: f64, rate: f64, options: &FitOptions) -> Result<Option<f64>> {
    let each_side = (half * rate * (1.0 + 1e-12)).floor();
    let samples = 2.0 * each_side + 1.0;
    if !(samples.is_finite() && samples >= samples_needed(options) as f64) {
        return Ok(None);
    }
    let m = each_side.min(((GAIN_SAMPLES - 1) / 2) as f64) as i64;
    let t: Vec<f64> = (-m..=m).map(|i| i as f64).collect();
    let fit = WindowFit::new(&t, 0.0, m as f64, options.torque_degree, None)?;
    let gain = fit.weights.row(0).norm() * ((2 * m + 1) as f64 / samples).sqrt();
    Ok(gain.is_finite().then_some(gain))
}

/// The most samples [`torque_reading_gain`] fits.
pub const GAIN_SAMPLES: usize = 4001;

/// A crossing's window in a recording: its samples `lo..lo + count` (times `t`), the
/// position fit, the full window's torque fit, and each joint's torque fit where it differs
/// (narrowed, or with a step) with its samples and step.
struct Window<'a> {
    lo: usize,
    count: usize,
    t: &'a [f64],
    fq: WindowFit,
    /// The positions' fit of degree [`POSITION_DEGREE_HIGH`], where the window holds enough
    /// samples to test it against the quadratic.
    fq_high: Option<WindowFit>,
    ft: WindowFit,
    torque: Vec<JointTorqueFit>,
}

/// One joint's torque fit in a window: its own fit where it differs from the window's, the
/// samples it covers (first, count) and the Coulomb step it models.
struct JointTorqueFit {
    fit: Option<WindowFit>,
    range: (usize, usize),
    step: Option<(f64, f64)>,
}

impl<'a> Window<'a> {
    /// The window of `+-half` s about `tc` (the recording's clock) with each joint's torque
    /// read as `torque[j]` says; fails when it is not inside the recording or holds too few
    /// samples.
    fn new(
        rec: &'a Recording,
        tc: f64,
        half: f64,
        torque: &[TorqueFit],
        options: &FitOptions,
        what: &str,
    ) -> Result<Self> {
        let n = rec.n;
        if torque.len() != n {
            return Err(Error::shape(
                "torque fits",
                format!("{n} (one per joint)"),
                torque.len().to_string(),
            ));
        }
        let (first, last) = (rec.t[0], rec.t[rec.len() - 1]);
        let eps = 1e-9 * half;
        if tc - half < first - eps || tc + half > last + eps {
            return Err(Error::recording(
                rec.name.clone(),
                format!(
                    "{what} at t = {tc:.4} s needs data from {:.4} to {:.4} s; the recording covers {first:.4} to {last:.4} s (too short, or its clock is offset from the plan's: align it with detected crossing times)",
                    tc - half,
                    tc + half
                ),
            ));
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
        let too_few = |count: usize, h: f64| {
            // the longest interval between samples over the window (with the samples either
            // side): a gap in the log, or a rate too low for the window
            let (lo, hi) = span(h);
            let (a, b) = (lo.saturating_sub(1), hi.min(rec.len() - 1));
            let (from, to) = (a..b)
                .map(|i| (rec.t[i], rec.t[i + 1]))
                .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
                .unwrap_or((rec.t[a], rec.t[b]));
            Error::recording(
                rec.name.clone(),
                format!(
                    "{what} at t = {tc:.4} s: {count} samples in the +-{h:.4} s window, need at least {needed}; the recording has no sample from {from:.4} to {to:.4} s there (a gap in the log, or too low a rate)"
                ),
            )
        };
        if count < needed {
            return Err(too_few(count, half));
        }
        let t = &rec.t[lo..hi];
        let degree = options.torque_degree;
        // the torque's window, moved by its delay
        let delay = options.torque_delay;
        let tt = tc + delay;
        let span_at = |h: f64| {
            let e = 1e-9 * h;
            let lo = rec.t.partition_point(|&t| t < tt - h - e);
            let hi = rec.t.partition_point(|&t| t <= tt + h + e);
            (lo, hi)
        };
        let own = |h: f64, step: Option<(f64, f64)>| -> Result<JointTorqueFit> {
            let (lo_j, hi_j) = span_at(h);
            if hi_j - lo_j < needed {
                return Err(too_few(hi_j - lo_j, h));
            }
            Ok(JointTorqueFit {
                fit: Some(WindowFit::new(&rec.t[lo_j..hi_j], tt, h, degree, step)?),
                range: (lo_j, hi_j - lo_j),
                step,
            })
        };
        let torque = torque
            .iter()
            .map(|fit| match *fit {
                TorqueFit::Window(h) if h >= half && delay == 0.0 => Ok(JointTorqueFit {
                    fit: None,
                    range: (lo, count),
                    step: None,
                }),
                TorqueFit::Window(h) => own(h.min(half), None),
                // the torque's step comes with its delay
                TorqueFit::Step { reversal, slope } => own(half, Some((reversal + delay, slope))),
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            lo,
            count,
            t,
            fq: WindowFit::new(t, tc, half, 2, None)?,
            fq_high: if count > POSITION_DEGREE_HIGH + 4 {
                Some(WindowFit::new(t, tc, half, POSITION_DEGREE_HIGH, None)?)
            } else {
                None
            },
            ft: WindowFit::new(t, tc, half, degree, None)?,
            torque,
        })
    }

    /// Joint `j`'s torque fit.
    fn torque_fit(&self, j: usize) -> &WindowFit {
        self.torque[j].fit.as_ref().unwrap_or(&self.ft)
    }
}

/// The noise level (the signal's unit) of each signal of each joint over the windows of
/// `+-half` s about the times `centres` (the recording's clock; each with its joints' torque
/// fits): per window, 1.4826 times the median studentised residual about the fit that reads
/// it ([`super::glitches::level`]); over the windows, their median. One row per joint,
/// indexed by [`Signal::index`]; 0 where unknown (a signal not recorded, or not read from
/// its own column). Windows that cannot be read (outside the recording, too few samples)
/// are passed over: reading them says why.
pub fn noise_levels(
    rec: &Recording,
    centres: &[(f64, Vec<TorqueFit>)],
    half: f64,
    options: &FitOptions,
) -> Vec<[f64; 4]> {
    let windows: Vec<Window> = centres
        .iter()
        .filter_map(|(tc, fits)| Window::new(rec, *tc, half, fits, options, "").ok())
        .collect();
    levels(rec, &windows, options)
}

/// [`noise_levels`] over windows already made.
fn levels(rec: &Recording, windows: &[Window], options: &FitOptions) -> Vec<[f64; 4]> {
    let n = rec.n;
    let mut per_window: Vec<[Vec<f64>; 4]> = (0..n).map(|_| Default::default()).collect();
    for w in windows {
        let range = (w.lo, w.count);
        for (j, levels) in per_window.iter_mut().enumerate() {
            let mut add = |signal: Signal, fit: &WindowFit, values: &[f64], range| {
                let y = samples(values, range, n, j);
                levels[signal.index()].push(glitches::level(&fit.basis, &fit.weights, &y));
            };
            add(Signal::Q, &w.fq, &rec.q, range);
            add(Signal::Tau, w.torque_fit(j), &rec.tau, w.torque[j].range);
            if options.recorded_derivatives {
                if let Some(qd) = &rec.qd {
                    add(Signal::Qd, &w.ft, qd, range);
                }
                if let Some(qdd) = &rec.qdd {
                    add(Signal::Qdd, &w.ft, qdd, range);
                }
            }
        }
    }
    per_window
        .into_iter()
        .map(|levels| {
            levels.map(|mut l| {
                if l.is_empty() {
                    return 0.0;
                }
                let mid = l.len() / 2;
                *l.select_nth_unstable_by(mid, f64::total_cmp).1
            })
        })
        .collect()
}

/// Reads the values at every window of `windows` (the time in the recording's clock, each
/// joint's torque fit, and what the window is, for messages) as [`values_at_with`] does,
/// with `scales`' noise levels set to the signals' over these windows ([`noise_levels`]),
/// each window's fits made once. Returns the values in the order of `windows`, and the
/// scales used.
pub fn values_in_windows(
    rec: &Recording,
    windows: &[(f64, Vec<TorqueFit>, String)],
    half: f64,
    scales: SignalScales,
    options: &FitOptions,
) -> Result<(Vec<CrossingValues>, SignalScales)> {
    let made = windows
        .iter()
        .map(|(tc, fits, what)| Window::new(rec, *tc, half, fits, options, what))
        .collect::<Result<Vec<_>>>()?;
    let scales = SignalScales {
        noise: levels(rec, &made, options),
        ..scales
    };
    check_scales(&scales, rec.n)?;
    let values = made
        .iter()
        .zip(windows)
        .map(|(w, (tc, _, _))| read(rec, w, *tc, half, &scales, options))
        .collect();
    Ok((values, scales))
}

/// Checks that `scales` has one entry per joint (or none) of each kind.
fn check_scales(scales: &SignalScales, n: usize) -> Result<()> {
    for (name, len) in [
        ("position steps", scales.position_step.len()),
        ("torque steps", scales.torque_step.len()),
        ("noise levels", scales.noise.len()),
    ] {
        if !(len == 0 || len == n) {
            return Err(Error::shape(
                name,
                format!("{n} (one per joint) or none"),
                len.to_string(),
            ));
        }
    }
    Ok(())
}

/// [`values_at`] with the torque of each joint read as `torque[j]` says (a narrower window, or
/// a step at a velocity reversal; see [`TorqueFit`]); the positions are always fitted over
/// `+-half`. `scales` gives what is known of the signals (one entry per joint each, or empty
/// for none): a joint whose positions lie on an encoder's grid
/// ([`super::rounded_positions::position_steps`]) has its state read by the band of half a
/// step where every reading of the window lies in it
/// ([`super::rounded_positions::band_state`]), by least squares otherwise. Every signal's
/// window is screened for isolated glitches first ([`super::glitches`]; the noise levels and
/// steps of `scales` are the least noise levels assumed), reported in
/// [`CrossingValues::glitches`].
pub fn values_at_with(
    rec: &Recording,
    tc: f64,
    half: f64,
    torque: &[TorqueFit],
    scales: &SignalScales,
    options: &FitOptions,
    what: &str,
) -> Result<CrossingValues> {
    check_scales(scales, rec.n)?;
    let w = Window::new(rec, tc, half, torque, options, what)?;
    Ok(read(rec, &w, tc, half, scales, options))
}

/// Degree of the positions' fit where the quadratic leaves motion it does not follow.
pub const POSITION_DEGREE_HIGH: usize = 6;

/// The p value below which the positions' scatter about the quadratic counts as motion the
/// quadratic does not follow (F-test against [`POSITION_DEGREE_HIGH`]).
pub const POSITION_DEGREE_LEVEL: f64 = 1e-3;

/// The positions' fit of window `w` for the samples `y`: the quadratic, exact on a planned
/// crossing segment, unless the higher-degree fit explains significantly more of them (a robot
/// whose controller moves it off the quadratic within the window: the quadratic's second
/// derivative would then be off the motion's at the crossing by more than its noise says).
fn position_fit<'w>(w: &'w Window, y: &[f64]) -> &'w WindowFit {
    let Some(high) = &w.fq_high else {
        return &w.fq;
    };
    let k = y.len() as f64;
    let (low_rss, high_rss) = (w.fq.scatter(y), high.scatter(y));
    let extra = (POSITION_DEGREE_HIGH - 2) as f64;
    let dof = k - (POSITION_DEGREE_HIGH + 1) as f64;
    if !(high_rss > 0.0 && low_rss > high_rss) {
        return &w.fq;
    }
    let f = ((low_rss - high_rss) / extra) / (high_rss / dof);
    if crate::student_t::f_upper_tail(f, extra, dof) < POSITION_DEGREE_LEVEL {
        high
    } else {
        &w.fq
    }
}

/// The values at `tc` read from the window `w` (see [`values_at_with`]).
fn read(
    rec: &Recording,
    w: &Window,
    tc: f64,
    half: f64,
    scales: &SignalScales,
    options: &FitOptions,
) -> CrossingValues {
    let n = rec.n;
    let (lo, count, t) = (w.lo, w.count, w.t);
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
        position_residuals: vec![vec![]; n],
        centre: (0..count)
            .min_by(|&a, &b| (t[a] - tc).abs().total_cmp(&(t[b] - tc).abs()))
            .unwrap_or(0),
        glitches: vec![],
    };
    for j in 0..n {
        let noise = |signal: Signal| scales.noise.get(j).map_or(0.0, |l| l[signal.index()]);
        let position_step = scales.position_step.get(j).copied().flatten();
        let floor = |signal: Signal, step: Option<f64>| Floor {
            noise: noise(signal),
            step,
        };
        let mut screen = |fit: &WindowFit, values: &[f64], range, signal, step| {
            screened(
                fit,
                rec,
                values,
                range,
                floor(signal, step),
                signal,
                j,
                &mut out.glitches,
            )
        };
        let fq = position_fit(w, &samples(&rec.q, (lo, count), n, j));
        let q = screen(fq, &rec.q, (lo, count), Signal::Q, position_step);
        let c = [0, 1, 2].map(|d| fq.coefficient(d, &q.values));
        out.q[j] = c[0];
        out.qd[j] = c[1] / half;
        out.qdd[j] = 2.0 * c[2] / (half * half);
        // sum of squared weights per coefficient: the variance factor of each estimate
        let gain: Vec<f64> = (0..3)
            .map(|d| {
                (0..count)
                    .map(|i| fq.weights[(d, i)].powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let dof = count.saturating_sub(fq.weights.nrows() + q.replaced());
        let residuals = fq.residuals(&q.values);
        let ss: f64 = residuals.iter().map(|r| r * r).sum();
        out.position_residuals[j] = residuals;
        let sigma = if dof > 0 {
            (ss / dof as f64).sqrt()
        } else {
            f64::NAN
        };
        out.state_stderr[0][j] = sigma * gain[0];
        out.state_stderr[1][j] = sigma * gain[1] / half;
        out.state_stderr[2][j] = 2.0 * sigma * gain[2] / (half * half);
        if let Some(step) = position_step {
            // the band of the samples kept: an isolated glitch is no reading of the encoder
            let left_out: Vec<usize> = match q.isolated {
                true => q.flagged.iter().map(|f| f.index).collect(),
                false => vec![],
            };
            let (tk, qk): (Vec<f64>, Vec<f64>) = (0..count)
                .filter(|i| !left_out.contains(i))
                .map(|i| (t[i], rec.q[(lo + i) * n + j]))
                .unzip();
            if let Some(b) = band_state(&tk, &qk, tc, half, step) {
                out.q[j] = b.values[0];
                out.qd[j] = b.values[1];
                out.qdd[j] = b.values[2];
                for (v, se) in b.stderr.iter().enumerate() {
                    out.state_stderr[v][j] = *se;
                }
                out.position_band[j] = true;
            }
        }
        let torque_step = scales.torque_step.get(j).copied().flatten();
        let jt = &w.torque[j];
        let y = screen(
            w.torque_fit(j),
            &rec.tau,
            jt.range,
            Signal::Tau,
            torque_step,
        );
        let tt = tc + options.torque_delay;
        let reading = read_torque(w.torque_fit(j), &y.values, tt, jt.step, y.replaced());
        out.tau[j] = reading.value;
        out.tau_gain[j] = reading.gain;
        out.tau_scatter[j] = reading.scatter;
        if options.recorded_derivatives {
            if let Some(qd) = &rec.qd {
                let v = screen(&w.ft, qd, (lo, count), Signal::Qd, None);
                out.qd[j] = w.ft.coefficient(0, &v.values);
                if options.torque_degree >= 1 && rec.qdd.is_none() {
                    out.qdd[j] = w.ft.coefficient(1, &v.values) / half;
                }
            }
            if let Some(qdd) = &rec.qdd {
                let a = screen(&w.ft, qdd, (lo, count), Signal::Qdd, None);
                out.qdd[j] = w.ft.coefficient(0, &a.values);
            }
        }
    }
    out
}
