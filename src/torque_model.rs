//! One interface for every identified model: [`TorqueModel::predict`] gives the joint torques
//! at a batch of states, whether the model is local (the paper's method), base-parameter or
//! globally linearised (the direct method); each model implements it beside its own type, and
//! [`crate::model_file::ModelFile`] loads any of them from JSON.

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};
use crate::operating_point::OperatingPoint;
use crate::states::States;

/// A model of the joint torques of a robot.
pub trait TorqueModel {
    /// The names of the joints the model is for, in coordinate order.
    fn joint_names(&self) -> &[String];

    /// Predicted joint torques (row-major `k x nv`, N m or N) at the `k` samples of `states`
    /// (rad, rad/s, rad/s^2; missing velocities or accelerations are zeros).
    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>>;

    /// The model's first-order expansion at `op`: the torque there and `D = d tau / d qdd`,
    /// `H = d tau / d qd`, `G = d tau / d q` (`nv x nv`, row = torque, column = joint). A local
    /// or globally linearised model is linear: its D, H, G are the same everywhere and its
    /// torque is its prediction at `op`; a base-parameter model is linearised exactly at `op`.
    fn linearize(&self, op: &OperatingPoint) -> Result<Expansion>;
}

/// A model's first-order expansion at an operating point ([`TorqueModel::linearize`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Expansion {
    /// The torque at the point (N m).
    pub torque: DVector<f64>,
    pub d: DMatrix<f64>,
    pub h: DMatrix<f64>,
    pub g: DMatrix<f64>,
    /// `d g / d q` at rest at the point's q, where the model knows it (a base-parameter model;
    /// a local model whose plan had the G_static experiment).
    pub g_static: Option<DMatrix<f64>>,
}

/// The torque of a linear model at `op`.
pub(crate) fn torque_at(model: &dyn TorqueModel, op: &OperatingPoint) -> Result<DVector<f64>> {
    let states = States::new(op.n(), &op.q, Some(&op.qd), Some(&op.qdd))?;
    Ok(DVector::from_vec(model.predict(&states)?))
}

/// Fails unless `states` has `nv` joints per sample.
pub(crate) fn check_joints(states: &States<'_>, nv: usize) -> Result<()> {
    if states.nv() != nv {
        return Err(Error::shape(
            "q",
            format!("{nv} joints per sample (the model's)"),
            format!("{} joints per sample", states.nv()),
        ));
    }
    Ok(())
}

/// What a fit would make of a flat torque column ([`refuse_flat_torques`]).
pub(crate) const FOR_A_FIT: &str =
    "a fit would take it for a torque that does not depend on the motion";
/// What a validation would make of one (the front ends validate).
#[cfg(any(feature = "cli", feature = "python"))]
pub(crate) const FOR_A_VALIDATION: &str =
    "a validation against it would report the model's whole torque as its error";

/// Refuses torques (row-major `k x nv`, N m) in which a joint's column holds one value in
/// every one of `k >= 2` samples, bit for bit, while the robot moves (some `qd` or `qdd` is
/// not 0) or the value is not 0: a dead or saturated channel, or one far coarser than the
/// motion's effect, from which a fit would take a row of zeros for certain and against which
/// a validation would measure nothing. A torque of exactly 0 at rest throughout stays allowed
/// (gravity compensated, a joint about a vertical axis). `names` name the joints; `use_`
/// says what the torques were for ([`FOR_A_FIT`], [`FOR_A_VALIDATION`]).
pub(crate) fn refuse_flat_torques(
    states: &States<'_>,
    tau: &[f64],
    names: &[String],
    use_: &str,
) -> Result<()> {
    let nv = states.nv();
    let k = states.len();
    if k < 2 || tau.len() != k * nv {
        return Ok(());
    }
    let moving = [states.qd(), states.qdd()]
        .into_iter()
        .flatten()
        .any(|x| x.iter().any(|&v| v != 0.0));
    for j in 0..nv {
        let first = tau[j];
        let flat = (1..k).all(|s| tau[s * nv + j].to_bits() == first.to_bits());
        if flat && (moving || first != 0.0) {
            let name = names
                .get(j)
                .cloned()
                .unwrap_or_else(|| format!("{}", j + 1));
            return Err(Error::invalid(
                "tau",
                format!(
                    "the torque of joint '{name}' (column {}) is {} N m in all {k} samples{}: a dead or saturated channel, or one far coarser than the motion's effect; {use_}",
                    j + 1,
                    crate::error::shown(first),
                    if moving { " while the robot moves" } else { "" }
                ),
            ));
        }
    }
    Ok(())
}

/// The first-order expansion `T + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)` about `op` at
/// every sample of `states` (row-major `k x nv` out): the form of the local and the globally
/// linearised models.
pub(crate) fn predict_linear(
    states: &States<'_>,
    torque: &[f64],
    [d, h, g]: [&DMatrix<f64>; 3],
    op: &OperatingPoint,
) -> Result<Vec<f64>> {
    let nv = torque.len();
    check_joints(states, nv)?;
    let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
    let mut out = Vec::with_capacity(states.len() * nv);
    for s in 0..states.len() {
        let r = s * nv..(s + 1) * nv;
        let delta = |x: &[f64], x0: &[f64]| DVector::from_fn(nv, |j, _| x[j] - x0[j]);
        let tau = DVector::from_column_slice(torque)
            + d * delta(&qdd[r.clone()], &op.qdd)
            + h * delta(&qd[r.clone()], &op.qd)
            + g * delta(&states.q()[r], &op.q);
        out.extend(tau.iter());
    }
    check_prediction(&out, nv)?;
    Ok(out)
}

/// Fails when a predicted torque (row-major `k x nv`) is not finite: a model's coefficients
/// (read from a file) or a state so large that the arithmetic overflowed. No inf or NaN is
/// handed back.
pub(crate) fn check_prediction(tau: &[f64], nv: usize) -> Result<()> {
    match crate::finite::first_non_finite(tau) {
        Some(i) => Err(Error::numerical(
            "prediction",
            format!(
                "the torque of joint {} at sample {} is {}: the model's coefficients or the state are too large to compute with",
                i % nv.max(1) + 1,
                i / nv.max(1),
                tau[i]
            ),
        )),
        None => Ok(()),
    }
}
