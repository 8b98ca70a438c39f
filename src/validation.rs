//! A model's torques against measured ones: per-joint error statistics and the residuals.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// One joint's prediction error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointError {
    pub joint: String,
    /// RMS of `measured - predicted` (N m or N).
    pub rms: f64,
    /// `rms` over the RMS of the measured torque; `None` when that is zero.
    pub relative_rms: Option<f64>,
    /// Largest `|measured - predicted|` (N m or N).
    pub max: f64,
    /// Mean of `measured - predicted` (N m or N): the constant part of the error. Near `rms`
    /// it is most of it: the log's torque offset is not the model's (a sensor zeroed anew
    /// since the model was identified; a model fitted with an offset of each log's own
    /// predicts with their mean), or a misfit of a constant torque such as gravity at a
    /// posture held. 0 in a file written before it was stored.
    #[serde(default)]
    pub mean: f64,
    /// RMS over the samples of the prediction's standard error (N m or N): the model's own
    /// uncertainty at these states ([`Validation::with_model_stderr`]). A model that holds there
    /// errs by about `sqrt(model_stderr_rms^2 + noise^2)` for the log's torque noise; an `rms`
    /// far beyond it is the model's error (a local model far from its point, a missing effect),
    /// not its identification's noise. None where the model carries none (a globally linearised
    /// model, one saved before they were stored) or one is unknown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_stderr_rms: Option<f64>,
}

/// The validation of a model on measured torques.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    pub joints: Vec<JointError>,
    /// Samples compared.
    pub samples: usize,
    /// `measured - predicted`, row-major `samples x n` (N m or N).
    #[serde(skip)]
    pub residuals: Vec<f64>,
}

/// The root mean square of finite `values` (0 for none), scaled by the largest so that values
/// past 1e154, whose squares overflow, still give it (a measured torque of 1e308 gave inf).
pub fn rms(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let largest = values.clone().fold(0.0, |a: f64, v| a.max(v.abs()));
    if largest == 0.0 {
        return 0.0;
    }
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| {
        (s + (v / largest).powi(2), c + 1)
    });
    largest * (sum / count as f64).sqrt()
}

/// The mean of finite `values` (0 for none), scaled by the largest as [`rms`] is, so that a
/// sum past f64's range still gives it.
pub fn mean(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let largest = values.clone().fold(0.0, |a: f64, v| a.max(v.abs()));
    if largest == 0.0 {
        return 0.0;
    }
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v / largest, c + 1));
    largest * (sum / count as f64)
}

/// Compares `predicted` with `measured` torques (both row-major `k x n`, `n =
/// joint_names.len()`, N m or N). Errors: lengths that disagree or are not a whole number of
/// samples, no sample, a non-finite value (named by sample and joint).
pub fn validate(joint_names: &[String], predicted: &[f64], measured: &[f64]) -> Result<Validation> {
    let n = joint_names.len();
    if n == 0
        || predicted.len() != measured.len()
        || !measured.len().is_multiple_of(n)
        || measured.is_empty()
    {
        return Err(Error::shape(
            "validation",
            format!("predicted and measured torques of the same k x {n} samples, k >= 1"),
            format!(
                "{} predicted and {} measured values",
                predicted.len(),
                measured.len()
            ),
        ));
    }
    for (what, v) in [("predicted", predicted), ("measured", measured)] {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFiniteInput {
                argument: format!(
                    "{what} torque of sample {}, joint {}",
                    i / n,
                    joint_names[i % n]
                ),
                index: i,
                value: v[i],
            });
        }
    }
    let k = measured.len() / n;
    let residuals: Vec<f64> = measured.iter().zip(predicted).map(|(m, p)| m - p).collect();
    // two finite torques of opposite signs past 9e307 differ by more than any f64
    if let Some(i) = residuals.iter().position(|r| !r.is_finite()) {
        return Err(Error::numerical(
            "validation",
            format!(
                "the error of sample {}, joint {} overflows (measured {}, predicted {}): torques this large cannot be compared",
                i / n,
                joint_names[i % n],
                crate::error::shown(measured[i]),
                crate::error::shown(predicted[i])
            ),
        ));
    }
    let joints = (0..n)
        .map(|j| {
            let e = rms((0..k).map(|s| residuals[s * n + j]));
            let m = rms((0..k).map(|s| measured[s * n + j]));
            JointError {
                joint: joint_names[j].clone(),
                rms: e,
                relative_rms: (m > 0.0).then(|| e / m),
                max: (0..k)
                    .map(|s| residuals[s * n + j].abs())
                    .fold(0.0, f64::max),
                mean: mean((0..k).map(|s| residuals[s * n + j])),
                model_stderr_rms: None,
            }
        })
        .collect();
    Ok(Validation {
        joints,
        samples: k,
        residuals,
    })
}

