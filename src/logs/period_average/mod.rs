//! Averaging a log over the periods of a periodic excitation (Swevers et al. 2007), in place
//! of the low-pass filter and numerical derivatives of [`crate::logs::preprocess`].
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

mod drift;
mod finding;
mod layout;
pub mod noise_colour;
mod options;
mod series;

pub use drift::{DRIFT_RATIO, MIN_COEFFICIENTS};
pub use finding::{LeftOutPeriod, PeriodAverage};
pub use options::{PeriodOptions, MAX_PERIODS, MAX_PROJECTION_WORK, PERIOD_RANGE};

use crate::error::{shown5, Error, Result};
use crate::logs::recording::Recording;
use layout::{too_few, Layout};
use series::{energy, median_coefficients, median_of, weighted_energy, weighted_power, Table};

/// A period's deviation from the periods' median beyond this many times the median period's
/// (in RMS) leaves it out.
pub const OUTLIER_RATIO: f64 = 3.0;

/// Positions that differ from period to period by more than this fraction of their motion
/// (RMS) do not repeat with the period.
pub const MAX_POSITION_SPREAD: f64 = 0.1;

/// The averaged period of `rec` (screened as [`crate::logs::preprocess::preprocess`] screens, at
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
    let (coef_q, coef_tau) = period_coefficients(rec, &layout, &table, p)?;
    let (keep, left_out) = leave_out_far_periods(&layout, &coef_q, &coef_tau, n, p);
    if keep.len() < 2 {
        return Err(too_few(rec, &layout, &left_out, p));
    }
    let count = keep.len();
    let w = std::f64::consts::TAU / p.period;
    let spread = Spread::of(rec, &layout, p, &keep, &coef_q, &coef_tau)?;
    let rows: Vec<usize> = (0..m).step_by(decimate).collect();
    let k_out = rows.len();
    let [q, qd, qdd, tau, coulomb] = averaged_signals(&table, &spread, &rows, n, h_q, h_tau, w)?;
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
    let Spread {
        pos_noise,
        vel_noise,
        acc_noise,
        tau_noise,
        beyond,
        drift,
        tilt,
        ..
    } = spread;
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
            kept_samples: k_out,
            position_noise: pos_noise,
            velocity_noise: vel_noise,
            acceleration_noise: acc_noise,
            torque_noise: tau_noise,
            position_beyond: beyond,
            torque_drift: drift,
            torque_noise_tilt: tilt,
            left_out,
        }),
        ..out
    })
}

/// Per period of `layout`, per joint, the Fourier coefficients of the positions and the
/// torques up to the torques' harmonics (positions that far to see beyond the harmonics kept).
#[allow(clippy::type_complexity)]
fn period_coefficients(
    rec: &Recording,
    layout: &Layout,
    table: &Table,
    p: &PeriodOptions,
) -> Result<(Vec<Vec<Vec<f64>>>, Vec<Vec<Vec<f64>>>)> {
    let (n, m, h_tau) = (rec.n, layout.samples, layout.torque_harmonics);
    let column =
        |x: &[f64], j: usize| -> Vec<f64> { (0..rec.len()).map(|i| x[i * n + j]).collect() };
    let q_cols: Vec<Vec<f64>> = (0..n).map(|j| column(&rec.q, j)).collect();
    let tau_cols: Vec<Vec<f64>> = (0..n).map(|j| column(&rec.tau, j)).collect();
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
    Ok((coef_q, coef_tau))
}

