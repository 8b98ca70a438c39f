//! A fit's residuals judged against the torques' noise measured apart from it
//! ([`super::TorqueNoise`]; docs/method.md, section 8f).
//!
//! Where the noise is known, the residuals tell whether the model holds what the robot does:
//! a model that does leaves only noise, and the cost `V = sum_j sum_k (r_jk / sigma_j)^2 / c`
//! (`c` the noise's [`super::TorqueNoise::correlation`]) is then chi-square distributed with
//! `K n / c - p` degrees of freedom (`K` samples, `n` joints, `p` unknowns; Swevers et al.
//! 2007, the maximum-likelihood cost). Where the noise was itself estimated (from an
//! excitation's periods), `V / dof` is F distributed with the noise's degrees of freedom
//! beside. A cost far above its degrees of freedom is a model error (friction the model lacks,
//! a flexible joint, a torque lag), below them an overstated noise or a fit that follows
//! noise.
//!
//! For the noise weighting ([`super::Weighting::Noise`]) the standard errors come from the
//! noise, `sqrt(c)` times the weighted regressor's `(W Phi)^T (W Phi)` inverse's diagonal,
//! scaled by `sqrt(V / dof)` where that exceeds 1 (the residuals then say more than the noise
//! does; the usual convention for a model error of unknown form), and by `sqrt(rho / c)` where
//! the residuals' own long-run variance factor `rho` ([`super::residual_correlation`], the
//! largest joint's) exceeds `c`: noise that is not white within its band (a slow ripple)
//! holds fewer independent values than its band says. For another weighting the
//! cost is at least the noise-weighted fit's, so the test reads model errors a little more
//! readily, and the standard errors are the fit's own.

use serde::{Deserialize, Serialize};

use nalgebra::DMatrix;

use super::torque_noise::TorqueNoise;
use super::{BaseOptions, Weighting};
use crate::error::{shown5, Error, Result};

/// The chance the noise alone gives a cost beyond which (or below which) a finding is made.
pub const FALSE_ALARM: f64 = 1e-3;

/// A fit's residuals against the noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseFit {
    /// The noise judged against.
    pub noise: TorqueNoise,
    /// Per joint, the fit's residual RMS over its noise level (1 where only noise is left; the
    /// parameters take up a share `p c / (K n)` of the noise, so a little below 1 is noise too).
    pub ratio: Vec<f64>,
    /// Per joint, the model's own error `sqrt(max(residual^2 - sigma^2, 0))` (N m).
    pub model_error: Vec<f64>,
    /// The cost `V` (see the module docs).
    pub cost: f64,
    /// Its degrees of freedom, `K n / c - p`.
    pub degrees_of_freedom: f64,
    /// The chance the noise alone gives a cost of `V` or more.
    pub p_value: f64,
}

impl NoiseFit {
    /// The residuals of a fit of `unknowns` unknowns to `samples` samples, their RMS `rms` a
    /// joint (N m), against `noise` (checked already: one level a joint). None where the noise
    /// holds no more independent values than there are unknowns, or where the residuals are
    /// too large against it for their cost to stay within f64's range ([`Self::why_not`]).
    pub fn of(noise: &TorqueNoise, rms: &[f64], samples: usize, unknowns: usize) -> Option<Self> {
        let c = noise.correlation;
        let dof = (samples * rms.len()) as f64 / c - unknowns as f64;
        if dof < 1.0 {
            return None;
        }
        let ratio: Vec<f64> = (rms.iter().zip(&noise.sigma)).map(|(r, s)| r / s).collect();
        let cost = ratio.iter().map(|x| x * x).sum::<f64>() * samples as f64 / c;
        if !cost.is_finite() {
            return None;
        }
        let p_value = match noise.degrees_of_freedom {
            Some(d2) => crate::student_t::f_upper_tail(cost / dof, dof, d2),
            None => crate::student_t::chi_square_upper_tail(cost, dof),
        };
        Some(Self {
            model_error: (rms.iter().zip(&noise.sigma))
                .map(|(r, s)| (r * r - s * s).max(0.0).sqrt())
                .collect(),
            noise: noise.clone(),
            ratio,
            cost,
            degrees_of_freedom: dof,
            p_value,
        })
    }

    /// Why [`Self::of`] gave no judgement for these arguments, in words: too few independent
    /// noise values for the unknowns, or residuals too large against the noise.
    pub fn why_not(noise: &TorqueNoise, samples: usize, joints: usize, unknowns: usize) -> String {
        let values = (samples * joints) as f64 / noise.correlation;
        match values - unknowns as f64 >= 1.0 {
            true => "the residuals are too large against the noise for their cost to stay within f64's range (a noise level far too small, or torques in other units)".into(),
            false => format!(
                "the noise holds {} independent values ({samples} samples x {joints} joints over a correlation of {} samples), no more than the {unknowns} unknowns",
                shown5(values),
                shown5(noise.correlation)
            ),
        }
    }

    /// `sqrt(max(V / dof, 1))`: what the noise's standard errors are scaled by.
    pub fn scale(&self) -> f64 {
        (self.cost / self.degrees_of_freedom).max(1.0).sqrt()
    }

