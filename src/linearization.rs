//! The local model of the dynamics at an operating point (the paper's eqs. 3-7):
//! `tau - T* ~= D* dqdd + H* dqd + G* dq`.

use nalgebra::{DMatrix, DVector};

use crate::algorithms::derivatives::rnea_derivatives;
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;

/// The linearisation of the inverse dynamics at `P = (q*, qd*, qdd*)`. Torques in N m (or N),
/// matrices `nv x nv` with row = torque, column = joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Linearization {
    /// `T* = tau(q*, qd*, qdd*)`.
    pub torque: DVector<f64>,
    /// `D* = d tau / d qdd = M(q*)`.
    pub d: DMatrix<f64>,
    /// `H* = d tau / d qd` at P (Coriolis and centrifugal Jacobian; rigid body only).
    pub h: DMatrix<f64>,
    /// `G* = d tau / d q` at P: includes `d(M(q) qdd*)/dq` and `d c(q, qd*)/dq`, not only gravity.
    pub g: DMatrix<f64>,
    /// `Gs = d tau / d q` at rest at `q*` (`qd = qdd = 0`): the static gravity stiffness
    /// `d g / d q`, what the paper's step 2 measures. Zero when `gravity` is off.
    pub g_static: DMatrix<f64>,
}

/// Linearises the inverse dynamics at `(q, qd, qdd)` (length `model.nv` each), analytically.
/// `gravity` switches gravity on in every term.
pub fn linearize(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: bool,
) -> Result<Linearization> {
    let zeros = vec![0.0; model.nv];
    rnea_derivatives(model, data, q, &zeros, &zeros, gravity)?;
    let g_static = data.dtau_dq.clone();
    rnea_derivatives(model, data, q, qd, qdd, gravity)?;
    Ok(Linearization {
        torque: data.tau.clone(),
        d: data.m.clone(),
        h: data.dtau_dv.clone(),
        g: data.dtau_dq.clone(),
        g_static,
    })
}