impl Validation {
    /// The validation with each joint's [`JointError::model_stderr_rms`] from the standard
    /// errors of the predictions (row-major `samples x n`, N m or N: a model's
    /// `predict_stderr` at the same states); a joint with an unknown one (NaN) gets None.
    /// Refused when the length is not the validation's or a value is negative or infinite.
    pub fn with_model_stderr(mut self, stderr: &[f64]) -> Result<Self> {
        let n = self.joints.len();
        if stderr.len() != self.samples * n {
            return Err(Error::shape(
                "model standard errors",
                format!("{} x {n} like the torques", self.samples),
                format!("{} values", stderr.len()),
            ));
        }
        if let Some(i) = stderr.iter().position(|v| *v < 0.0 || v.is_infinite()) {
            return Err(Error::invalid(
                "model standard errors",
                format!(
                    "sample {}, joint {} is {}: expected a standard error (>= 0, or NaN where unknown)",
                    i / n,
                    self.joints[i % n].joint,
                    stderr[i]
                ),
            ));
        }
        for (j, e) in self.joints.iter_mut().enumerate() {
            let column = (0..self.samples).map(|s| stderr[s * n + j]);
            e.model_stderr_rms = column.clone().all(|v| !v.is_nan()).then(|| rms(column));
        }
        Ok(self)
    }
}

/// The standard errors a model's `predict_stderr` gave, for [`Validation::with_model_stderr`]:
/// `None`, with the refusal's reason, for a model that carries none (saved before they were
/// stored); any other error as it is.
pub fn stored_stderr(result: Result<Vec<f64>>) -> Result<std::result::Result<Vec<f64>, String>> {
    match result {
        Ok(se) => Ok(Ok(se)),
        Err(Error::InvalidArgument { argument, message }) if argument == "predict_stderr" => {
            Ok(Err(message))
        }
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_past_the_largest_number_are_refused_and_large_ones_kept() {
        let joints = vec!["a".to_string(), "b".to_string()];
        let err = validate(&joints, &[0.0, -1e308, 0.0, 0.0], &[0.0, 1e308, 0.0, 0.0]).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("sample 0, joint b overflows (measured 1e308, predicted -1e308)"),
            "{message}"
        );
        // a torque of 1e308 against a prediction of 0 is an error of 1e308: kept, and its RMS too
        let v = validate(&joints, &[0.0, 0.0, 0.0, 0.0], &[0.0, 1e308, 0.0, 1e308]).unwrap();
        assert_eq!(v.joints[1].max, 1e308);
        assert!((v.joints[1].rms / 1e308 - 1.0).abs() < 1e-12);
        // and its mean, whose plain sum would overflow
        assert!((v.joints[1].mean / 1e308 - 1.0).abs() < 1e-12);
        assert_eq!(v.joints[0].mean, 0.0);
        let v = validate(&joints, &[0.0; 4], &[1.0, -2.0, 4.0, 1.0]).unwrap();
        assert_eq!((v.joints[0].mean, v.joints[1].mean), (2.5, -0.5));
    }

    #[test]
    fn model_standard_errors_are_summarised_per_joint() {
        let joints = vec!["a".to_string(), "b".to_string()];
        let v = validate(&joints, &[0.0; 4], &[1.0, 2.0, 3.0, 4.0]).unwrap();
        let v = v.with_model_stderr(&[0.3, f64::NAN, 0.4, 1.0]).unwrap();
        assert!((v.joints[0].model_stderr_rms.unwrap() - 0.125f64.sqrt()).abs() < 1e-15);
        assert_eq!(v.joints[1].model_stderr_rms, None);
        let e = v
            .clone()
            .with_model_stderr(&[0.3, 0.1, -0.4, 1.0])
            .unwrap_err();
        assert!(e.to_string().contains("sample 1, joint a is -0.4"), "{e}");
        assert!(v.with_model_stderr(&[0.3]).is_err());
    }
}
