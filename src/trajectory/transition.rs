//! Quintic transitions between two states, timed to respect the joint limits.

use super::piecewise::quintic;

/// The bounds a transition must respect: per joint, position range, speed and acceleration
/// (already scaled by any safety margin; `f64::INFINITY` where unbounded).
#[derive(Clone, Debug)]
pub struct TransitionLimits {
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
}

/// Number of points per transition at which the bounds are checked.
const CHECK_POINTS: usize = 64;

/// How far a quintic of `duration` from `from` to `to` exceeds the bounds: 0 when inside, else
/// the largest excess relative to the bound.
fn excess(from: &[[f64; 3]], to: &[[f64; 3]], duration: f64, lim: &TransitionLimits) -> f64 {
    let mut worst: f64 = 0.0;
    for j in 0..from.len() {
        let [p0, v0, a0] = from[j];
        let [p1, v1, a1] = to[j];
        let c = quintic(p0, v0, a0, p1, v1, a1, duration);
        for k in 0..=CHECK_POINTS {
            let s = duration * k as f64 / CHECK_POINTS as f64;
            let q = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
            let v = c[1] + s * (2.0 * c[2] + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
            let a = 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
            let span = (lim.upper[j] - lim.lower[j]).min(1.0);
            if q > lim.upper[j] {
                worst = worst.max((q - lim.upper[j]) / span);
            }
            if q < lim.lower[j] {
                worst = worst.max((lim.lower[j] - q) / span);
            }
            worst = worst.max(v.abs() / lim.velocity[j] - 1.0);
            worst = worst.max(a.abs() / lim.acceleration[j] - 1.0);
        }
    }
    worst
}

/// The shortest duration, a whole number of sampling periods of `rate` Hz and at least
/// `min_duration` s, of a quintic from `from` to `to` (per joint `[q, qd, qdd]`) that stays
/// inside `lim`. Durations grow geometrically up to `max_duration`; when none fits, the one
/// with the smallest excess is returned (the caller's limit check then names the problem).
/// Returns the duration in samples.
pub fn transition(
    from: &[[f64; 3]],
    to: &[[f64; 3]],
    lim: &TransitionLimits,
    rate: f64,
    min_duration: f64,
    max_duration: f64,
) -> usize {
    let to_samples = |d: f64| ((d * rate).ceil() as usize).max(1);
    let mut best = (f64::INFINITY, to_samples(min_duration));
    let mut d = min_duration.max(1.0 / rate);
    while d <= max_duration * 1.0001 {
        let samples = to_samples(d);
        let e = excess(from, to, samples as f64 / rate, lim);
        if e <= 0.0 {
            return samples;
        }
        if e < best.0 {
            best = (e, samples);
        }
        d *= 1.15;
    }
    best.1
}
