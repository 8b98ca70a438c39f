//! Where the periods of a log lie, how they are sampled, and which a gap leaves out.

use super::finding::LeftOutPeriod;
use super::options::{PeriodOptions, MAX_PERIODS, MAX_PROJECTION_WORK, PERIOD_RANGE};
use crate::error::{shown, shown5, Error, Result};
use crate::logs::recording::Recording;

/// Where the periods of a log lie and how they are sampled.
pub(super) struct Layout {
    /// Samples a period.
    pub(super) samples: usize,
    pub(super) torque_harmonics: usize,
    /// The periods to project: their place among the whole periods from the start, and their
    /// start in the log's time.
    pub(super) periods: Vec<(usize, f64)>,
    /// Periods left out before projecting (gaps).
    pub(super) left_out: Vec<LeftOutPeriod>,
    /// The whole periods from the start (after `skip`).
    pub(super) whole: usize,
    pub(super) from: f64,
}

impl Layout {
    pub(super) fn of(
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
        let (dt, gaps) = crate::logs::gaps::gaps(rec);
        let from = start + p.skip as f64 * p.period;
        if start < t0 - 0.5 * dt {
            return Err(Error::recording(
                rec.name.clone(),
                format!(
                    "the periods start at t = {} s, before the log's first sample ({} s)",
                    shown5(start),
                    shown5(t0)
                ),
            ));
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
        if wanted > MAX_PERIODS {
            return Err(invalid(format!(
                "{wanted} whole periods of {} s to average, more than {}: give a count of periods (count, or --skip-periods and a shorter log)",
                shown5(p.period),
                MAX_PERIODS
            )));
        }
        // every period's coefficients are held: positions' and torques' for every joint
        let held = (wanted * 2 * rec.n) as f64 * (2 * torque_harmonics + 1) as f64;
        crate::limits::check_values("period averaging", held, || {
            format!("the Fourier coefficients of {wanted} periods")
        })?;
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
pub(super) fn too_few(
    rec: &Recording,
    layout: &Layout,
    left_out: &[LeftOutPeriod],
    p: &PeriodOptions,
) -> Error {
    let reasons: Vec<String> = (left_out.iter().take(3))
        .map(|l| format!("period {}: {}", l.period + 1, l.reason))
        .collect();
    Error::recording(
        rec.name.clone(),
        format!(
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
    )
}
