//! Averaging a log over the periods of a periodic excitation (Swevers et al. 2007), in place
//! of the low-pass filter and numerical derivatives of [`crate::preprocess`].
//!
//! A Fourier excitation repeats every period `T`, and so does everything the robot does while
//! it runs one; only the noise differs from period to period. Each whole period of the log is
//! resampled onto `M = round(T rate)` points and projected onto the harmonics `k / T` (a
//! discrete Fourier series, exact on the grid):
//! - the positions onto the excitation's own `L` harmonics, from which the velocities and
//!   accelerations are the series' exact derivatives (`i k w` and `-(k w)^2` a harmonic), free
//!   of the lag and noise gain of numerical differences;
//! - the torques onto the harmonics up to the cutoff (`floor(cutoff T)`, at least `L`): a
//!   low-pass without a transient, whose Coulomb column is `sign(qd)` projected alike.
//!
//! The mean of the periods' coefficients is the averaged period (the noise's variance divided
//! by the periods averaged); their spread about it is the noise itself, measured from the
//! data and not from a model's residuals: each signal's noise a sample within its band
//! (Parseval: `d_0^2 + 1/2 sum_k (da_k^2 + db_k^2)` a period, summed over the periods and
//! divided by `P - 1`). A model's residual beyond the averaged noise is the model's error.
//!
//! Refused or left out, never averaged in (docs/method.md, section 8e):
//! - fewer than two whole periods (nothing tells noise from motion);
//! - a period holding a gap of the log (left out, said);
//! - a period far off the others (from 3 periods: a signal's deviation from the
//!   coefficient-wise median of the periods beyond 3 times the median period's in RMS, as a
//!   run's lead-in at rest, a collision or a stop gives): left out, said;
//! - positions that differ from period to period by more than a tenth of their motion: the
//!   log does not repeat with that period (a wrong period, or not the excitation), an error
//!   naming the joint.

use serde::{Deserialize, Serialize};

use crate::error::{shown, shown5, Error, Result};
use crate::recording::Recording;

/// What [`average_periods`] averages: the excitation's period and harmonics, and where in the
/// log its periods lie.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodOptions {
    /// The excitation's period (s): `1 / base frequency`, within 0.001 to 1,000 s.
    pub period: f64,
    /// The harmonics of the base frequency the positions hold (the excitation's `L`, 1 to
    /// [`crate::limits::MAX_HARMONICS`]): the positions are projected onto harmonics 0 to `L`.
    pub harmonics: usize,
    /// The log's time (s) at which a period starts (the excitation's `t = 0`, modulo the
    /// period); None: the log's first sample. [`crate::excitation_start`] finds it from the
    /// excitation.
    pub start: Option<f64>,
    /// Whole periods left out after `start` (a lead-in, the first period's transient).
    pub skip: usize,
    /// At most this many periods averaged (None: every whole period in the log).
    pub count: Option<usize>,
}

impl PeriodOptions {
    /// Periods of `period` s with `harmonics` harmonics, from the log's first sample, every
    /// whole period averaged.
    pub fn new(period: f64, harmonics: usize) -> Self {
        Self {
            period,
            harmonics,
            start: None,
            skip: 0,
            count: None,
        }
    }
}

/// A period of the log left out of the average, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeftOutPeriod {
    /// The period's place among the log's whole periods from the start (0-based, `skip`
    /// counted).
    pub period: usize,
    /// Its start and end in the log's time (s).
    pub t0: f64,
    pub t1: f64,
    /// Why: a gap, or the signal and joint far off the other periods.
    pub reason: String,
}

