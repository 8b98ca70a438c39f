//! The joint-torque regressor `tau = Phi(q, qd, qdd) theta`: inverse dynamics linear in the
//! inertial parameters (Pinocchio's `computeJointTorqueRegressor`, same parameter order).

use nalgebra::{DMatrix, Vector3};

use super::kinematics::motion_pass;
use super::load_state;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::spatial::{Force, Motion, Se3};

pub use crate::parameters::{
    dynamic_parameters, inertia_from_parameters, model_parameters, PARAMETER_NAMES, PARAMS_PER_BODY,
};

/// The wrench (in the body frame) per unit of each of the 10 parameters of a body with twist
/// `v` and spatial acceleration `a` (gravity included): `f = Y(v, a) theta_body`.
pub fn body_regressor(v: &Motion, a: &Motion) -> [Force; 10] {
    let (w, al) = (v.angular, a.angular);
    let ac = a.linear + w.cross(&v.linear); // classical acceleration of the origin
    let zero = Vector3::zeros();
    let mut out = [Force::zeros(); 10];
    out[0] = Force {
        angular: zero,
        linear: ac,
    };
    for k in 0..3 {
        let e = Vector3::ith(k, 1.0);
        out[1 + k] = Force {
            angular: e.cross(&ac),
            linear: al.cross(&e) + w.cross(&w.cross(&e)),
        };
    }
    let (ia, iw) = (unit_inertia_products(&al), unit_inertia_products(&w));
    for p in 0..6 {
        out[4 + p] = Force {
            angular: ia[p] + w.cross(&iw[p]),
            linear: zero,
        };
    }
    out
}

/// [`body_regressor`] expressed in the base frame, for a body at pose `x` (`oXi`): column `c`
/// is `x.act_force(&body_regressor(v, a)[c])`. The six rotational-inertia columns have no force
/// part (`linear == 0`) in any frame.
#[inline(always)]
pub fn world_body_regressor(v: &Motion, a: &Motion, x: &Se3) -> [Force; 10] {
    let (r, p) = (&x.rotation, &x.translation);
    let (w, al) = (v.angular, a.angular);
    let ac = r * (a.linear + w.cross(&v.linear)); // classical acceleration of the origin
    let (ww, alw) = (r * w, r * al);
    let w2 = w.norm_squared();
    let mut out = [Force::zeros(); 10];
    out[0] = Force {
        angular: p.cross(&ac),
        linear: ac,
    };
    for k in 0..3 {
        // R (e_k x ac_local) = r_k x ac;  R (al x e_k + w x (w x e_k)) = alw x r_k + ww w_k - r_k |w|^2
        let rk: Vector3<f64> = r.column(k).into();
        let linear = alw.cross(&rk) + ww * w[k] - rk * w2;
        out[1 + k] = Force {
            angular: rk.cross(&ac) + p.cross(&linear),
            linear,
        };
    }
    // the rotational-inertia columns, rotated
    let (ia, iw) = (unit_inertia_products(&al), unit_inertia_products(&w));
    for q in 0..6 {
        out[4 + q].angular = r * (ia[q] + w.cross(&iw[q]));
    }
    out
}

/// `I x` for the unit rotational inertias of `[Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (the symmetric
/// matrices with ones at those entries).
#[inline(always)]
fn unit_inertia_products(x: &Vector3<f64>) -> [Vector3<f64>; 6] {
    [
        Vector3::new(x.x, 0.0, 0.0),
        Vector3::new(x.y, x.x, 0.0),
        Vector3::new(0.0, x.y, 0.0),
        Vector3::new(x.z, 0.0, x.x),
        Vector3::new(0.0, x.z, x.y),
        Vector3::new(0.0, 0.0, x.z),
    ]
}

/// The joint-torque regressor at `(q, qd, qdd)` (length `model.nv` each; rad, rad/s, rad/s^2):
/// writes `out` (`nv x 10 nbodies`, N m per parameter unit) such that
/// `out * theta = rnea(q, qd, qdd)`, with `theta` from [`model_parameters`] ordering (body
/// after body, each in [`PARAMETER_NAMES`] order, about the body's joint frame). `gravity`
/// includes gravity.
pub fn joint_torque_regressor(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    let nb = model.nbodies();
    if out.shape() != (model.nv, PARAMS_PER_BODY * nb) {
        return Err(Error::shape(
            "regressor output",
            format!("{} x {}", model.nv, PARAMS_PER_BODY * nb),
            format!("{} x {}", out.nrows(), out.ncols()),
        ));
    }
    load_state(model, data, q, Some(qd), Some(qdd))?;
    motion_pass(model, data, gravity);
    // base-frame poses and motion subspaces: each column's wrench is moved to the base frame
    // once, then projected on every ancestor's axis there (Pinocchio's approach)
    for (i, b) in model.bodies.iter().enumerate() {
        data.o_mi[i] = match b.parent {
            Some(p) => data.o_mi[p].compose(&data.li_mi[i]),
            None => data.li_mi[i],
        };
        data.s_world[i] = b.motion_subspace_in(&data.o_mi[i]);
    }
    out.fill(0.0);
    let nv = model.nv;
    let o = out.as_mut_slice(); // column-major nv x 10 nb
    for i in 0..nb {
        let columns = world_body_regressor(&data.v[i], &data.a[i], &data.o_mi[i]);
        let first = PARAMS_PER_BODY * i * nv;
        let mut j = Some(i);
        while let Some(k) = j {
            let b = &model.bodies[k];
            let s = &data.s_world[k];
            let (w, l) = (s.angular * b.multiplier, s.linear * b.multiplier);
            let at = |c: usize| first + c * nv + b.dof;
            // mass and first moments: full wrenches; rotational inertias: moments only
            for (c, f) in columns[..4].iter().enumerate() {
                o[at(c)] += w.dot(&f.angular) + l.dot(&f.linear);
            }
            for (c, f) in columns[4..].iter().enumerate() {
                o[at(4 + c)] += w.dot(&f.angular);
            }
            j = b.parent;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_columns_are_the_moved_body_columns() {
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let a = Motion::new(Vector3::new(-0.2, 0.4, 0.1), Vector3::new(0.5, -0.3, 9.9));
        let x = Se3::from_xyz_rpy([0.1, 0.2, -0.3], [0.4, -0.5, 0.6]);
        let local = body_regressor(&v, &a);
        let world = world_body_regressor(&v, &a, &x);
        for (l, w) in local.iter().zip(&world) {
            let moved = x.act_force(l).to_vector();
            assert!((moved - w.to_vector()).norm() < 1e-12, "{moved} vs {w:?}");
        }
    }
}
