//! The globally linearised model (METHOD.md section 8a, the paper's "direct method" rows):
//! constant `D_g`, `H_g`, `G_g` and an offset fitted to all samples of an excitation in the form
//! `tau = T + D_g (qdd - qdd*) + H_g (qd - qd*) + G_g (q - q*)`.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::parameters::Batch;
use crate::error::Result;
use crate::local::OperatingPoint;
use crate::regression::least_squares;

/// A globally linearised model about an operating point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GlobalLinearModel {
    pub op: OperatingPoint,
    /// The fitted torque at the operating point `T` (N m).
    pub offset: Vec<f64>,
    #[serde(with = "crate::json::rows")]
    pub d: DMatrix<f64>,
    #[serde(with = "crate::json::rows")]
    pub h: DMatrix<f64>,
    #[serde(with = "crate::json::rows")]
    pub g: DMatrix<f64>,
    /// Standard errors of `[T D H G]` (`nv x (1 + 3 nv)`).
    #[serde(with = "crate::json::rows")]
    pub stderr: DMatrix<f64>,
    pub residual_rms: Vec<f64>,
    pub cond: f64,
}

impl GlobalLinearModel {
    /// Predicted torques (N m, row-major `k x nv`) at a batch of states:
    /// `T + D_g (qdd - qdd*) + H_g (qd - qd*) + G_g (q - q*)`.
    pub fn predict(&self, batch: &Batch<'_>) -> Result<Vec<f64>> {
        let nv = self.offset.len();
        let k = batch.samples(nv)?;
        let mut out = Vec::with_capacity(k * nv);
        for s in 0..k {
            let x = |v: &[f64], o: &[f64]| DVector::from_fn(nv, |j, _| v[s * nv + j] - o[j]);
            let tau = DVector::from_column_slice(&self.offset)
                + &self.d * x(batch.qdd, &self.op.qdd)
                + &self.h * x(batch.qd, &self.op.qd)
                + &self.g * x(batch.q, &self.op.q);
            out.extend(tau.iter());
        }
        Ok(out)
    }
}

/// Fits the globally linearised model at `op` to the samples of `batch` and `tau` (row-major
/// `k x nv`; rad, rad/s, rad/s^2, N m): one least-squares solve, `nv` outputs.
pub fn identify_global_linear(
    op: &OperatingPoint,
    batch: &Batch<'_>,
    tau: &[f64],
) -> Result<GlobalLinearModel> {
    let nv = op.n();
    let k = batch.samples_with_torques(nv, tau)?;
    let x = DMatrix::from_fn(k, 1 + 3 * nv, |s, c| match c {
        0 => 1.0,
        c if c <= nv => batch.qdd[s * nv + c - 1] - op.qdd[c - 1],
        c if c <= 2 * nv => batch.qd[s * nv + c - 1 - nv] - op.qd[c - 1 - nv],
        c => batch.q[s * nv + c - 1 - 2 * nv] - op.q[c - 1 - 2 * nv],
    });
    let y = DMatrix::from_fn(k, nv, |s, j| tau[s * nv + j]);
    let mut names = vec!["1".to_string()];
    for v in ["dqdd", "dqd", "dq"] {
        names.extend((1..=nv).map(|j| format!("{v}{j}")));
    }
    let ls = least_squares(&x, &y, "globally linearised model", &names)?;
    Ok(GlobalLinearModel {
        op: op.clone(),
        offset: ls.coef.column(0).iter().copied().collect(),
        d: ls.coef.columns(1, nv).into_owned(),
        h: ls.coef.columns(1 + nv, nv).into_owned(),
        g: ls.coef.columns(1 + 2 * nv, nv).into_owned(),
        stderr: ls.stderr,
        residual_rms: ls.residual_rms.iter().copied().collect(),
        cond: ls.cond,
    })
}
