//! Friction the direct fit left out, found by fitting it (docs/method.md, section 8).
//!
//! Every real joint has friction, but the direct method identifies it only where asked (Python's
//! default is none). Left out, it went into the inertial parameters without a word: on the
//! A465's test excitation, a Coulomb friction of 1 N m on the shoulder moved the base
//! parameters by 215 of their standard errors, with the residual RMS on that joint 14 times the
//! torque noise; on the real Franka Emika Panda log fitted without friction, viscous, Coulomb
//! and offset terms explain 51 to 92 % of every joint's residual.
//!
//! So a fit that lacks some of the friction terms (viscous `qd_j`, Coulomb `sign(qd_j)`, a
//! constant offset, each per joint) is fitted again with them, on at most [`SAMPLES`] samples
//! spread evenly over the data, with the same weighting (where the data cannot tell two terms
//! apart, as the Coulomb term and the offset of a joint that never reverses, without the
//! offset, or else without the Coulomb term). A joint is a finding where the terms
//! take at least [`EXPLAINED`] off its residual sum of squares there, and at least one of its
//! own new terms is [`T_NAMED`] or more of its standard errors (inflated for residuals
//! correlated from sample to sample, [`super::residual_correlation`]) from 0; those terms are
//! named with their coefficients. A joint whose residual shrinks only because the other joints'
//! friction no longer biases the shared parameters has no term of its own to name, and is no
//! finding. What the data cannot tell from the rigid-body model is not found: an offset where
//! gravity barely changes over a joint's motion is absorbed by the gravity parameters, and the
//! terms are not judged where the refit's parameters are not determined.

use super::base_model::BaseModel;
use super::base_options::BaseOptions;
pub use super::findings::unmodelled_friction::*;
use super::parameters::FrictionTerms;
use crate::error::Result;
use crate::model::Model;
use crate::states::States;

/// The joints of `model` whose torques `tau` (row-major `k x nv`, N m, at `states`, samples in
/// time order) show friction terms `fit` (identified from them with `options`) lacks (see the
/// module documentation). None where the fit has every term, the states have no velocities,
/// or the refit is not determined. Stops on Ctrl-C.
pub fn check_unmodelled_friction(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
    options: &BaseOptions,
) -> Result<Vec<UnmodelledFriction>> {
    let fitted = fit.base.layout.friction;
    let missing: Vec<&str> = (TERMS.iter().copied())
        .filter(|t| match *t {
            "viscous" => !fitted.viscous,
            "coulomb" => !fitted.coulomb,
            _ => !fitted.offset,
        })
        .collect();
    let (n, k) = (model.nv, states.len());
    let Some(qd) = states.qd() else {
        return Ok(vec![]);
    };
    if missing.is_empty() || k == 0 {
        return Ok(vec![]);
    }
    crate::interrupt::check("checking the fit for friction it leaves out")?;
    // the samples refitted, spread evenly over the data and in time order
    let rows = crate::states::SpreadRows::new(k, SAMPLES, n);
    let (count, pick) = (rows.len(), |x: &[f64]| rows.pick(x));
    let (q, v, a, measured) = (
        pick(states.q()),
        pick(qd),
        states.qdd().map(pick),
        pick(tau),
    );
    let c = states.coulomb().map(pick);
    let sub = States::new(n, &q, Some(&v), a.as_deref())?;
    let sub = match &c {
        Some(c) => sub.with_coulomb(c)?,
        None => sub,
    };
    // every term; where the data cannot tell two apart (the Coulomb term of a joint that never
    // reverses is its offset), without the offset, then without the Coulomb term. Fewer
    // samples than parameters, or a refit the data do not determine: nothing to judge. Ctrl-C
    // stops the fit it is part of
    let mut solved = None;
    for (coulomb, offset) in [(true, true), (true, false), (false, true)] {
        let terms = FrictionTerms {
            viscous: true,
            coulomb: fitted.coulomb || coulomb,
            offset: fitted.offset || offset,
            ..fitted
        };
        let options = BaseOptions {
            friction: terms,
            ..options.clone()
        };
        match super::base_solve::solve(model, &sub, &measured, &options) {
            Ok(s) => {
                solved = Some(s);
                break;
            }
            Err(e @ crate::error::Error::Interrupted { .. }) => return Err(e),
            Err(_) => {}
        }
    }
    let Some(solved) = solved else {
        return Ok(vec![]);
    };
    let refit = BaseModel {
        theta: solved.ls.coef.row(0).iter().copied().collect(),
        stderr: solved.ls.stderr.row(0).iter().copied().collect(),
        base: solved.base,
        // of the fit's layout, not the refit's
        joint_term_rms: vec![],
        ..fit.clone()
    };
    let residual = |m: &BaseModel| -> Result<Vec<f64>> {
        let p = m.predict(model, &sub)?;
        Ok(measured.iter().zip(&p).map(|(t, p)| t - p).collect())
    };
    let (before, after) = (residual(fit)?, residual(&refit)?);
    // each run's rows a time series of their own
    let long_run = super::residual_correlation::long_run_factors_over_runs(
        &after,
        n,
        &rows.counts_in(&options.runs),
    );
    let table = refit.parameter_table();
    let sum_of_squares =
        |r: &[f64], j: usize| (0..count).map(|i| r[i * n + j].powi(2)).sum::<f64>();
    let mut found = vec![];
    for (j, joint) in model.joint_names.iter().enumerate() {
        let (was, is) = (sum_of_squares(&before, j), sum_of_squares(&after, j));
        let explained = 1.0 - is / was;
        if !(was > 0.0 && explained >= EXPLAINED) {
            continue;
        }
        let inflation = long_run[j].sqrt();
        let terms: Vec<MissingTerm> = (missing.iter())
            .filter_map(|t| {
                let row = table.iter().find(|r| r.name == format!("{joint}.{t}"))?;
                let stderr = row.std? * inflation;
                (!row.combination && row.value.abs() >= T_NAMED * stderr).then(|| MissingTerm {
                    term: t.to_string(),
                    coefficient: row.value,
                    stderr,
                })
            })
            .collect();
        if !terms.is_empty() && explained.is_finite() {
            found.push(UnmodelledFriction {
                joint: joint.clone(),
                explained: explained.min(1.0),
                residual_rms: (was / count as f64).sqrt(),
                remaining_rms: (is / count as f64).sqrt(),
                terms,
            });
        }
    }
    Ok(found)
}
