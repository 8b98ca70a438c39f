//! The regressor of the linearisation: the torque at a point and its derivatives `D = M(q)`,
//! `H = d tau / d qd`, `G = d tau / d q` and `G_static = d g / d q` are all linear in the
//! parameters, `vec(X) = Y_X theta`; this computes every `Y_X` at once, so that identified
//! local models (T*, D*, H*, G*, Gs) become linear equations in the robot's parameters.
//!
//! The inertial columns are exact analytic derivatives: the dynamics are linear in each
//! body's 10 parameters, so column `k` is the analytic linearisation ([`crate::linearize`]) of
//! the model with parameters `S + e_k` minus that with `S`, where the shift `S` (a unit point
//! mass per body) makes every body representable. The friction columns (viscous, Coulomb,
//! offset) add their torque and the viscous slope of H.

use nalgebra::DMatrix;

use crate::algorithms::regressor::inertia_from_parameters;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::linearization::{linearize, Linearization};
use crate::model::Model;
use crate::parameters::ParameterLayout;

/// `Y_X` for every part of the linearisation at one point: `torque` is `nv x p`; `d`, `h`, `g`,
/// `g_static` are `nv^2 x p` with row `i * nv + j` for the entry `(i, j)` (row = torque,
/// column = joint); `p` is the layout's parameter count.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearizationRegressor {
    pub torque: DMatrix<f64>,
    pub d: DMatrix<f64>,
    pub h: DMatrix<f64>,
    pub g: DMatrix<f64>,
    pub g_static: DMatrix<f64>,
}

fn shifted(model: &Model, body: Option<(usize, usize)>) -> Result<Model> {
    let mut m = model.clone();
    for (i, b) in m.bodies.iter_mut().enumerate() {
        let mut p = [0.0; 10];
        p[0] = 1.0;
        if let Some((bi, k)) = body {
            if bi == i {
                p[k] += 1.0;
            }
        }
        b.inertia = inertia_from_parameters(&p).ok_or_else(|| Error::Internal {
            context: "linearization_regressor".into(),
            message: "a unit shift left a mass non-positive".into(),
        })?;
    }
    m.refresh();
    Ok(m)
}

/// The regressor of the linearisation of `model` at `(q, qd, qdd)` (rad, rad/s, rad/s^2) for
/// the parameters of `layout` (which must be `model`'s), with or without `gravity` (the static
/// part `g_static` is zero without it). Costs `10 nbodies + 1` analytic linearisations.
///
/// Errors: another layout, inputs of the wrong length or non-finite.
pub fn linearization_regressor(
    model: &Model,
    layout: &ParameterLayout,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<LinearizationRegressor> {
    let nv = model.nv;
    if layout.nv != nv || layout.nbodies != model.nbodies() {
        return Err(Error::invalid(
            "layout",
            format!(
                "for {} joints and {} bodies; the model has {nv} and {}",
                layout.nv,
                layout.nbodies,
                model.nbodies()
            ),
        ));
    }
    for (name, x) in [("q", q), ("qd", qd), ("qdd", qdd)] {
        crate::model::check_finite_vector(name, x, nv)?;
    }
    let p = layout.len();
    let mut out = LinearizationRegressor {
        torque: DMatrix::zeros(nv, p),
        d: DMatrix::zeros(nv * nv, p),
        h: DMatrix::zeros(nv * nv, p),
        g: DMatrix::zeros(nv * nv, p),
        g_static: DMatrix::zeros(nv * nv, p),
    };
    let mut data = Data::new(model);
    let base: Linearization = linearize(&shifted(model, None)?, &mut data, q, qd, qdd, gravity)?;
    for b in 0..model.nbodies() {
        for k in 0..10 {
            let col = 10 * b + k;
            let l = linearize(
                &shifted(model, Some((b, k)))?,
                &mut data,
                q,
                qd,
                qdd,
                gravity,
            )?;
            for i in 0..nv {
                out.torque[(i, col)] = l.torque[i] - base.torque[i];
                for j in 0..nv {
                    let r = i * nv + j;
                    out.d[(r, col)] = l.d[(i, j)] - base.d[(i, j)];
                    out.h[(r, col)] = l.h[(i, j)] - base.h[(i, j)];
                    out.g[(r, col)] = l.g[(i, j)] - base.g[(i, j)];
                    out.g_static[(r, col)] = l.g_static[(i, j)] - base.g_static[(i, j)];
                }
            }
        }
    }
    let terms = layout.friction.names();
    let mut col = 10 * model.nbodies();
    for (j, &v) in qd.iter().enumerate() {
        for t in &terms {
            match *t {
                "viscous" => {
                    out.torque[(j, col)] = v;
                    out.h[(j * nv + j, col)] = 1.0;
                }
                "coulomb" => out.torque[(j, col)] = crate::parameters::sign0(v),
                "armature" => {
                    out.torque[(j, col)] = qdd[j];
                    out.d[(j * nv + j, col)] = 1.0;
                }
                _ => out.torque[(j, col)] = 1.0,
            }
            col += 1;
        }
    }
    Ok(out)
}
