//! Where in a log the robot runs its Fourier excitation: the time of a period's start, and the
//! run of whole periods it follows the excitation through, for averaging over them
//! ([`crate::logs::period_average`]).
//!
//! A log of an excitation rarely starts at the excitation's `t = 0`: the logger runs before
//! the motion starts and after it ends, at rest. The excitation repeats every period `T`, so
//! its start is a shift `s` in `[0, T)`: the one whose excitation, `q_e(t - s)`, is nearest the
//! logged positions, by the median over the samples of the squared distance (robust to the
//! half of the log that may be at rest), refined by Gauss-Newton over the periods that follow
//! it. A period follows the excitation where its positions' RMS distance from it, each
//! joint's mean distance taken off (a zero offset), is below a fifth of the excitation's motion.

use crate::error::{shown5, Error, Result};
use crate::logs::recording::Recording;
use crate::trajectory::FourierTrajectory;

/// Where a log runs its excitation.
#[derive(Clone, Debug, PartialEq)]
pub struct ExcitationStart {
    /// The log's time (s) at which the first whole period it follows the excitation through
    /// starts (the excitation's `t = 0`, modulo its period).
    pub start: f64,
    /// The whole periods, one after another from `start`, that follow the excitation.
    pub periods: usize,
    /// Per joint, the RMS distance (rad, or m) of the logged positions from the excitation
    /// over those periods, each joint's mean distance (its offset) taken off.
    pub tracking_rms: Vec<f64>,
}

/// A period follows the excitation where its positions' distance from it is below this
/// fraction of the excitation's motion (RMS).
pub const MAX_TRACKING: f64 = 0.2;

/// The samples of the log the coarse search reads (evenly spread).
const SEARCH_SAMPLES: usize = 20_000;
/// Shifts of the coarse search over a period.
const SHIFTS: usize = 1_000;

/// Finds where `rec` runs the excitation `traj` (the same joints, in the same order).
///
/// Errors: joints that differ in number; a log shorter than one period; a log none of whose
/// whole periods follows the excitation (naming the best alignment's distance against the
/// motion); Ctrl-C.
pub fn excitation_start(rec: &Recording, traj: &FourierTrajectory) -> Result<ExcitationStart> {
    let al = Alignment::new(rec, traj)?;
    let shift = al.refine(al.coarse_shift()?)?;
    let periods = al.matched(shift);
    // the longest run of consecutive periods that follow it
    let (mut run, mut best_run) = ((0, 0), (0, 0));
    for (k, p) in periods.iter().enumerate() {
        if al.follows(p) {
            run = if run.1 > 0 && run.0 + run.1 == k {
                (run.0, run.1 + 1)
            } else {
                (k, 1)
            };
            if run.1 > best_run.1 {
                best_run = run;
            }
        }
    }
    if best_run.1 == 0 {
        let nearest = periods.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
        return Err(Error::recording(
            rec.name.clone(),
            format!(
                "none of its {} whole periods of {} s follows the excitation: the nearest is {} rad RMS from it (offsets taken off), against the excitation's motion of {} rad RMS (at most {} of it is taken as following). Is it a log of this excitation, with the joints in its order?",
                periods.len(),
                shown5(al.period),
                shown5(nearest),
                shown5(al.motion),
                MAX_TRACKING
            ),
        ));
    }
    let start = periods[best_run.0].0;
    let mut tracking = vec![0.0; al.n];
    for p in &periods[best_run.0..best_run.0 + best_run.1] {
        for (t, d) in tracking.iter_mut().zip(&p.1) {
            *t += d * d / best_run.1 as f64;
        }
    }
    Ok(ExcitationStart {
        start,
        periods: best_run.1,
        tracking_rms: tracking.into_iter().map(f64::sqrt).collect(),
    })
}

/// Points of the excitation's table over a period.
const GRID: usize = 4096;

/// A whole period of the log: its start, its joints' distances from the excitation and their
/// norm (rad RMS).
type Period = (f64, Vec<f64>, f64);

