//! The noise of the torques read at the crossings, and the separated regressions weighted by it
//! (docs/method.md, section 4).
//!
//! The torque of joint j read at crossing k errs by two parts:
//! - the torque samples' noise through the window's fit: variance `s_j^2 g_kj^2`, with the
//!   fit's noise gain `g_kj` ([`CrossingValues::tau_gain`]) and the samples' noise level `s_j`
//!   pooled over the experiment's windows ([`CrossingValues::tau_scatter`]). A window narrowed
//!   at a velocity reversal holds fewer samples: its `g_kj` is larger, up to 2.5 times on the
//!   A465 at the paper's point;
//! - whatever else varies from pass to pass, the same for every crossing: variance `a_j`
//!   (repeatability, noise slower than a window, and in the residuals the even-order terms that
//!   symmetric pairs cancel from the estimate).
//!
//! Ordinary least squares assumes equal variances. With unequal `g_kj` its standard errors
//! are wrong: the D* row of the A465's joint 5, narrowed at 10 of its 12 crossings, had errors
//! 1.1-1.25 times its standard errors. The weighted fit takes each row with weight `1 / (a_j +
//! s_j^2 g_kj^2)`, `a_j` estimated by moments as in a random-effects meta-analysis
//! (DerSimonian-Laird: the excess of the chi-square of the fit weighted by the samples' noise
//! alone over its degrees of freedom). Its standard errors are `sigma_j sqrt((X^T W X)^-1)`,
//! with `sigma_j` still estimated from the weighted residuals (as Knapp and Hartung's), so the
//! variance model needs to be right only in its proportions. Over noise whose variances differ
//! 36-fold from row to row the standard errors match the scatter to 10 % (ordinary least
//! squares: 0.5-1.5 times), and t intervals cover 93-97 % for 95 %.

use nalgebra::{DMatrix, DVector};

use super::crossing_values::{CrossingValues, ExperimentValues};
use super::diagnostics::TorqueNoise;
use crate::error::Result;
use crate::regression::{least_squares, LeastSquares};

/// Per joint, the torque samples' noise variance (N^2 m^2) pooled over `crossings`: the sum of
/// the squared residuals about every window's fit over the sum of their degrees of freedom (0
/// without any).
pub fn sample_variance<'a>(
    crossings: impl IntoIterator<Item = &'a CrossingValues>,
    n: usize,
) -> Vec<f64> {
    let mut ss = vec![0.0; n];
    let mut dof = vec![0usize; n];
    for c in crossings {
        for (j, &(s, d)) in c.tau_scatter.iter().enumerate().take(n) {
            ss[j] += s;
            dof[j] += d;
        }
    }
    ss.iter()
        .zip(&dof)
        .map(|(&s, &d)| if d > 0 { s / d as f64 } else { 0.0 })
        .collect()
}

/// The noise of the nominal experiment's torques, one entry a joint of `joints`: its samples'
/// ([`sample_variance`]) and what its readings, all through one state, scattered by beyond
/// what the samples' noise gives them (the square root of their variance about their mean less
/// the mean of [`reading_variance`], 0 where less; `None` with fewer than 2 readings). The
/// planner's prediction takes the latter as the noise from pass to pass
/// ([`super::PlanOptions::torque_pass_noise`]). The torque's step is not given (the nominal
/// readings enter no regression); the encoder step is, as for every experiment.
pub fn nominal_noise(nominal: &ExperimentValues, joints: &[String]) -> Vec<TorqueNoise> {
    let n = joints.len();
    let samples = sample_variance(&nominal.crossings, n);
    let readings: Vec<&[f64]> = nominal.crossings.iter().map(|c| &c.tau[..]).collect();
    let scatter = super::response::PassNoise::of(readings);
    let k = nominal.crossings.len() as f64;
    joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let from_samples: f64 = nominal
                .crossings
                .iter()
                .map(|c| reading_variance(c, &samples)[j])
                .sum::<f64>()
                / k;
            let passes = scatter
                .as_ref()
                .map(|s| (s.variance[j] - from_samples).max(0.0).sqrt())
                .filter(|p| p.is_finite());
            TorqueNoise {
                experiment: nominal.kind.name().to_string(),
                joint: joint.clone(),
                samples: samples[j].sqrt(),
                passes,
                step: None,
                position_step: nominal.position_step.get(j).copied().flatten(),
            }
        })
        .collect()
}

/// The variance (N^2 m^2) the torque samples' noise gives the torque of each joint read at
/// `crossing`: `s_j^2 g_kj^2` with `variance` the pooled `s_j^2` ([`sample_variance`]).
pub fn reading_variance(crossing: &CrossingValues, variance: &[f64]) -> Vec<f64> {
    crossing
        .tau_gain
        .iter()
        .zip(variance)
        .map(|(g, s2)| s2 * g * g)
        .collect()
}

