//! Forward dynamics by the mass matrix and an in-place Cholesky factorisation: the faster of
//! the two algorithms for few degrees of freedom, and the one for coupled joints.

use super::crba::mass_matrix;
use super::rnea::bias_torque;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;

/// [`super::forward_dynamics::forward_dynamics`] by the mass matrix and a Cholesky factorisation, whatever the size.
/// Writes `data.qdd` (and `data.m`, `data.bias`). Fails if `M(q)` is not positive definite.
pub fn forward_dynamics_crba(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: Gravity,
) -> Result<()> {
    model.check_vector("tau", tau)?;
    bias_torque(model, data, q, qd, gravity)?;
    mass_matrix(model, data, q)?;
    let n = model.nv;
    for (qdd, (t, b)) in data.qdd.iter_mut().zip(tau.iter().zip(data.bias.iter())) {
        *qdd = t - b;
    }
    // Cholesky M = L L^T into the lower triangle of `chol`.
    let l = &mut data.chol;
    l.copy_from(&data.m);
    for j in 0..n {
        let mut d = l[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        // NaN fails too
        if d.is_nan() || d <= 0.0 {
            return Err(Error::numerical(
                "forward_dynamics",
                format!(
                    "the mass matrix is not positive definite at q = {q:?} (pivot {j} is {d:e})"
                ),
            ));
        }
        let d = d.sqrt();
        l[(j, j)] = d;
        for i in (j + 1)..n {
            let mut s = l[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = s / d;
        }
    }
    // Solve L y = b, then L^T x = y.
    let x = &mut data.qdd;
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= l[(i, k)] * x[k];
        }
        x[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in (i + 1)..n {
            s -= l[(k, i)] * x[k];
        }
        x[i] = s / l[(i, i)];
    }
    super::check_result("forward_dynamics", "qdd", data.qdd.as_slice())
}
