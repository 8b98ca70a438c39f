//! `preprocess` in Python: real logs to uniform, filtered, differentiated samples (mirrors
//! `crate::preprocess`).

use pyo3::prelude::*;

use super::scalars;

use super::detached;

use super::arrays::ArrayLike;
use super::recording::PyRecording;

use crate::preprocess::{preprocess as preprocess_rs, PreprocessOptions};
use crate::recording::Recording;

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
#[pyfunction]
#[pyo3(signature = (t, q, tau, qd=None, *, rate=1000.0, cutoff=Some(10.0), order=4, decimate=10, trim=0.5, filter_position=false, split_at_gaps=false, screen_glitches=true, name="recording"),
    text_signature = "(t, q, tau, qd=None, *, rate=1000.0, cutoff=10.0, order=4, decimate=10, trim=0.5, filter_position=False, split_at_gaps=False, screen_glitches=True, name='recording')")]
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
    #[pyo3(from_py_with = scalars::real)] trim: f64,
    filter_position: bool,
    split_at_gaps: bool,
    screen_glitches: bool,
    name: &str,
) -> PyResult<PyRecording> {
    let rec = PyRecording::build(t, q, tau, qd, None, name)?;
    let options = PreprocessOptions {
        rate,
        cutoff,
        order,
        filter_position,
        trim,
        decimate,
        split_at_gaps,
        screen_glitches,
        periods: None,
    };
    let out: Recording = detached(py, "preprocess", || preprocess_rs(&rec, &options))?;
    let warnings: Vec<String> = [
        crate::log_screening::warning(
            &out.glitches,
            name,
            &[],
            crate::log_screening::BEFORE_PREPROCESSING,
        ),
        crate::log_dropouts::dropout_warning(
            &out.dropouts,
            name,
            &[],
            crate::log_dropouts::BRIDGED_BY_PREPROCESSING,
        ),
        crate::position_rounding::warning(&out.position_rounding, &[])
            .map(|w| format!("{name}: {w}{}", crate::position_rounding::IN_A_FIT)),
        crate::torque_saturation::warning(&out.torque_saturation, &[], name),
        crate::position_wraps::warning(&out.position_wraps, name, &[], "before preprocessing"),
        crate::held_columns::warning(&out.held_columns, name, &[]),
        crate::stamp_jitter::warning(&out.stamp_jitter, name, &[]),
    ]
    .into_iter()
    .flatten()
    .collect();
    super::errors::warn_all(py, &warnings)?;
    Ok(PyRecording::from(out))
}
