//! Positions logged in coarse encoder counts, seen through the direct method's preprocessing
//! (docs/method.md, section 8).
//!
//! Where a log has no velocity channel, [`crate::logs::preprocess`] differentiates the positions
//! twice (through its low-pass filter) for qd and qdd. Positions rounded to whole counts of `s`
//! rad carry a rounding error of about `s / sqrt(12)` a sample, and what of it passes the
//! filter is noise in qd and qdd: errors in the regressor's variables, which least squares
//! does not count. They bias the parameters of the terms they enter toward zero by about the
//! ratio of their variance to the signal's (`r^2`, with `r` the ratio of their RMS values),
//! and the standard errors do not show it. On an excitation of the A465 logged with 4,096
//! counts a revolution, qdd carried 11-26 % noise and the base parameters erred by 2.9
//! standard errors RMS.
//!
//! So where a joint's logged positions lie on a grid
//! ([`grid_step`]) and its velocity is derived from
//! them, a rounding error of the same motion (the filtered positions rounded again to the grid
//! shifted by a random fraction of a step, [`REALISATIONS`] times, seeded) is passed through
//! the same filter and differentiation, and its RMS compared with that of the preprocessed qd
//! and qdd over the samples kept (`tests/position_rounding.rs` checks it against the true
//! noise, within a factor of 2; on joints slower than a count a millisecond it runs low, up
//! to 2.5). A ratio of at least [`NOISE_RATIO`] is warned of.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use crate::logs::findings::position_rounding::*;
use crate::logs::recording::Recording;
use crate::signal::grid_step;

/// Realisations of the rounding the preprocessing passes through its chain; their mean
/// squares are averaged.
pub const REALISATIONS: u64 = 2;

/// The rounding's noise in one joint's derived qd and qdd. `step` is the grid its logged
/// positions lie on ([`grid_step`], rad or m),
/// `smooth` the positions on the preprocessing's uniform grid low-pass filtered (None without
/// a filter), `grid_len` that grid's length, `derive` the preprocessing's chain from a noise
/// on that grid to `(qd, qdd)` over the samples it keeps, and `qd`, `qdd` what the chain gave
/// for the logged positions. With `smooth`, each realisation rounds it again to the grid
/// shifted by a random fraction of a step: a rounding error of the same motion, sawtooths and
/// slow steps at turnarounds included. Without, an independent error uniform over one step a
/// sample (white: it leaves out the slow part). None where the chain fails or the ratios are
/// not numbers (signals whose squares overflow: a log beyond any robot's, refused or warned
/// of elsewhere).
pub(crate) fn measure(
    joint: usize,
    step: f64,
    smooth: Option<&[f64]>,
    grid_len: usize,
    qd: &[f64],
    qdd: &[f64],
    derive: impl Fn(&[f64]) -> Option<(Vec<f64>, Vec<f64>)>,
) -> Option<PositionRounding> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x726f756e64 ^ joint as u64);
    let ms = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64;
    let (mut noise_qd, mut noise_qdd) = (0.0, 0.0);
    for _ in 0..REALISATIONS {
        let noise: Vec<f64> = match smooth {
            Some(s) => {
                let shift = rng.random::<f64>();
                s.iter()
                    .map(|&x| step * ((x / step + shift).round() - shift) - x)
                    .collect()
            }
            None => (0..grid_len)
                .map(|_| step * (rng.random::<f64>() - 0.5))
                .collect(),
        };
        let (nqd, nqdd) = derive(&noise)?;
        noise_qd += ms(&nqd) / REALISATIONS as f64;
        noise_qdd += ms(&nqdd) / REALISATIONS as f64;
    }
    let ratio = |noise: f64, signal: &[f64]| {
        let s = ms(signal);
        if s > 0.0 {
            (noise / s).sqrt()
        } else {
            0.0
        }
    };
    let (qd_ratio, qdd_ratio) = (ratio(noise_qd, qd), ratio(noise_qdd, qdd));
    (qd_ratio.is_finite() && qdd_ratio.is_finite()).then_some(PositionRounding {
        joint,
        step,
        qd_ratio,
        qdd_ratio,
    })
}

/// The findings of `all` at or beyond [`NOISE_RATIO`].
pub fn findings(all: &[PositionRounding]) -> Vec<&PositionRounding> {
    all.iter().filter(|r| r.ratio() >= NOISE_RATIO).collect()
}

/// Per joint, the finding of `all` (from the parts of a log split at its gaps) with the
/// largest ratio, in joint order.
pub fn worst_of(all: impl Iterator<Item = PositionRounding>) -> Vec<PositionRounding> {
    let mut worst: Vec<PositionRounding> = Vec::new();
    for r in all {
        match worst.iter_mut().find(|w| w.joint == r.joint) {
            Some(w) if r.ratio() > w.ratio() => *w = r,
            Some(_) => {}
            None => worst.push(r),
        }
    }
    worst.sort_by_key(|r| r.joint);
    worst
}

/// What the noise does to a fit, to end [`warning`] with.
pub const IN_A_FIT: &str = ": errors in the regressor's variables, which bias the parameters of those terms toward zero (by about the square of the ratio) and which the standard errors do not count. Log a velocity channel or finer positions, or filter lower";

/// What the noise does to a validation, to end [`warning`] with.
pub const IN_A_VALIDATION: &str = ": the residuals hold it beside the model's errors. Log a velocity channel or finer positions, or filter lower";

/// The findings among `all` (joints named by `joint_names`, or numbered from 1 where it has
/// none), described for a warning that the caller ends with what they do ([`IN_A_FIT`],
/// [`IN_A_VALIDATION`]); None without findings.
pub fn warning(all: &[PositionRounding], joint_names: &[String]) -> Option<String> {
    let found = findings(all);
    if found.is_empty() {
        return None;
    }
    let name = |j: usize| {
        joint_names
            .get(j)
            .map(|n| format!("'{n}'"))
            .unwrap_or_else(|| format!("joint {}", j + 1))
    };
    let each: Vec<String> = found
        .iter()
        .map(|r| {
            format!(
                "{} in steps of {:.3e} leave {:.1} % in qd and {:.1} % in qdd",
                name(r.joint),
                r.step,
                100.0 * r.qd_ratio,
                100.0 * r.qdd_ratio
            )
        })
        .collect();
    Some(format!(
        "positions logged in coarse counts, with velocities derived from them: their rounding leaves noise (RMS, after the filter, of the signal's RMS): {}",
        each.join("; ")
    ))
}

/// Per joint, the step (rad) of the grid `rec`'s positions lie on (whole encoder counts, see
/// [`grid_step`]), or None: positions off any grid (a continuous or resampled signal) or a
/// joint that reads fewer than two values.
pub fn position_steps(rec: &Recording) -> Vec<Option<f64>> {
    let n = rec.n;
    (0..n)
        .map(|j| {
            let column: Vec<f64> = rec.q.iter().skip(j).step_by(n.max(1)).copied().collect();
            grid_step(&column)
        })
        .collect()
}
