//! The torques' noise measured apart from a fit, from Python: the `noise=` argument of the
//! direct fits (or a Recording's period average) and the model's `noise_fit` dict.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::ArrayLike;
use crate::direct::{NoiseFit, TorqueNoise, Weighting};
use crate::error::Error;
use crate::Recording;
use std::sync::Arc;

/// The noise a direct fit takes ([`crate::direct::BaseOptions::noise`]): `noise` ((n,), N m a
/// joint) with `correlation` (samples an independent value, 1 for white noise) where given;
/// otherwise that of the Recordings fitted where each was averaged over its periods
/// ([`crate::logs::period_average::PeriodAverage::torque_noise`]; several pooled,
/// [`TorqueNoise::pooled`]). Errors, for the noise weighting only: a Recording not averaged, or
/// whose periods measured no noise, naming it; several whose noise differs too much to pool.
pub(crate) fn torque_noise(
    noise: Option<ArrayLike<'_>>,
    correlation: f64,
    recordings: &[Arc<Recording>],
    joints: &[String],
    weighting: Weighting,
) -> PyResult<Option<TorqueNoise>> {
    if let Some(noise) = noise {
        let given = TorqueNoise {
            correlation,
            ..TorqueNoise::white(super::arrays::vector("noise", &noise)?)
        };
        given.check(joints)?;
        return Ok(Some(given));
    }
    if correlation != 1.0 {
        return Err(Error::invalid(
            "noise_correlation",
            "given without noise: it is the correlation of the noise levels given as noise=",
        )
        .into());
    }
    let logs = (recordings.iter().enumerate())
        .map(|(i, rec)| {
            let noise = match &rec.period_average {
                Some(a) => crate::direct::TorqueNoise::from_period_average(a, joints),
                None => Err(Error::invalid(
                    "weighting",
                    "'noise' needs noise= or a Recording averaged over its excitation's periods (preprocess(..., excitation=...) or period=), whose spread measures the noise",
                )),
            };
            (format!("Recording {i} ('{}')", rec.name), noise, rec.len())
        })
        .collect();
    Ok(TorqueNoise::of_logs(
        logs,
        joints,
        weighting == Weighting::Noise,
    )?)
}

/// `options` with the noise [`torque_noise`] finds for them (`noise`, `correlation`, the
/// Recordings fitted and the robot's `joints`).
pub(crate) fn with_noise(
    options: crate::direct::BaseOptions,
    noise: Option<ArrayLike<'_>>,
    correlation: f64,
    recordings: &[Arc<Recording>],
    joints: &[String],
) -> PyResult<crate::direct::BaseOptions> {
    let noise = torque_noise(noise, correlation, recordings, joints, options.weighting)?;
    Ok(crate::direct::BaseOptions { noise, ..options })
}

/// A fit's residuals against the noise as a dict (`BaseParameterModel.noise_fit`).
pub(crate) fn noise_fit_dict<'py>(py: Python<'py>, f: &NoiseFit) -> PyResult<Bound<'py, PyDict>> {
    let e = PyDict::new(py);
    e.set_item("noise", f.noise.sigma.clone())?;
    e.set_item("correlation", f.noise.correlation)?;
    e.set_item("noise_degrees_of_freedom", f.noise.degrees_of_freedom)?;
    e.set_item("ratio", f.ratio.clone())?;
    e.set_item("model_error", f.model_error.clone())?;
    e.set_item("cost", f.cost)?;
    e.set_item("degrees_of_freedom", f.degrees_of_freedom)?;
    e.set_item("p_value", f.p_value)?;
    Ok(e)
}
