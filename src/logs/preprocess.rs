//! Preprocessing of real recordings for identification: resampling irregular timestamps onto a
//! uniform grid, zero-phase low-pass filtering, differentiation for velocity and acceleration,
//! trimming and decimation.

use crate::error::{Error, Result};
use crate::logs::gaps::{gap_positions, gaps};
pub use crate::logs::preprocess_options::PreprocessOptions;
use crate::logs::recording::Recording;
use crate::signal::{butterworth_lowpass, differentiate, filtfilt, interpolate};

/// Preprocesses a recording: takes steps of whole turns out of its positions
/// ([`crate::logs::position_wraps`], listed in the result's [`Recording::position_wraps`]), reads
/// columns logged at a lower rate and held on its grid again at their values' arrivals
/// ([`crate::logs::held_columns`], [`Recording::held_columns`]),
/// replaces its glitches and removes its dropouts (when
/// `options.screen_glitches`: single samples far off the curve their neighbours follow, and
/// rows in which every joint of a signal reads exactly 0 while the robot moves, see
/// [`crate::logs::log_screening`]; listed in the result's [`Recording::glitches`] and
/// [`Recording::dropouts`]), resamples `q`, `tau` (and `qd` when logged; otherwise qd is the
/// derivative of q) onto a uniform grid at `rate`, filters qd and tau (and q if asked) with a
/// zero-phase Butterworth low-pass, differentiates the filtered qd into qdd, trims and
/// decimates. The result is a recording with `qd` and `qdd`, named `<name> (preprocessed)`;
/// where it filters, also with [`Recording::coulomb`]: the sign of the filtered qd, filtered
/// again as tau is, the Coulomb friction term's column for a fit of the filtered torques.
/// Where a joint's logged positions lie on a grid (encoder counts) and its velocity is derived
/// from them, the noise their rounding leaves in qd and qdd is estimated and kept in
/// [`Recording::position_rounding`] ([`crate::logs::position_rounding`]). Stamps that jitter while
/// the samples were taken on a regular clock are found and kept in
/// [`Recording::stamp_jitter`] ([`crate::logs::stamp_jitter`]); the log is not changed.
///
/// A gap in `t` longer than [`MAX_GAP_INTERVALS`] median sample intervals is an error naming
/// its time, unless `options.split_at_gaps`: then each part between gaps is preprocessed on its
/// own and the parts are concatenated (`t` keeps the gaps); a part too short to filter and trim
/// is an error naming its time span.
///
/// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
pub fn preprocess(rec: &Recording, options: &PreprocessOptions) -> Result<Recording> {
    // the grids of the positions as logged: a glitch replaced by its neighbours' fit is off
    // the grid, and would hide it (and whole turns taken out are no multiple of its step)
    let steps = crate::logs::position_rounding::position_steps(rec);
    // steps of whole turns taken back out before anything reads the positions' motion
    let (unwrapped, position_wraps) = crate::logs::position_wraps::unwrap_positions(rec);
    // columns held at a lower rate read again at their values' arrivals, before anything
    // reads their motion (their holds would otherwise end as frozen readings here and there)
    let (reread, held_columns) = crate::logs::held_columns::find_held_columns(&unwrapped)?;
    // each step's copy of the log is let go as soon as the next holds it (a long log's
    // copies are what a preprocessing holds most of)
    drop(unwrapped);
    let rec = &reread;
    // clipped torques, as logged: screening could replace a short clipped run
    let torque_saturation = crate::logs::torque_saturation::find_torque_saturation(rec);
    // the stamps against the positions, as logged: resampling reads them as the samples' times
    let stamp_jitter = crate::logs::stamp_jitter::find_stamp_jitter(rec);
    if options.periods.is_some() && options.filter_position {
        return Err(Error::invalid(
            "filter_position",
            "averaging over periods takes the positions' first harmonics, which filters them: filter_position does not apply",
        ));
    }
    if !options.screen_glitches {
        return preprocess_screened(rec, options, &steps).map(|out| Recording {
            torque_saturation,
            position_wraps,
            held_columns,
            stamp_jitter,
            ..out
        });
    }
    if !options.split_at_gaps && options.periods.is_none() {
        check_gaps(rec)?;
    }
    let (screened, glitches) = crate::logs::log_screening::screen_recording(rec)?;
    let dropouts = crate::logs::log_dropouts::find_removed_rows(rec, &screened)?;
    // a glitch in rows removed is not told of: its row is gone
    let kept_rows = crate::logs::log_dropouts::kept_rows(rec.len(), &dropouts);
    drop(reread);
    let glitches: Vec<_> = glitches
        .into_iter()
        .filter(|g| kept_rows.binary_search(&g.sample).is_ok())
        .collect();
    drop(kept_rows);
    let kept = crate::logs::log_dropouts::without_dropouts(&screened, &dropouts)?;
    drop(screened);
    let out = preprocess_screened(&kept, options, &steps)
        .map_err(|e| crate::logs::log_dropouts::after_removing(e, &dropouts))?;
    Ok(Recording {
        glitches,
        dropouts,
        torque_saturation,
        position_wraps,
        held_columns,
        stamp_jitter,
        ..out
    })
}

