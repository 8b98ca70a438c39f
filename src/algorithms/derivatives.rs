//! Analytic partial derivatives of the inverse dynamics: the recursion of Carpentier & Mansard,
//! "Analytical derivatives of rigid body dynamics algorithms" (RSS 2018), carried out in the
//! base frame. Exact (no finite differences), O(n^2) for a chain.

use nalgebra::{DMatrix, DVector};

use super::{check_result, contract_matrix, contract_vector, load_state};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;
use crate::spatial::Motion;

/// Inverse dynamics and its partial derivatives at `(q, qd, qdd)`.
///
/// - `q`, `qd`, `qdd`: length `model.nv` (rad, rad/s, rad/s^2 or m, m/s, m/s^2).
/// - `gravity`: include gravity in `tau` and in `d tau / d q`.
///
/// Writes `data.tau` (`nv`), `data.dtau_dq` (`nv x nv`: entry `(i, j)` is `d tau_i / d q_j`),
/// `data.dtau_dv` (`d tau_i / d qd_j`) and `data.m` (`d tau / d qdd = M(q)`).
pub fn rnea_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<()> {
    derivatives_at(model, data, q, Some(qd), Some(qdd), gravity)
}

/// [`rnea_derivatives`] with `qd` and `qdd` optional (absent = zero).
pub(crate) fn derivatives_at(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: Gravity,
) -> Result<()> {
    load_state(model, data, q, qd, qdd)?;
    let mut tau = std::mem::take(&mut data.tau);
    let mut m = std::mem::take(&mut data.m);
    let mut dq = std::mem::take(&mut data.dtau_dq);
    let mut dv = std::mem::take(&mut data.dtau_dv);
    if model.coupled {
        let mut tb = std::mem::take(&mut data.tau_b);
        let mut mb = std::mem::take(&mut data.m_b);
        let mut dqb = std::mem::take(&mut data.dq_b);
        let mut dvb = std::mem::take(&mut data.dv_b);
        derivatives_loaded(model, data, gravity, &mut tb, &mut mb, &mut dqb, &mut dvb);
        contract_vector(model, &tb, &mut tau);
        contract_matrix(model, &mb, &mut m);
        contract_matrix(model, &dqb, &mut dq);
        contract_matrix(model, &dvb, &mut dv);
        (data.tau_b, data.m_b, data.dq_b, data.dv_b) = (tb, mb, dqb, dvb);
    } else {
        derivatives_loaded(model, data, gravity, &mut tau, &mut m, &mut dq, &mut dv);
    }
    if let Some(qdd) = qdd {
        model.add_armature_torque(qdd, tau.as_mut_slice());
    }
    model.add_armature_inertia(m.as_mut_slice());
    (data.tau, data.m, data.dtau_dq, data.dtau_dv) = (tau, m, dq, dv);
    check_result("rnea_derivatives", "tau", data.tau.as_slice())?;
    check_result("rnea_derivatives", "d tau / d q", data.dtau_dq.as_slice())?;
    check_result("rnea_derivatives", "d tau / d qd", data.dtau_dv.as_slice())
}

/// The recursion over bodies, for the body coordinates already in `data`.
fn derivatives_loaded(
    model: &Model,
    data: &mut Data,
    gravity: Gravity,
    tau: &mut DVector<f64>,
    m: &mut DMatrix<f64>,
    dq: &mut DMatrix<f64>,
    dv: &mut DMatrix<f64>,
) {
    let minus_g = model.base_acceleration(gravity);
    for (i, b) in model.bodies.iter().enumerate() {
        let x = b.pose_in_parent(data.qb[i]);
        let o_mi = match b.parent {
            Some(p) => data.o_mi[p].compose(&x),
            None => x,
        };
        data.o_mi[i] = o_mi;
        let j = b.motion_subspace_in(&o_mi);
        let (ov_p, oa_gf_p) = match b.parent {
            Some(p) => (data.ov[p], data.oa_gf[p]),
            None => (Motion::zeros(), minus_g),
        };
        let vj = j.scale(data.vb[i]);
        let ov = ov_p + vj;
        let oa_gf = oa_gf_p + j.scale(data.ab[i]) + ov.cross(&vj);
        let oy = o_mi.act_inertia(&b.inertia);
        let oh = oy.apply(&ov);
        data.of[i] = oy.apply(&oa_gf) + ov.cross_force(&oh);
        data.ov[i] = ov;
        data.oa_gf[i] = oa_gf;

        let ymat = oy.to_matrix();
        data.o_ycrb[i] = ymat;
        data.do_ycrb[i] =
            ov.cross_force_matrix() * ymat - ymat * ov.cross_matrix() + oh.cross_matrix_of_motion();

        let jv = j.to_vector();
        data.j[i] = jv;
        let mut dadq = oa_gf_p.cross(&j);
        let mut dadv = ov.cross(&j);
        if b.parent.is_some() {
            let dvdq = ov_p.cross(&j);
            dadq = dadq + ov_p.cross(&dvdq);
            dadv = dadv + dvdq;
            data.dvdq[i] = dvdq.to_vector();
        } else {
            data.dvdq[i].fill(0.0);
        }
        data.dadq[i] = dadq.to_vector();
        data.dadv[i] = dadv.to_vector();
    }

    for i in (0..model.nbodies()).rev() {
        let b = &model.bodies[i];
        let end = b.subtree_end;
        let j = data.j[i];
        tau[i] = j.dot(&data.of[i].to_vector());

        // d tau / d qdd (the mass matrix)
        data.dfda[i] = data.o_ycrb[i] * j;
        for k in i..end {
            let v = j.dot(&data.dfda[k]);
            m[(i, k)] = v;
            m[(k, i)] = v;
        }

        // d tau / d q
        data.dfdq[i] = data.do_ycrb[i] * data.dvdq[i] + data.o_ycrb[i] * data.dadq[i];
        data.dytj[i] = data.do_ycrb[i].tr_mul(&j);
        for k in (i + 1)..end {
            dq[(k, i)] = data.dfda[k].dot(&data.dadq[i]) + data.dytj[k].dot(&data.dvdq[i]);
        }
        for k in i..end {
            dq[(i, k)] = j.dot(&data.dfdq[k]);
        }
        data.dfdq[i] += Motion::from_vector(&j).cross_force(&data.of[i]).to_vector();

        // d tau / d qd
        data.dfdv[i] = data.do_ycrb[i] * j + data.o_ycrb[i] * data.dadv[i];
        for k in (i + 1)..end {
            dv[(k, i)] = data.dfda[k].dot(&data.dadv[i]) + data.dytj[k].dot(&j);
        }
        for k in i..end {
            dv[(i, k)] = j.dot(&data.dfdv[k]);
        }

        if let Some(p) = b.parent {
            let (yi, dyi, fi) = (data.o_ycrb[i], data.do_ycrb[i], data.of[i]);
            data.o_ycrb[p] += yi;
            data.do_ycrb[p] += dyi;
            data.of[p] += fi;
        }
    }
    // Entries between bodies of different branches are never written: they stay zero.
}
