//! Composite rigid body algorithm for the mass matrix (Featherstone, RBDA Table 6.2), run in the
//! base frame as Pinocchio does: composite inertias are summed there, and each column's
//! momentum `Ic_i S_i` is projected on every ancestor's motion subspace by a dot product.

use nalgebra::DMatrix;

use super::{check_result, contract_matrix, kinematics::update_placements, load_state};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;

/// Joint-space mass matrix `M(q)` (kg m^2, kg m or kg by joint pair), symmetric positive
/// definite. `q`: length `model.nv`. Writes `data.m` (`nv x nv`, both triangles).
///
/// ```
/// use perturbid_rs::{mass_matrix, rnea, robots, Data, Gravity};
/// let model = robots::builtin("a465")?;
/// let mut data = Data::new(&model);
/// let (q, qdd) = ([0.3, -0.2, 0.5, 0.1, 0.4, -0.6], [1.0, -2.0, 0.5, 0.0, 3.0, 1.5]);
/// mass_matrix(&model, &mut data, &q)?;
/// let m_qdd = &data.m * nalgebra::DVector::from_column_slice(&qdd);
/// rnea(&model, &mut data, &q, &[0.0; 6], &qdd, Gravity::Excluded)?; // M(q) qdd alone
/// assert!((&data.tau - m_qdd).amax() < 1e-10);
/// assert!((&data.m - data.m.transpose()).amax() < 1e-12);
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn mass_matrix(model: &Model, data: &mut Data, q: &[f64]) -> Result<()> {
    load_state(model, data, q, None, None)?;
    update_placements(model, data);
    let mut out = std::mem::take(&mut data.m);
    if model.coupled {
        let mut mb = std::mem::take(&mut data.m_b);
        crba_bodies(model, data, &mut mb);
        contract_matrix(model, &mb, &mut out);
        data.m_b = mb;
    } else {
        crba_bodies(model, data, &mut out);
    }
    model.add_armature_inertia(out.as_mut_slice());
    data.m = out;
    // M is positive semi-definite, so |M_ij| <= sqrt(M_ii M_jj): a finite diagonal bounds every
    // entry, and checking the nv diagonal entries is enough (the whole matrix costs 6 % of a call)
    let n = model.nv;
    let diagonal: [f64; 1] = [(0..n).fold(0.0, |s, i| s + data.m[(i, i)])];
    check_result("mass_matrix", "the diagonal of M", &diagonal)
}

/// CRBA over bodies with poses in `data.li_mi`; fills the body-level matrix `out`.
fn crba_bodies(model: &Model, data: &mut Data, out: &mut DMatrix<f64>) {
    // base-frame poses, motion subspaces and inertias
    for (i, b) in model.bodies.iter().enumerate() {
        let x = match b.parent {
            Some(p) => data.o_mi[p].compose(&data.li_mi[i]),
            None => data.li_mi[i],
        };
        data.s_world[i] = b.motion_subspace_in(&x);
        data.ycrb[i] = b.origin_inertia.transformed(&x);
        data.o_mi[i] = x;
    }
    let n = model.nbodies();
    let m = out.as_mut_slice(); // column-major n x n
    for i in (0..n).rev() {
        let f = data.ycrb[i].apply(&data.s_world[i]);
        let mut j = Some(i);
        while let Some(k) = j {
            let mik = data.s_world[k].dot(&f);
            m[i + k * n] = mik;
            m[k + i * n] = mik;
            j = model.bodies[k].parent;
        }
        if let Some(p) = model.bodies[i].parent {
            let child = data.ycrb[i];
            data.ycrb[p] += child;
        }
    }
}