/// A log held against an excitation: the excitation's positions tabled over a period, its
/// motion, and the log's span and sample interval.
struct Alignment<'a> {
    rec: &'a Recording,
    traj: &'a FourierTrajectory,
    n: usize,
    period: f64,
    /// Per joint, the excitation's positions at `GRID + 1` points over a period.
    table: Vec<Vec<f64>>,
    /// The excitation's motion (rad RMS over the joints).
    motion: f64,
    /// The log's first and last times.
    t0: f64,
    t1: f64,
    /// The median sample interval: a period is whole where its last sample before the next
    /// period's first lies in the log.
    dt: f64,
    /// Every how many samples the searches read.
    stride: usize,
}

impl<'a> Alignment<'a> {
    /// Refuses joints that differ in number and a log shorter than one period.
    fn new(rec: &'a Recording, traj: &'a FourierTrajectory) -> Result<Alignment<'a>> {
        let n = rec.n;
        if traj.n() != n {
            return Err(Error::shape(
                "excitation",
                format!("{n} joints, the log's"),
                format!("{} joints", traj.n()),
            ));
        }
        let period = traj.period();
        let (t0, t1) = (rec.t[0], rec.t[rec.len() - 1]);
        if t1 - t0 < period * (1.0 - 1e-9) || (t1 - t0).is_nan() {
            return Err(Error::recording(
                rec.name.clone(),
                format!(
                    "{} s long, shorter than one period of the excitation ({} s)",
                    shown5(t1 - t0),
                    shown5(period)
                ),
            ));
        }
        let table: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                (0..=GRID)
                    .map(|i| traj.eval(j, period * i as f64 / GRID as f64).0)
                    .collect()
            })
            .collect();
        let motion = (0..n)
            .map(|j| {
                let x = &table[j][..GRID];
                let mean = x.iter().sum::<f64>() / GRID as f64;
                x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / GRID as f64
            })
            .sum::<f64>()
            .sqrt();
        Ok(Alignment {
            rec,
            traj,
            n,
            period,
            table,
            motion,
            t0,
            t1,
            dt: crate::logs::gaps::gaps(rec).0,
            stride: rec.len().div_ceil(SEARCH_SAMPLES).max(1),
        })
    }

    /// The excitation's position of joint `j` at time `t`, from the table.
    fn at(&self, j: usize, t: f64) -> f64 {
        let phase = (t / self.period).rem_euclid(1.0) * GRID as f64;
        let i = (phase.floor() as usize).min(GRID - 1);
        let w = phase - i as f64;
        self.table[j][i] + w * (self.table[j][i + 1] - self.table[j][i])
    }

    /// The coarse search: of [`SHIFTS`] shifts over a period, the one whose excitation is
    /// nearest the log by the median over its samples of the squared distance.
    fn coarse_shift(&self) -> Result<f64> {
        let (rec, n) = (self.rec, self.n);
        let samples: Vec<usize> = (0..rec.len()).step_by(self.stride).collect();
        let mut best = (f64::INFINITY, 0.0);
        let mut squares = vec![0.0; samples.len()];
        for k in 0..SHIFTS {
            if k % 100 == 0 {
                crate::interrupt::check("finding the excitation's start")?;
            }
            let s = self.period * k as f64 / SHIFTS as f64;
            for (d, &i) in squares.iter_mut().zip(&samples) {
                *d = (0..n)
                    .map(|j| (rec.q[i * n + j] - self.at(j, rec.t[i] - s)).powi(2))
                    .sum();
            }
            let mid = squares.len() / 2;
            let median = *squares.select_nth_unstable_by(mid, f64::total_cmp).1;
            if median < best.0 {
                best = (median, s);
            }
        }
        Ok(best.1)
    }

    /// The starts of the whole periods within the log for the shift `s`.
    fn boundaries(&self, s: f64) -> Vec<f64> {
        let period = self.period;
        let first = ((self.t0 - s) / period - 1e-9).ceil();
        (0..)
            .map(|k| s + (first + k as f64) * period)
            .take_while(|b| b + period <= self.t1 + 1.01 * self.dt)
            .collect()
    }

    /// The samples of the period from `a`.
    fn in_period(&self, a: f64) -> std::ops::Range<usize> {
        let t = &self.rec.t;
        t.partition_point(|&t| t < a)..t.partition_point(|&t| t < a + self.period)
    }

    /// Per joint, the RMS distance of the period from `a` from the excitation shifted by `s`,
    /// the joint's mean distance taken off.
    fn distance(&self, s: f64, a: f64) -> Vec<f64> {
        let (rec, n) = (self.rec, self.n);
        let rows = self.in_period(a);
        (0..n)
            .map(|j| {
                // at most about 2,000 samples a period
                let r: Vec<f64> = (rows.clone().step_by(rows.len().div_ceil(2000).max(1)))
                    .map(|i| rec.q[i * n + j] - self.at(j, rec.t[i] - s))
                    .collect();
                let mean = r.iter().sum::<f64>() / r.len().max(1) as f64;
                (r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / r.len().max(1) as f64).sqrt()
            })
            .collect()
    }

    /// The whole periods for the shift `s`, with their distances.
    fn matched(&self, s: f64) -> Vec<Period> {
        self.boundaries(s)
            .into_iter()
            .map(|a| {
                let d = self.distance(s, a);
                let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                (a, d, norm)
            })
            .collect()
    }

    /// Whether a period follows the excitation.
    fn follows(&self, p: &Period) -> bool {
        p.2 < MAX_TRACKING * self.motion
    }

    /// Gauss-Newton on the shift over the samples of the periods that follow it, each joint's
    /// offset taken off.
    fn refine(&self, mut shift: f64) -> Result<f64> {
        let (rec, n, period) = (self.rec, self.n, self.period);
        for _ in 0..8 {
            crate::interrupt::check("finding the excitation's start")?;
            let periods: Vec<f64> = self
                .matched(shift)
                .into_iter()
                .filter(|p| self.follows(p))
                .map(|p| p.0)
                .collect();
            let rows: Vec<usize> = periods
                .iter()
                .flat_map(|&a| self.in_period(a))
                .step_by(self.stride)
                .collect();
            if rows.is_empty() {
                break;
            }
            let (mut num, mut den) = (0.0, 0.0);
            for j in 0..n {
                let r: Vec<(f64, f64)> = rows
                    .iter()
                    .map(|&i| {
                        let (q, v, _) = self.traj.eval(j, rec.t[i] - shift);
                        (rec.q[i * n + j] - q, v)
                    })
                    .collect();
                let count = r.len() as f64;
                let (mr, mv) = r
                    .iter()
                    .fold((0.0, 0.0), |a, x| (a.0 + x.0 / count, a.1 + x.1 / count));
                // d r / d s = +v: the step that zeroes the linearised residual
                for (ri, vi) in r {
                    num += (ri - mr) * (vi - mv);
                    den += (vi - mv).powi(2);
                }
            }
            if den <= 0.0 {
                break;
            }
            let step = -num / den;
            shift = (shift + step.clamp(-0.05 * period, 0.05 * period)).rem_euclid(period);
            if step.abs() < 1e-9 * period {
                break;
            }
        }
        Ok(shift)
    }
}

/// The periods of `rec` to average for the excitation `traj` ([`crate::logs::period_average`]): its
/// period and harmonics, from the start [`excitation_start`] finds, over the whole periods
/// that follow it, `skip` of them left out first.
///
/// Errors: those of [`excitation_start`].
pub fn excitation_periods(
    rec: &Recording,
    traj: &FourierTrajectory,
    skip: usize,
) -> Result<crate::logs::period_average::PeriodOptions> {
    let found = excitation_start(rec, traj)?;
    Ok(crate::logs::period_average::PeriodOptions {
        start: Some(found.start),
        count: Some(found.periods),
        skip,
        ..crate::logs::period_average::PeriodOptions::new(traj.period(), traj.harmonics())
    })
}