/// What averaging over the periods found, kept with the recording it made
/// ([`Recording::period_average`]) and with a model fitted to it.
///
/// Noise levels are per joint, of one period's samples within the band kept (rad, rad/s,
/// rad/s^2, N m; m and N for a prismatic joint); the averaged recording's are these over
/// `sqrt(periods)` ([`PeriodAverage::averaged_torque_noise`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodAverage {
    /// The period (s).
    pub period: f64,
    /// The log's time (s) at which the first period used starts (after `skip`).
    pub start: f64,
    /// The periods averaged.
    pub periods: usize,
    /// Harmonics kept in the positions (and so in the velocities and accelerations).
    pub harmonics: usize,
    /// Harmonics kept in the torques (and the Coulomb column).
    pub torque_harmonics: usize,
    /// Samples of the averaged period (before decimation).
    pub samples: usize,
    pub position_noise: Vec<f64>,
    pub velocity_noise: Vec<f64>,
    pub acceleration_noise: Vec<f64>,
    pub torque_noise: Vec<f64>,
    /// Per joint, the RMS of the averaged positions' content between harmonic `L + 1` and
    /// the torques' band (rad): motion the harmonics kept leave out (tracking errors at
    /// higher frequencies), which the regressor then does not see.
    pub position_beyond: Vec<f64>,
    /// Periods left out, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out: Vec<LeftOutPeriod>,
}

impl PeriodAverage {
    /// The noise of the averaged torques a sample (N m a joint): one period's over
    /// `sqrt(periods)`.
    pub fn averaged_torque_noise(&self) -> Vec<f64> {
        let s = (self.periods as f64).sqrt();
        self.torque_noise.iter().map(|x| x / s).collect()
    }

    /// Per joint, a fit's residual RMS (N m, of the averaged torques) against the averaged
    /// torques' noise: their ratio (1 where the fit leaves only noise), and the model's own
    /// error `sqrt(max(residual^2 - noise^2, 0))` (N m). The fit's parameters take up a small
    /// share of the noise (their count over the `2 H + 1` values a period and joint holds), so
    /// a ratio a little below 1 is noise too.
    pub fn model_error(&self, residual_rms: &[f64]) -> Vec<(f64, f64)> {
        (residual_rms.iter().zip(self.averaged_torque_noise()))
            .map(|(r, n)| (r / n, (r * r - n * n).max(0.0).sqrt()))
            .collect()
    }

    /// What is wrong with it for `n` joints (a document edited by hand); None where nothing.
    pub(crate) fn problem(&self, n: usize) -> Option<String> {
        let lists = [
            ("position_noise", &self.position_noise),
            ("velocity_noise", &self.velocity_noise),
            ("acceleration_noise", &self.acceleration_noise),
            ("torque_noise", &self.torque_noise),
            ("position_beyond", &self.position_beyond),
        ];
        if let Some((name, v)) = lists.iter().find(|(_, v)| v.len() != n) {
            return Some(format!(
                "{name}: {} values, expected one a joint ({n})",
                v.len()
            ));
        }
        if let Some((name, x)) = lists.iter().find_map(|(name, v)| {
            v.iter()
                .find(|x| !(x.is_finite() && **x >= 0.0))
                .map(|x| (name, x))
        }) {
            return Some(format!("{name}: {x}, expected finite and >= 0"));
        }
        let (low, high) = PERIOD_RANGE;
        if !(self.period.is_finite()
            && (low..=high).contains(&self.period)
            && self.start.is_finite())
        {
            return Some(format!(
                "period {} s from t = {} s; expected a period of {low} to {high} s, a finite start",
                shown(self.period),
                shown(self.start)
            ));
        }
        if self.periods < 2
            || self.harmonics == 0
            || self.torque_harmonics < self.harmonics
            || self.samples <= 2 * self.torque_harmonics
        {
            return Some(format!(
                "{} periods, {} and {} harmonics over {} samples; expected at least 2 periods, harmonics >= 1 and torque harmonics no fewer, below half the samples",
                self.periods, self.harmonics, self.torque_harmonics, self.samples
            ));
        }
        (self.left_out.iter().enumerate())
            .find(|(_, p)| !(p.t0.is_finite() && p.t1 > p.t0) || p.reason.len() > 4096)
            .map(|(i, _)| format!("left_out[{i}]: expected t0 < t1, finite, and a short reason"))
    }
}

