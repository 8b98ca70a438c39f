//! Torques that drift from period to period: a joint warming over a long excitation changes
//! its friction, and the periods' spread, which averaging counts as noise, then holds a trend.
//!
//! Each Fourier coefficient of a joint's torques is fitted over the periods by a straight line
//! in the period's place (`c_p = alpha + beta (p - p_mean)`); the energy of the lines' slopes
//! (Parseval-weighted, as the noise is) against what the lines leave is an F ratio, near 1 for
//! noise alone: `F = (E_trend / D) / (E_left / (D (P - 2)))` over `D = 2 H + 1` coefficients
//! and `P` periods.

/// The F ratio beyond which torques drift: for noise alone, with at least
/// [`MIN_COEFFICIENTS`] coefficients and 3 periods, it lies beyond 3 with a probability below
/// 3e-4.
pub const DRIFT_RATIO: f64 = 3.0;

/// The fewest coefficients (`2 H + 1`: harmonics of the torques' band) a drift is judged
/// over.
pub const MIN_COEFFICIENTS: usize = 41;

/// The F ratio of the trend of one joint's torque coefficients over the periods: `coefs[k]`
/// the coefficients `[a_0, a_1, b_1, ...]` of period `k`, at place `place[k]` (its index among
/// the whole periods). None where not judged: fewer than 3 periods or [`MIN_COEFFICIENTS`]
/// coefficients, or no spread at all.
pub(super) fn trend_ratio(coefs: &[&[f64]], place: &[f64]) -> Option<f64> {
    let p = coefs.len();
    let d = coefs.first()?.len();
    if p < 3 || d < MIN_COEFFICIENTS {
        return None;
    }
    let mean_place = place.iter().sum::<f64>() / p as f64;
    let x: Vec<f64> = place.iter().map(|t| t - mean_place).collect();
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    if sxx <= 0.0 {
        return None;
    }
    let (mut trend, mut left) = (0.0, 0.0);
    for c in 0..d {
        let weight = if c == 0 { 1.0 } else { 0.5 };
        let mean = coefs.iter().map(|k| k[c]).sum::<f64>() / p as f64;
        let slope = coefs
            .iter()
            .zip(&x)
            .map(|(k, x)| (k[c] - mean) * x)
            .sum::<f64>()
            / sxx;
        trend += weight * slope * slope * sxx;
        left += weight
            * (coefs.iter().zip(&x))
                .map(|(k, x)| (k[c] - mean - slope * x).powi(2))
                .sum::<f64>();
    }
    let f = (trend / d as f64) / (left / (d * (p - 2)) as f64);
    f.is_finite().then_some(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trend_stands_out_of_noise() {
        // 5 periods of 101 coefficients: noise alone, then with a drift of 3 noise levels a
        // period in every coefficient
        let mut state = 1u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let place = [0.0, 1.0, 2.0, 3.0, 4.0];
        let plain: Vec<Vec<f64>> = (0..5)
            .map(|_| (0..101).map(|_| noise()).collect())
            .collect();
        let drifting: Vec<Vec<f64>> = (plain.iter().enumerate())
            .map(|(k, c)| c.iter().map(|v| v + 0.3 * k as f64).collect())
            .collect();
        let view = |c: &[Vec<f64>]| -> Vec<Vec<f64>> { c.to_vec() };
        let f = |c: &[Vec<f64>]| {
            let c = view(c);
            trend_ratio(&c.iter().map(Vec::as_slice).collect::<Vec<_>>(), &place).unwrap()
        };
        assert!(f(&plain) < 1.6, "{}", f(&plain));
        assert!(f(&drifting) > 10.0, "{}", f(&drifting));
        // too few periods or coefficients: not judged
        let two: Vec<&[f64]> = plain[..2].iter().map(Vec::as_slice).collect();
        assert_eq!(trend_ratio(&two, &place[..2]), None);
        let short: Vec<&[f64]> = plain.iter().map(|c| &c[..11]).collect();
        assert_eq!(trend_ratio(&short, &place), None);
    }
}
