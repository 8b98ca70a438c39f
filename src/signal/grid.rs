//! The grid a signal's readings lie on: an encoder's counts, an ADC's steps, a field logged
//! with few digits. Readings on a grid coarser than their noise carry the rounding as an
//! error of their own (docs/method.md, sections 4 and 8).

/// The fewest distinct values a window's samples must take for their spacing to say anything
/// about a grid beyond "two levels" (two levels are a grid of their difference).
pub const MIN_LEVELS: usize = 2;

/// Tolerance of "a whole multiple of the step", in steps: a value logged with a few
/// significant digits is still on its grid, and a continuous signal's differences (whose
/// ratios to the smallest are anything) pass it at a few of its many gaps, never at all.
pub const ON_GRID: f64 = 0.01;

/// The most steps of a grid the smallest difference between the values read may span: a
/// torque held within each window reads few of its grid's levels, e.g. 0.1 and 0.15 N m apart
/// on a grid of 0.05.
pub const MAX_STEPS_IN_GAP: usize = 10;

/// The smallest grid step [`grid_step`] reports, relative to the largest magnitude of the
/// values: every f64 in `[0.5, 1)` is a whole multiple of 2^-53, so a signal that is
/// continuous but for a few values one rounding error apart would otherwise be "on a grid" of
/// that rounding error. Encoders of 2^24 counts a revolution (3.7e-7 rad) and torques logged in
/// 1e-4 N m steps about 100 N m (1e-6) stay far above it.
pub const MIN_RELATIVE_STEP: f64 = 1e-9;

/// The step of the uniform grid the finite `values` lie on: the largest `d / m` (`d` the
/// smallest difference between two distinct values, `m` up to [`MAX_STEPS_IN_GAP`]) of which
/// every difference between neighbouring distinct values is a whole multiple (to [`ON_GRID`]
/// of a step), and at least [`MIN_RELATIVE_STEP`] of the largest magnitude. None for fewer than
/// two distinct values, or values off any such grid (a continuous signal: its neighbours'
/// differences are no multiples of a common step above its rounding errors).
///
/// ```
/// use perturbid_rs::signal::grid_step;
/// // torques logged in steps of 0.05 N m
/// let step = grid_step(&[0.1, 0.15, 0.3, -0.05]).unwrap();
/// assert!((step - 0.05).abs() < 1e-12);
/// assert_eq!(grid_step(&[0.1, 0.1234567, 0.31415]), None); // a continuous signal
/// ```
pub fn grid_step(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| a == b); // -0 and 0 are one level
    if v.len() < MIN_LEVELS {
        return None;
    }
    let gaps: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let smallest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
    let largest = v[0].abs().max(v[v.len() - 1].abs());
    if !(smallest > 0.0 && smallest.is_finite()) {
        return None;
    }
    let floor = MIN_RELATIVE_STEP * largest;
    (1..=MAX_STEPS_IN_GAP)
        .map(|m| smallest / m as f64)
        .take_while(|&step| step >= floor)
        .find(|&step| {
            gaps.iter().all(|&g| {
                let m = g / step;
                (m - m.round()).abs() <= ON_GRID
            })
        })
}
