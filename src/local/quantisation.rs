//! Torques logged at a coarse resolution (docs/method.md, section 4).
//!
//! A torque channel rounded to whole steps `q` (an ADC, a fixed-point field, a motor current
//! logged in counts) errs by up to `q / 2` in each sample. Where the samples' noise is at
//! least about half a step, the rounding is dithered: it acts as more white noise
//! (`q^2 / 12` a sample), averages out in each window's fit and shows in the samples' scatter
//! like any noise. Where the noise is smaller, the rounding is a function of the torque: a
//! window that stays within one step reads one level whatever the perturbation did, and the
//! errors, though up to `q / 2` at every crossing, can agree between passes so well that the
//! regression's residuals do not show them. On the A465 at Table 2 with 0.05 N m steps and
//! 0.002 N m of noise, D* entries erred by up to 700 of their standard errors.
//!
//! So a torque whose samples lie on a grid coarser than their noise (`s^2 < q^2 / 3`, with
//! `s` the samples' scatter about their fits: noise plus dithered rounding of `q^2 / 12`) gets
//! standard errors of at least those of an independent rounding error of `q / sqrt(12)` at
//! every crossing, and a warning.

use super::diagnostics::TorqueNoise;
use crate::regression::LeastSquares;

pub use crate::signal::grid::{
    grid_step, MAX_STEPS_IN_GAP, MIN_LEVELS, MIN_RELATIVE_STEP, ON_GRID,
};

/// Per joint, the grid step (N m) of the torque samples an experiment read in its windows
/// (`columns`, [`super::identify::window_torques`]), see [`grid_step`]; None where they lie on
/// no grid or take fewer than two values (a flat channel: [`super::identify::flat_torques`]).
pub fn torque_steps(columns: &[Vec<f64>]) -> Vec<Option<f64>> {
    columns.iter().map(|c| grid_step(c)).collect()
}

/// Whether a torque logged in steps of `step` (N m) is rounded without dithering: its samples'
/// scatter about their fits (`variance`, N^2 m^2: noise plus the rounding's `step^2 / 12` when
/// dithered) is below `step^2 / 3`, the scatter of noise of half a step.
pub fn undithered(step: f64, variance: f64) -> bool {
    variance < step * step / 3.0
}

/// The standard deviation (N m) of the rounding error of one reading of a torque logged in
/// steps of `step` without dithering, taken as independent from crossing to crossing:
/// `step / sqrt(12)`, a uniform error over one step.
pub fn rounding_stderr(step: f64) -> f64 {
    step / 12f64.sqrt()
}

/// `step` when a torque logged in steps of `step` (N m, see [`torque_steps`]) is rounded
/// without dithering by its samples' scatter `variance` (N^2 m^2, see [`undithered`]); None
/// otherwise.
pub fn undithered_step(step: Option<f64>, variance: f64) -> Option<f64> {
    step.filter(|&q| undithered(q, variance))
}

/// Raises the standard errors of output `c` of `fit` to at least those an independent error
/// of `sigma` (N m) in every row of its regression gives, `sigma sqrt(cov_diag)`. Standard
/// errors that are NaN (no residual degree of freedom) stay NaN.
pub fn floor_stderr(fit: &mut LeastSquares, c: usize, sigma: f64) {
    for (p, &v) in fit.cov_diag.iter().enumerate() {
        let se = &mut fit.stderr[(c, p)];
        if se.is_finite() {
            *se = se.max(sigma * v.sqrt());
        }
    }
}

