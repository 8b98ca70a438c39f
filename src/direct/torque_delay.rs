//! The delay of a log's torque channel behind its positions, to a fraction of a sample: a
//! torque sensor's filter, a drive's current loop, a logger that stamps the torque later. A
//! delay `d` biases every local estimate (H* by about `-d G*`, D* by `-d H*`, T* by `-d` times
//! the torque's rate at P) and every direct fit, and moves a friction step off the velocity
//! reversal that causes it.
//!
//! The delay is found as the clock offset is, by the residual of a model of the torque: the
//! robot's rigid-body regressor (every link's ten inertial parameters free, so a payload or
//! link errors the URDF lacks do not matter) beside each joint's viscous, Coulomb (the sign of
//! its speed, filtered as the torque is) and offset terms, fitted to the torques read at the
//! positions' times plus each delay tried. Positions and torques are low-passed alike, without
//! phase. The delay whose fit leaves least unexplained, refined between the tried ones by a
//! parabola, is the estimate. Without a rigid-body model the delay cannot be told from the
//! local matrices themselves: a linear model's torque read late is the same linear model with
//! H* - d G* and D* - d H*.
//!
//! What it finds is the delay the torque behaves with. A drive command held over each sample
//! period (a logged controller command) acts half a sample after its stamp, so under
//! closed-loop tracking the estimate is the sensor's delay minus half a sample; read past
//! that, the crossings' torques belong with their positions.
//!
//! The standard error counts the residual's correlation in time: the residual is summed over
//! blocks of [`BLOCK`] s and the blocks taken as independent (a cluster-robust variance).
//! Rows where a joint moves slower than [`DelayOptions::slow`] are left out for that joint's
//! torque: a Stribeck hump there is no term of the fit.

use faer::linalg::solvers::Svd;
use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::algorithms::parallel::{self, Workspace};
use crate::error::{Error, Result};
use crate::logs::preprocess::{preprocess, PreprocessOptions};
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::parameters::PARAMS_PER_BODY;
use crate::{Gravity, States};

/// How [`estimate_torque_delay`] searches.
#[derive(Clone, Debug, PartialEq)]
pub struct DelayOptions {
    /// The delays tried lie within `+-range` (s; default 0.02), half a sample apart.
    pub range: f64,
    /// A joint's torque is left out of the fit where the joint moves slower than this (rad/s,
    /// or m/s; default 0.15).
    pub slow: f64,
    /// How many samples of all the recordings the fit uses at most, spread evenly over them
    /// (default 6000).
    pub samples: usize,
    /// The low-pass cutoff (Hz) applied alike, without phase, to positions and torques
    /// (default 15).
    pub cutoff: f64,
}

impl Default for DelayOptions {
    fn default() -> Self {
        Self {
            range: 0.02,
            slow: 0.15,
            samples: 6000,
            cutoff: 15.0,
        }
    }
}

/// Contiguous time (s) over which the residual is taken as correlated for the standard error.
pub const BLOCK: f64 = 0.5;

/// The most entries the fit's design matrix may hold (its rows are then fewer samples).
pub const MAX_DESIGN: usize = 8_000_000;

/// A torque delay found by [`estimate_torque_delay`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueDelay {
    /// How long after the positions the torque logs what belongs with them (s): positive for
    /// a sensor's or filter's delay; a held drive command makes it half a sample less.
    pub delay: f64,
    /// Its standard error (s) from the noise, the residual summed over blocks of [`BLOCK`] s.
    /// A misfit of the rigid-body fit (torque ripple, friction it lacks) is not in it: on the
    /// rehearsed arms of docs/closed_loop_campaign.md it moved the delay by up to 0.25 ms,
    /// 4-9 of these standard errors.
    pub stderr: f64,
    /// The rows (samples times joints) the fit used.
    pub rows: usize,
    /// The fraction of the weighted torques the fit leaves unexplained, read at the
    /// positions' times.
    pub unexplained_at_zero: f64,
    /// The same, read `delay` later.
    pub unexplained: f64,
}

impl TorqueDelay {
    /// One line for a summary: the delay with its standard error in ms.
    pub fn line(&self) -> String {
        format!(
            "torque delay {:.3} ms +- {:.3} (the noise's share; the rigid-body fit's misfit, torque ripple above all, moves it further: up to 0.25 ms on rehearsed arms, docs/closed_loop_campaign.md), found over {} rows (unexplained {:.2e} read then, {:.2e} at the positions' times); a held drive command reads as half a sample early",
            1e3 * self.delay,
            1e3 * self.stderr,
            self.rows,
            self.unexplained,
            self.unexplained_at_zero
        )
    }
}

