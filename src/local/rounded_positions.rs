//! Positions logged in coarse encoder counts (docs/method.md, section 4).
//!
//! A crossing's q, qd and qdd come from a quadratic fitted to the positions in its window. When
//! the positions are whole counts of `s` rad and the encoder has no noise beyond its rounding,
//! the rounding error is a function of the motion: a joint that moves a few counts in a window
//! reads a staircase, and the least-squares quadratic through it errs in curvature by several
//! times the standard error its scatter gives. On the A465 at Table 2 with 4,096 counts a
//! revolution the measured D perturbations erred by 0.55 rad/s^2 RMS where the scatter said 0.08,
//! and D* by up to 11 of its standard errors.
//!
//! So where a recording's positions lie on a grid ([`position_steps`]) and every reading of a
//! window is within half a step of some quadratic (rounding without noise), the crossing's
//! values are read by [`band_state`] instead: each of q, qd, qdd ranges over an interval among
//! those quadratics ([`crate::band_fit`]), the value is its midpoint and its standard error the
//! half-width / sqrt(3) (an error uniform over the interval). A window where no quadratic stays
//! within half a step (noise beyond the rounding, which then dithers it) keeps the least-squares
//! values. The regressions then count these errors of their regressors
//! ([`super::errors_in_variables`]).

use super::plan::Experiment;
use crate::band_fit::coefficient_ranges;
use crate::error::{Error, Result};

pub use crate::logs::position_rounding::position_steps;

/// A crossing's state of one joint read from positions rounded to steps of `step` (rad):
/// `values` (q in rad, qd in rad/s, qdd in rad/s^2 at `tc`) the midpoints of their ranges over
/// the quadratics within `step / 2` of every reading, `stderr` their half-widths / sqrt(3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandState {
    pub values: [f64; 3],
    pub stderr: [f64; 3],
}

/// Reads one joint's state at `tc` (s) from its positions `q` (rad) at the times `t` (s) of a
/// window of half-width `half` (s) about `tc`, rounded to whole steps of `step` (rad): see
/// the module documentation. None when no quadratic passes within half a step of every
/// reading (noise beyond the rounding), fewer than three distinct times are given, or the
/// inputs are not finite and positive where they must be.
pub fn band_state(t: &[f64], q: &[f64], tc: f64, half: f64, step: f64) -> Option<BandState> {
    if !(half > 0.0 && half.is_finite() && step > 0.0 && step.is_finite()) || q.is_empty() {
        return None;
    }
    // in steps about the middle reading, and in half-widths about the crossing: both of order 1
    let origin = q[q.len() / 2];
    let u: Vec<f64> = t.iter().map(|&x| (x - tc) / half).collect();
    let y: Vec<f64> = q.iter().map(|&x| (x - origin) / step).collect();
    let r = coefficient_ranges(&u, &y, 0.5, 2)?;
    let mid = |d: usize| 0.5 * (r[d][0] + r[d][1]);
    let width = |d: usize| 0.5 * (r[d][1] - r[d][0]) / 3f64.sqrt();
    let scale = [step, step / half, 2.0 * step / (half * half)];
    let values = [
        origin + scale[0] * mid(0),
        scale[1] * mid(1),
        scale[2] * mid(2),
    ];
    let stderr = [
        scale[0] * width(0),
        scale[1] * width(1),
        scale[2] * width(2),
    ];
    (values.iter().chain(&stderr).all(|v| v.is_finite())).then_some(BandState { values, stderr })
}

/// The error for an experiment (`shape`: its K crossings x N joints) whose measured
/// perturbations of `variable` (0 = q, 1 = qd, 2 = qdd) are all zero for `joint` (its column
/// `column`), whose positions were read by the band of encoder steps of `step` rad: the encoder
/// resolves none of them. `reference`: measured from the reference posture rather than the
/// operating point.
pub fn unresolved(
    experiment: &str,
    shape: (usize, usize),
    column: &str,
    joint: &str,
    step: f64,
    variable: usize,
    reference: bool,
) -> Error {
    let what = ["position", "velocity", "acceleration"][variable.min(2)];
    let base = if reference {
        "the reference posture"
    } else {
        "the operating point"
    };
    Error::RankDeficient {
        context: format!("experiment '{experiment}'"),
        rows: shape.0,
        cols: shape.1,
        rank: shape.1.saturating_sub(1),
        missing: format!(
            "{column} (the column is all zeros: the encoder of joint '{joint}', in steps of {step:.2e} rad, reads the same {what} at every crossing and at {base}, resolving none of the perturbations; perturb more, widen the crossing window or log the positions more finely)"
        ),
    }
}

/// The plural name and unit of a perturbed variable (0 = q, 1 = qd, 2 = qdd) in warnings.
fn variable_name(variable: usize) -> (&'static str, &'static str) {
    match variable {
        0 => ("positions", "rad"),
        1 => ("velocities", "rad/s"),
        _ => ("accelerations", "rad/s^2"),
    }
}

