//! Torque channels that do not change where an experiment reads them (a dead or saturated
//! channel, or a resolution coarser than the perturbations' effect; docs/method.md, section 4),
//! and the torque samples of the crossing windows they are told by.

use super::plan::ExperimentKind;
use crate::logs::recording::Recording;

/// Per joint, the torque samples (N m) of `rec` in the windows `[tc - half, tc + half]`, one
/// per centre `tc` (the recording's clock), window after window.
pub fn window_torques(rec: &Recording, centres: &[f64], half: f64) -> Vec<Vec<f64>> {
    let n = rec.n;
    let mut columns: Vec<Vec<f64>> = vec![vec![]; n];
    for &tc in centres {
        let lo = rec.t.partition_point(|&t| t < tc - half);
        let hi = rec.t.partition_point(|&t| t <= tc + half);
        for i in lo..hi {
            for (j, column) in columns.iter_mut().enumerate() {
                column.push(rec.tau[i * n + j]);
            }
        }
    }
    columns
}

/// Per joint, `Some(value)` when every torque sample of `rec` in the windows `[tc - half, tc +
/// half]` (one per centre `tc`) has the same value (0 and -0 are one): a torque signal that did not
/// change where the experiment was read (a dead or saturated channel, or a resolution coarser
/// than the perturbations' effect). `None` where any sample differs or no window holds a
/// sample.
pub fn flat_torques(rec: &Recording, centres: &[f64], half: f64) -> Vec<Option<f64>> {
    flat(&window_torques(rec, centres, half))
}

/// [`flat_torques`] of the window samples `columns` ([`window_torques`]).
pub(super) fn flat(columns: &[Vec<f64>]) -> Vec<Option<f64>> {
    columns
        .iter()
        .map(|c| {
            let first = *c.first()?;
            c.iter().all(|&v| v == first).then_some(first) // -0 reads as 0
        })
        .collect()
}

/// The warning for the joints whose torque read one value (N m) in every sample of an
/// experiment that perturbs the robot: `(joint, value)` each.
pub(super) fn flat_torque_warning(kind: ExperimentKind, joints: &[(&str, f64)]) -> String {
    let matrix = kind.estimate_name();
    // 6 significant digits, and no -0
    let value = |v: f64| {
        let v: f64 = format!("{v:.5e}").parse().unwrap_or(v);
        crate::error::shown(if v == 0.0 { 0.0 } else { v })
    };
    let list = joints
        .iter()
        .map(|(j, v)| format!("'{j}' ({} N m)", value(*v)))
        .collect::<Vec<_>>()
        .join(", ");
    let (whose, rows) = if joints.len() == 1 {
        ("torque of joint", "reads the same value in every sample around the crossings, though the experiment perturbs the robot: a torque signal that does not change (a dead or saturated channel, or a resolution coarser than the perturbations' effect); its row of {} is")
    } else {
        ("torques of joints", "read the same value in every sample around the crossings, though the experiment perturbs the robot: torque signals that do not change (dead or saturated channels, or a resolution coarser than the perturbations' effect); their rows of {} are")
    };
    let rows = rows.replace("{}", matrix);
    format!(
        "experiment '{}': the {whose} {list} {rows} not measured (standard errors set to NaN)",
        kind.name()
    )
}