/// The torque delay of `recordings` (runs of one robot, `model`'s joints in its order,
/// logged at any rate), see the module documentation.
///
/// Errors: a recording with other joints than the model, one too short to filter, options
/// out of range, or too few rows where the joints move.
pub fn estimate_torque_delay(
    model: &Model,
    recordings: &[&Recording],
    options: &DelayOptions,
) -> Result<TorqueDelay> {
    check_options(options)?;
    let series = recordings
        .iter()
        .map(|r| filtered(model, r, options))
        .collect::<Result<Vec<_>>>()?;
    let design = Design::new(model, &series, options)?;
    // joints weighted first by their torques' spread, then by what the fit leaves of them
    let spread = design.joint_rms(&design.torques(&series, 0.0));
    let first = Projection::new(&design, &spread)?;
    let (delay, ..) = first.search(&design, &series, options.range)?;
    let left = first.residual(&design.weighted(&design.torques(&series, delay), &spread));
    let fit = Projection::new(
        &design,
        &design.joint_rms(&unweight(&design, &left, &spread)),
    )?;
    let (delay, unexplained, at_zero) = fit.search(&design, &series, options.range)?;
    let stderr = fit.stderr(&design, &series, delay);
    crate::interrupt::check("the torque delay")?;
    Ok(TorqueDelay {
        delay,
        stderr,
        rows: design.rows.len(),
        unexplained_at_zero: at_zero,
        unexplained,
    })
}

fn check_options(o: &DelayOptions) -> Result<()> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !(positive(o.range) && o.range <= 0.2) {
        return Err(Error::invalid(
            "range",
            format!("{} s; expected a delay range in (0, 0.2] s", o.range),
        ));
    }
    if !(o.slow.is_finite() && o.slow >= 0.0) {
        return Err(Error::invalid(
            "slow",
            format!("{}; expected a speed of at least 0", o.slow),
        ));
    }
    if o.samples < 100 {
        return Err(Error::invalid(
            "samples",
            format!("{}; expected at least 100 samples", o.samples),
        ));
    }
    if !positive(o.cutoff) {
        return Err(Error::invalid(
            "cutoff",
            format!("{} Hz; expected a positive cutoff", o.cutoff),
        ));
    }
    Ok(())
}

/// A recording on its own uniform grid: the states lightly low-passed (at
/// [`STATE_CUTOFF`]), the torque low-passed at the options' cutoff.
struct Series {
    dt: f64,
    rec: Recording,
    tau: Vec<f64>,
    filter: Vec<crate::signal::Biquad>,
}

/// The cutoff (Hz, at most a fifth of the rate) of the states the regressor is computed at:
/// above the motion, so that its columns, low-passed like the torque afterwards, are the
/// low-passed torque's (a regressor at states low-passed near the motion's frequencies is
/// not: under tracking that moved the delay found by 0.3-0.8 ms).
pub const STATE_CUTOFF: f64 = 50.0;

fn filtered(model: &Model, rec: &Recording, options: &DelayOptions) -> Result<Series> {
    if rec.n != model.nv {
        return Err(Error::recording(
            rec.name.clone(),
            format!("{} joints; the robot has {}", rec.n, model.nv),
        ));
    }
    let (dt, _) = crate::logs::gaps::gaps(rec);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::recording(
            rec.name.clone(),
            "too few samples to read a sampling interval from",
        ));
    }
    let rate = 1.0 / dt;
    if options.cutoff >= 0.2 * rate {
        return Err(Error::invalid(
            "cutoff",
            format!(
                "{} Hz for '{}' logged at {rate:.0} Hz; expected below a fifth of the rate",
                options.cutoff, rec.name
            ),
        ));
    }
    let pre = PreprocessOptions {
        rate,
        cutoff: Some(STATE_CUTOFF.min(0.2 * rate).max(options.cutoff)),
        filter_position: true,
        decimate: 1,
        ..PreprocessOptions::default()
    };
    let out = preprocess(rec, &pre)?;
    let filter = crate::signal::butterworth_lowpass(4, options.cutoff, rate)?;
    let n = out.n;
    let mut series = Series {
        dt,
        tau: vec![0.0; out.tau.len()],
        rec: out,
        filter,
    };
    for j in 0..n {
        let column: Vec<f64> = series.rec.tau.iter().skip(j).step_by(n).copied().collect();
        for (i, v) in crate::signal::filtfilt(&series.filter, &column)?
            .into_iter()
            .enumerate()
        {
            series.tau[i * n + j] = v;
        }
    }
    Ok(series)
}