/// A measured perturbation is called coarse when the median standard error of its crossings
/// exceeds this fraction of its RMS over them ([`resolution_warning`]).
pub const COARSE_FRACTION: f64 = 0.1;

/// How well one joint's perturbations were resolved in an experiment whose positions were read
/// by the band ([`band_state`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Resolution {
    pub joint: String,
    /// The encoder step (rad).
    pub step: f64,
    /// The median standard error of the perturbed variable at the crossings (rad, rad/s or
    /// rad/s^2).
    pub stderr: f64,
    /// The RMS of the measured perturbations over the crossings (same units).
    pub perturbation: f64,
}

impl Resolution {
    /// The joint's resolution in `experiment`: `stderr` the standard errors of its perturbed
    /// variable at the crossings, `perturbations` the measured perturbations; None when no
    /// crossing has a finite standard error.
    pub fn of(joint: &str, step: f64, stderr: &[f64], perturbations: &[f64]) -> Option<Self> {
        let mut se: Vec<f64> = stderr.iter().copied().filter(|v| v.is_finite()).collect();
        if se.is_empty() || perturbations.is_empty() {
            return None;
        }
        se.sort_by(f64::total_cmp);
        let median = 0.5 * (se[(se.len() - 1) / 2] + se[se.len() / 2]);
        let rms =
            (perturbations.iter().map(|v| v * v).sum::<f64>() / perturbations.len() as f64).sqrt();
        Some(Self {
            joint: joint.to_string(),
            step,
            stderr: median,
            perturbation: rms,
        })
    }

    /// Whether the perturbations are uncertain by more than [`COARSE_FRACTION`] of their size.
    pub fn coarse(&self) -> bool {
        self.stderr > COARSE_FRACTION * self.perturbation
    }
}

/// The warning for an experiment perturbing `variable` (0 = q, 1 = qd, 2 = qdd) whose coarse
/// encoders leave some joints' measured perturbations uncertain by more than
/// [`COARSE_FRACTION`] of their size (the [`Resolution::coarse`] ones of `joints`); None when
/// none is.
pub fn resolution_warning(
    experiment: &str,
    variable: usize,
    joints: &[Resolution],
) -> Option<String> {
    let (what, unit) = variable_name(variable);
    let coarse: Vec<String> = joints
        .iter()
        .filter(|r| r.coarse())
        .map(|r| {
            format!(
                "'{}' (steps of {:.2e} rad: {what} known to {:.2e} {unit} at the crossings, perturbed by {:.2e} {unit} RMS)",
                r.joint, r.step, r.stderr, r.perturbation
            )
        })
        .collect();
    (!coarse.is_empty()).then(|| {
        format!(
            "experiment '{experiment}': the encoders of joint(s) {} leave the measured perturbations uncertain by more than a tenth of their size: the standard errors count it, but the estimate loses precision; perturb more, widen the crossing window (a window of half-width h resolves an acceleration to about a step / h^2), or log the positions more finely",
            coarse.join(", ")
        )
    })
}

/// The most readings of one window [`planned_resolution`] rounds and reads: a longer window
/// (up to 60 s at up to 10 MHz) is read at every few samples, which can only widen its ranges.
pub const MAX_PLANNED_READINGS: usize = 10_001;

/// How finely encoders of steps `steps` (rad, or m for a prismatic joint; one per joint, 0 for
/// unknown) will resolve `experiment`'s perturbations if the robot follows it exactly: each
/// crossing's planned positions over its window, sampled at `rate` (Hz), rounded to the steps
/// and read by [`band_state`] as the identification will read them. One entry per joint with a
/// step; empty for the nominal experiment. A crossing whose band is not read (none is: the
/// planned quadratic is in it, unless the simplex method exceeds its steps) is left out. Stops
/// on Ctrl-C (`Error::Interrupted`) between crossings.
pub fn planned_resolution(
    experiment: &Experiment,
    joint_names: &[String],
    steps: &[f64],
    rate: f64,
) -> Result<Vec<Resolution>> {
    let Some(var) = experiment.kind.perturbed() else {
        return Ok(vec![]);
    };
    let half = experiment.window;
    let each_side = (half * rate).round().max(1.0) as usize;
    let stride = (2 * each_side + 1).div_ceil(MAX_PLANNED_READINGS).max(1);
    let offsets: Vec<f64> = (0..=2 * each_side)
        .step_by(stride)
        .map(|i| (i as f64 - each_side as f64) / rate)
        .collect();
    let traj = &experiment.trajectory;
    let mut out = vec![];
    for j in 0..steps.len().min(joint_names.len()) {
        let step = steps[j];
        if !(step > 0.0 && step.is_finite()) {
            continue;
        }
        let mut stderr = Vec::with_capacity(experiment.crossings.len());
        for c in &experiment.crossings {
            crate::interrupt::check("planning")?;
            let t: Vec<f64> = offsets.iter().map(|d| c.time + d).collect();
            let q: Vec<f64> = t
                .iter()
                .map(|&x| (traj.segment_at(x).eval(j, x).0 / step).round() * step)
                .collect();
            stderr.push(
                band_state(&t, &q, c.time, half, step).map_or(f64::INFINITY, |b| b.stderr[var]),
            );
        }
        let perturbations: Vec<f64> = experiment.deltas.column(j).iter().copied().collect();
        out.extend(Resolution::of(
            &joint_names[j],
            step,
            &stderr,
            &perturbations,
        ));
    }
    Ok(out)
}

