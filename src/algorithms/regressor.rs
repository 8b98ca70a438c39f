//! The joint-torque regressor `tau = Phi(q, qd, qdd) theta`: inverse dynamics linear in the
//! inertial parameters (Pinocchio's `computeJointTorqueRegressor`, same parameter order).

use nalgebra::{DMatrix, DVector, Vector3};

use super::kinematics::motion_pass;
use super::load_state;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::spatial::{Force, Inertia, Motion, Se3};

/// Number of inertial parameters per body.
pub const PARAMS_PER_BODY: usize = 10;

/// Names of the 10 parameters of a body, in order: `m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz,
/// Izz`.
pub const PARAMETER_NAMES: [&str; 10] = [
    "m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz",
];

/// The 10 inertial parameters of a body in Pinocchio's order `[m, m cx, m cy, m cz, Ixx, Ixy,
/// Iyy, Ixz, Iyz, Izz]` (kg, kg m, kg m^2), the inertia about the body (joint) frame's origin.
pub fn dynamic_parameters(inertia: &Inertia) -> [f64; 10] {
    let h = inertia.com * inertia.mass;
    let i = inertia.inertia_origin();
    [
        inertia.mass,
        h.x,
        h.y,
        h.z,
        i[(0, 0)],
        i[(0, 1)],
        i[(1, 1)],
        i[(0, 2)],
        i[(1, 2)],
        i[(2, 2)],
    ]
}

/// The inertia with the 10 parameters `p` (the inverse of [`dynamic_parameters`]); `None` when
/// the mass is not positive (the centre of mass `h / m` is then undefined). The rotational
/// inertia need not be one a rigid body can have: the algorithms are linear in it.
pub fn inertia_from_parameters(p: &[f64; 10]) -> Option<Inertia> {
    let m = p[0];
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let com = nalgebra::Vector3::new(p[1], p[2], p[3]) / m;
    let origin = nalgebra::Matrix3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]);
    let shift = (nalgebra::Matrix3::identity() * com.norm_squared() - com * com.transpose()) * m;
    Some(Inertia::new(m, com, origin - shift))
}

/// The inertial parameters of every moving body, stacked (`10 * nbodies`), so that
/// `Phi theta = rnea` for the model's own inertias.
pub fn model_parameters(model: &Model) -> DVector<f64> {
    DVector::from_iterator(
        PARAMS_PER_BODY * model.nbodies(),
        model
            .bodies
            .iter()
            .flat_map(|b| dynamic_parameters(&b.inertia)),
    )
}

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
        return Err(Error::Shape {
            argument: "regressor output".into(),
            expected: format!("{} x {}", model.nv, PARAMS_PER_BODY * nb),
            got: format!("{} x {}", out.nrows(), out.ncols()),
        });
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