/// The periods averaged may last 0.001 to 1,000 s (base frequencies of 1 kHz to 1 mHz, as
/// [`crate::limits::BASE_FREQUENCY`]).
pub const PERIOD_RANGE: (f64, f64) = (1e-3, 1e3);

/// The most multiply-adds the projections may take (samples of the log's periods times
/// harmonics): about ten seconds' work. A 10 s period at 1 kHz with 10 Hz of torque band
/// takes 10^6 for each period and joint.
pub const MAX_PROJECTION_WORK: f64 = 2e10;

/// A period's deviation from the periods' median beyond this many times the median period's
/// (in RMS) leaves it out.
pub const OUTLIER_RATIO: f64 = 3.0;

/// Positions that differ from period to period by more than this fraction of their motion
/// (RMS) do not repeat with the period.
pub const MAX_POSITION_SPREAD: f64 = 0.1;

/// The averaged period of `rec` (screened as [`crate::preprocess::preprocess`] screens, at
/// least two whole periods long): `M = round(period rate)` samples from the first period's
/// start, every `decimate`-th kept (`rate`, `cutoff` and `decimate` from `options`; `cutoff`
/// None keeps every harmonic the grid holds), `q`, `qd`, `qdd` from the positions' first
/// `harmonics` harmonics, `tau` and [`Recording::coulomb`] from the torques' harmonics up to
/// the cutoff, and [`Recording::period_average`] saying what was found. The time `t` is the
/// log's over the first period used.
///
/// Errors: options out of range, naming them; fewer than 2 whole periods left (naming the
/// log's span and the periods left out); positions that do not repeat (naming the joint and
/// their spread against their motion); work beyond [`MAX_PROJECTION_WORK`]; Ctrl-C.
pub fn average_periods(
    rec: &Recording,
    rate: f64,
    cutoff: Option<f64>,
    decimate: usize,
    p: &PeriodOptions,
) -> Result<Recording> {
    let n = rec.n;
    let layout = Layout::of(rec, rate, cutoff, decimate, p)?;
    let (m, h_q, h_tau) = (layout.samples, p.harmonics, layout.torque_harmonics);
    let table = Table::new(m);
    let column =
        |x: &[f64], j: usize| -> Vec<f64> { (0..rec.len()).map(|i| x[i * n + j]).collect() };
    let q_cols: Vec<Vec<f64>> = (0..n).map(|j| column(&rec.q, j)).collect();
    let tau_cols: Vec<Vec<f64>> = (0..n).map(|j| column(&rec.tau, j)).collect();
    // each period's coefficients: [period][joint] -> positions (to h_tau, to see beyond L) and torques
    let mut coef_q = Vec::with_capacity(layout.periods.len());
    let mut coef_tau = Vec::with_capacity(layout.periods.len());
    for &(_, a) in &layout.periods {
        crate::interrupt::check("period averaging")?;
        let grid: Vec<f64> = (0..m).map(|i| a + i as f64 * p.period / m as f64).collect();
        let project = |cols: &[Vec<f64>], h: usize| -> Vec<Vec<f64>> {
            cols.iter()
                .map(|x| table.project(&crate::signal::interpolate(&rec.t, x, &grid), h))
                .collect()
        };
        coef_q.push(project(&q_cols, h_tau));
        coef_tau.push(project(&tau_cols, h_tau));
    }
    // periods far off the others, from the coefficient-wise median
    let mut left_out = layout.left_out.clone();
    let mut keep: Vec<usize> = (0..layout.periods.len()).collect();
    if keep.len() >= 3 {
        let names = ["positions", "torques"];
        let mut far: Vec<(usize, String)> = Vec::new();
        for (signal, coefs) in [&coef_q, &coef_tau].into_iter().enumerate() {
            for j in 0..n {
                let per: Vec<&[f64]> = coefs.iter().map(|c| c[j].as_slice()).collect();
                let median = median_coefficients(&per);
                let dev: Vec<f64> = per.iter().map(|c| energy(c, &median).sqrt()).collect();
                let scale = energy(&median, &vec![0.0; median.len()]).sqrt();
                let typical = median_of(&dev);
                for (k, &d) in dev.iter().enumerate() {
                    if d > OUTLIER_RATIO * typical
                        && d > 1e-9 * scale
                        && !far.iter().any(|f| f.0 == k)
                    {
                        far.push((
                            k,
                            format!(
                                "joint {}'s {} {} RMS off the periods' median, {} times the median period's",
                                j + 1,
                                names[signal],
                                shown5(d),
                                shown5(d / typical.max(f64::MIN_POSITIVE))
                            ),
                        ));
                    }
                }
            }
        }
        far.sort_by_key(|f| f.0);
        for (k, reason) in far {
            let (index, a) = layout.periods[k];
            left_out.push(LeftOutPeriod {
                period: index,
                t0: a,
                t1: a + p.period,
                reason,
            });
            keep.retain(|&x| x != k);
        }
        left_out.sort_by_key(|l| l.period);
    }
    if keep.len() < 2 {
        return Err(too_few(rec, &layout, &left_out, p));
    }
    let count = keep.len();
    let mean = |coefs: &[Vec<Vec<f64>>], j: usize| -> Vec<f64> {
        let len = coefs[0][j].len();
        (0..len)
            .map(|c| keep.iter().map(|&k| coefs[k][j][c]).sum::<f64>() / count as f64)
            .collect()
    };
    // each signal's noise a sample of one period within its band, from the periods' spread
    // about their mean, weighted a harmonic by `weight(k)` (a derivative's `(k w)^2`)
    let noise = |coefs: &[Vec<Vec<f64>>],
                 j: usize,
                 h: usize,
                 mean: &[f64],
                 weight: &dyn Fn(usize) -> f64|
     -> f64 {
        let sum: f64 = keep
            .iter()
            .map(|&k| weighted_energy(&coefs[k][j][..2 * h + 1], &mean[..2 * h + 1], weight))
            .sum();
        (sum / (count - 1) as f64).sqrt()
    };
    let w = std::f64::consts::TAU / p.period;
    let one = |_k: usize| 1.0;
    let (mut pos_noise, mut vel_noise, mut acc_noise, mut tau_noise, mut beyond) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    let mut q_mean = Vec::with_capacity(n);
    let mut tau_mean = Vec::with_capacity(n);
    for j in 0..n {
        let qm = mean(&coef_q, j);
        let tm = mean(&coef_tau, j);
        pos_noise[j] = noise(&coef_q, j, h_q, &qm, &one);
        vel_noise[j] = noise(&coef_q, j, h_q, &qm, &|k| (k as f64 * w).powi(2));
        acc_noise[j] = noise(&coef_q, j, h_q, &qm, &|k| (k as f64 * w).powi(4));
        tau_noise[j] = noise(&coef_tau, j, h_tau, &tm, &one);
        let zero = vec![0.0; qm.len()];
        beyond[j] = weighted_energy(&qm, &zero, &|k| if k > h_q { 1.0 } else { 0.0 }).sqrt();
        // the positions' motion (without their mean) against their spread from period to period
        let motion = weighted_energy(&qm[..2 * h_q + 1], &zero[..2 * h_q + 1], &|k| {
            if k > 0 {
                1.0
            } else {
                0.0
            }
        })
        .sqrt();
        let spread = noise(&coef_q, j, h_tau, &qm, &one);
        if motion > 0.0 && spread > MAX_POSITION_SPREAD * motion {
            return Err(Error::Recording {
                recording: rec.name.clone(),
                message: format!(
                    "joint {}'s positions differ from period to period by {} RMS, {:.0} % of their motion ({} RMS) over the {count} periods of {} s from t = {} s: the log does not repeat with that period. Is the period the excitation's (its base frequency's inverse), and did the robot run the excitation through these periods (a start, skip_periods or --skip-periods past a lead-in)?",
                    j + 1,
                    shown5(spread),
                    100.0 * spread / motion,
                    shown5(motion),
                    shown5(p.period),
                    shown5(layout.periods[keep[0]].1)
                ),
            });
        }
        q_mean.push(qm);
        tau_mean.push(tm);
    }
    // the averaged period, from its coefficients
    let rows: Vec<usize> = (0..m).step_by(decimate).collect();
    let k_out = rows.len();
    let (mut q, mut qd, mut qdd, mut tau, mut coulomb) = (
        vec![0.0; k_out * n],
        vec![0.0; k_out * n],
        vec![0.0; k_out * n],
        vec![0.0; k_out * n],
        vec![0.0; k_out * n],
    );
    for j in 0..n {
        crate::interrupt::check("period averaging")?;
        let (x, v, acc) = table.series(&q_mean[j], h_q, w);
        let sign: Vec<f64> = v
            .iter()
            .map(|&v| crate::direct::parameters::sign0(v))
            .collect();
        let c = table.project(&sign, h_tau);
        let c = table.series(&c, h_tau, w).0;
        let t = table.series(&tau_mean[j], h_tau, w).0;
        for (r, &i) in rows.iter().enumerate() {
            q[r * n + j] = x[i];
            qd[r * n + j] = v[i];
            qdd[r * n + j] = acc[i];
            tau[r * n + j] = t[i];
            coulomb[r * n + j] = c[i];
        }
    }
    let first = layout.periods[keep[0]].1;
    let t: Vec<f64> = rows
        .iter()
        .map(|&i| first + i as f64 * p.period / m as f64)
        .collect();
    let out = Recording::new(
        format!("{} (averaged over {count} periods)", rec.name),
        n,
        t,
        q,
        tau,
        Some(qd),
        Some(qdd),
    )?;
    Ok(Recording {
        experiment: rec.experiment.clone(),
        coulomb: Some(coulomb),
        period_average: Some(PeriodAverage {
            period: p.period,
            start: first,
            periods: count,
            harmonics: h_q,
            torque_harmonics: h_tau,
            samples: m,
            position_noise: pos_noise,
            velocity_noise: vel_noise,
            acceleration_noise: acc_noise,
            torque_noise: tau_noise,
            position_beyond: beyond,
            left_out,
        }),
        ..out
    })
}

