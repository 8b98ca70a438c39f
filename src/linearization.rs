//! The local model of the dynamics at an operating point (the paper's eqs. 3-7):
//! `tau - T* ~= D* dqdd + H* dqd + G* dq`.

use nalgebra::{DMatrix, DVector};

use crate::algorithms::derivatives::derivatives_at;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
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

impl Linearization {
    /// A linearisation of `nv` joints filled with zeros (a buffer for [`linearize_into`]).
    pub fn zeros(nv: usize) -> Self {
        Self {
            torque: DVector::zeros(nv),
            d: DMatrix::zeros(nv, nv),
            h: DMatrix::zeros(nv, nv),
            g: DMatrix::zeros(nv, nv),
            g_static: DMatrix::zeros(nv, nv),
        }
    }
}

/// Linearises the inverse dynamics at `(q, qd, qdd)` (length `model.nv` each), analytically.
/// `gravity` switches gravity on in every term.
///
/// ```
/// use perturbid_rs::{linearize, mass_matrix, robots, Data, Gravity};
/// let model = robots::builtin("a465")?;
/// let mut data = Data::new(&model);
/// let (q, qd, qdd) = ([0.1; 6], [0.2; 6], [0.3; 6]);
/// let lin = linearize(&model, &mut data, &q, &qd, &qdd, Gravity::Excluded)?;
/// mass_matrix(&model, &mut data, &q)?;
/// assert!((&lin.d - &data.m).norm() < 1e-12); // D* = M(q*)
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn linearize(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<Linearization> {
    let mut out = Linearization::zeros(model.nv);
    linearize_into(model, data, q, qd, qdd, gravity, &mut out)?;
    Ok(out)
}

/// [`linearize`] into a preallocated `out` (from [`Linearization::zeros`]): no allocation.
/// Fails if `out` is not sized for `model.nv`.
pub fn linearize_into(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: &mut Linearization,
) -> Result<()> {
    if out.torque.len() != model.nv || out.d.shape() != (model.nv, model.nv) {
        return Err(Error::shape(
            "out",
            format!("a Linearization of {} joints", model.nv),
            format!("{} joints", out.torque.len()),
        ));
    }
    derivatives_at(model, data, q, Some(qd), Some(qdd), gravity)?;
    out.torque.copy_from(&data.tau);
    out.d.copy_from(&data.m);
    out.h.copy_from(&data.dtau_dv);
    out.g.copy_from(&data.dtau_dq);
    // At rest: Gs = d tau / d q at (q, 0, 0).
    derivatives_at(model, data, q, None, None, gravity)?;
    out.g_static.copy_from(&data.dtau_dq);
    Ok(())
}
