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
        return Err(Error::Shape {
            argument: "validation".into(),
            expected: format!("predicted and measured torques of the same k x {n} samples, k >= 1"),
            got: format!(
                "{} predicted and {} measured values",
                predicted.len(),
                measured.len()
            ),
        });
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
        return Err(Error::Numerical {
            operation: "validation".into(),
            message: format!(
                "the error of sample {}, joint {} overflows (measured {}, predicted {}): torques this large cannot be compared",
                i / n,
                joint_names[i % n],
                crate::error::shown(measured[i]),
                crate::error::shown(predicted[i])
            ),
        });
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
            }
        })
        .collect();
    Ok(Validation {
        joints,
        samples: k,
        residuals,
    })
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
    }
}