/// The planner's warning for an experiment perturbing `variable` (0 = q, 1 = qd, 2 = qdd) with
/// crossing windows of half-width `window` (s) whose encoders would resolve some joints'
/// perturbations to worse than [`COARSE_FRACTION`] of their size (the [`Resolution::coarse`]
/// ones of `joints`, from [`planned_resolution`]), with the window or the perturbation size
/// that would resolve them (an acceleration's resolution improves about as the window squared,
/// a velocity's as the window, a position's not at all); None when none would.
pub fn planned_resolution_warning(
    experiment: &str,
    variable: usize,
    joints: &[Resolution],
    window: f64,
) -> Option<String> {
    let (what, unit) = variable_name(variable);
    let coarse: Vec<&Resolution> = joints.iter().filter(|r| r.coarse()).collect();
    if coarse.is_empty() {
        return None;
    }
    let factor = coarse
        .iter()
        .map(|r| r.stderr / (COARSE_FRACTION * r.perturbation))
        .fold(1.0f64, f64::max);
    let list: Vec<String> = coarse
        .iter()
        .map(|r| {
            format!(
                "'{}' (steps of {:.2e}: {what} resolved to {:.2e} {unit} at the crossings, perturbed by {:.2e} {unit} RMS)",
                r.joint, r.step, r.stderr, r.perturbation
            )
        })
        .collect();
    let remedy = match variable {
        0 => format!("perturbations about {factor:.1} times larger (dq)"),
        1 => format!(
            "a crossing window of about {:.2} s (window, --window; now {window} s) or perturbations about {factor:.1} times larger (dqd)",
            window * factor
        ),
        _ => format!(
            "a crossing window of about {:.2} s (window, --window; now {window} s) or perturbations about {factor:.1} times larger (dqdd)",
            window * factor.sqrt()
        ),
    };
    Some(format!(
        "experiment '{experiment}': its encoders would measure the perturbations of joint(s) {} to worse than a tenth of their size, even on a robot that follows the plan exactly, and the estimate would lose precision; {remedy} would resolve them",
        list.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logs::recording::Recording;

    #[test]
    fn a_rounded_quadratic_is_inside_its_ranges() {
        // 4,096 counts a revolution, 1 kHz, +-0.05 s: a joint crossing a few counts
        let step = 2.0 * std::f64::consts::PI / 4096.0;
        let tc = 3.0;
        let t: Vec<f64> = (0..101).map(|i| tc - 0.05 + i as f64 * 1e-3).collect();
        for (q0, qd, qdd) in [(0.7, 0.089, -0.155), (1.1, 0.011, 0.4), (0.0, -0.2, 1.2)] {
            let q: Vec<f64> = t
                .iter()
                .map(|&x| {
                    let s = x - tc;
                    ((q0 + qd * s + 0.5 * qdd * s * s) / step).round() * step
                })
                .collect();
            let b = band_state(&t, &q, tc, 0.05, step).expect("exact rounding is in the band");
            for (d, truth) in [q0, qd, qdd].into_iter().enumerate() {
                let bound = 3f64.sqrt() * b.stderr[d];
                assert!(
                    (b.values[d] - truth).abs() <= bound * (1.0 + 1e-9) + 1e-12,
                    "{d}: {} vs {truth} (bound {bound})",
                    b.values[d]
                );
            }
        }
        // noise of a step on one reading: no quadratic stays within half a step
        let mut q: Vec<f64> = t.iter().map(|_| 10.0 * step).collect();
        q[50] += 2.0 * step;
        assert_eq!(band_state(&t, &q, tc, 0.05, step), None);
    }

    #[test]
    fn steps_come_from_the_whole_recording() {
        let step = 0.01;
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.01).collect();
        // joint 1 on a grid of 0.01 (offset by 0.003), joint 2 continuous, joint 3 constant
        let q: Vec<f64> = t
            .iter()
            .flat_map(|&x| {
                [
                    0.003 + (x * x * 3.0 / step).round() * step,
                    (7.0 * x).sin(),
                    0.2,
                ]
            })
            .collect();
        let rec = Recording::new("r", 3, t.clone(), q, vec![0.0; 150], None, None).unwrap();
        let steps = position_steps(&rec);
        assert!((steps[0].unwrap() - step).abs() < 1e-9, "{steps:?}");
        assert_eq!(steps[1..], [None, None]);
    }
}