/// One warning per experiment whose torques were rounded without dithering (the entries of
/// `noise` with a `step`), naming the joints, their steps and their samples' scatter.
pub fn warnings(noise: &[TorqueNoise]) -> Vec<String> {
    let mut experiments: Vec<&str> = noise
        .iter()
        .filter(|e| e.step.is_some())
        .map(|e| e.experiment.as_str())
        .collect();
    experiments.dedup();
    experiments
        .into_iter()
        .map(|x| {
            let joints: Vec<String> = noise
                .iter()
                .filter(|e| e.experiment == x)
                .filter_map(|e| {
                    e.step.map(|q| {
                        format!(
                            "'{}' (steps of {} N m, scatter {:.2e} N m)",
                            e.joint,
                            // four significant digits: the step is a difference of readings
                            crate::error::shown(format!("{q:.3e}").parse().unwrap_or(q)),
                            e.samples
                        )
                    })
                })
                .collect();
            format!(
                "experiment '{x}': the torque of joint(s) {} is logged in steps coarser than its noise (below half a step), so the rounding does not average out and can agree between passes: the standard errors of its rows include a rounding error of a step / sqrt(12) at every crossing, and torque changes smaller than a step are lost; log the torque at a finer resolution or perturb more",
                joints.join(", ")
            )
        })
        .collect()
}

/// The warning for the torques of `joints` that read exactly 0 in every sample of
/// `experiment` at rest while the experiment's other torques are rounded without dithering,
/// the finest to steps of `step` (N m): their standard errors include that rounding.
pub fn flat_zero_warning(experiment: &str, joints: &[&str], step: f64) -> String {
    let list: Vec<String> = joints.iter().map(|j| format!("'{j}'")).collect();
    format!(
        "experiment '{experiment}': the torque of joint(s) {} read exactly 0 in every sample at rest, and the other torques are logged in steps coarser than their noise (the finest {} N m), so this 0 is likely a level of such a grid and hides anything below half a step: the standard errors of its rows include a rounding error of {} N m / sqrt(12) at every crossing (conservative if its channel is finer)",
        list.join(", "),
        crate::error::shown(format!("{step:.3e}").parse().unwrap_or(step)),
        crate::error::shown(format!("{step:.3e}").parse().unwrap_or(step)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_are_found_and_continuous_values_are_not() {
        // 0.05 N m steps about an offset, printed with six significant digits
        let on: Vec<f64> = [3, 7, 8, 12, 20, 21, 5]
            .iter()
            .map(|&k| format!("{:.6}", 1.234 + 0.05 * k as f64).parse().unwrap())
            .collect();
        let step = grid_step(&on).unwrap();
        assert!((step - 0.05).abs() < 1e-9, "{step}");
        // levels 0.1 and 0.15 apart are on a grid of 0.05 (a torque held within each window
        // reads one level there); -0 and 0 are one level
        let few = [0.35, -0.25, -0.0, 0.1, -0.4, 0.5, 0.0];
        assert!((grid_step(&few).unwrap() - 0.05).abs() < 1e-12);
        // two levels are a grid of their difference; one is none
        assert_eq!(grid_step(&[1.0, 1.5, 1.0]), Some(0.5));
        assert_eq!(grid_step(&[2.0, 2.0]), None);
        assert_eq!(grid_step(&[0.0, -0.0]), None);
        // a continuous signal: neighbours' differences are no multiples of the smallest
        let continuous: Vec<f64> = (0..200).map(|i| (i as f64 * 0.37).sin()).collect();
        assert_eq!(grid_step(&continuous), None);
        // non-finite values are left out
        assert_eq!(grid_step(&[0.0, f64::NAN, 0.25, 1.0]), Some(0.25));
        // a continuous signal whose values at rest differ by a rounding error: every f64 in
        // [0.5, 1) is a multiple of 2^-53, which is no grid
        let mut rest: Vec<f64> = continuous.iter().map(|v| 0.75 + 0.2 * v).collect();
        rest.extend([0.78, 0.78 + f64::EPSILON / 2.0, 0.78 + f64::EPSILON]);
        assert_eq!(grid_step(&rest), None);
    }

    #[test]
    fn dithering_is_noise_of_half_a_step() {
        let q: f64 = 0.05;
        // rounding alone (scatter q^2 / 12) is not dithered; noise of q / 2 (with the
        // rounding: q^2 / 4 + q^2 / 12 = q^2 / 3) is
        assert!(undithered(q, q * q / 12.0));
        assert!(!undithered(q, q * q / 3.0));
        assert!((rounding_stderr(q) - q / 12f64.sqrt()).abs() < 1e-15);
    }
}