/// The fit's rows: one per sample used and joint that moves there.
struct Row {
    series: usize,
    sample: usize,
    joint: usize,
}

/// The design matrix of the fit (rows x columns, column-major) and its rows.
struct Design {
    n: usize,
    rows: Vec<Row>,
    columns: usize,
    x: Vec<f64>,
}

/// Samples whose regressor is low-passed at once, and the samples either side it is computed
/// over so that the filter has settled in the middle (s).
const CHUNK: usize = 4096;
const SETTLE: f64 = 0.25;

impl Design {
    fn new(model: &Model, series: &[Series], options: &DelayOptions) -> Result<Self> {
        let n = model.nv;
        let columns = PARAMS_PER_BODY * model.nbodies() + 3 * n;
        let most = options
            .samples
            .min(MAX_DESIGN / (n * columns).max(1))
            .max(1);
        // samples far enough from the ends to be read at every delay tried
        let spans: Vec<(usize, usize)> = series
            .iter()
            .map(|s| {
                let margin = (options.range / s.dt).ceil() as usize + 3;
                let len = s.rec.len();
                (margin, len.saturating_sub(margin).max(margin))
            })
            .collect();
        let total: usize = spans.iter().map(|(a, b)| b - a).sum();
        let stride = total.div_ceil(most).max(1);
        let mut rows: Vec<(Row, Vec<f64>)> = vec![];
        let mut ws = Workspace::new(model);
        for (k, (s, &(from, to))) in series.iter().zip(&spans).enumerate() {
            let mut core = from;
            while core < to {
                crate::interrupt::check("the torque delay")?;
                let end = (core + CHUNK).min(to);
                let picked: Vec<usize> = (core..end).filter(|i| (i - from) % stride == 0).collect();
                if !picked.is_empty() {
                    rows.extend(chunk_rows(
                        model,
                        &mut ws,
                        s,
                        k,
                        core..end,
                        &picked,
                        options,
                    )?);
                }
                core = end;
            }
        }
        let rows_needed = 2 * columns + 20;
        if rows.len() < rows_needed {
            return Err(Error::invalid(
                "recordings",
                format!(
                    "{} torque samples where their joint moves faster than {} (rad/s); the torque delay needs at least {rows_needed}",
                    rows.len(),
                    options.slow
                ),
            ));
        }
        let count = rows.len();
        let mut x = vec![0.0; count * columns];
        for (r, (_, values)) in rows.iter().enumerate() {
            for (c, v) in values.iter().enumerate() {
                x[c * count + r] = *v;
            }
        }
        Ok(Self {
            n,
            rows: rows.into_iter().map(|(r, _)| r).collect(),
            columns,
            x,
        })
    }

    /// The torque of every row read `delay` after its sample's time (cubic interpolation).
    fn torques(&self, series: &[Series], delay: f64) -> Vec<f64> {
        self.rows
            .iter()
            .map(|r| {
                let s = &series[r.series];
                read_at(&s.tau, self.n, r.joint, r.sample as f64 + delay / s.dt)
            })
            .collect()
    }

    /// The RMS of `values` over each joint's rows (1 where a joint has none).
    fn joint_rms(&self, values: &[f64]) -> Vec<f64> {
        let mut sum = vec![(0.0, 0usize); self.n];
        for (r, v) in self.rows.iter().zip(values) {
            sum[r.joint].0 += v * v;
            sum[r.joint].1 += 1;
        }
        sum.iter()
            .map(|&(s, c)| {
                let rms = (s / c.max(1) as f64).sqrt();
                if rms > 0.0 && rms.is_finite() {
                    rms
                } else {
                    1.0
                }
            })
            .collect()
    }

    /// `values` divided by their joint's weight.
    fn weighted(&self, values: &[f64], per_joint: &[f64]) -> Vec<f64> {
        (self.rows.iter().zip(values))
            .map(|(r, v)| v / per_joint[r.joint])
            .collect()
    }
}

