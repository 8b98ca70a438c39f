//! The globally linearised model (docs/method.md, section 8a, the paper's "direct method" rows):
//! constant `D_g`, `H_g`, `G_g` and an offset fitted to all samples of an excitation in the form
//! `tau = T + D_g (qdd - qdd*) + H_g (qd - qd*) + G_g (q - q*)`.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::document::{check_condition, check_magnitude_rows, check_magnitudes, invalid, Document};
use crate::error::Result;
use crate::operating_point::OperatingPoint;
use crate::regression::least_squares;
use crate::states::States;
use crate::torque_model::{check_joints, predict_linear};
use crate::torque_model::{torque_at, Expansion, TorqueModel};

/// A globally linearised model about an operating point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GlobalLinearModel {
    /// `perturbid-global-linear-model/1`.
    pub format: String,
    /// The joints of the robot, in coordinate order (`joint1`, ... when not known).
    pub joint_names: Vec<String>,
    pub op: OperatingPoint,
    /// The fitted torque at the operating point `T` (N m).
    pub offset: Vec<f64>,
    #[serde(with = "crate::json::rows")]
    pub d: DMatrix<f64>,
    #[serde(with = "crate::json::rows")]
    pub h: DMatrix<f64>,
    #[serde(with = "crate::json::rows")]
    pub g: DMatrix<f64>,
    /// Standard errors of `[T D H G]` (`nv x (1 + 3 nv)`); NaN (`null` in JSON) without a
    /// residual degree of freedom.
    #[serde(with = "crate::json::stderr_rows")]
    pub stderr: DMatrix<f64>,
    pub residual_rms: Vec<f64>,
    pub cond: f64,
}

impl GlobalLinearModel {
    /// Predicted torques (N m, row-major `k x nv`) at a batch of states:
    /// `T + D_g (qdd - qdd*) + H_g (qd - qd*) + G_g (q - q*)`.
    pub fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        predict_linear(states, &self.offset, [&self.d, &self.h, &self.g], &self.op)
    }
}

/// Fits the globally linearised model at `op` to the samples of `batch` and `tau` (row-major
/// `k x nv`; rad, rad/s, rad/s^2, N m): one least-squares solve, `nv` outputs.
pub fn identify_global_linear(
    op: &OperatingPoint,
    states: &States<'_>,
    tau: &[f64],
) -> Result<GlobalLinearModel> {
    let nv = op.n();
    check_joints(states, nv)?;
    states.check_companion("tau", tau, nv)?;
    let joint_names: Vec<String> = (1..=nv).map(|j| format!("joint{j}")).collect();
    crate::torque_model::refuse_flat_torques(
        states,
        tau,
        &joint_names,
        crate::torque_model::FOR_A_FIT,
    )?;
    let k = states.len();
    let (q, qd, qdd) = (states.q(), states.qd_or_zeros(), states.qdd_or_zeros());
    let x = DMatrix::from_fn(k, 1 + 3 * nv, |s, c| match c {
        0 => 1.0,
        c if c <= nv => qdd[s * nv + c - 1] - op.qdd[c - 1],
        c if c <= 2 * nv => qd[s * nv + c - 1 - nv] - op.qd[c - 1 - nv],
        c => q[s * nv + c - 1 - 2 * nv] - op.q[c - 1 - 2 * nv],
    });
    let y = DMatrix::from_fn(k, nv, |s, j| tau[s * nv + j]);
    let mut names = vec!["1".to_string()];
    for v in ["dqdd", "dqd", "dq"] {
        names.extend((1..=nv).map(|j| format!("{v}{j}")));
    }
    let ls = least_squares(&x, &y, "globally linearised model", &names)?;
    Ok(GlobalLinearModel {
        format: GlobalLinearModel::tag(),
        joint_names,
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

impl Document for GlobalLinearModel {
    const FORMAT: &'static str = "perturbid-global-linear-model";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "globally linearised model";

    /// Checks every shape against the number of joints, and that standard errors and
    /// residuals are magnitudes (`>= 0`, or unknown) and the condition number at least 1.
    fn validate(&self) -> Result<()> {
        let n = self.offset.len();
        let square = [&self.d, &self.h, &self.g]
            .iter()
            .all(|m| m.shape() == (n, n));
        if !square
            || self.joint_names.len() != n
            || self.op.q.len() != n
            || self.op.qd.len() != n
            || self.op.qdd.len() != n
            || self.stderr.shape() != (n, 1 + 3 * n)
            || self.residual_rms.len() != n
        {
            return Err(invalid(
                Self::WHAT,
                format!("its parts do not all have the {n} joints of the offset"),
            ));
        }
        crate::document::check_joint_names(Self::WHAT, &self.joint_names)?;
        check_magnitude_rows(Self::WHAT, "stderr", &self.stderr, true)?;
        check_magnitudes(Self::WHAT, "residual_rms", &self.residual_rms, false)?;
        check_condition(Self::WHAT, "cond", self.cond)
    }
}

impl TorqueModel for GlobalLinearModel {
    fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        GlobalLinearModel::predict(self, states)
    }

    fn linearize(&self, op: &OperatingPoint) -> Result<Expansion> {
        Ok(Expansion {
            torque: torque_at(self, op)?,
            d: self.d.clone(),
            h: self.h.clone(),
            g: self.g.clone(),
            g_static: None,
        })
    }
}
