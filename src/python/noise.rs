//! The torques' noise measured apart from a fit, from Python: the `noise=` argument of the
//! direct fits (or a Recording's period average) and the model's `noise_fit` dict.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::ArrayLike;
use crate::direct::{NoiseFit, TorqueNoise, Weighting};
use crate::error::Error;
use crate::Recording;

/// The noise a direct fit takes ([`crate::direct::BaseOptions::noise`]): `noise` ((n,), N m a
/// joint) with `correlation` (samples an independent value, 1 for white noise) where given;
/// otherwise that of the one Recording fitted where it was averaged over its periods
/// ([`crate::period_average::PeriodAverage::torque_noise`]). Errors, for the noise weighting
/// only: several Recordings without `noise`, or an averaged one whose periods measured none.
pub(crate) fn torque_noise(
    noise: Option<ArrayLike<'_>>,
    correlation: f64,
    recordings: &[&Recording],
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
        return Err(Error::InvalidArgument {
            argument: "noise_correlation".into(),
            message:
                "given without noise: it is the correlation of the noise levels given as noise="
                    .into(),
        }
        .into());
    }
    let weighted = weighting == Weighting::Noise;
    match recordings {
        [rec] => match (&rec.period_average, weighted) {
            (Some(a), true) => Ok(Some(a.torque_noise(joints)?)),
            (Some(a), false) => Ok(a.torque_noise(joints).ok()),
            (None, _) => Ok(None),
        },
        [_, _, ..] if weighted => Err(Error::InvalidArgument {
            argument: "weighting".into(),
            message: format!(
                "'noise' with {} Recordings and no noise=: each one's periods measure a noise of its own, which one weight a joint cannot hold; give noise= (one level a joint for all), or weight from the residuals ('wls')",
                recordings.len()
            ),
        }
        .into()),
        _ => Ok(None),
    }
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
