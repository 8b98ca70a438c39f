//! Forward dynamics by the articulated-body algorithm (Featherstone, "Rigid Body Dynamics
//! Algorithms", 2008, ch. 7): O(n) in the bodies, in the body frames. [`crate::forward_dynamics`]
//! uses it from [`ABA_FROM_DOF`] degrees of freedom on, and the mass matrix with a Cholesky
//! factorisation below (fewer operations for short chains).

use nalgebra::{Matrix3, Matrix6};

use super::{check_result, load_state};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::{JointKind, Model};
use crate::spatial::{Motion, Se3};

/// From this many degrees of freedom [`crate::forward_dynamics`] runs the articulated-body
/// algorithm, below it the mass matrix and a Cholesky factorisation (measured on chains and
/// trees: `cargo bench --bench dynamics -- forward_dynamics`; see benches/README.md).
pub const ABA_FROM_DOF: usize = 12;

/// Joint accelerations `qdd = M(q)^-1 (tau - c(q, qd) - g(q))` (rad/s^2 or m/s^2) by the
/// articulated-body algorithm.
///
/// `q`, `qd`, `tau` (N m or N): length `model.nv`. `gravity`: include `g(q)`. Writes `data.qdd`.
/// Models with coupled (mimic) joints, whose bodies do not move independently, are solved by
/// the mass matrix instead ([`super::forward_dynamics::forward_dynamics_crba`]). Fails if a
/// joint's articulated inertia is not positive (a massless chain end).
pub fn aba(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: Gravity,
) -> Result<()> {
    if model.coupled || model.bodies.iter().any(|b| b.multiplier != 1.0) {
        return super::forward_dynamics_crba::forward_dynamics_crba(
            model, data, q, qd, tau, gravity,
        );
    }
    model.check_vector("tau", tau)?;
    load_state(model, data, q, Some(qd), None)?;
    let nb = model.nbodies();
    // pass 1: poses, twists, velocity-product accelerations, body inertias and bias forces
    for (i, b) in model.bodies.iter().enumerate() {
        let x = b.pose_in_parent(data.qb[i]);
        let s = subspace(b.kind, &b.axis);
        let vj = s.scale(data.vb[i]);
        let v = match b.parent {
            Some(p) => x.act_inv_motion(&data.v[p]) + vj,
            None => vj,
        };
        data.aba_c[i] = v.cross(&vj);
        let inertia = &b.inertia;
        data.aba_ia[i] = inertia.to_matrix();
        data.aba_pa[i] = v.cross_force(&inertia.apply(&v)).to_vector();
        data.li_mi[i] = x;
        data.v[i] = v;
    }
    // pass 2: articulated inertias from the leaves
    for i in (0..nb).rev() {
        let b = &model.bodies[i];
        let s = subspace(b.kind, &b.axis).to_vector();
        let ia = data.aba_ia[i];
        let u = ia * s;
        let d = s.dot(&u) + model.armature[b.dof];
        if d.is_nan() || d <= 0.0 {
            return Err(Error::numerical(
                "aba",
                format!(
                    "joint '{}' has articulated inertia {d:e} (not positive): nothing it moves \
                     has mass or inertia about its axis",
                    b.joint
                ),
            ));
        }
        let dinv = 1.0 / d;
        let ui = tau[b.dof] - s.dot(&data.aba_pa[i]);
        data.aba_u[i] = u;
        data.aba_dinv[i] = dinv;
        data.qdd[b.dof] = ui; // u_i, until pass 3
        if let Some(p) = b.parent {
            let ia_a = ia - u * u.transpose() * dinv;
            let c = data.aba_c[i].to_vector();
            let pa = data.aba_pa[i] + ia_a * c + u * (ui * dinv);
            let a = act_inv_matrix(&data.li_mi[i]);
            let ia_p = a.transpose() * ia_a * a;
            data.aba_ia[p] += ia_p;
            data.aba_pa[p] += a.transpose() * pa;
        }
    }
    // pass 3: accelerations from the base (gravity as a base acceleration)
    let base = model.base_acceleration(gravity);
    for (i, b) in model.bodies.iter().enumerate() {
        let x = &data.li_mi[i];
        let ap = match b.parent {
            Some(p) => data.a[p],
            None => base,
        };
        let a = x.act_inv_motion(&ap) + data.aba_c[i];
        let av = a.to_vector();
        let qdd = (data.qdd[b.dof] - data.aba_u[i].dot(&av)) * data.aba_dinv[i];
        data.qdd[b.dof] = qdd;
        data.a[i] = a + subspace(b.kind, &b.axis).scale(qdd);
    }
    check_result("aba", "qdd", data.qdd.as_slice())
}

/// The motion subspace of a joint in its body's frame.
#[inline]
fn subspace(kind: JointKind, axis: &nalgebra::Vector3<f64>) -> Motion {
    match kind {
        JointKind::Revolute => Motion::new(*axis, nalgebra::Vector3::zeros()),
        JointKind::Prismatic => Motion::new(nalgebra::Vector3::zeros(), *axis),
    }
}

/// The 6x6 matrix of `x.act_inv_motion` (`[angular; linear]`): parent motions into the child's
/// frame. Its transpose carries child forces into the parent's frame.
#[inline]
fn act_inv_matrix(x: &Se3) -> Matrix6<f64> {
    let rt = x.rotation.transpose();
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
    let px: Matrix3<f64> = crate::spatial::skew(&x.translation);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-rt * px));
    m
}
