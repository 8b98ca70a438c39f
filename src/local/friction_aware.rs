//! The friction-aware H regression ([`super::IdentifyOptions::friction_aware_h`]): H* and each
//! joint's Coulomb step from the differences of the H experiment's +- pairs, where the even
//! rigid-body terms cancel and a reversed joint's step is its own column.

use nalgebra::DMatrix;

use super::diagnostics::TorqueNoise;
use super::identify::ExperimentValues;
use super::model::{CoulombSteps, Estimate};
use super::noise::{reading_variance, sample_variance, weighted_least_squares};
use super::plan::{Experiment, Plan};
use super::rounded_positions::{resolution_warning, Resolution};
use crate::error::{Error, Result};
use crate::parameters::sign0;

/// H* and the Coulomb steps from the differences of the H experiment's +- pairs; see
/// [`IdentifyOptions::friction_aware_h`]. One least-squares solve per torque row: the columns
/// are the measured velocity differences and, where some pair reverses that row's joint, its
/// step `sign(d_j)`. Each pair weighs by the noise of its two torques (see [`super::noise`]);
/// the torque noise is returned per joint (what varied from pass to pass: per pass), with the
/// warnings of [`super::response::unresolved_warning`] (no joint's torque responded) and of
/// [`super::rounded_positions::resolution_warning`] (coarse encoders read the velocity
/// changes to worse than a tenth of their size).
pub(super) fn friction_aware_h(
    plan: &Plan,
    e: &Experiment,
    v: &ExperimentValues,
) -> Result<(Estimate, CoulombSteps, Vec<TorqueNoise>, Vec<String>)> {
    let n = plan.n();
    let k = v.crossings.len();
    let (m, reverses) = check_pairs(plan, e, v)?;
    let samples = sample_variance(&v.crossings, n);
    let variance: Vec<Vec<f64>> = v
        .crossings
        .iter()
        .map(|c| reading_variance(c, &samples))
        .collect();
    let mut noise = Vec::with_capacity(n);
    let mut matrix = DMatrix::zeros(n, n);
    let mut stderr = DMatrix::zeros(n, n);
    let (mut cond, mut residual_rms) = (1.0f64, vec![0.0; n]);
    let mut steps = CoulombSteps {
        joint_names: plan.joint_names.clone(),
        step: vec![None; n],
        stderr: vec![None; n],
    };
    let mut responded = Vec::with_capacity(n);
    let mut correlation = Vec::with_capacity(n);
    for j in 0..n {
        let row = RowInput {
            plan,
            e,
            v,
            m,
            reverses: reverses[j],
            variance: &variance,
            samples: &samples,
        };
        let fit = row.fit(j)?;
        let ls = fit.ls;
        responded.extend(fit.responded);
        correlation.push(fit.correlation);
        noise.push(fit.noise);
        for c in 0..n {
            matrix[(j, c)] = ls.coef[(0, c)];
            stderr[(j, c)] = ls.stderr[(0, c)];
        }
        if reverses[j] {
            steps.step[j] = Some(ls.coef[(0, n)]);
            let se = ls.stderr[(0, n)];
            steps.stderr[j] = se.is_finite().then_some(se);
        }
        cond = cond.max(ls.cond);
        residual_rms[j] = ls.residual_rms[0];
    }
    let estimate = Estimate {
        matrix,
        cond,
        residual_rms,
        stderr,
        crossings: k,
        correlation,
    };
    let mut warnings: Vec<String> = super::response::unresolved_warning(e.kind, &responded)
        .into_iter()
        .collect();
    // coarse encoders: how well each pair's velocity change was read, as the plain regression
    // reports it
    let resolutions: Vec<Resolution> = (0..n)
        .filter_map(|j| {
            let se: Vec<f64> = v.crossings.iter().map(|c| c.state_stderr[1][j]).collect();
            let half: Vec<f64> = (0..m)
                .map(|i| 0.5 * (v.crossings[2 * i].qd[j] - v.crossings[2 * i + 1].qd[j]))
                .collect();
            Resolution::of(&plan.joint_names[j], v.position_step[j]?, &se, &half)
        })
        .collect();
    warnings.extend(resolution_warning(e.kind.name(), 1, &resolutions));
    Ok((estimate, steps, noise, warnings))
}

/// Pair `i`'s Coulomb step at joint `j`: `sign(qd*_j + d) - sign(qd*_j - d)` halved, non-zero
/// where the pair reverses the joint.
fn coulomb_step(plan: &Plan, e: &Experiment, i: usize, j: usize) -> f64 {
    let (qd0, d) = (plan.op.qd[j], e.deltas[(2 * i, j)]);
    0.5 * (sign0(qd0 + d) - sign0(qd0 - d))
}

