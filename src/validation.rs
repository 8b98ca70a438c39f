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
    let joints = (0..n)
        .map(|j| {
            let (mut e, mut m, mut max) = (0.0f64, 0.0f64, 0.0f64);
            for s in 0..k {
                let r = residuals[s * n + j];
                e += r * r;
                m += measured[s * n + j].powi(2);
                max = max.max(r.abs());
            }
            JointError {
                joint: joint_names[j].clone(),
                rms: (e / k as f64).sqrt(),
                relative_rms: (m > 0.0).then(|| (e / m).sqrt()),
                max,
            }
        })
        .collect();
    Ok(Validation {
        joints,
        samples: k,
        residuals,
    })
}
