//! Recursive Newton-Euler inverse dynamics, in body frames (Featherstone, RBDA Table 5.1).

use nalgebra::DVector;

use super::kinematics::motion_pass;
use super::{check_result, contract_vector, load_state};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;

/// Inverse dynamics `tau = M(q) qdd + c(q, qd) + g(q)` (rigid bodies and the joints'
/// armature, [`Model::armature`]; no friction).
///
/// - `q` (rad or m), `qd` (rad/s or m/s), `qdd` (rad/s^2 or m/s^2): length `model.nv` each.
/// - `gravity`: include `g(q)` (gravity `model.gravity`, along -z of the base frame).
///
/// Writes `data.tau` (`nv`, N m or N). Fails on a wrong length or a non-finite entry.
///
/// ```
/// use perturbid_rs::{rnea, robots, Data, Gravity};
/// let model = robots::builtin("a465")?;
/// let mut data = Data::new(&model);
/// let q = [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0];
/// rnea(&model, &mut data, &q, &[0.0; 6], &[0.0; 6], Gravity::Included)?;
/// let holding = data.tau.clone(); // at rest: the gravity torques
/// perturbid_rs::gravity_torque(&model, &mut data, &q)?;
/// assert!((&holding - &data.tau).norm() < 1e-12);
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn rnea(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<()> {
    load_state(model, data, q, Some(qd), Some(qdd))?;
    let mut out = std::mem::take(&mut data.tau);
    rnea_loaded(model, data, gravity, &mut out);
    model.add_armature_torque(qdd, out.as_mut_slice());
    data.tau = out;
    check_result("rnea", "tau", data.tau.as_slice())
}

/// Gravity torque `g(q)` (N m or N): the torque that holds the robot at rest at `q`.
/// Writes `data.g` (`nv`).
///
/// ```
/// use perturbid_rs::{gravity_torque, rnea, robots, Data, Gravity};
/// let model = robots::builtin("a465")?;
/// let mut data = Data::new(&model);
/// let q = [0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
/// gravity_torque(&model, &mut data, &q)?;
/// let g = data.g.clone();
/// rnea(&model, &mut data, &q, &[0.0; 6], &[0.0; 6], Gravity::Included)?; // at rest
/// assert!((&data.tau - &g).amax() < 1e-12);
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn gravity_torque(model: &Model, data: &mut Data, q: &[f64]) -> Result<()> {
    load_state(model, data, q, None, None)?;
    let mut out = std::mem::take(&mut data.g);
    rnea_loaded(model, data, Gravity::Included, &mut out);
    data.g = out;
    check_result("gravity_torque", "g", data.g.as_slice())
}

/// Bias torque `c(q, qd) + g(q)` (Coriolis, centrifugal and, with `gravity`, gravity terms):
/// the inverse dynamics at zero acceleration. Writes `data.bias` (`nv`).
pub fn bias_torque(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    gravity: Gravity,
) -> Result<()> {
    load_state(model, data, q, Some(qd), None)?;
    let mut out = std::mem::take(&mut data.bias);
    rnea_loaded(model, data, gravity, &mut out);
    data.bias = out;
    check_result("bias_torque", "the bias torque", data.bias.as_slice())
}

/// RNEA on the body coordinates already in `data` (`qb`, `vb`, `ab`); torques into `out`.
pub(crate) fn rnea_loaded(
    model: &Model,
    data: &mut Data,
    gravity: Gravity,
    out: &mut DVector<f64>,
) {
    motion_pass(model, data, gravity);
    for (i, b) in model.bodies.iter().enumerate() {
        let h = b.inertia.apply(&data.v[i]);
        data.f[i] = b.inertia.apply(&data.a[i]) + data.v[i].cross_force(&h);
    }
    let coupled = model.coupled;
    for i in (0..model.nbodies()).rev() {
        let b = &model.bodies[i];
        let t = b.motion_subspace().dot(&data.f[i]);
        if coupled {
            data.tau_b[i] = t;
        } else {
            out[i] = t;
        }
        if let Some(p) = b.parent {
            let fp = data.li_mi[i].act_force(&data.f[i]);
            data.f[p] += fp;
        }
    }
    if coupled {
        contract_vector(model, &data.tau_b, out);
    }
}
