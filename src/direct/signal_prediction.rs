//! The signal a model with drive gains predicts (motor currents: the feed-forward a motion
//! needs), with its standard error from the joint fit of base parameters and gains
//! ([`super::drive_gains`]).
//!
//! Joint `j`'s signal is `i_j = Phi_j theta / K_j`. The parameters and the gains were fitted
//! together and share one scale (the payload's), so their errors are correlated: a payload
//! that loads a joint weakly leaves `theta` and `K` free to grow together, which leaves `i`
//! well determined although each of them is not. The standard error takes the whole
//! covariance of `[theta, K_j]`: `sqrt(z^T C z)`, `z = [Phi_j / K_j, -Phi_j theta / K_j^2]`
//! times the standard errors, `C` their correlation ([`BaseModel::correlation`] and
//! [`super::DriveGains::correlation`]).

use nalgebra::{DMatrix, DVector};

use super::base_model::BaseModel;
use super::parameters::regressor_blocks;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::regression::{refuse_overflow, root};
use crate::states::States;

impl BaseModel {
    /// The logged signal (row-major `k x nv`, in the unit the gains were identified for: A
    /// for motor currents) the model predicts at the samples of `states`: each joint's torque
    /// ([`Self::predict`]) over its drive gain. Refused for a model without drive gains, and
    /// as [`Self::predict`] refuses.
    pub fn predict_signal(&self, model: &Model, states: &States<'_>) -> Result<Vec<f64>> {
        let gains = self.gains_for("predict_signal")?;
        let mut tau = self.predict(model, states)?;
        for (x, t) in tau.iter_mut().enumerate() {
            *t /= gains.gain[x % model.nv];
        }
        Ok(tau)
    }

    /// The standard errors (row-major `k x nv`, signal units) of the signal
    /// [`Self::predict_signal`] gives at the samples of `states`, from the covariance of the
    /// parameters and the gains together (see the module docs): the uncertainty of the
    /// model's signal, not a measured one's scatter about it. NaN for a joint whose row weights
    /// a parameter of unknown standard error. Refused for a model without drive gains, or
    /// saved before their correlation with the parameters was stored, as
    /// [`Self::predict_stderr`] refuses, and where the arithmetic overflows.
    pub fn predict_signal_stderr(&self, model: &Model, states: &States<'_>) -> Result<Vec<f64>> {
        let gains = self.gains_for("predict_signal_stderr")?;
        let (p, nv) = (self.theta.len(), model.nv);
        self.check(model)?;
        if self.correlation.shape() != (p, p) || gains.correlation.shape() != (nv, p + nv) {
            return Err(Error::invalid(
                "predict_signal_stderr",
                "the model holds no correlation of its parameters' and gains' estimates (a model saved before it was stored): identify it again from its logs",
            ));
        }
        let theta = DVector::from_column_slice(&self.theta);
        // the correlation of the gains with the parameters: row j gain j's
        let cross = gains.correlation.columns(0, p);
        let mut out = Vec::with_capacity(states.len() * nv);
        regressor_blocks(model, &self.base.layout, states, self.gravity, |_, phi| {
            let rows = self.base.select(phi);
            let tau = &rows * &theta;
            // the block's rows (its samples' joints, sample after sample) over the gains, in
            // standard errors; every row's z^T R z at once: one product for the block
            let z = DMatrix::from_fn(rows.nrows(), p, |r, a| match self.stderr[a] {
                se if se.is_nan() => 0.0,
                se => rows[(r, a)] * se / gains.gain[r % nv],
            });
            let w = &z * &self.correlation;
            for r in 0..rows.nrows() {
                let j = r % nv;
                let (k, se_k) = (gains.gain[j], gains.stderr[j]);
                let unknown = (0..p).any(|a| self.stderr[a].is_nan() && rows[(r, a)] != 0.0);
                if unknown || se_k.is_nan() {
                    out.push(f64::NAN);
                    continue;
                }
                let zk = -tau[r] / (k * k) * se_k;
                let var =
                    z.row(r).dot(&w.row(r)) + 2.0 * zk * z.row(r).dot(&cross.row(j)) + zk * zk;
                out.push(root(var));
            }
            Ok(())
        })?;
        refuse_overflow(out, nv, "predicted signal's standard error")
    }

    /// The drive gains, for `operation`; refused for a model identified from torques.
    fn gains_for(&self, operation: &str) -> Result<&super::DriveGains> {
        self.drive_gains
            .as_ref()
            .ok_or_else(|| Error::invalid(
                operation,
                format!(
                    "the model of '{}' holds no drive gains: it was identified from torques, not from a logged signal (identify_drive_gains)",
                    self.robot
                ),
            ))
    }
}
