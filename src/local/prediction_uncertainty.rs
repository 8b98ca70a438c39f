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

use super::model::{Estimate, Estimator, LocalModel};

use crate::error::{Error, Result};
use crate::regression::root;
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
    stderr_of_prediction(model, states, true)
}

/// [`predict_stderr`], with `T*`'s own standard error counted or not (`with_t_star`): without
/// it, what the matrices' uncertainty alone gives the deltas of `states`.
pub(crate) fn stderr_of_prediction(
    model: &LocalModel,
    states: &States<'_>,
    with_t_star: bool,
) -> Result<Vec<f64>> {
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
    let k = states.len();
    let mut out = vec![0.0; k * n];
    // blocks of samples, each delta a contiguous column over the block's samples (columns
    // dqdd, dqd, dq, one a joint), so each term of the quadratic forms runs over the samples
    let mut deltas = vec![0.0; 3 * n * BLOCK];
    let (mut var, mut unknown) = ([0.0; BLOCK], [false; BLOCK]);
    for start in (0..k).step_by(BLOCK) {
        let b = (k - start).min(BLOCK);
        for s in 0..b {
            let r = (start + s) * n..(start + s + 1) * n;
            let blocks = [(&qdd[r.clone()], &op.qdd), (&qd[r.clone()], &op.qd)];
            for (v, (x, x0)) in blocks
                .into_iter()
                .chain([(&states.q()[r], &op.q)])
                .enumerate()
            {
                for j in 0..n {
                    deltas[(v * n + j) * BLOCK + s] = x[j] - x0[j];
                }
            }
        }
        let column = |c: usize| &deltas[c * BLOCK..c * BLOCK + b];
        for j in 0..n {
            // an unknown standard error counts only where the state weights it (T*'s always);
            // kept apart from the sums, so that a sum which overflows is told from it
            let t_star = if with_t_star {
                model.torque_stderr[j]
            } else {
                0.0
            };
            unknown[..b].fill(t_star.is_nan());
            var[..b].fill(if t_star.is_nan() {
                0.0
            } else {
                t_star * t_star
            });
            for &(e, first) in &parts {
                let (cols, r) = (e.matrix.ncols(), &e.correlation[j]);
                let se = |a: usize| e.stderr[(j, a)];
                for a in 0..cols {
                    let xa = column(first * n + a);
                    if se(a).is_nan() {
                        for (u, x) in unknown[..b].iter_mut().zip(xa) {
                            *u |= *x != 0.0;
                        }
                        continue;
                    }
                    // the pairs (a, c) and (c, a) at once: R is symmetric
                    for c in (a..cols).filter(|&c| !se(c).is_nan()) {
                        let w = if c == a { 1.0 } else { 2.0 } * r[(a, c)] * se(a) * se(c);
                        let xc = column(first * n + c);
                        for ((v, x), y) in var[..b].iter_mut().zip(xa).zip(xc) {
                            *v += w * x * y;
                        }
                    }
                }
            }
            for s in 0..b {
                out[(start + s) * n + j] = if unknown[s] { f64::NAN } else { root(var[s]) };
            }
        }
    }
    if let Some(i) = out.iter().position(|v| v.is_infinite()) {
        return Err(Error::numerical(
            "prediction's standard error",
            format!(
                "the standard error of joint {} at sample {} overflows: the model's standard errors or the state are too large to compute with",
                i % n.max(1) + 1,
                i / n.max(1)
            ),
        ));
    }
    Ok(out)
}

/// Samples whose deltas are laid out together ([`predict_stderr`]).
const BLOCK: usize = 256;

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

impl LocalModel {
    /// The standard errors (row-major `k x N`, N m, or N for a prismatic joint) of the torques
    /// [`Self::predict`] gives at the samples of `states`: from those of `T*` and of the
    /// matrices' entries with their correlation within each row (docs/method.md, section 5).
    /// NaN for a joint where the model holds an unknown standard error that the state weights.
    /// Refused for a model without the D, H or G experiment, or saved before the correlations
    /// were stored.
    ///
    /// A model whose recordings were currents put in torques ([`Self::drive_gains`]) adds the
    /// gains' relative standard errors: joint `j`'s every coefficient is `K_j` times the
    /// signal's, so its prediction `tau_j` varies by `tau_j se_K_j / |K_j|` more, independent
    /// of the local fit (the gains came from other data).
    pub fn predict_stderr(&self, states: &States<'_>) -> Result<Vec<f64>> {
        let mut out = predict_stderr(self, states)?;
        if let Some(g) = &self.drive_gains {
            let n = self.n();
            let tau = self.predict(states)?;
            for (x, (se, t)) in out.iter_mut().zip(&tau).enumerate() {
                let relative = g.stderr[x % n] / g.gain[x % n].abs();
                *se = se.hypot(t * relative);
            }
            return crate::regression::refuse_overflow(out, n, "prediction's standard error");
        }
        Ok(out)
    }
}