/// What [`preprocess`] found in the log `name` (its joints named `joint_names`, numbered where
/// empty), in words, one warning a finding: periods averaged and left out, glitches replaced,
/// columns held at a lower rate, jittering stamps, whole turns taken out, rows removed and
/// clipped torques. (The noise that rounded positions leave, [`Recording::position_rounding`],
/// is a fit's to tell of: it biases the terms a fit reads from qd and qdd.)
pub fn warnings(rec: &Recording, name: &str, joint_names: &[String]) -> Vec<String> {
    use crate::logs::{
        held_columns, log_dropouts, log_screening, period_average, position_wraps, stamp_jitter,
        torque_saturation,
    };
    [
        period_average::warning(&rec.period_average, name, joint_names),
        log_screening::warning(
            &rec.glitches,
            name,
            joint_names,
            log_screening::BEFORE_PREPROCESSING,
        ),
        held_columns::warning(&rec.held_columns, name, joint_names),
        stamp_jitter::warning(&rec.stamp_jitter, name, joint_names),
        position_wraps::warning(
            &rec.position_wraps,
            name,
            joint_names,
            "before preprocessing",
        ),
        log_dropouts::dropout_warning(
            &rec.dropouts,
            name,
            joint_names,
            log_dropouts::BRIDGED_BY_PREPROCESSING,
        ),
        torque_saturation::warning(&rec.torque_saturation, joint_names, name),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// [`preprocess`] of a recording whose glitches were screened (or are not to be).
/// `steps`: per joint, the grid its logged positions lie on (for [`crate::logs::position_rounding`]).
fn preprocess_screened(
    rec: &Recording,
    options: &PreprocessOptions,
    steps: &[Option<f64>],
) -> Result<Recording> {
    if let Some(p) = &options.periods {
        check_sample_interval(rec)?;
        return crate::logs::period_average::average_periods(
            rec,
            options.rate,
            options.cutoff,
            options.decimate,
            p,
        );
    }
    if !options.split_at_gaps {
        return preprocess_part(rec, options, steps);
    }
    let parts = split_at_gaps(rec)?;
    if parts.len() == 1 {
        return preprocess_part(rec, options, steps);
    }
    // microseconds for a log's times; exponent form for absurd ones (1e300 s)
    let time = |t: f64| {
        if t.abs() < 1e9 {
            format!("{t:.6}")
        } else {
            crate::error::shown(t)
        }
    };
    let mut done = Vec::with_capacity(parts.len());
    for (k, part) in parts.iter().enumerate() {
        let p = preprocess_part(part, options, steps).map_err(|e| match e {
            Error::Recording { message, .. } => Error::recording(
                rec.name.clone(),
                format!(
                    "part {} of {} (t = {} s to {} s, between gaps): {message}",
                    k + 1,
                    parts.len(),
                    time(part.t[0]),
                    time(part.t[part.len() - 1])
                ),
            ),
            other => other,
        })?;
        done.push(p);
    }
    let cat = |f: fn(&Recording) -> &[f64]| -> Vec<f64> {
        done.iter().flat_map(|r| f(r).iter().copied()).collect()
    };
    Recording::new(
        format!("{} (preprocessed, {} parts)", rec.name, done.len()),
        rec.n,
        cat(|r| &r.t),
        cat(|r| &r.q),
        cat(|r| &r.tau),
        Some(cat(|r| r.qd.as_deref().unwrap_or(&[]))),
        Some(cat(|r| r.qdd.as_deref().unwrap_or(&[]))),
    )
    .map(|out| Recording {
        experiment: rec.experiment.clone(),
        position_rounding: crate::logs::position_rounding::worst_of(
            done.iter()
                .flat_map(|r| r.position_rounding.iter().cloned()),
        ),
        coulomb: (done.iter().all(|r| r.coulomb.is_some()))
            .then(|| cat(|r| r.coulomb.as_deref().unwrap_or(&[]))),
        ..out
    })
}

/// The parts of a recording between its gaps (intervals longer than [`MAX_GAP_INTERVALS`]
/// median sample intervals), in order; the whole recording if it has none. Each part keeps the
/// recording's name with ` [t0-t1 s]` appended.
///
/// Errors: a part of fewer than 2 samples (an isolated sample between two gaps), naming its
/// time.
///
/// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
pub fn split_at_gaps(rec: &Recording) -> Result<Vec<Recording>> {
    let gaps = gap_positions(rec);
    if gaps.is_empty() {
        return Ok(vec![rec.clone()]);
    }
    let n = rec.n;
    let mut bounds = vec![0];
    bounds.extend(gaps.iter().map(|&i| i + 1));
    bounds.push(rec.len());
    let mut parts = Vec::with_capacity(bounds.len() - 1);
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a < 2 {
            return Err(Error::recording(
                rec.name.clone(),
                format!(
                    "the sample at t = {:.6} s stands alone between two gaps; remove it or the gaps",
                    rec.t[a]
                ),
            ));
        }
        let rows = |x: &[f64]| x[a * n..b * n].to_vec();
        let part = Recording::new(
            format!("{} [{:.3}-{:.3} s]", rec.name, rec.t[a], rec.t[b - 1]),
            n,
            rec.t[a..b].to_vec(),
            rows(&rec.q),
            rows(&rec.tau),
            rec.qd.as_deref().map(rows),
            rec.qdd.as_deref().map(rows),
        )?;
        parts.push(Recording {
            experiment: rec.experiment.clone(),
            ..part
        });
    }
    Ok(parts)
}

fn preprocess_part(
    rec: &Recording,
    options: &PreprocessOptions,
    steps: &[Option<f64>],
) -> Result<Recording> {
    let o = options;
    if !(o.rate.is_finite() && o.rate > 0.0) || o.decimate == 0 || o.trim.is_nan() || o.trim < 0.0 {
        return Err(Error::invalid(
            "preprocess options",
            format!(
                "rate {} Hz, decimate {}, trim {} s; expected rate > 0, decimate >= 1, trim >= 0",
                o.rate, o.decimate, o.trim
            ),
        ));
    }
    let n = rec.n;
    let (t0, t1) = (rec.t[0], rec.t[rec.len() - 1]);
    check_sample_interval(rec)?;
    let count = crate::limits::sample_count("preprocess", t1 - t0, o.rate, 1 + 4 * n)?;
    check_gaps(rec)?;
    let grid: Vec<f64> = (0..count).map(|i| t0 + i as f64 / o.rate).collect();
    let dt = 1.0 / o.rate;
    let filter = o
        .cutoff
        .map(|c| butterworth_lowpass(o.order, c, o.rate))
        .transpose()?;
    let column =
        |x: &[f64], j: usize| -> Vec<f64> { (0..rec.len()).map(|i| x[i * n + j]).collect() };
    let smooth = |x: Vec<f64>| -> Result<Vec<f64>> {
        match &filter {
            Some(f) => filtfilt(f, &x).map_err(|e| {
                Error::recording(
                    rec.name.clone(),
                    format!(
                        "{} s long, {count} samples at {} Hz: too short to filter ({e})",
                        crate::error::shown5(t1 - t0),
                        crate::error::shown(o.rate)
                    ),
                )
            }),
            None => Ok(x),
        }
    };
    // q, qd, qdd, tau per joint, and the Coulomb term's column: sign(qd) filtered as tau is
    let mut cols: [Vec<Vec<f64>>; 5] = Default::default();
    for j in 0..n {
        crate::interrupt::check("preprocessing")?;
        let q = interpolate(&rec.t, &column(&rec.q, j), &grid);
        let qd = match &rec.qd {
            Some(v) => interpolate(&rec.t, &column(v, j), &grid),
            None => differentiate(&q, dt),
        };
        let qd = smooth(qd)?;
        if filter.is_some() {
            let sign: Vec<f64> = qd.iter().map(|&v| crate::parameters::sign0(v)).collect();
            cols[4].push(smooth(sign)?);
        }
        cols[2].push(differentiate(&qd, dt));
        cols[1].push(qd);
        cols[0].push(if o.filter_position { smooth(q)? } else { q });
        cols[3].push(smooth(interpolate(&rec.t, &column(&rec.tau, j), &grid))?);
    }
    let skip = (o.trim * o.rate).round() as usize;
    if count <= 2 * skip + 1 {
        return Err(Error::recording(
            rec.name.clone(),
            format!(
                "{:.3} s long; trimming {} s at both ends leaves nothing (a shorter trim keeps more: trim, --trim; it drops the low-pass filter's transients at each end)",
                t1 - t0,
                o.trim
            ),
        ));
    }
    // logged velocities against the positions' derivative, filtered alike, where kept
    if rec.qd.is_some() {
        let mut derived = Vec::with_capacity(n);
        for q in &cols[0] {
            crate::interrupt::check("preprocessing")?;
            derived.push(smooth(differentiate(q, dt))?[skip..count - skip].to_vec());
        }
        let logged: Vec<Vec<f64>> = cols[1]
            .iter()
            .map(|v| v[skip..count - skip].to_vec())
            .collect();
        crate::logs::derivative_columns::check_velocity_columns(&rec.name, &logged, &derived)?;
    }
    let keep: Vec<usize> = (skip..count - skip).step_by(o.decimate).collect();
    // positions in coarse counts under velocities derived from them: the noise of their
    // rounding, through the same chain (crate::logs::position_rounding)
    let at_keep = |c: &[f64]| -> Vec<f64> { keep.iter().map(|&i| c[i]).collect() };
    let mut rounding = Vec::new();
    if rec.qd.is_none() {
        let derive = |noise: &[f64]| -> Option<(Vec<f64>, Vec<f64>)> {
            let qd = smooth(differentiate(noise, dt)).ok()?;
            let qdd = differentiate(&qd, dt);
            Some((at_keep(&qd), at_keep(&qdd)))
        };
        let derived = cols[1].iter().zip(&cols[2]);
        for (j, (q_grid, (qd, qdd))) in cols[0].iter().zip(derived).enumerate() {
            crate::interrupt::check("preprocessing")?;
            let Some(step) = steps.get(j).copied().flatten() else {
                continue;
            };
            let smoothed = match (&filter, o.filter_position) {
                (None, _) => None,
                (Some(_), true) => Some(q_grid.clone()),
                (Some(_), false) => smooth(q_grid.clone()).ok(),
            };
            rounding.extend(crate::logs::position_rounding::measure(
                j,
                step,
                smoothed.as_deref(),
                count,
                &at_keep(qd),
                &at_keep(qdd),
                derive,
            ));
        }
    }
    let rows = |c: &Vec<Vec<f64>>| -> Vec<f64> {
        keep.iter()
            .flat_map(|&i| (0..n).map(move |j| c[j][i]))
            .collect()
    };
    Recording::new(
        format!("{} (preprocessed)", rec.name),
        n,
        keep.iter().map(|&i| grid[i]).collect(),
        rows(&cols[0]),
        rows(&cols[3]),
        Some(rows(&cols[1])),
        Some(rows(&cols[2])),
    )
    .map(|out| Recording {
        experiment: rec.experiment.clone(),
        position_rounding: rounding,
        coulomb: filter.is_some().then(|| rows(&cols[4])),
        ..out
    })
}

/// The longest median sample interval (s) of a log preprocessed: 2 Hz. No robot's dynamics
/// are identified from slower samples, and a log whose time column is in milliseconds reads
/// as 1 Hz.
pub const SLOWEST_INTERVAL: f64 = 0.5;

/// The shortest median sample interval (s) of a log preprocessed: 1 MHz. No robot logs its
/// joints faster (100 kHz is the fastest expected), and a 1 kHz log whose time column is in
/// hours reads as 3.6 MHz.
pub const FASTEST_INTERVAL: f64 = 1e-6;

/// Refuses a log whose median sample interval is [`SLOWEST_INTERVAL`] or longer, asking
/// whether its time is in milliseconds, microseconds or nanoseconds where one of them gives a
/// robot's logging rate (10 Hz to 100 kHz; it would otherwise be resampled into a log 1,000
/// times slower than the robot moved, or refused for its size), and one whose median interval
/// is below [`FASTEST_INTERVAL`], asking likewise about minutes and hours (it would otherwise
/// be resampled into a handful of samples, or none).
fn check_sample_interval(rec: &Recording) -> Result<()> {
    let median = gaps(rec).0;
    // each unit the time might be in: seconds per its unit, its name, what turns it into s
    type Unit = (f64, &'static str, &'static str);
    let (candidates, verdict, otherwise): (&[Unit], &str, &str) = if median >= SLOWEST_INTERVAL {
        (
            &[
                (1e-3, "milliseconds", "divide it by 1,000"),
                (1e-6, "microseconds", "divide it by 1e6"),
                (1e-9, "nanoseconds (a ROS stamp)", "divide it by 1e9"),
            ],
            "too slow to identify a robot's dynamics from",
            "milliseconds or another unit",
        )
    } else if median > 0.0 && median < FASTEST_INTERVAL {
        (
            &[
                (60.0, "minutes", "multiply it by 60"),
                (3600.0, "hours", "multiply it by 3,600"),
            ],
            "faster than a robot logs its joints (at most 100 kHz is expected)",
            "another unit than seconds",
        )
    } else {
        return Ok(());
    };
    // the units a robot's logging rate (10 Hz to 100 kHz) would make of it, if any do
    let units: Vec<String> = candidates
        .iter()
        .filter(|(scale, _, _)| (10.0..=1e5).contains(&(1.0 / (median * scale))))
        .map(|(scale, unit, turn)| {
            format!(
                "{unit} (the samples would come at {} Hz: {turn})",
                crate::error::shown5(1.0 / (median * scale))
            )
        })
        .collect();
    let question = if units.is_empty() {
        format!("Is the time column in {otherwise}?")
    } else {
        format!("Is the time column in {}?", units.join(" or "))
    };
    Err(Error::recording(
        rec.name.clone(),
        format!(
            "its samples are {} s apart (the median interval; {} Hz): {verdict}. {question} It is read in seconds",
            crate::error::shown5(median),
            crate::error::shown5(1.0 / median)
        ),
    ))
}

/// Refuses a log with a gap longer than [`MAX_GAP_INTERVALS`] times its median sample
/// interval: resampling would fill it with invented, interpolated values. The error names the
/// gap's time.
///
/// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
fn check_gaps(rec: &Recording) -> Result<()> {
    let (median, at) = gaps(rec);
    match at.first() {
        Some(&i) => {
            let d = rec.t[i + 1] - rec.t[i];
            Err(Error::recording(
                rec.name.clone(),
                format!(
                    "a gap of {:.6} s after t = {:.6} s, {:.0} times the median sample interval ({:.3e} s); resampling would invent the values in it (at most {} intervals are bridged): split the log there (split_at_gaps, --split-at-gaps) or remove the gap",
                    d,
                    rec.t[i],
                    d / median,
                    median,
                    crate::limits::MAX_GAP_INTERVALS
                ),
            ))
        }
        None => Ok(()),
    }
}