/// The warning for what averaging found in the log `log` (joints named `joints`, or numbered
/// where empty): periods left out, and positions with motion beyond the harmonics kept. None
/// where neither.
pub fn warning(average: &Option<PeriodAverage>, log: &str, joints: &[String]) -> Option<String> {
    let a = average.as_ref()?;
    let name = |j: usize| {
        joints
            .get(j)
            .cloned()
            .unwrap_or_else(|| format!("joint {}", j + 1))
    };
    let mut said = Vec::new();
    if !a.left_out.is_empty() {
        let list: Vec<String> = (a.left_out.iter().take(5))
            .map(|l| {
                format!(
                    "period {} (t = {} to {} s): {}",
                    l.period + 1,
                    shown5(l.t0),
                    shown5(l.t1),
                    l.reason
                )
            })
            .collect();
        let more = a.left_out.len().saturating_sub(5);
        said.push(format!(
            "{} of its periods left out of the average ({}{}); {} averaged",
            a.left_out.len(),
            list.join("; "),
            if more > 0 {
                format!("; {more} more")
            } else {
                String::new()
            },
            a.periods
        ));
    }
    // content beyond the harmonics kept: a twentieth of the noise's or more, and 1e-4 rad
    let beyond: Vec<String> = (0..a.position_beyond.len())
        .filter(|&j| {
            a.position_beyond[j] > 1e-4 && a.position_beyond[j] > 5.0 * a.position_noise[j]
        })
        .map(|j| format!("{} {} rad RMS", name(j), shown5(a.position_beyond[j])))
        .collect();
    if !beyond.is_empty() {
        said.push(format!(
            "the averaged positions move beyond the {} harmonics kept ({}): the regressor is computed from the positions' first {} harmonics and does not see that motion (the robot's tracking error at higher frequencies, or an excitation of more harmonics than given)",
            a.harmonics,
            beyond.join(", "),
            a.harmonics
        ));
    }
    (!said.is_empty()).then(|| format!("{log}: {}", said.join("; ")))
}

