//! Signal processing for recordings: Butterworth low-pass filters applied forward and backward
//! (zero phase, as scipy's `sosfiltfilt`), linear resampling and numerical differentiation.

pub mod grid;

pub use grid::grid_step;

use crate::error::{Error, Result};

/// One second-order section `b0 + b1 z^-1 + b2 z^-2 / (1 + a1 z^-1 + a2 z^-2)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biquad {
    pub b: [f64; 3],
    pub a: [f64; 2],
}

impl Biquad {
    /// The direct-form-II-transposed state for a constant input of 1 at steady state.
    fn steady_state(&self) -> [f64; 2] {
        let gain = self.b.iter().sum::<f64>() / (1.0 + self.a[0] + self.a[1]);
        let z2 = self.b[2] - self.a[1] * gain;
        [self.b[1] - self.a[0] * gain + z2, z2]
    }
}

/// A digital Butterworth low-pass of `order` with cutoff `cutoff` Hz at sampling rate `rate`
/// Hz (bilinear transform with pre-warping), as second-order sections with unit DC gain.
pub fn butterworth_lowpass(order: usize, cutoff: f64, rate: f64) -> Result<Vec<Biquad>> {
    let max = crate::limits::MAX_FILTER_ORDER;
    if !((1..=max).contains(&order) && cutoff > 0.0 && cutoff < 0.5 * rate) {
        return Err(Error::invalid(
            "filter",
            format!(
                "order {order}, cutoff {} Hz at {} Hz; need 1 <= order <= {max} and 0 < cutoff < rate / 2",
                crate::error::shown(cutoff),
                crate::error::shown(rate)
            ),
        ));
    }
    let fs2 = 2.0 * rate;
    let wc = fs2 * (std::f64::consts::PI * cutoff / rate).tan();
    let mut sections = Vec::new();
    for k in 0..order / 2 {
        // analog pole pair wc * exp(i theta), theta in (pi/2, pi)
        let theta = std::f64::consts::PI * (2 * k + order + 1) as f64 / (2 * order) as f64;
        let (re, im) = (wc * theta.cos(), wc * theta.sin());
        // z = (fs2 + p) / (fs2 - p)
        let den = (fs2 - re).powi(2) + im * im;
        let zr = ((fs2 + re) * (fs2 - re) - im * im) / den;
        let zi = ((fs2 - re) * im + (fs2 + re) * im) / den;
        let (a1, a2) = (-2.0 * zr, zr * zr + zi * zi);
        let g = (1.0 + a1 + a2) / 4.0;
        sections.push(Biquad {
            b: [g, 2.0 * g, g],
            a: [a1, a2],
        });
    }
    if order % 2 == 1 {
        let z = (fs2 - wc) / (fs2 + wc);
        let g = (1.0 - z) / 2.0;
        sections.push(Biquad {
            b: [g, g, 0.0],
            a: [-z, 0.0],
        });
    }
    Ok(sections)
}

fn run(sections: &[Biquad], x: &mut [f64]) {
    let x0 = x[0];
    for s in sections {
        let [mut z1, mut z2] = s.steady_state().map(|z| z * x0);
        for v in x.iter_mut() {
            let y = s.b[0] * *v + z1;
            z1 = s.b[1] * *v - s.a[0] * y + z2;
            z2 = s.b[2] * *v - s.a[1] * y;
            *v = y;
        }
    }
}

/// Zero-phase filtering of `x` (forward then backward), with odd extension of `3 (2 s + 1)`
/// samples at both ends (`s` sections) and steady-state initial conditions, like scipy's
/// `sosfiltfilt`. Fails when `x` is shorter than the extension.
pub fn filtfilt(sections: &[Biquad], x: &[f64]) -> Result<Vec<f64>> {
    let pad = 3 * (2 * sections.len() + 1);
    let n = x.len();
    if n <= pad {
        return Err(Error::invalid(
            "signal",
            format!("{n} samples; zero-phase filtering needs more than {pad}"),
        ));
    }
    let mut ext = Vec::with_capacity(n + 2 * pad);
    ext.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
    ext.extend_from_slice(x);
    ext.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
    run(sections, &mut ext);
    ext.reverse();
    run(sections, &mut ext);
    ext.reverse();
    Ok(ext[pad..pad + n].to_vec())
}

/// Derivative of uniformly sampled `x` (period `dt`): second-order central differences inside,
/// one-sided second-order at the ends (numpy's `gradient(..., edge_order=2)`).
pub fn differentiate(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    if n < 3 {
        return vec![0.0; n];
    }
    let mut d = vec![0.0; n];
    for i in 1..n - 1 {
        d[i] = (x[i + 1] - x[i - 1]) / (2.0 * dt);
    }
    d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / (2.0 * dt);
    d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / (2.0 * dt);
    d
}

/// Linear interpolation of samples `(t, x)` (t increasing) at the times `grid` (inside
/// `[t[0], t[last]]`).
pub fn interpolate(t: &[f64], x: &[f64], grid: &[f64]) -> Vec<f64> {
    let mut j = 0;
    grid.iter()
        .map(|&g| {
            while j + 2 < t.len() && t[j + 1] < g {
                j += 1;
            }
            let (t0, t1) = (t[j], t[j + 1]);
            let w = ((g - t0) / (t1 - t0)).clamp(0.0, 1.0);
            x[j] + w * (x[j + 1] - x[j])
        })
        .collect()
}