/// The periods kept and those left out: the layout's, and periods far off the others (from
/// the coefficient-wise median, with at least 3 periods).
fn leave_out_far_periods(
    layout: &Layout,
    coef_q: &[Vec<Vec<f64>>],
    coef_tau: &[Vec<Vec<f64>>],
    n: usize,
    p: &PeriodOptions,
) -> (Vec<usize>, Vec<LeftOutPeriod>) {
    let mut left_out = layout.left_out.clone();
    let mut keep: Vec<usize> = (0..layout.periods.len()).collect();
    if keep.len() >= 3 {
        let names = [("positions", "rad"), ("torques", "N m")];
        let mut far: Vec<(usize, String)> = Vec::new();
        for (signal, coefs) in [coef_q, coef_tau].into_iter().enumerate() {
            for j in 0..n {
                let per: Vec<&[f64]> = coefs.iter().map(|c| c[j].as_slice()).collect();
                let median = median_coefficients(&per);
                let dev: Vec<f64> = per.iter().map(|c| energy(c, &median).sqrt()).collect();
                let scale = weighted_power(&median, &|_| 1.0).sqrt();
                let typical = median_of(&dev);
                for (k, &d) in dev.iter().enumerate() {
                    if d > OUTLIER_RATIO * typical
                        && d > 1e-9 * scale
                        && !far.iter().any(|f| f.0 == k)
                    {
                        far.push((
                            k,
                            format!(
                                "joint {}'s {} {} {} RMS off the periods' median, {} times the median period's",
                                j + 1,
                                names[signal].0,
                                shown5(d),
                                names[signal].1,
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
    (keep, left_out)
}

/// The kept periods' mean coefficients per joint and their spread: each signal's noise (a
/// sample of one period within its band), the torques' drift and noise colour, and the
/// positions' motion beyond the harmonics kept.
struct Spread {
    q_mean: Vec<Vec<f64>>,
    tau_mean: Vec<Vec<f64>>,
    pos_noise: Vec<f64>,
    vel_noise: Vec<f64>,
    acc_noise: Vec<f64>,
    tau_noise: Vec<f64>,
    beyond: Vec<f64>,
    drift: Vec<Option<f64>>,
    tilt: Vec<Option<f64>>,
}

impl Spread {
    /// The spread of the periods `keep`; refuses positions that do not repeat and sums of
    /// squares past f64's range.
    fn of(
        rec: &Recording,
        layout: &Layout,
        p: &PeriodOptions,
        keep: &[usize],
        coef_q: &[Vec<Vec<f64>>],
        coef_tau: &[Vec<Vec<f64>>],
    ) -> Result<Spread> {
        let (n, h_q, h_tau) = (rec.n, p.harmonics, layout.torque_harmonics);
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
        let mut drift = vec![None; n];
        let mut tilt = vec![None; n];
        let mut q_mean = Vec::with_capacity(n);
        let mut tau_mean = Vec::with_capacity(n);
        for j in 0..n {
            let qm = mean(coef_q, j);
            let tm = mean(coef_tau, j);
            pos_noise[j] = noise(coef_q, j, h_q, &qm, &one);
            vel_noise[j] = noise(coef_q, j, h_q, &qm, &|k| (k as f64 * w).powi(2));
            acc_noise[j] = noise(coef_q, j, h_q, &qm, &|k| (k as f64 * w).powi(4));
            tau_noise[j] = noise(coef_tau, j, h_tau, &tm, &one);
            let per: Vec<&[f64]> = keep.iter().map(|&k| coef_tau[k][j].as_slice()).collect();
            let place: Vec<f64> = keep.iter().map(|&k| layout.periods[k].0 as f64).collect();
            drift[j] = drift::trend_ratio(&per, &place);
            tilt[j] = noise_colour::tilt(coef_tau, keep, j, h_tau, &tm);
            beyond[j] = weighted_power(&qm, &|k| if k > h_q { 1.0 } else { 0.0 }).sqrt();
            // the positions' motion (without their mean) against their spread from period to period
            let motion =
                weighted_power(&qm[..2 * h_q + 1], &|k| if k > 0 { 1.0 } else { 0.0 }).sqrt();
            let spread = noise(coef_q, j, h_tau, &qm, &one);
            if motion > 0.0 && spread > MAX_POSITION_SPREAD * motion {
                return Err(Error::recording(
                    rec.name.clone(),
                    format!(
                        "joint {}'s positions differ from period to period by {} rad RMS, {:.0} % of their motion ({} rad RMS) over the {count} periods of {} s from t = {} s: the log does not repeat with that period. Is the period the excitation's (its base frequency's inverse), and did the robot run the excitation through these periods (a start, skip_periods or --skip-periods past a lead-in)?",
                        j + 1,
                        shown5(spread),
                        100.0 * spread / motion,
                        shown5(motion),
                        shown5(p.period),
                        shown5(layout.periods[keep[0]].1)
                    ),
                ));
            }
            // sums of squares past f64's range (values near 1e300) cannot be vouched for
            let levels = [
                ("positions", pos_noise[j]),
                ("velocities", vel_noise[j]),
                ("accelerations", acc_noise[j]),
                ("torques", tau_noise[j]),
                ("positions beyond the harmonics kept", beyond[j]),
                ("positions' motion", motion),
            ];
            if let Some((what, x)) = levels.iter().find(|(_, x)| !x.is_finite()) {
                return Err(Error::numerical(
                    "period averaging",
                    format!(
                        "joint {}'s {what}: their spread from period to period is {x}, past f64's range: the log's values are too large for f64 arithmetic (near 1e300?); rescale the log to SI units",
                        j + 1
                    ),
                ));
            }
            q_mean.push(qm);
            tau_mean.push(tm);
        }
        Ok(Spread {
            q_mean,
            tau_mean,
            pos_noise,
            vel_noise,
            acc_noise,
            tau_noise,
            beyond,
            drift,
            tilt,
        })
    }
}

/// The averaged period at the samples `rows` of the period's grid, from the mean coefficients:
/// positions, velocities and accelerations (to `h_q`), torques and the sign of the velocity's
/// Coulomb column (to `h_tau`), row-major.
fn averaged_signals(
    table: &Table,
    spread: &Spread,
    rows: &[usize],
    n: usize,
    h_q: usize,
    h_tau: usize,
    w: f64,
) -> Result<[Vec<f64>; 5]> {
    let (q_mean, tau_mean) = (&spread.q_mean, &spread.tau_mean);
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
        let sign: Vec<f64> = v.iter().map(|&v| crate::parameters::sign0(v)).collect();
        let c = table.values(&table.project(&sign, h_tau), h_tau);
        let t = table.values(&tau_mean[j], h_tau);
        for (r, &i) in rows.iter().enumerate() {
            q[r * n + j] = x[i];
            qd[r * n + j] = v[i];
            qdd[r * n + j] = acc[i];
            tau[r * n + j] = t[i];
            coulomb[r * n + j] = c[i];
        }
    }
    Ok([q, qd, qdd, tau, coulomb])
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
    let drifting: Vec<String> = (a.torque_drift.iter().enumerate())
        .filter_map(|(j, f)| {
            f.filter(|f| *f > DRIFT_RATIO)
                .map(|f| format!("{} (F = {})", name(j), shown5(f)))
        })
        .collect();
    if !drifting.is_empty() {
        said.push(format!(
            "its torques drift from period to period ({}: a straight line over the periods explains more of their spread than noise would): a joint warming over the run, whose friction changes, or a payload or controller that changed; the noise measured holds the drift, and the average is the periods' mean. Fewer periods, after the robot warmed up (skip_periods, --skip-periods), drift less",
            drifting.join(", ")
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
