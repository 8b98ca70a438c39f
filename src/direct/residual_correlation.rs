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

/// The samples (the first ones) of each of several runs whose residuals estimate its
/// autocorrelation, at the least: [`SAMPLES`] are shared among the runs, but none reads fewer
/// than this.
pub const SAMPLES_A_RUN: usize = 1_000;

/// [`long_run_factors`] of residuals `r` (row-major, `k x n`) that are several runs one after
/// the other, of `runs` samples each (they add up to `k`; empty for one run): each run is a
/// time series of its own (a join between two logs is no lag, and two logs' residuals may
/// differ in mean: a torque offset that drifted between them would read as correlation at
/// every lag), its factor `f_ij` estimated within it. Per joint the factors combine as the
/// samples' information does: `f_j = sum_i k_i / sum_i (k_i / f_ij)`, `k_i` the run's
/// samples.
pub fn long_run_factors_over_runs(r: &[f64], n: usize, runs: &[usize]) -> Vec<f64> {
    let k = r.len().checked_div(n).unwrap_or(0);
    if runs.len() <= 1 || runs.iter().sum::<usize>() != k {
        return long_run_factors(r, n);
    }
    let mut start = 0;
    let factors: Vec<(Vec<f64>, usize)> = (runs.iter())
        .map(|&len| {
            let f = long_run_factors(&r[start * n..(start + len) * n], n);
            start += len;
            (f, len)
        })
        .collect();
    combine(&factors, n)
}

/// Per joint, the factors `(f_i, k_i)` of runs of `k_i` samples combined as their
/// information is: `sum k_i / sum (k_i / f_ij)` (1 for no samples).
pub fn combine(factors: &[(Vec<f64>, usize)], n: usize) -> Vec<f64> {
    if let [(f, _)] = factors {
        return f.clone();
    }
    let total: usize = factors.iter().map(|(_, k)| k).sum();
    (0..n)
        .map(|j| {
            let information: f64 = (factors.iter()).map(|(f, k)| *k as f64 / f[j]).sum();
            match total {
                0 => 1.0,
                _ => (total as f64 / information).max(1.0),
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

    #[test]
    fn runs_are_series_of_their_own_and_their_factors_combine_as_information() {
        // two runs of white noise whose means differ: read across the join the step is
        // correlation at every lag; run by run there is none
        let k = 20_000;
        let e = white(2 * k, 5);
        let r: Vec<f64> = (0..2 * k)
            .map(|i| e[i] + if i < k { 0.3 } else { -0.3 })
            .collect();
        let across = long_run_factors(&r, 1)[0];
        let within = long_run_factors_over_runs(&r, 1, &[k, k])[0];
        assert!(across > 50.0, "{across}");
        assert!((within - 1.0).abs() < 0.15, "{within}");
        // a white run and a moving average of 5 (factor 5), of k and 3k samples:
        // 4k / (k / 1 + 3k / 5) = 2.5
        let e = white(4 * k + 4, 7);
        let mut r: Vec<f64> = e[..k].to_vec();
        r.extend((k..4 * k).map(|i| e[i..i + 5].iter().sum::<f64>() / 5.0));
        let f = long_run_factors_over_runs(&r, 1, &[k, 3 * k])[0];
        assert!((f / 2.5 - 1.0).abs() < 0.1, "{f}");
        // runs that do not add up to the samples are one run
        assert_eq!(
            long_run_factors_over_runs(&r, 1, &[k, k]),
            long_run_factors(&r, 1)
        );
        assert_eq!(combine(&[], 2), vec![1.0, 1.0]);
    }
}
