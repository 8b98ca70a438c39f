//! Rigid-body dynamics algorithms as free functions `algo(&model, &mut data, ...)`, writing
//! their results into [`crate::Data`]. Vectors are slices of length `model.nv` in joint units
//! (rad, m, rad/s, m/s, rad/s^2, m/s^2); torques are N m (revolute) or N (prismatic).
//!
//! Internally every algorithm runs over bodies; for models with mimic couplings the body
//! coordinates are mapped from and to the degrees of freedom here.

pub mod aba;
pub mod batch;
pub mod crba;
pub mod derivatives;
pub mod forward_dynamics;
pub mod forward_dynamics_crba;
pub mod kinematics;
pub mod linearization_regressor;
pub mod parallel;
pub mod regressor;
pub mod rnea;
pub(crate) mod row_major;

use nalgebra::{DMatrix, DVector};

use crate::data::Data;
use crate::error::Result;
use crate::model::Model;

/// Checks the state vectors and writes the body coordinates into `data`.
// inlined into every algorithm: measured 5-10 % faster one-sample calls
#[inline(always)]
pub(crate) fn load_state(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
) -> Result<()> {
    data.check(model)?;
    model.check_vector("q", q)?;
    if let Some(qd) = qd {
        model.check_vector("qd", qd)?;
    }
    if let Some(qdd) = qdd {
        model.check_vector("qdd", qdd)?;
    }
    for (i, b) in model.bodies.iter().enumerate() {
        data.qb[i] = b.multiplier * q[b.dof] + b.offset;
        data.vb[i] = qd.map_or(0.0, |v| b.multiplier * v[b.dof]);
        data.ab[i] = qdd.map_or(0.0, |a| b.multiplier * a[b.dof]);
    }
    Ok(())
}

/// `out[dof] = sum over bodies i of that dof of multiplier_i * body[i]`.
pub(crate) fn contract_vector(model: &Model, body: &DVector<f64>, out: &mut DVector<f64>) {
    out.fill(0.0);
    for (i, b) in model.bodies.iter().enumerate() {
        out[b.dof] += b.multiplier * body[i];
    }
}

/// `out = C^T body C` with `C[i, dof_i] = multiplier_i`.
pub(crate) fn contract_matrix(model: &Model, body: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    out.fill(0.0);
    for (i, bi) in model.bodies.iter().enumerate() {
        for (j, bj) in model.bodies.iter().enumerate() {
            out[(bi.dof, bj.dof)] += bi.multiplier * bj.multiplier * body[(i, j)];
        }
    }
}

/// Fails when a result of `algorithm` is not finite: finite inputs so large that the arithmetic
/// overflowed. No inf or NaN is handed back.
#[inline]
pub(crate) fn check_result(algorithm: &str, name: &str, values: &[f64]) -> Result<()> {
    match crate::finite::first_non_finite(values) {
        Some(i) => Err(overflow(algorithm, name, values[i], i)),
        None => Ok(()),
    }
}

/// The error for a result `name` of `algorithm` that came out as `value` (inf or NaN) at `entry`.
pub(crate) fn overflow(algorithm: &str, name: &str, value: f64, entry: usize) -> crate::Error {
    crate::error::Error::numerical(
        algorithm,
        format!("{name} is {value} at entry {entry}: the state is too large to compute with"),
    )
}
