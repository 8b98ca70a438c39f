//! The base-parameter model linearised at any point, exactly: `T`, `D = d tau / d qdd`,
//! `H = d tau / d qd`, `G = d tau / d q` and `G_static`, so that it answers the same question
//! as a local model.
//!
//! The identified base parameters are placed in the full parameter vector (`theta[kept] =
//! theta_base`, the rest 0), which gives the same torques for every state. Its inertial part is
//! any 10-vector per body, not necessarily a rigid body's; the dynamics are linear in it, so it
//! is split as `(theta + S) - S` with `S` a shift that makes every body's mass positive, and the
//! analytic linearisation ([`crate::linearize`]) of the two is subtracted. Friction adds its
//! torque and the viscous slope to the diagonal of H (the Coulomb step has no slope away from
//! zero speed).

use nalgebra::DMatrix;

use super::base_model::BaseModel;
use super::parameters::sign0;
use crate::algorithms::regressor::inertia_from_parameters;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::linearization::{linearize, Linearization};
use crate::model::Model;

const PER_BODY: usize = 10;

/// `model` with the inertial parameters `theta` (10 per body, Pinocchio's order, about each
/// joint frame), every mass increased by `shift` (which must make it positive).
fn with_parameters(model: &Model, theta: &[f64], shift: &[f64]) -> Result<Model> {
    let mut m = model.clone();
    for (i, b) in m.bodies.iter_mut().enumerate() {
        let mut p = [0.0; PER_BODY];
        p.copy_from_slice(&theta[i * PER_BODY..(i + 1) * PER_BODY]);
        p[0] += shift[i];
        b.inertia = inertia_from_parameters(&p).ok_or_else(|| {
            Error::numerical(
                "linearize",
                format!("body '{}': shifted mass {} is not positive", b.link, p[0]),
            )
        })?;
    }
    m.refresh();
    Ok(m)
}

impl BaseModel {
    /// The identified model linearised at `(q, qd, qdd)` of `model` (the robot it was
    /// identified for; rad, rad/s, rad/s^2): the torque there and its exact derivatives, `nv x
    /// nv` each (row = torque, column = joint). `G_static` is taken at rest at `q`. Exact to
    /// rounding: the same analytic derivatives as [`crate::linearize`], on the identified
    /// parameters.
    ///
    /// Errors: another robot, inputs of the wrong length or non-finite.
    pub fn linearize(
        &self,
        model: &Model,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<Linearization> {
        self.on(model)?;
        let nv = model.nv;
        for (name, x) in [("q", q), ("qd", qd), ("qdd", qdd)] {
            crate::model::check_finite_vector(name, x, nv)?;
        }
        let layout = &self.base.layout;
        let mut full = vec![0.0; layout.len()];
        for (i, &k) in self.base.kept.iter().enumerate() {
            full[k] = self.theta[i];
        }
        let nb = layout.nbodies;
        let rigid = &full[..PER_BODY * nb];
        // a shift that makes every mass positive, of the size of the masses involved
        let shift: Vec<f64> = (0..nb).map(|i| rigid[i * PER_BODY].abs() + 1.0).collect();
        let plus = with_parameters(model, rigid, &shift)?;
        let only_shift = with_parameters(model, &vec![0.0; rigid.len()], &shift)?;
        let mut data = Data::new(model);
        let a = linearize(&plus, &mut data, q, qd, qdd, self.gravity)?;
        let b = linearize(&only_shift, &mut data, q, qd, qdd, self.gravity)?;
        let mut out = Linearization {
            torque: &a.torque - &b.torque,
            d: &a.d - &b.d,
            h: &a.h - &b.h,
            g: &a.g - &b.g,
            g_static: &a.g_static - &b.g_static,
        };
        // friction, joint after joint in the layout's order
        let terms = layout.friction.names();
        let mut at = PER_BODY * nb;
        for (j, &v) in qd.iter().enumerate() {
            for t in &terms {
                let c = full[at];
                match *t {
                    "viscous" => {
                        out.torque[j] += c * v;
                        out.h[(j, j)] += c;
                    }
                    "coulomb" => out.torque[j] += c * sign0(v),
                    "armature" => {
                        out.torque[j] += c * qdd[j];
                        out.d[(j, j)] += c;
                    }
                    _ => out.torque[j] += c,
                }
                at += 1;
            }
        }
        debug_assert_eq!(at, layout.len());
        let finite = |m: &DMatrix<f64>| m.iter().all(|v| v.is_finite());
        if !(out.torque.iter().all(|v| v.is_finite())
            && finite(&out.d)
            && finite(&out.h)
            && finite(&out.g))
        {
            return Err(Error::numerical(
                "linearize",
                "the identified parameters give a non-finite linearisation here",
            ));
        }
        Ok(out)
    }
}