/// The rows of the samples `picked` of `core` (in series `k`): the regressor and friction
/// columns computed over the core and [`SETTLE`] s either side, each low-passed as the torque
/// is, read at the picked samples for every joint moving there.
fn chunk_rows(
    model: &Model,
    ws: &mut Workspace,
    s: &Series,
    k: usize,
    core: std::ops::Range<usize>,
    picked: &[usize],
    options: &DelayOptions,
) -> Result<Vec<(Row, Vec<f64>)>> {
    let n = model.nv;
    let inertial = PARAMS_PER_BODY * model.nbodies();
    let columns = inertial + 3 * n;
    let pad = (SETTLE / s.dt).ceil() as usize;
    let (lo, hi) = (
        core.start.saturating_sub(pad),
        (core.end + pad).min(s.rec.len()),
    );
    let len = hi - lo;
    let r = &s.rec;
    let (qd, qdd) = (
        r.qd.as_deref().unwrap_or(&[]),
        r.qdd.as_deref().unwrap_or(&[]),
    );
    if qd.len() < hi * n || qdd.len() < hi * n {
        return Err(Error::numerical(
            "torque delay",
            "the preprocessed recording has no velocities or accelerations",
        ));
    }
    let states = States::new(
        n,
        &r.q[lo * n..hi * n],
        Some(&qd[lo * n..hi * n]),
        Some(&qdd[lo * n..hi * n]),
    )?;
    let mut phi = vec![0.0; len * n * inertial];
    parallel::regressor(model, ws, &states, Gravity::Included, &mut phi)?;
    let mut filtered = vec![vec![0.0; picked.len()]; n * columns];
    let mut column = vec![0.0; len];
    for j in 0..n {
        for c in 0..columns {
            for (i, v) in column.iter_mut().enumerate() {
                let at = lo + i;
                *v = match c {
                    c if c < inertial => phi[(i * n + j) * inertial + c],
                    c if c == inertial + 3 * j => qd[at * n + j],
                    c if c == inertial + 3 * j + 1 => qd[at * n + j].signum(),
                    c if c == inertial + 3 * j + 2 => 1.0,
                    _ => 0.0,
                };
            }
            if column.iter().all(|v| *v == 0.0) {
                continue;
            }
            let smooth = crate::signal::filtfilt(&s.filter, &column)?;
            for (p, &i) in picked.iter().enumerate() {
                filtered[j * columns + c][p] = smooth[i - lo];
            }
        }
    }
    let mut out = vec![];
    for (p, &i) in picked.iter().enumerate() {
        for j in 0..n {
            if qd[i * n + j].abs() < options.slow {
                continue;
            }
            let values = (0..columns).map(|c| filtered[j * columns + c][p]).collect();
            out.push((
                Row {
                    series: k,
                    sample: i,
                    joint: j,
                },
                values,
            ));
        }
    }
    Ok(out)
}

/// `values` (weighted) back in their joints' units.
fn unweight(design: &Design, values: &[f64], per_joint: &[f64]) -> Vec<f64> {
    (design.rows.iter().zip(values))
        .map(|(r, v)| v * per_joint[r.joint])
        .collect()
}

/// Joint `j` of row-major `values` (`n` per sample) at the fractional sample `at`: the cubic
/// through the four samples around it (Lagrange).
fn read_at(values: &[f64], n: usize, j: usize, at: f64) -> f64 {
    let len = values.len() / n;
    let k = (at.floor() as usize).clamp(1, len.saturating_sub(3).max(1));
    let s = at - k as f64;
    let p = |i: usize| values[i.min(len - 1) * n + j];
    let (p0, p1, p2, p3) = (p(k - 1), p(k), p(k + 1), p(k + 2));
    let (a, b, c, d) = (s + 1.0, s, s - 1.0, s - 2.0);
    (-b * c * d * p0 + 3.0 * a * c * d * p1 - 3.0 * a * b * d * p2 + a * b * c * p3) / 6.0
}

/// The orthonormal basis of the weighted design's column space (column-major, rows x rank).
struct Projection {
    rows: usize,
    rank: usize,
    u: Vec<f64>,
    weights: Vec<f64>,
}