/// Refuses perturbations that are not in +- pairs, a joint reversed at one magnitude in every
/// pair and too few pairs; returns the number of pairs and which joints some pair reverses.
fn check_pairs(plan: &Plan, e: &Experiment, v: &ExperimentValues) -> Result<(usize, Vec<bool>)> {
    let n = plan.n();
    let k = v.crossings.len();
    let refuse = |message: String| Error::InvalidArgument {
        argument: "friction_aware_h".into(),
        message,
    };
    let paired = k.is_multiple_of(2)
        && (0..k / 2).all(|i| {
            (0..n).all(|j| {
                let (a, b) = (e.deltas[(2 * i, j)], e.deltas[(2 * i + 1, j)]);
                (a + b).abs() <= 1e-12 * a.abs().max(1e-300)
            })
        });
    if !paired {
        return Err(refuse(
            "the H perturbations are not in +- pairs (plan with symmetric pairs)".into(),
        ));
    }
    let m = k / 2;
    let step = |i: usize, j: usize| coulomb_step(plan, e, i, j);
    let reverses: Vec<bool> = (0..n).map(|j| (0..m).any(|i| step(i, j) != 0.0)).collect();
    // a joint reversed at one magnitude throughout: its step sign(d) is d / size
    if let Some(j) = (0..n).find(|&j| {
        let first = e.deltas.get((0, j)).map_or(0.0, |d| d.abs());
        m > 0
            && (0..m).all(|i| step(i, j) != 0.0)
            && (0..m).all(|i| (e.deltas[(2 * i, j)].abs() - first).abs() <= 1e-9 * first)
    }) {
        return Err(refuse(format!(
            "the H perturbations of joint '{}' reverse it at one magnitude in every pair (an orthogonal design's Hadamard columns), so its Coulomb step sign(d) is proportional to its velocity change and the two cannot be told apart; plan the H experiment for the friction-aware regression (PlanOptions::friction_aware_h, --friction-aware-h), which draws magnitudes that vary",
            plan.joint_names[j]
        )));
    }
    let needed = n + usize::from(reverses.iter().any(|&r| r));
    if m < needed {
        return Err(refuse(format!(
            "{m} +- pairs of H passes for {needed} unknowns per joint; plan at least {} H passes (PlanOptions::friction_aware_h, --friction-aware-h)",
            2 * needed
        )));
    }
    Ok((m, reverses))
}

/// What one torque row's regression reads: the experiment's pairs and their noise.
struct RowInput<'a> {
    plan: &'a Plan,
    e: &'a Experiment,
    v: &'a ExperimentValues,
    /// The number of +- pairs.
    m: usize,
    /// Whether some pair reverses the row's joint (a Coulomb step column).
    reverses: bool,
    /// Per crossing, per joint, its torque reading's variance.
    variance: &'a [Vec<f64>],
    /// Per joint, the torque's sample variance.
    samples: &'a [f64],
}

/// One torque row's fit: its coefficients, their correlation (the H block), the torque noise
/// and whether the torque responded.
struct RowFit {
    ls: crate::regression::LeastSquares,
    correlation: DMatrix<f64>,
    noise: TorqueNoise,
    responded: Vec<Option<super::response::Response>>,
}

impl RowInput<'_> {
    /// The weighted regression of joint `j`'s torque differences on the pairs' velocity
    /// differences (and its Coulomb step), with the standard errors floored by the torque's
    /// rounding and the velocities' errors.
    fn fit(&self, j: usize) -> Result<RowFit> {
        let (plan, e, v, m) = (self.plan, self.e, self.v, self.m);
        let (variance, samples) = (self.variance, self.samples);
        let n = plan.n();
        let p = n + usize::from(self.reverses);
        let x = DMatrix::from_fn(m, p, |i, c| {
            if c < n {
                v.crossings[2 * i].qd[c] - v.crossings[2 * i + 1].qd[c]
            } else {
                coulomb_step(plan, e, i, j)
            }
        });
        let y = DMatrix::from_fn(m, 1, |i, _| {
            v.crossings[2 * i].tau[j] - v.crossings[2 * i + 1].tau[j]
        });
        let mut columns: Vec<String> = plan
            .joint_names
            .iter()
            .map(|q| format!("dqd({q})"))
            .collect();
        if self.reverses {
            columns.push(format!("coulomb_step({})", plan.joint_names[j]));
        }
        // a difference of two torques: the sum of their variances
        let u = DMatrix::from_fn(m, 1, |i, _| variance[2 * i][j] + variance[2 * i + 1][j]);
        let responded =
            super::response::responses(&x, &y, &u, false, &[v.flat_torque[j].is_none()], None);
        let weighted = weighted_least_squares(
            &x,
            &y,
            &u,
            &format!(
                "friction-aware H regression, torque of joint '{}'",
                plan.joint_names[j]
            ),
            &columns,
        )?;
        let step = super::quantisation::undithered_step(v.torque_step[j], samples[j]);
        let mut ls = weighted.fit;
        // the H columns' block: the marginal correlation of those coefficients
        let correlation = weighted.correlation[0].view((0, 0), (n, n)).into_owned();
        if let Some(q) = step {
            // a pair's difference: two readings' rounding
            let sigma = std::f64::consts::SQRT_2 * super::quantisation::rounding_stderr(q);
            super::quantisation::floor_stderr(&mut ls, 0, sigma);
        }
        // the measured velocity differences err by both passes' errors; the Coulomb step's
        // column is exact
        let row_var = DMatrix::from_fn(m, p, |i, c| {
            if c < n {
                v.crossings[2 * i].state_stderr[1][c].powi(2)
                    + v.crossings[2 * i + 1].state_stderr[1][c].powi(2)
            } else {
                0.0
            }
        });
        super::errors_in_variables::floor_stderr(&mut ls, &x, &row_var, &vec![0.0; p])?;
        let noise = TorqueNoise {
            experiment: e.kind.name().to_string(),
            joint: plan.joint_names[j].clone(),
            samples: samples[j].sqrt(),
            // a pair's difference varies by twice one pass's variance
            passes: Some((0.5 * weighted.common[0]).sqrt()).filter(|p| p.is_finite()),
            step,
            position_step: v.position_step[j],
        };
        Ok(RowFit {
            ls,
            correlation,
            noise,
            responded,
        })
    }
}
