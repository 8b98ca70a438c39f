//! Composite rigid body algorithm for the mass matrix (Featherstone, RBDA Table 6.2).

use nalgebra::DMatrix;

use super::{contract_matrix, kinematics::update_placements, load_state};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;

/// Joint-space mass matrix `M(q)` (kg m^2, kg m or kg by joint pair), symmetric positive
/// definite. `q`: length `model.nv`. Writes `data.m` (`nv x nv`, both triangles).
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
    data.m = out;
    Ok(())
}

/// CRBA over bodies with poses in `data.li_mi`; fills the body-level matrix `out`.
fn crba_bodies(model: &Model, data: &mut Data, out: &mut DMatrix<f64>) {
    for (i, b) in model.bodies.iter().enumerate() {
        data.ic[i] = b.inertia;
    }
    for i in (0..model.nbodies()).rev() {
        let b = &model.bodies[i];
        let mut f = data.ic[i].apply(&b.motion_subspace());
        out[(i, i)] = b.motion_subspace().dot(&f);
        let mut j = i;
        while let Some(p) = model.bodies[j].parent {
            f = data.li_mi[j].act_force(&f);
            j = p;
            let mij = model.bodies[j].motion_subspace().dot(&f);
            out[(i, j)] = mij;
            out[(j, i)] = mij;
        }
        if let Some(p) = b.parent {
            let child = data.li_mi[i].act_inertia(&data.ic[i]);
            data.ic[p] = data.ic[p].add(&child);
        }
    }
}