/// `Y ~= X A^T` like [`least_squares`], each output `c` fitted with the rows weighted by `1 /
/// (a_c + u[(k, c)])`: `u` (K x m) the variance of each entry of `Y` from the samples' noise
/// ([`reading_variance`]), `a_c >= 0` the variance common to every row, estimated by moments
/// from the fit weighted by `1 / u` alone (residuals `r`, leverages `h`): `a_c = max(0, (sum_k
/// r_k^2 / u_k - (K - p)) / sum_k (1 - h_k) / u_k)`. An output whose rows all weigh the same,
/// without residual degrees of freedom, or with a `u` of 0 (noise-free data: then `a_c` is the
/// residuals' variance) keeps the ordinary fit.
///
/// The fit's coefficients, standard errors and residual RMS (of `Y - X A^T`, unweighted) are
/// the weighted ones; its condition number, `cov_diag` and leverages describe `X`.
pub fn weighted_least_squares(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    u: &DMatrix<f64>,
    context: &str,
    columns: &[String],
) -> Result<Weighted> {
    let ordinary = least_squares(x, y, context, columns)?;
    let (k, p) = x.shape();
    let m = y.ncols();
    if u.shape() != y.shape() {
        return Err(crate::error::Error::shape(
            format!("{context}: sample variances"),
            format!("{k} x {m} like Y"),
            format!("{} x {}", u.nrows(), u.ncols()),
        ));
    }
    let mut common = vec![f64::NAN; m];
    let mut correlation = vec![ordinary.correlation.clone(); m];
    if k <= p {
        return Ok(Weighted {
            fit: ordinary,
            common,
            correlation,
        });
    }
    let mut out = ordinary.clone();
    for (c, (common, correlation)) in common.iter_mut().zip(&mut correlation).enumerate() {
        let uc = u.column(c);
        if uc.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            continue;
        }
        let umax = uc.amax();
        if umax == 0.0 {
            // no samples' noise (noise-free data): all of the residuals vary from pass to pass
            let sigma = ordinary.residual_rms[c] * (k as f64 / (k - p) as f64).sqrt();
            *common = sigma * sigma;
            continue;
        }
        if uc.min() <= 1e-12 * umax {
            continue;
        }
        // relative to the largest, so that torques far from 1 N m do not square out of range
        let un: Vec<f64> = uc.iter().map(|v| v / umax).collect();
        let equal = un.iter().all(|v| *v == un[0]);
        // DerSimonian-Laird: the fit weighted by the samples' noise alone, and the excess of its
        // chi-square over its degrees of freedom
        let w: Vec<f64> = un.iter().map(|v| 1.0 / v).collect();
        let first = if equal {
            ordinary.clone()
        } else {
            fit_weighted(x, y, c, &w, context, columns)?
        };
        let row = if equal { c } else { 0 };
        let r: DVector<f64> = y.column(c) - x * first.coef.row(row).transpose();
        let root = umax.sqrt();
        let chi2: f64 = (0..k).map(|i| w[i] * (r[i] / root).powi(2)).sum();
        let trace: f64 = (0..k).map(|i| w[i] * (1.0 - first.leverage[i])).sum();
        let a = ((chi2 - (k - p) as f64) / trace).max(0.0);
        if !(a.is_finite() && trace > 0.0) {
            continue;
        }
        *common = a * umax;
        if equal {
            continue;
        }
        let fit = if a == 0.0 {
            first
        } else {
            let w: Vec<f64> = un.iter().map(|v| 1.0 / (a + v)).collect();
            fit_weighted(x, y, c, &w, context, columns)?
        };
        correlation.copy_from(&fit.correlation);
        out.coef.row_mut(c).copy_from(&fit.coef.row(0));
        out.stderr.row_mut(c).copy_from(&fit.stderr.row(0));
        let r: DVector<f64> = y.column(c) - x * fit.coef.row(0).transpose();
        let amax = r.amax();
        out.residual_rms[c] = if amax > 0.0 {
            amax * ((r / amax).norm_squared() / k as f64).sqrt()
        } else {
            0.0
        };
    }
    Ok(Weighted {
        fit: out,
        common,
        correlation,
    })
}

/// Output `c` of `Y ~= X A^T` with row `k` weighted by `w[k] > 0` (relative weights: the
/// standard errors take the noise level from the weighted residuals).
fn fit_weighted(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    c: usize,
    w: &[f64],
    context: &str,
    columns: &[String],
) -> Result<LeastSquares> {
    let top = w.iter().cloned().fold(0.0, f64::max);
    let root: Vec<f64> = w.iter().map(|w| (w / top).sqrt()).collect();
    let xw = DMatrix::from_fn(x.nrows(), x.ncols(), |i, j| root[i] * x[(i, j)]);
    let yw = DMatrix::from_fn(x.nrows(), 1, |i, _| root[i] * y[(i, c)]);
    least_squares(&xw, &yw, context, columns)
}

/// The result of [`weighted_least_squares`].
#[derive(Clone, Debug, PartialEq)]
pub struct Weighted {
    pub fit: LeastSquares,
    /// Per output, the variance common to every row, `a_c` (N^2 m^2 for torques): NaN where
    /// it was not estimated (no residual degree of freedom, or a variance in `u` that is not
    /// finite).
    pub common: Vec<f64>,
    /// Per output, the correlation of its coefficients (p x p, as
    /// [`LeastSquares::correlation`]) under the weights it was fitted with.
    pub correlation: Vec<DMatrix<f64>>,
}
