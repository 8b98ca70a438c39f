//! The standard error of a local model's predicted torques: what the noise of `T*` and of the
//! identified matrices' entries, with their correlation within each row, leaves in `T* + D*
//! (qdd - qdd*) + H* (qd - qd*) + G* (q - q*)` at a state (docs/method.md, section 5).
//!
//! A row's entries come out of one regression and are correlated by its design: with standard
//! errors `se` and correlation `R` its covariance is `diag(se) R diag(se)`, and a prediction
//! that weights them by the state's deltas `x` varies by `x^T diag(se) R diag(se) x`. The
//! separated regressions run on different experiments and are independent of each other; the
//! combined estimate is one regression over `[dqdd, dqd, dq]`, taken whole. `T*` enters every
//! regression's response too; its error reaches the slopes through the sum of the perturbations,
//! which the planned designs balance (+- pairs), and is counted once, in the prediction's own
//! `T*`.

use nalgebra::DMatrix;

use super::model::{Estimate, Estimator, LocalModel};
use crate::document::{check_correlation, invalid};
use crate::error::{Error, Result};
use crate::states::States;
use crate::torque_model::check_joints;

/// The standard error (N m, or N for a prismatic joint) of every torque
/// [`LocalModel::predict`] gives at the samples of `states`: row-major `k x N`, in the model's
/// joint order. NaN for a joint where the model holds an unknown standard error (`T*` from one
/// nominal crossing, a regression without residual degrees of freedom, a torque that did not
/// change) that the state weights; an entry the state's delta leaves at exactly 0 does not
/// count. Refused for a model without the D, H or G experiment, or saved before the
/// correlations were stored (identify it again), and where the arithmetic overflows.
pub(crate) fn predict_stderr(model: &LocalModel, states: &States<'_>) -> Result<Vec<f64>> {
    let n = model.n();
    check_joints(states, n)?;
    // each estimate with the block of deltas its first column weighs
    let parts: Vec<(&Estimate, usize)> = match model.estimator {
        Estimator::Combined => vec![(part(&model.combined, "combined", n)?, 0)],
        Estimator::Separated => vec![
            (part(&model.d, "D", n)?, 0),
            (part(&model.h, "H", n)?, 1),
            (part(&model.g, "G", n)?, 2),
        ],
    };
    let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
    let op = &model.planned_op;
    let mut out = Vec::with_capacity(states.len() * n);
    let (mut deltas, mut z) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
    for s in 0..states.len() {
        let r = s * n..(s + 1) * n;
        // the deltas in the columns' order: dqdd, dqd, dq
        let blocks = [(&qdd[r.clone()], &op.qdd), (&qd[r.clone()], &op.qd)];
        let blocks = blocks.into_iter().chain([(&states.q()[r], &op.q)]);
        for (d, (x, x0)) in deltas.chunks_mut(n).zip(blocks) {
            for ((d, a), b) in d.iter_mut().zip(x).zip(x0) {
                *d = a - b;
            }
        }
        for j in 0..n {
            let mut var = model.torque_stderr[j].powi(2);
            for &(e, block) in &parts {
                let cols = e.matrix.ncols();
                let x = &deltas[block * n..block * n + cols];
                // an unknown standard error counts only where the state weights it
                for (a, za) in z[..cols].iter_mut().enumerate() {
                    *za = match x[a] {
                        0.0 => 0.0,
                        xa => xa * e.stderr[(j, a)],
                    };
                }
                var += quadratic_form(&e.correlation[j], &z[..cols]);
            }
            out.push(var.max(0.0).sqrt());
        }
    }
    if let Some(i) = out.iter().position(|v| v.is_infinite()) {
        return Err(Error::Numerical {
            operation: "prediction's standard error".into(),
            message: format!(
                "the standard error of joint {} at sample {} overflows: the model's standard errors or the state are too large to compute with",
                i % n.max(1) + 1,
                i / n.max(1)
            ),
        });
    }
    Ok(out)
}

/// `z^T R z` for a square `r` of `z.len()` columns, without forming `R z`.
fn quadratic_form(r: &DMatrix<f64>, z: &[f64]) -> f64 {
    // column by column: nalgebra stores them contiguously
    (r.column_iter().zip(z))
        .map(|(column, zb)| zb * column.iter().zip(z).map(|(r, za)| r * za).sum::<f64>())
        .sum()
}

/// The estimate `name` of a model, with a correlation for each of its `n` rows.
fn part<'a>(e: &'a Option<Estimate>, name: &str, n: usize) -> Result<&'a Estimate> {
    let refuse = |message: String| Error::InvalidArgument {
        argument: "predict_stderr".into(),
        message,
    };
    let e = e.as_ref().ok_or_else(|| {
        refuse(format!(
            "the model has no {name} estimate: its plan had no {name} experiment"
        ))
    })?;
    if e.correlation.len() != n {
        return Err(refuse(format!(
            "the model's {name} estimate holds no correlation of its entries (a model saved before they were stored): identify it again from its recordings"
        )));
    }
    Ok(e)
}

/// Checks the correlations of an estimate `what` read from a file (`cols` columns, `n` rows):
/// none (a model saved before they were stored), or one per row, each `cols x cols`, symmetric
/// with a unit diagonal, entries in [-1, 1] and positive semi-definite (else a prediction's
/// variance could come out negative).
pub(crate) fn check_correlations(kind: &str, what: &str, e: &Estimate, n: usize) -> Result<()> {
    let cols = e.matrix.ncols();
    if e.correlation.is_empty() {
        return Ok(());
    }
    let bad = |message: String| invalid(kind, format!("{what}.correlation: {message}"));
    if e.correlation.len() != n {
        return Err(bad(format!(
            "{} matrices; expected one per torque ({n}) or none",
            e.correlation.len()
        )));
    }
    for (j, r) in e.correlation.iter().enumerate() {
        check_correlation(
            kind,
            &format!("{what}.correlation matrix {}", j + 1),
            r,
            cols,
        )?;
    }
    Ok(())
}
