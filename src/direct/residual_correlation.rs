//! Residuals correlated from sample to sample, and what they do to the direct method's
//! standard errors (docs/method.md, section 8).
//!
//! The least-squares standard errors `sigma sqrt((Phi^T W Phi)^-1)` take every sample's
//! residual as independent. A log low-pass filtered and then decimated less than its cutoff
//! allows is not: the common protocol (10 Hz zero-phase Butterworth, then 100 Hz) leaves about
//! five correlated samples to every independent one, and on the A465 the base parameters erred
//! by 2.6 of their standard errors RMS (up to 6) with 0.05 N m of white torque noise; decimated
//! to 20 Hz or less, by 1.1. So each joint's residual series gives its long-run variance factor
//! `f_j = 1 + 2 sum_{k=1}^{L} (1 - k / (L + 1)) rho_k` (Bartlett weights; `rho_k` its
//! autocorrelation at lag k, `L` twice the first lag at which `rho_k` falls below the noise of
//! an estimate from independent samples, `2 / sqrt(K)`), and the standard errors are scaled by
//! the square root of the largest `f_j` (at least 1: residuals that alternate in sign do not
//! shrink them). Regressors that vary slowly against the residuals' correlation (smooth
//! excitations) are what makes one factor per joint apply to every parameter.

/// The most lags the autocorrelation is summed over.
pub const MAX_LAG: usize = 1000;

/// The samples (the first ones, in time order) whose residuals estimate the autocorrelation:
/// to about `2 / sqrt(20,000) = 0.014`, and at a small part of the cost of a fit on a long log.
pub const SAMPLES: usize = 20_000;

/// Per joint, the long-run variance factor (at least 1) of the residuals `r` (row-major, `k x
/// n`, samples in time order; see the module documentation). 1 for fewer than 8 samples, or a
/// joint whose residuals are all 0.
pub fn long_run_factors(r: &[f64], n: usize) -> Vec<f64> {
    let k = r.len().checked_div(n).unwrap_or(0);
    (0..n)
        .map(|j| {
            if k < 8 {
                return 1.0;
            }
            let x: Vec<f64> = (0..k).map(|i| r[i * n + j]).collect();
            let mean = x.iter().sum::<f64>() / k as f64;
            let c0: f64 = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / k as f64;
            if !(c0 > 0.0 && c0.is_finite()) {
                return 1.0;
            }
            let rho = |lag: usize| {
                (0..k - lag)
                    .map(|i| (x[i] - mean) * (x[i + lag] - mean))
                    .sum::<f64>()
                    / (k as f64 * c0)
            };
            let noise = 2.0 / (k as f64).sqrt();
            let cap = MAX_LAG.min(k / 4);
            let mut rhos = vec![];
            let mut first_small = None;
            for lag in 1..=cap {
                let r = rho(lag);
                rhos.push(r);
                match first_small {
                    None if r < noise => first_small = Some(lag),
                    Some(f) if lag >= 2 * f => break,
                    _ => {}
                }
            }
            let l = rhos.len();
            let f = 1.0
                + 2.0
                    * rhos
                        .iter()
                        .enumerate()
                        .map(|(i, r)| (1.0 - (i + 1) as f64 / (l + 1) as f64) * r)
                        .sum::<f64>();
            if f.is_finite() {
                f.max(1.0)
            } else {
                1.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White noise from a linear congruential generator (Box-Muller).
    fn white(count: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..count)
            .map(|_| {
                let (a, b) = (u(), u());
                (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect()
    }

    #[test]
    fn white_noise_gives_one_and_a_moving_average_its_long_run_variance() {
        let k = 40_000;
        let e = white(k + 4, 3);
        // joint 1 white; joint 2 a moving average of 5 (long-run factor 5: the variance of a
        // mean of m samples is 5 times that of independent ones); joint 3 alternating
        // (negative correlation: not below 1)
        let r: Vec<f64> = (0..k)
            .flat_map(|i| {
                let ma = e[i..i + 5].iter().sum::<f64>() / 5.0;
                [e[i], ma, e[i] - e[i + 1]]
            })
            .collect();
        let f = long_run_factors(&r, 3);
        assert!((f[0] - 1.0).abs() < 0.15, "{f:?}");
        assert!((f[1] / 5.0 - 1.0).abs() < 0.15, "{f:?}");
        assert_eq!(f[2], 1.0);
        // the factor is what the spread of means says: means of 200-sample blocks of the
        // moving average vary f times as much as those of white noise
        let blocks: Vec<f64> = (0..k / 200)
            .map(|b| (0..200).map(|i| r[(b * 200 + i) * 3 + 1]).sum::<f64>() / 200.0)
            .collect();
        let var_ma = blocks.iter().map(|m| m * m).sum::<f64>() / blocks.len() as f64;
        let per_sample: f64 = (0..k).map(|i| r[i * 3 + 1].powi(2)).sum::<f64>() / k as f64;
        let ratio = var_ma / (per_sample / 200.0);
        assert!((ratio / f[1] - 1.0).abs() < 0.3, "{ratio} vs {}", f[1]);
        // too few samples, zeros: 1
        assert_eq!(long_run_factors(&[1.0, 2.0, 3.0], 1), vec![1.0]);
        assert_eq!(long_run_factors(&vec![0.0; 100], 2), vec![1.0, 1.0]);
    }
}
