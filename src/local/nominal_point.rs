//! T* and the measured operating point: the means over the nominal experiment's crossings,
//! with their standard errors and the variance of the point's error.

use super::crossing::CrossingValues;
use super::identify::ExperimentValues;
use super::noise::sample_variance;
use super::plan::{ExperimentKind, Plan};
use super::quantisation;
use super::repeated_reading::{mean_variance, repeated_share};
use crate::error::{Error, Result};
use crate::operating_point::OperatingPoint;

/// T* and the measured operating point: the means over the nominal crossings, with their
/// standard errors.
pub(super) struct NominalPoint {
    /// The index of the nominal experiment among the values, if the plan has one.
    pub(super) nominal: Option<usize>,
    pub(super) torque: Vec<f64>,
    pub(super) torque_stderr: Vec<f64>,
    pub(super) op: OperatingPoint,
    /// `[q, qd, qdd]` of `op`.
    pub(super) state: [Vec<f64>; 3],
    /// The variance of the operating point's error, per variable and joint.
    pub(super) var: [Vec<f64>; 3],
    /// The part of `var` that every nominal pass repeats ([`super::repeated_reading`]): it
    /// stays whole in a reading carried to the planned point.
    pub(super) common: [Vec<f64>; 3],
    /// Per joint, the floor the torque's rounding to its logged steps puts under the standard
    /// error of `torque` (0 where the torque is not logged coarser than its noise).
    pub(super) rounding: Vec<f64>,
}

impl NominalPoint {
    pub(super) fn of(plan: &Plan, values: &[ExperimentValues]) -> Result<Self> {
        let n = plan.n();
        let index = values
            .iter()
            .position(|v| v.kind == ExperimentKind::Nominal);
        let nominal = index.map(|i| &values[i]);
        let needs_nominal = values.iter().any(|v| {
            matches!(
                v.kind,
                ExperimentKind::GDynamic | ExperimentKind::H | ExperimentKind::D
            )
        });
        let (torque, torque_stderr, op) = match nominal {
            Some(v) => Self::means(v, n),
            None if needs_nominal => return Err(Error::invalid(
                "plan",
                "the plan has no nominal experiment, which the G, H and D regressions need for T*",
            )),
            None => (vec![f64::NAN; n], vec![f64::NAN; n], plan.op.clone()),
        };
        let rounding = nominal.map_or_else(|| vec![0.0; n], |v| rounding_floor(v, n));
        let state = [op.q.clone(), op.qd.clone(), op.qdd.clone()];
        // the variance of the operating point's error, the mean of the nominal crossings':
        // noise averages over their K passes (/ K), but an error every pass repeats does not
        // (positions read by their band are rounded the same way in every pass of one
        // trajectory; otherwise the passes' residuals say how much repeats)
        let [mut var, mut common]: [[Vec<f64>; 3]; 2] =
            std::array::from_fn(|_| std::array::from_fn(|_| vec![0.0; n]));
        if let Some(v) = nominal {
            let k = v.crossings.len().max(1);
            for j in 0..n {
                let share = if v.crossings.iter().any(|c| c.position_band[j]) {
                    1.0
                } else {
                    repeated_share(&v.crossings, j)
                };
                for x in 0..3 {
                    let each = v.crossings.iter().map(|c| c.state_stderr[x][j].powi(2));
                    let each = each.sum::<f64>() / k as f64;
                    var[x][j] = mean_variance(each, share, k);
                    common[x][j] = each * share;
                }
            }
        }
        Ok(Self {
            nominal: index,
            torque,
            torque_stderr,
            op,
            state,
            var,
            common,
            rounding,
        })
    }

    /// The mean torque, its standard error and the mean state over the nominal crossings `v`.
    fn means(v: &ExperimentValues, n: usize) -> (Vec<f64>, Vec<f64>, OperatingPoint) {
        let k = v.crossings.len() as f64;
        let mean = |f: &dyn Fn(&CrossingValues) -> &[f64]| -> Vec<f64> {
            (0..n)
                .map(|j| v.crossings.iter().map(|c| f(c)[j]).sum::<f64>() / k)
                .collect()
        };
        let tau = mean(&|c| &c.tau);
        let rounding = rounding_floor(v, n);
        let se = (0..n)
            .map(|j| {
                let readings = v.crossings.iter().map(|c| c.tau[j]);
                let se = mean_stderr(readings, tau[j], v.crossings.len());
                if se.is_nan() {
                    se
                } else {
                    se.max(rounding[j])
                }
            })
            .collect();
        let op = OperatingPoint {
            q: mean(&|c| &c.q),
            qd: mean(&|c| &c.qd),
            qdd: mean(&|c| &c.qdd),
        };
        (tau, se, op)
    }
}

/// Per joint, the floor that rounding to the logged torque steps puts under the standard error
/// of the mean torque over the crossings of `v` (0 where the torque is not logged coarser than
/// its noise).
fn rounding_floor(v: &ExperimentValues, n: usize) -> Vec<f64> {
    let k = v.crossings.len().max(1) as f64;
    let samples = sample_variance(&v.crossings, n);
    (0..n)
        .map(|j| {
            quantisation::undithered_step(v.torque_step[j], samples[j])
                .map_or(0.0, |q| quantisation::rounding_stderr(q) / k.sqrt())
        })
        .collect()
}

/// The standard error of the mean `mean` of `k` readings from their scatter; NaN for fewer
/// than two.
pub(super) fn mean_stderr(readings: impl Iterator<Item = f64>, mean: f64, k: usize) -> f64 {
    if k < 2 {
        return f64::NAN;
    }
    let ss: f64 = readings.map(|x| (x - mean).powi(2)).sum();
    let k = k as f64;
    (ss / (k - 1.0) / k).sqrt()
}
