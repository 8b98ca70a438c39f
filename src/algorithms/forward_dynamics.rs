//! Forward dynamics: the articulated-body algorithm ([`super::aba::aba`]) from
//! [`super::aba::ABA_FROM_DOF`] degrees of freedom on, the mass matrix and an in-place Cholesky
//! factorisation ([`forward_dynamics_crba`]) below.

pub use super::forward_dynamics_crba::forward_dynamics_crba;
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;

/// Joint accelerations `qdd = M(q)^-1 (tau - c(q, qd) - g(q))` (rad/s^2 or m/s^2), by whichever
/// of the two algorithms is faster for the model's size (equal up to rounding).
///
/// `q`, `qd`, `tau` (N m or N): length `model.nv`. `gravity`: include `g(q)`. Writes `data.qdd`.
/// Fails if the model's inertia is singular at `q`.
///
/// ```
/// use perturbid_rs::{forward_dynamics, rnea, robots, Data, Gravity};
/// let model = robots::builtin("a465")?;
/// let mut data = Data::new(&model);
/// let (q, qd) = ([0.3, -0.2, 0.5, 0.1, 0.4, -0.6], [0.5, 0.1, -0.3, 0.2, 0.0, 1.0]);
/// let tau = [10.0, -5.0, 3.0, 0.5, -0.2, 0.1];
/// forward_dynamics(&model, &mut data, &q, &qd, &tau, Gravity::Included)?;
/// let qdd = data.qdd.clone();
/// rnea(&model, &mut data, &q, &qd, qdd.as_slice(), Gravity::Included)?; // back to the torques
/// assert!(data.tau.iter().zip(tau).all(|(a, b)| (a - b).abs() < 1e-9));
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn forward_dynamics(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: Gravity,
) -> Result<()> {
    if model.nv >= super::aba::ABA_FROM_DOF {
        super::aba::aba(model, data, q, qd, tau, gravity)
    } else {
        forward_dynamics_crba(model, data, q, qd, tau, gravity)
    }
}