    /// One line on it, of `what` (a fit's residuals, a validation's errors): the cost over its
    /// degrees of freedom and its chance from noise alone.
    pub fn summary(&self, what: &str) -> String {
        format!(
            "{what} against the torques' noise measured apart: their cost over its {} degrees of freedom is {} (1 for noise alone), a chance of {} from noise alone",
            shown5(self.degrees_of_freedom),
            shown5(self.cost / self.degrees_of_freedom),
            shown5(self.p_value)
        )
    }

    /// The finding in words, for the joints `joints`: residuals beyond the noise (a model
    /// error), or below it; None where the cost is within what the noise gives.
    pub fn finding(&self, joints: &[String]) -> Option<String> {
        let reduced = shown5(self.cost / self.degrees_of_freedom);
        let list = |x: &[f64]| -> String {
            (joints.iter().zip(x))
                .map(|(j, v)| format!("{j} {}", shown5(*v)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if self.p_value < FALSE_ALARM {
            return Some(format!(
                "the residuals exceed the torques' noise (cost over its {} degrees of freedom {reduced}, a chance of {} from noise alone): the model lacks an effect the robot has (friction of another form, a flexible joint or drive, a torque lag, a payload), the states are noisy enough to count (the positions' noise through the velocities and accelerations, which the torques' noise does not hold), or the noise measured is too low. Residual over noise, a joint: {}; the model's own error (N m): {}",
                shown5(self.degrees_of_freedom),
                shown5(self.p_value),
                list(&self.ratio),
                list(&self.model_error)
            ));
        }
        (self.p_value > 1.0 - FALSE_ALARM).then(|| {
            format!(
                "the residuals are below the torques' noise (cost over its {} degrees of freedom {reduced}, residual over noise, a joint: {}): the noise given is too high, or too correlated for the correlation given, or the fit follows the noise with too many parameters for its data; the standard errors from that noise are too large",
                shown5(self.degrees_of_freedom),
                list(&self.ratio)
            )
        })
    }

    /// What is wrong with it for the joints `joints` (a document edited by hand); None where
    /// nothing.
    pub fn problem(&self, joints: &[String]) -> Option<String> {
        let n = joints.len();
        self.noise.problem(joints).or_else(|| {
            if self.ratio.len() != n || self.model_error.len() != n {
                return Some(format!(
                    "{} ratios and {} model errors, expected one a joint ({n})",
                    self.ratio.len(),
                    self.model_error.len()
                ));
            }
            let bad = |x: f64| !(x.is_finite() && x >= 0.0);
            if self.ratio.iter().chain(&self.model_error).any(|&x| bad(x))
                || bad(self.cost)
                || !(self.degrees_of_freedom.is_finite() && self.degrees_of_freedom >= 1.0)
                || !(0.0..=1.0).contains(&self.p_value)
            {
                return Some(format!(
                    "cost {}, {} degrees of freedom, p {}; expected finite ratios and errors >= 0, a cost >= 0, at least 1 degree of freedom and p in [0, 1]",
                    shown5(self.cost),
                    shown5(self.degrees_of_freedom),
                    shown5(self.p_value)
                ));
            }
            None
        })
    }
}

/// The fit's residuals (RMS `rms` a joint over `k` samples of `nv` joints) against
/// [`BaseOptions::noise`] where given; for [`Weighting::Noise`], `ls`'s standard errors
/// replaced by the noise's, `sqrt(c cov_diag)` scaled by [`NoiseFit::scale`]. Errors:
/// the noise weighting where the noise holds no more independent values than the unknowns.
pub(super) fn judge(
    ls: &mut crate::regression::LeastSquares,
    options: &BaseOptions,
    rms: &[f64],
    k: usize,
    nv: usize,
) -> Result<Option<NoiseFit>> {
    let Some(noise) = &options.noise else {
        return Ok(None);
    };
    let unknowns = ls.coef.ncols();
    let found = NoiseFit::of(noise, rms, k, unknowns);
    if options.weighting != Weighting::Noise {
        return Ok(found);
    }
    let Some(n) = found else {
        return Err(Error::invalid(
            "noise",
            format!(
                "{}: standard errors cannot be had from it; give more samples, or weight otherwise (wls)",
                NoiseFit::why_not(noise, k, nv, unknowns)
            ),
        ));
    };
    let scale = n.scale();
    ls.stderr = DMatrix::from_fn(1, unknowns, |_, j| {
        (noise.correlation * ls.cov_diag[j]).sqrt() * scale
    });
    Ok(Some(n))
}

/// What is wrong with a base-parameter model's `noise_fit` beside its `weighting` and `sigma`
/// (a document edited by hand); None where nothing: the noise weighting needs its noise, whose
/// levels are the model's `sigma`.
pub(super) fn problem_in_model(
    noise_fit: &Option<NoiseFit>,
    weighting: Weighting,
    sigma: &[f64],
    joints: &[String],
) -> Option<String> {
    match (noise_fit, weighting) {
        (None, Weighting::Noise) => Some(
            "the noise weighting without its noise_fit: the noise the rows were weighted by"
                .to_string(),
        ),
        (Some(f), w) => f.problem(joints).or_else(|| {
            (w == Weighting::Noise && f.noise.sigma != sigma)
                .then(|| "the noise weighting with a sigma other than its noise's".to_string())
        }),
        (None, _) => None,
    }
}