/// Where the periods of a log lie and how they are sampled.
struct Layout {
    /// Samples a period.
    samples: usize,
    torque_harmonics: usize,
    /// The periods to project: their place among the whole periods from the start, and their
    /// start in the log's time.
    periods: Vec<(usize, f64)>,
    /// Periods left out before projecting (gaps).
    left_out: Vec<LeftOutPeriod>,
    /// The whole periods from the start (after `skip`).
    whole: usize,
    from: f64,
}

impl Layout {
    fn of(
        rec: &Recording,
        rate: f64,
        cutoff: Option<f64>,
        decimate: usize,
        p: &PeriodOptions,
    ) -> Result<Self> {
        let (low, high) = PERIOD_RANGE;
        let invalid = |message: String| Error::InvalidArgument {
            argument: "period averaging".into(),
            message,
        };
        if !(p.period.is_finite() && (low..=high).contains(&p.period)) {
            return Err(invalid(format!(
                "a period of {} s; expected {low} to {high} s",
                shown(p.period)
            )));
        }
        let max_h = crate::limits::MAX_HARMONICS;
        if !(1..=max_h).contains(&p.harmonics) {
            return Err(invalid(format!(
                "{} harmonics; expected 1 to {max_h} (the excitation's)",
                p.harmonics
            )));
        }
        if p.start.is_some_and(|s| !s.is_finite())
            || p.skip > 1_000_000
            || p.count.is_some_and(|c| c < 2)
        {
            return Err(invalid(format!(
                "start {}, skip {}, count {:?}; expected a finite start, at most 10^6 periods skipped, and at least 2 periods averaged",
                p.start.map_or("none".into(), shown),
                p.skip,
                p.count
            )));
        }
        if !(rate.is_finite() && rate > 0.0) || decimate == 0 {
            return Err(invalid(format!(
                "rate {} Hz, decimate {decimate}; expected rate > 0, decimate >= 1",
                shown(rate)
            )));
        }
        let m = crate::limits::sample_count("period averaging", p.period, rate, 1 + 4 * rec.n)? - 1;
        let nyquist = m.saturating_sub(1) / 2;
        let torque_harmonics = match cutoff {
            None => nyquist,
            Some(c) if c.is_finite() && c > 0.0 && c < 0.5 * rate => {
                ((c * p.period + 1e-9).floor() as usize).max(p.harmonics)
            }
            Some(c) => {
                return Err(invalid(format!(
                    "a cutoff of {} Hz at {} Hz; expected 0 < cutoff < rate / 2",
                    shown(c),
                    shown(rate)
                )))
            }
        };
        if torque_harmonics > nyquist || m < 4 {
            return Err(invalid(format!(
                "{m} samples a period of {} s at {} Hz hold harmonics up to {nyquist}, and {torque_harmonics} are asked for (the excitation's {} and those below the cutoff): a higher rate holds more",
                shown5(p.period),
                shown(rate),
                p.harmonics
            )));
        }
        let (t0, t1) = (rec.t[0], rec.t[rec.len() - 1]);
        let start = p.start.unwrap_or(t0);
        let dt = median_interval(rec);
        let from = start + p.skip as f64 * p.period;
        if start < t0 - 0.5 * dt {
            return Err(Error::Recording {
                recording: rec.name.clone(),
                message: format!(
                    "the periods start at t = {} s, before the log's first sample ({} s)",
                    shown5(start),
                    shown5(t0)
                ),
            });
        }
        // a period is whole where its grid's last point, a grid step before the next period,
        // lies within the log
        let fits = ((t1 - from + p.period / m as f64) / p.period + 1e-9).floor();
        let whole = if fits.is_finite() && fits > 0.0 {
            fits.min(1e9) as usize
        } else {
            0
        };
        let wanted = p.count.map_or(whole, |c| c.min(whole));
        let work = (wanted * m) as f64 * (2 * torque_harmonics + 1) as f64 * 2.0 * rec.n as f64;
        if work > MAX_PROJECTION_WORK {
            return Err(invalid(format!(
                "{wanted} periods of {m} samples onto {torque_harmonics} harmonics for {} joints take {work:.2e} multiply-adds, more than {MAX_PROJECTION_WORK:.0e}: a lower cutoff, rate or count of periods takes less",
                rec.n
            )));
        }
        crate::limits::check_values("period averaging", (m * (1 + 4 * rec.n)) as f64, || {
            format!("a period of {m} samples")
        })?;
        let gaps = crate::preprocess::gap_positions(rec);
        let mut periods = Vec::new();
        let mut left_out = Vec::new();
        for k in 0..wanted {
            let a = from + k as f64 * p.period;
            let b = a + p.period;
            // a gap whose interval overlaps the period
            match gaps.iter().find(|&&i| rec.t[i] < b && rec.t[i + 1] > a) {
                Some(&i) => left_out.push(LeftOutPeriod {
                    period: k + p.skip,
                    t0: a,
                    t1: b,
                    reason: format!(
                        "a gap of {} s after t = {} s",
                        shown5(rec.t[i + 1] - rec.t[i]),
                        shown5(rec.t[i])
                    ),
                }),
                None => periods.push((k + p.skip, a)),
            }
        }
        let layout = Self {
            samples: m,
            torque_harmonics,
            periods,
            left_out,
            whole,
            from,
        };
        if layout.periods.len() < 2 {
            return Err(too_few(rec, &layout, &layout.left_out, p));
        }
        Ok(layout)
    }
}