impl Projection {
    fn new(design: &Design, weights: &[f64]) -> Result<Self> {
        let (rows, p) = (design.rows.len(), design.columns);
        let scale: Vec<f64> = (0..p)
            .map(|c| {
                let norm = (0..rows)
                    .map(|r| (design.x[c * rows + r] / weights[design.rows[r].joint]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if norm > 0.0 {
                    norm
                } else {
                    1.0
                }
            })
            .collect();
        let xs = Mat::<f64>::from_fn(rows, p, |r, c| {
            design.x[c * rows + r] / weights[design.rows[r].joint] / scale[c]
        });
        let svd = Svd::new_thin(xs.as_ref()).map_err(|e| {
            Error::numerical("torque delay", format!("the SVD did not converge: {e:?}"))
        })?;
        let s = svd.S().column_vector();
        let largest = (0..p).map(|i| s[i]).fold(0.0, f64::max);
        let kept: Vec<usize> = (0..p).filter(|&i| s[i] > 1e-9 * largest).collect();
        let u = svd.U();
        let mut basis = Vec::with_capacity(rows * kept.len());
        for &i in &kept {
            basis.extend((0..rows).map(|r| u[(r, i)]));
        }
        Ok(Self {
            rows,
            rank: kept.len(),
            u: basis,
            weights: weights.to_vec(),
        })
    }

    /// What the fit leaves of `y` (weighted rows).
    fn residual(&self, y: &[f64]) -> Vec<f64> {
        let mut e = y.to_vec();
        for c in 0..self.rank {
            let col = &self.u[c * self.rows..(c + 1) * self.rows];
            let dot: f64 = col.iter().zip(y).map(|(a, b)| a * b).sum();
            e.iter_mut().zip(col).for_each(|(e, a)| *e -= dot * a);
        }
        e
    }

    /// The fraction of `y` the fit leaves unexplained.
    fn unexplained(&self, y: &[f64]) -> f64 {
        let total: f64 = y.iter().map(|v| v * v).sum();
        let left: f64 = self.residual(y).iter().map(|v| v * v).sum();
        left / total.max(f64::MIN_POSITIVE)
    }

    /// The delay within `+-range` whose torques the fit explains best, the fraction it leaves
    /// unexplained, and the fraction left at no delay: tried half a sample apart (0 among
    /// them), the best refined by a parabola.
    fn search(&self, design: &Design, series: &[Series], range: f64) -> Result<(f64, f64, f64)> {
        let step = 0.5 * series.iter().map(|s| s.dt).fold(f64::INFINITY, f64::min);
        let half = (range / step).floor() as i64;
        let left =
            |d: f64| self.unexplained(&design.weighted(&design.torques(series, d), &self.weights));
        let tried: Vec<(f64, f64)> = (-half..=half)
            .map(|i| {
                let d = i as f64 * step;
                (d, left(d))
            })
            .collect();
        let best = (0..tried.len())
            .min_by(|&a, &b| tried[a].1.total_cmp(&tried[b].1))
            .expect("at least one delay tried");
        if best == 0 || best + 1 == tried.len() {
            return Err(Error::numerical(
                "torque delay",
                format!(
                    "the fit is best at the edge of the delays tried (+-{:.1} ms): the torques do not follow the positions by any delay within it",
                    1e3 * range
                ),
            ));
        }
        let (a, b, c) = (tried[best - 1].1, tried[best].1, tried[best + 1].1);
        let curvature = a - 2.0 * b + c;
        let offset = if curvature > 0.0 {
            (0.5 * (a - c) / curvature).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let delay = tried[best].0 + offset * step;
        Ok((delay, left(delay), tried[half as usize].1))
    }

    /// The standard error of `delay`: the residual's projection on the torques' rate, summed
    /// over blocks of [`BLOCK`] s of each recording and the blocks taken as independent.
    fn stderr(&self, design: &Design, series: &[Series], delay: f64) -> f64 {
        let h = 0.25 * series.iter().map(|s| s.dt).fold(f64::INFINITY, f64::min);
        let y = |d: f64| design.weighted(&design.torques(series, d), &self.weights);
        let e = self.residual(&y(delay));
        let (up, down) = (y(delay + h), y(delay - h));
        let rate: Vec<f64> = up
            .iter()
            .zip(&down)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        let z = self.residual(&rate);
        let zz: f64 = z.iter().map(|v| v * v).sum();
        let mut blocks: std::collections::BTreeMap<(usize, i64), f64> = Default::default();
        for ((r, z), e) in design.rows.iter().zip(&z).zip(&e) {
            let block = (r.sample as f64 * series[r.series].dt / BLOCK).floor() as i64;
            *blocks.entry((r.series, block)).or_default() += z * e;
        }
        let g = blocks.len() as f64;
        let sum: f64 = blocks.values().map(|s| s * s).sum();
        let dof = (self.rows as f64 / (self.rows - self.rank.min(self.rows - 1)) as f64).max(1.0);
        (sum * dof * g / (g - 1.0).max(1.0)).sqrt() / zz.max(f64::MIN_POSITIVE)
    }
}

#[cfg(test)]
mod tests {
    use super::read_at;

    /// The cubic reads a cubic exactly between samples.
    #[test]
    fn the_interpolation_is_exact_on_a_cubic() {
        let f = |x: f64| 0.3 * x * x * x - x * x + 2.0 * x - 1.0;
        let values: Vec<f64> = (0..10).map(|i| f(i as f64)).collect();
        for at in [1.0, 2.25, 4.5, 6.99] {
            assert!((read_at(&values, 1, 0, at) - f(at)).abs() < 1e-9, "{at}");
        }
    }
}
