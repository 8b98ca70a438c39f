//! How much of a state reading's error repeats in every pass of one point.
//!
//! The mean of K passes' readings averages their errors out only where they are independent.
//! A robot that repeats its motion to within an encoder count rounds its positions the same
//! way in every pass, and a controller's transient the window's fit does not follow is the same
//! in every pass: such an error is common to the passes and stays whole in their mean. The
//! passes' residuals about their position fits show it: where the errors repeat, the residuals
//! of two passes, lined up on their crossing samples, agree. [`repeated_share`] is their mean
//! correlation over the pairs of passes, and the variance of the mean reading is then
//! `var (rho + (1 - rho) / K)` ([`mean_variance`]) instead of `var / K`.

use super::crossing_values::CrossingValues;

/// The share of the position-reading error of joint `j` that the passes `crossings` have in
/// common: the mean correlation of their residuals over the pairs of passes, lined up on
/// each window's crossing sample, in `[0, 1]` (0 for fewer than two passes or no residuals).
pub fn repeated_share(crossings: &[CrossingValues], j: usize) -> f64 {
    let passes: Vec<(&[f64], usize)> = crossings
        .iter()
        .filter_map(|c| {
            let r = c.position_residuals.get(j)?;
            (!r.is_empty()).then_some((r.as_slice(), c.centre))
        })
        .collect();
    if passes.len() < 2 {
        return 0.0;
    }
    // the samples every pass has, relative to its crossing sample
    let before = passes.iter().map(|(_, c)| *c).min().unwrap_or(0);
    let after = passes.iter().map(|(r, c)| r.len() - c).min().unwrap_or(0);
    let len = before + after;
    if len == 0 {
        return 0.0;
    }
    // sum over pairs of r_k . r_l = |sum_k r_k|^2 - sum_k |r_k|^2, each pass scaled to unit
    // length so that every pair counts alike
    let mut sum = vec![0.0; len];
    let mut used = 0usize;
    for (r, c) in &passes {
        let part = &r[c - before..c + after];
        let norm = part.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            continue;
        }
        sum.iter_mut().zip(part).for_each(|(s, x)| *s += x / norm);
        used += 1;
    }
    if used < 2 {
        return 0.0;
    }
    let k = used as f64;
    let pairs = (sum.iter().map(|s| s * s).sum::<f64>() - k) / (k * (k - 1.0));
    pairs.clamp(0.0, 1.0)
}

/// The variance of the mean of `k` readings of variance `var` each whose errors share
/// `share` ([`repeated_share`]): `var (share + (1 - share) / k)`.
pub fn mean_variance(var: f64, share: f64, k: usize) -> f64 {
    let k = k.max(1) as f64;
    var * (share + (1.0 - share) / k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pass(residuals: Vec<f64>, centre: usize) -> CrossingValues {
        CrossingValues {
            time: 0.0,
            q: vec![0.0],
            qd: vec![0.0],
            qdd: vec![0.0],
            tau: vec![0.0],
            state_stderr: [vec![0.0], vec![0.0], vec![0.0]],
            tau_gain: vec![0.0],
            tau_scatter: vec![(0.0, 0)],
            position_band: vec![false],
            position_residuals: vec![residuals],
            centre,
            glitches: vec![],
        }
    }

    /// A deterministic pseudo-random sequence in [-0.5, 0.5).
    fn noise(seed: u64, len: usize) -> Vec<f64> {
        let mut x = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..len)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn identical_passes_share_everything_even_when_shifted_in_their_windows() {
        let base = noise(1, 120);
        // the same errors about each crossing sample, windows starting 0, 3 and 7 samples early
        let passes: Vec<CrossingValues> = [0usize, 3, 7]
            .iter()
            .map(|&shift| {
                let mut r = noise(99 + shift as u64, shift);
                r.extend_from_slice(&base[..100]);
                pass(r, 50 + shift)
            })
            .collect();
        assert!((repeated_share(&passes, 0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn independent_passes_share_about_nothing() {
        let passes: Vec<CrossingValues> = (0..20).map(|s| pass(noise(s, 100), 50)).collect();
        let share = repeated_share(&passes, 0);
        // the pairs' mean correlation of independent windows of 100 samples scatters by about
        // 1 / (100 sqrt(190 / 2)) ~ 0.01
        assert!(share < 0.04, "{share}");
    }

    #[test]
    fn a_common_part_is_measured_as_its_share_of_the_variance() {
        let common = noise(7, 400);
        let passes: Vec<CrossingValues> = (0..30)
            .map(|s| {
                let own = noise(100 + s, 400);
                // equal variances: half of each pass's error is common
                pass(common.iter().zip(&own).map(|(c, o)| c + o).collect(), 200)
            })
            .collect();
        let share = repeated_share(&passes, 0);
        assert!((share - 0.5).abs() < 0.06, "{share}");
        assert_eq!(mean_variance(2.0, 0.5, 10), 2.0 * (0.5 + 0.05));
        assert_eq!(mean_variance(2.0, 0.0, 10), 0.2);
        assert_eq!(mean_variance(2.0, 1.0, 10), 2.0);
    }

    #[test]
    fn too_few_passes_or_no_residuals_share_nothing() {
        assert_eq!(repeated_share(&[pass(noise(1, 10), 5)], 0), 0.0);
        assert_eq!(repeated_share(&[pass(vec![], 0), pass(vec![], 0)], 0), 0.0);
        assert_eq!(
            repeated_share(&[pass(vec![0.0; 10], 5), pass(vec![0.0; 10], 5)], 0),
            0.0
        );
    }
}