/// The error for fewer than two periods left to average.
fn too_few(
    rec: &Recording,
    layout: &Layout,
    left_out: &[LeftOutPeriod],
    p: &PeriodOptions,
) -> Error {
    let reasons: Vec<String> = (left_out.iter().take(3))
        .map(|l| format!("period {}: {}", l.period + 1, l.reason))
        .collect();
    Error::Recording {
        recording: rec.name.clone(),
        message: format!(
            "it holds {} whole periods of {} s from t = {} s (its samples run from {} to {} s){}; at least 2 are needed to average them and to tell their noise from their motion",
            layout.whole,
            shown5(p.period),
            shown5(layout.from),
            shown5(rec.t[0]),
            shown5(rec.t[rec.len() - 1]),
            if left_out.is_empty() {
                String::new()
            } else {
                format!(", {} of them left out ({})", left_out.len(), reasons.join("; "))
            }
        ),
    }
}

fn median_interval(rec: &Recording) -> f64 {
    let mut dt: Vec<f64> = rec.t.windows(2).map(|w| w[1] - w[0]).collect();
    median_of_mut(&mut dt)
}

fn median_of(x: &[f64]) -> f64 {
    median_of_mut(&mut x.to_vec())
}

fn median_of_mut(x: &mut [f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    x.sort_by(f64::total_cmp);
    let k = x.len();
    if k % 2 == 1 {
        x[k / 2]
    } else {
        0.5 * (x[k / 2 - 1] + x[k / 2])
    }
}

/// The coefficient-wise median of the periods' coefficients.
fn median_coefficients(per: &[&[f64]]) -> Vec<f64> {
    (0..per[0].len())
        .map(|c| median_of_mut(&mut per.iter().map(|x| x[c]).collect::<Vec<f64>>()))
        .collect()
}

/// The mean square over a period of the series `x - y` (coefficients `[a_0, a_1, b_1, ...]`),
/// by Parseval.
fn energy(x: &[f64], y: &[f64]) -> f64 {
    weighted_energy(x, y, &|_| 1.0)
}

/// [`energy`] with harmonic `k`'s share weighted by `weight(k)`.
fn weighted_energy(x: &[f64], y: &[f64], weight: &dyn Fn(usize) -> f64) -> f64 {
    let mut e = weight(0) * (x[0] - y[0]).powi(2);
    for k in 1..=(x.len() - 1) / 2 {
        let (da, db) = (x[2 * k - 1] - y[2 * k - 1], x[2 * k] - y[2 * k]);
        e += 0.5 * weight(k) * (da * da + db * db);
    }
    e
}

/// The cosines and sines of one period's grid of `m` points.
struct Table {
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl Table {
    fn new(m: usize) -> Self {
        let (sin, cos) = (0..m)
            .map(|i| (std::f64::consts::TAU * i as f64 / m as f64).sin_cos())
            .unzip();
        Self { cos, sin }
    }

    /// The Fourier coefficients `[a_0, a_1, b_1, ..., a_h, b_h]` of one period's samples `x`
    /// (`x(i) = a_0 + sum_k a_k cos(2 pi k i / m) + b_k sin(2 pi k i / m)`), exact for a
    /// series of at most `h < m / 2` harmonics.
    fn project(&self, x: &[f64], h: usize) -> Vec<f64> {
        let m = x.len();
        let mut c = Vec::with_capacity(2 * h + 1);
        c.push(x.iter().sum::<f64>() / m as f64);
        for k in 1..=h {
            let (mut a, mut b, mut idx) = (0.0, 0.0, 0usize);
            for &xi in x {
                a += xi * self.cos[idx];
                b += xi * self.sin[idx];
                idx += k;
                if idx >= m {
                    idx -= m;
                }
            }
            c.push(2.0 * a / m as f64);
            c.push(2.0 * b / m as f64);
        }
        c
    }

    /// The series of coefficients `c` (its first `h` harmonics) on the grid, with its first
    /// and second derivatives in time for the base pulsation `w` (rad/s).
    fn series(&self, c: &[f64], h: usize, w: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let m = self.cos.len();
        let (mut x, mut v, mut acc) = (vec![c[0]; m], vec![0.0; m], vec![0.0; m]);
        for k in 1..=h {
            let (a, b) = (c[2 * k - 1], c[2 * k]);
            let wk = w * k as f64;
            let mut idx = 0usize;
            for i in 0..m {
                let (co, si) = (self.cos[idx], self.sin[idx]);
                x[i] += a * co + b * si;
                v[i] += wk * (b * co - a * si);
                acc[i] -= wk * wk * (a * co + b * si);
                idx += k;
                if idx >= m {
                    idx -= m;
                }
            }
        }
        (x, v, acc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_and_series_are_exact_on_the_grid() {
        let m = 100;
        let table = Table::new(m);
        let w = std::f64::consts::TAU / 2.0;
        let f = |t: f64| 0.3 + 0.5 * (w * t).cos() - 0.2 * (3.0 * w * t).sin();
        let x: Vec<f64> = (0..m).map(|i| f(2.0 * i as f64 / m as f64)).collect();
        let c = table.project(&x, 5);
        let expected = [0.3, 0.5, 0.0, 0.0, 0.0, 0.0, -0.2, 0.0, 0.0, 0.0, 0.0];
        for (a, b) in c.iter().zip(expected) {
            assert!((a - b).abs() < 1e-14, "{c:?}");
        }
        let (y, v, acc) = table.series(&c, 5, w);
        for i in 0..m {
            let t = 2.0 * i as f64 / m as f64;
            let h = 1e-5;
            assert!((y[i] - f(t)).abs() < 1e-13);
            assert!((v[i] - (f(t + h) - f(t - h)) / (2.0 * h)).abs() < 1e-8);
            assert!((acc[i] - (f(t + h) - 2.0 * f(t) + f(t - h)) / (h * h)).abs() < 1e-4);
        }
        // Parseval: the mean square on the grid
        let ms = x.iter().map(|v| v * v).sum::<f64>() / m as f64;
        assert!((energy(&c, &[0.0; 11]) - ms).abs() < 1e-14);
    }
}
