//! Torque noise that is not white within its band: the noise weighting and a fit's cost
//! against the noise ([`crate::direct::noise_fit`]) take a joint's noise flat over the torques'
//! harmonics, so that an averaged period of `K` samples holds `2 H + 1` independent values of
//! it. A drive's noise that rises toward low frequencies (a slow ripple) or high ones (a
//! current loop's) breaks that.
//!
//! The periods' spread is split between the band's lower half (harmonics `0..=H/2`) and its
//! upper half: each half's power a value (Parseval: the mean level `d_0^2` one value, a
//! harmonic `1/2 (da^2 + db^2)` two) over the other's is the noise's tilt, F distributed with
//! `(P - 1)` times each half's values as degrees of freedom for white noise.

use super::series::weighted_energy;
use crate::error::shown5;

/// The fewest torque harmonics a tilt is judged over.
pub const MIN_HARMONICS: usize = 10;

/// The tilt (or its inverse) beyond which the noise is said not to be white: the noise
/// weighting's standard errors may then be off by up to its square root.
pub const TILT: f64 = 2.0;

/// The chance noise that is white gives a tilt beyond which it is said not to be.
const FALSE_ALARM: f64 = 1e-3;

/// A joint's noise tilt: its lower half band's power a value over its upper half's, from the
/// periods `keep` of `coefs` (`[period][joint]`, coefficients `[a_0, a_1, b_1, ...]`) about
/// their `mean`, over `h` harmonics. None below [`MIN_HARMONICS`] or without spread in the
/// upper half.
pub(super) fn tilt(
    coefs: &[Vec<Vec<f64>>],
    keep: &[usize],
    j: usize,
    h: usize,
    mean: &[f64],
) -> Option<f64> {
    if h < MIN_HARMONICS {
        return None;
    }
    let half = h / 2;
    let energy = |low: bool| -> f64 {
        keep.iter()
            .map(|&k| {
                weighted_energy(&coefs[k][j][..2 * h + 1], &mean[..2 * h + 1], &|i| {
                    f64::from(u8::from((i <= half) == low))
                })
            })
            .sum()
    };
    let (values_low, values_high) = values(h);
    let (low, high) = (energy(true) / values_low, energy(false) / values_high);
    (high > 0.0 && low.is_finite()).then(|| low / high)
}

/// The values (Parseval's counting: the mean one, a harmonic two) of the lower and upper half
/// of a band of `h` harmonics.
fn values(h: usize) -> (f64, f64) {
    let half = h / 2;
    ((1 + 2 * half) as f64, (2 * (h - half)) as f64)
}

/// The finding for the tilts `tilts` a joint (named by `joints`, or numbered) of a log whose
/// `periods` periods were averaged over `h` torque harmonics: the joints whose tilt lies
/// beyond [`TILT`] either way, and beyond what white noise gives with a chance of 1e-3. None
/// where none does.
pub fn finding(
    tilts: &[Option<f64>],
    periods: usize,
    h: usize,
    joints: &[String],
) -> Option<String> {
    let (values_low, values_high) = values(h);
    let (d_low, d_high) = (
        (periods.saturating_sub(1)) as f64 * values_low,
        (periods.saturating_sub(1)) as f64 * values_high,
    );
    if d_low < 1.0 || d_high < 1.0 {
        return None;
    }
    let tilted: Vec<String> = (tilts.iter().enumerate())
        .filter_map(|(j, t)| {
            let t = (*t)?;
            let chance = match t >= 1.0 {
                true => crate::student_t::f_upper_tail(t, d_low, d_high),
                false => crate::student_t::f_upper_tail(1.0 / t, d_high, d_low),
            };
            let beyond = !(1.0 / TILT..=TILT).contains(&t);
            (beyond && chance < FALSE_ALARM).then(|| {
                let name = joints
                    .get(j)
                    .cloned()
                    .unwrap_or_else(|| format!("joint {}", j + 1));
                format!("{name} {}", shown5(t))
            })
        })
        .collect();
    (!tilted.is_empty()).then(|| {
        format!(
            "the torques' noise the periods measured is not white within their band (the lower half's power a value over the upper half's: {}; 1 for white noise): the noise weighting and the cost against the noise take it flat over the band, so the standard errors from it and the cost's degrees of freedom may be off by up to the square root of that ratio",
            tilted.join(", ")
        )
    })
}
