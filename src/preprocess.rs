//! Preprocessing of real recordings for identification: resampling irregular timestamps onto a
//! uniform grid, zero-phase low-pass filtering, differentiation for velocity and acceleration,
//! trimming and decimation.

use crate::error::{Error, Result};
use crate::recording::Recording;
use crate::signal::{butterworth_lowpass, differentiate, filtfilt, interpolate};

/// Options of [`preprocess`]. The defaults follow the common protocol (and the reference
/// result on the real Panda log, docs/data.md): 1 kHz, 4th-order Butterworth at 10 Hz applied
/// zero-phase to qd and tau, qdd from the filtered qd, 0.5 s dropped at both ends, every 10th
/// sample kept.
#[derive(Clone, Debug, PartialEq)]
pub struct PreprocessOptions {
    /// Uniform sampling rate after resampling (Hz).
    pub rate: f64,
    /// Low-pass cutoff (Hz); `None` switches filtering off.
    pub cutoff: Option<f64>,
    /// Butterworth order (each pass; zero-phase doubles it).
    pub order: usize,
    /// Also filter the positions (default false: encoders are precise and filtering lags
    /// nothing but can round corners).
    pub filter_position: bool,
    /// Seconds dropped at both ends (filter transients, ramps).
    pub trim: f64,
    /// Keep every `decimate`-th sample (1 keeps all).
    pub decimate: usize,
}

impl Default for PreprocessOptions {
    fn default() -> Self {
        Self {
            rate: 1000.0,
            cutoff: Some(10.0),
            order: 4,
            filter_position: false,
            trim: 0.5,
            decimate: 10,
        }
    }
}

/// Preprocesses a recording: resamples `q`, `tau` (and `qd` when logged; otherwise qd is the
/// derivative of q) onto a uniform grid at `rate`, filters qd and tau (and q if asked) with a
/// zero-phase Butterworth low-pass, differentiates the filtered qd into qdd, trims and
/// decimates. The result is a recording with `qd` and `qdd`, named `<name> (preprocessed)`.
pub fn preprocess(rec: &Recording, options: &PreprocessOptions) -> Result<Recording> {
    let o = options;
    if !(o.rate.is_finite() && o.rate > 0.0) || o.decimate == 0 || o.trim.is_nan() || o.trim < 0.0 {
        return Err(Error::InvalidArgument {
            argument: "preprocess options".into(),
            message: format!(
                "rate {} Hz, decimate {}, trim {} s; expected rate > 0, decimate >= 1, trim >= 0",
                o.rate, o.decimate, o.trim
            ),
        });
    }
    let n = rec.n;
    let (t0, t1) = (rec.t[0], rec.t[rec.len() - 1]);
    let count = crate::limits::sample_count("preprocess", t1 - t0, o.rate)?;
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
            Some(f) => filtfilt(f, &x).map_err(|e| Error::Recording {
                recording: rec.name.clone(),
                message: format!("too short to filter: {e}"),
            }),
            None => Ok(x),
        }
    };
    let mut cols: [Vec<Vec<f64>>; 4] = Default::default(); // q, qd, qdd, tau per joint
    for j in 0..n {
        crate::interrupt::check("preprocessing")?;
        let q = interpolate(&rec.t, &column(&rec.q, j), &grid);
        let qd = match &rec.qd {
            Some(v) => interpolate(&rec.t, &column(v, j), &grid),
            None => differentiate(&q, dt),
        };
        let qd = smooth(qd)?;
        cols[2].push(differentiate(&qd, dt));
        cols[1].push(qd);
        cols[0].push(if o.filter_position { smooth(q)? } else { q });
        cols[3].push(smooth(interpolate(&rec.t, &column(&rec.tau, j), &grid))?);
    }
    let skip = (o.trim * o.rate).round() as usize;
    if count <= 2 * skip + 1 {
        return Err(Error::Recording {
            recording: rec.name.clone(),
            message: format!(
                "{:.3} s long; trimming {} s at both ends leaves nothing",
                t1 - t0,
                o.trim
            ),
        });
    }
    let keep: Vec<usize> = (skip..count - skip).step_by(o.decimate).collect();
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
        ..out
    })
}

/// Refuses a log with a gap longer than [`MAX_GAP_INTERVALS`] times its median sample
/// interval: resampling would fill it with invented, interpolated values. The error names the
/// gap's time.
///
/// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
fn check_gaps(rec: &Recording) -> Result<()> {
    let dt: Vec<f64> = rec.t.windows(2).map(|w| w[1] - w[0]).collect();
    if dt.is_empty() {
        return Ok(());
    }
    let mut sorted = dt.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let limit = crate::limits::MAX_GAP_INTERVALS * median;
    match dt.iter().position(|&d| d > limit) {
        Some(i) => Err(Error::Recording {
            recording: rec.name.clone(),
            message: format!(
                "a gap of {:.6} s after t = {:.6} s, {:.0} times the median sample interval ({:.3e} s); resampling would invent the values in it (at most {} intervals are bridged): split the log there",
                dt[i],
                rec.t[i],
                dt[i] / median,
                median,
                crate::limits::MAX_GAP_INTERVALS
            ),
        }),
        None => Ok(()),
    }
}
