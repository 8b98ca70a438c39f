//! `preprocess` in Python: real logs to uniform, filtered, differentiated samples (mirrors
//! `crate::logs::preprocess`).

use pyo3::prelude::*;

use super::scalars;

use super::detached;

use super::arrays::ArrayLike;
use super::recording::PyRecording;

use crate::logs::preprocess::{preprocess as preprocess_rs, PreprocessOptions};
use crate::logs::recording::Recording;

/// Excitation, periods and harmonics of `preprocess`'s averaging over periods: an excitation
/// (FourierTrajectory or ExcitationDesign) brings its period and harmonics.
#[derive(FromPyObject)]
pub(crate) enum ExcitationArg<'py> {
    Fourier(PyRef<'py, super::trajectory::PyFourier>),
    Design(PyRef<'py, super::excitation::PyExcitationDesign>),
}

impl ExcitationArg<'_> {
    fn trajectory(&self) -> crate::trajectory::FourierTrajectory {
        match self {
            Self::Fourier(f) => f.traj.clone(),
            Self::Design(d) => d.trajectory_ref().clone(),
        }
    }
}

/// Preprocesses a real recording: resample `t`, `q`, `tau` (and `qd` when logged) onto a
/// uniform grid at `rate` Hz, zero-phase Butterworth low-pass (`order`, `cutoff` Hz; None = no
/// filter) on qd and tau (and q with `filter_position`), qdd by differentiating the filtered
/// qd, drop `trim` s at both ends and keep every `decimate`-th sample. Returns a Recording with
/// qd and qdd. A gap in `t` longer than 20 median sample intervals is an InputError naming its
/// time, unless `split_at_gaps`: then each part between gaps is preprocessed on its own and the
/// parts are concatenated (the gaps stay in `t`; nothing is interpolated across them).
/// First, unless `screen_glitches=False`, single samples far off the curve their neighbours
/// follow (glitches of the log) are replaced by the fit of their neighbours, and rows in which
/// every joint of a signal reads exactly 0 while the robot moves (dropouts) are removed: a
/// PerturbidWarning lists them, and the result's `glitches` and `dropouts` hold them.
///
/// Averaging over periods in place of the filter (Swevers et al. 2007; docs/method.md, section
/// 8e): `excitation` (a FourierTrajectory or ExcitationDesign; its start and whole periods are
/// found in the log from its positions), or `period` (s) with `harmonics` (the excitation's
/// L) from `period_start` (the log's time of a period's start; default its first sample);
/// `skip_periods` whole periods left out first. The result is one period sampled at `rate`,
/// every `decimate`-th kept: `q`, `qd`, `qdd` from the positions' first `harmonics`
/// harmonics (their exact derivatives), `tau` and `coulomb` from the torques' harmonics up to
/// `cutoff`; periods with a gap or far off the others are left out and warned of; the result's
/// `period_average` says what was found, with each signal's noise measured from the periods.
/// `trim` (default 0.5 s, for the filter) is refused with it.
#[pyfunction]
#[pyo3(signature = (t, q, tau, qd=None, *, rate=1000.0, cutoff=Some(10.0), order=4, decimate=10, trim=None, filter_position=false, split_at_gaps=false, screen_glitches=true, excitation=None, period=None, harmonics=None, period_start=None, skip_periods=0, name="recording"),
    text_signature = "(t, q, tau, qd=None, *, rate=1000.0, cutoff=10.0, order=4, decimate=10, trim=None, filter_position=False, split_at_gaps=False, screen_glitches=True, excitation=None, period=None, harmonics=None, period_start=None, skip_periods=0, name='recording')")]
#[allow(clippy::too_many_arguments)]
pub(crate) fn preprocess(
    py: Python<'_>,
    t: ArrayLike<'_>,
    q: ArrayLike<'_>,
    tau: ArrayLike<'_>,
    qd: Option<ArrayLike<'_>>,
    #[pyo3(from_py_with = scalars::real)] rate: f64,
    #[pyo3(from_py_with = scalars::real_or_none)] cutoff: Option<f64>,
    #[pyo3(from_py_with = scalars::count)] order: usize,
    #[pyo3(from_py_with = scalars::count)] decimate: usize,
    #[pyo3(from_py_with = scalars::real_or_none)] trim: Option<f64>,
    filter_position: bool,
    split_at_gaps: bool,
    screen_glitches: bool,
    excitation: Option<ExcitationArg<'_>>,
    #[pyo3(from_py_with = scalars::real_or_none)] period: Option<f64>,
    #[pyo3(from_py_with = scalars::count_or_none)] harmonics: Option<usize>,
    #[pyo3(from_py_with = scalars::real_or_none)] period_start: Option<f64>,
    #[pyo3(from_py_with = scalars::count)] skip_periods: usize,
    name: &str,
) -> PyResult<PyRecording> {
    let rec = PyRecording::build(t, q, tau, qd, None, name)?;
    let invalid = |argument: &str, message: &str| -> PyErr {
        crate::error::Error::invalid(argument, message).into()
    };
    let periodic = excitation.is_some() || period.is_some();
    if !periodic && (harmonics.is_some() || period_start.is_some() || skip_periods > 0) {
        return Err(invalid(
            "harmonics, period_start, skip_periods",
            "they average over periods: give period or excitation too",
        ));
    }
    if periodic && trim.is_some() {
        return Err(invalid(
            "trim",
            "it drops a filter's transients, and averaging over periods has none: leave it out",
        ));
    }
    let traj = excitation.as_ref().map(ExcitationArg::trajectory);
    let periods = match (&traj, period, harmonics) {
        (None, None, _) => None,
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            return Err(invalid(
                "excitation",
                "it brings its own period and harmonics: give it, or period and harmonics, not both",
            ))
        }
        (Some(_), None, None) if period_start.is_some() => {
            return Err(invalid(
                "period_start",
                "the excitation's start is found in the log from its positions: give period and harmonics instead to set it",
            ))
        }
        // found in the log, below
        (Some(_), None, None) => None,
        (None, Some(p), Some(h)) => Some(crate::logs::period_average::PeriodOptions {
            start: period_start,
            skip: skip_periods,
            ..crate::logs::period_average::PeriodOptions::new(p, h)
        }),
        (None, Some(_), None) => {
            return Err(invalid(
                "period",
                "it needs harmonics, the harmonics of the excitation's base frequency its positions hold",
            ))
        }
    };
    let options = PreprocessOptions {
        rate,
        cutoff,
        order,
        filter_position,
        trim: trim.unwrap_or(0.5),
        decimate,
        split_at_gaps,
        screen_glitches,
        periods,
    };
    let out: Recording = detached(py, "preprocess", || match &traj {
        // the excitation's start and periods found in the log first
        Some(traj) => {
            let periods =
                crate::logs::excitation_start::excitation_periods(&rec, traj, skip_periods)?;
            preprocess_rs(
                &rec,
                &PreprocessOptions {
                    periods: Some(periods),
                    ..options.clone()
                },
            )
        }
        None => preprocess_rs(&rec, &options),
    })?;
    let mut warnings = crate::logs::preprocess::warnings(&out, name, &[]);
    // a Recording is fitted later, by functions that do not warn of its findings again
    warnings.extend(
        crate::logs::position_rounding::warning(&out.position_rounding, &[])
            .map(|w| format!("{name}: {w}{}", crate::logs::position_rounding::IN_A_FIT)),
    );
    super::errors::warn_all(py, &warnings)?;
    Ok(PyRecording::from(out))
}
