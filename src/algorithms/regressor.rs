//! The joint-torque regressor `tau = Phi(q, qd, qdd) theta`: inverse dynamics linear in the
//! inertial parameters (Pinocchio's `computeJointTorqueRegressor`, same parameter order).

use nalgebra::{DMatrix, DVector, Vector3};

use super::kinematics::motion_pass;
use super::load_state;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{Force, Inertia, Motion};

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
    // I_p x for the unit inertias of [Ixx, Ixy, Iyy, Ixz, Iyz, Izz]
    let unit = |x: &Vector3<f64>| {
        [
            Vector3::new(x.x, 0.0, 0.0),
            Vector3::new(x.y, x.x, 0.0),
            Vector3::new(0.0, x.y, 0.0),
            Vector3::new(x.z, 0.0, x.x),
            Vector3::new(0.0, x.z, x.y),
            Vector3::new(0.0, 0.0, x.z),
        ]
    };
    let (ia, iw) = (unit(&al), unit(&w));
    for p in 0..6 {
        out[4 + p] = Force {
            angular: ia[p] + w.cross(&iw[p]),
            linear: zero,
        };
    }
    out
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
    gravity: bool,
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
        data.s_world[i] = data.o_mi[i].act_motion(&b.motion_subspace());
    }
    out.fill(0.0);
    for i in 0..nb {
        let columns = body_regressor(&data.v[i], &data.a[i]);
        let x = data.o_mi[i];
        for (c, f) in columns.iter().enumerate() {
            let fw = x.act_force(f);
            let col = PARAMS_PER_BODY * i + c;
            let mut j = Some(i);
            while let Some(k) = j {
                let b = &model.bodies[k];
                out[(b.dof, col)] += b.multiplier * data.s_world[k].dot(&fw);
                j = b.parent;
            }
        }
    }
    Ok(())
}
