//! One experiment's recording made ready for its crossing windows: steps of whole turns taken
//! out of its positions ([`crate::logs::position_wraps`]), columns held at a lower rate read again
//! at their values' arrivals ([`crate::logs::held_columns`]), stamps that jitter over a regular
//! clock found ([`crate::logs::stamp_jitter`]), its logged velocities and
//! accelerations checked against the derivatives where they are to be used
//! ([`crate::logs::derivative_columns::check_logged_derivatives`]), one joint's held readings
//! (a lost message logged as its last value or zeros) replaced, rows of zeros and frozen
//! readings while the robot moves removed ([`crate::logs::log_dropouts`]), clipped torques found in
//! the recording as logged, and each told of in warnings that name the experiment. The samples
//! the diagnostics name are counted in the recording as logged.

use super::identify::{experiment_values, ExperimentValues, IdentifyOptions};
use super::plan::Experiment;
use crate::error::Result;
use crate::logs::log_dropouts::LogDropout;
use crate::logs::log_screening::LogGlitch;
use crate::logs::recording::Recording;

/// An experiment's recording read: its values, what was repaired or removed (each naming the
/// experiment), and the warnings that tell of it.
pub(super) struct ReadExperiment {
    pub values: ExperimentValues,
    pub dropouts: Vec<LogDropout>,
    pub held: Vec<LogGlitch>,
    pub warnings: Vec<String>,
}

/// The values of experiment `e` from its recording `r` (joints named `joint_names`), read as
/// [`experiment_values`] reads them after the repairs of the module documentation. Errors:
/// those of the screening and of [`experiment_values`] (where rows were removed, the error
/// says which: a window may be short of samples for the removal).
pub(super) fn read_experiment(
    e: &Experiment,
    r: &Recording,
    joint_names: &[String],
    options: &IdentifyOptions,
) -> Result<ReadExperiment> {
    let name = e.kind.name();
    // what each step found, in words: each becomes a warning naming the experiment
    let mut said: Vec<Option<String>> = vec![];
    let (unwrapped, wraps) = crate::logs::position_wraps::unwrap_positions(r);
    said.push(crate::logs::position_wraps::warning(
        &wraps,
        &r.name,
        joint_names,
        "before the crossing windows were read",
    ));
    let (reread, held_columns) = crate::logs::held_columns::find_held_columns(&unwrapped)?;
    said.push(crate::logs::held_columns::warning(
        &held_columns,
        &r.name,
        joint_names,
    ));
    // the unwrapped copy let go as soon as the reread one holds it (a long log's copies are
    // what the reading holds most of)
    drop(unwrapped);
    let r = &reread;
    // the stamps against the positions: the windows' fits read the stamps as the samples' times
    said.push(crate::logs::stamp_jitter::warning(
        &crate::logs::stamp_jitter::find_stamp_jitter(r),
        &r.name,
        joint_names,
    ));
    if options.fit.recorded_derivatives {
        crate::logs::derivative_columns::check_logged_derivatives(r)?;
    }
    let clipped = crate::logs::torque_saturation::find_torque_saturation(r);
    let (repaired, held) = crate::logs::log_screening::screen_held_readings(r)?;
    said.push(crate::logs::log_screening::warning(
        &held,
        &r.name,
        joint_names,
        "before the crossing windows were read",
    ));
    let found = crate::logs::log_dropouts::find_removed_rows(r, &repaired)?;
    let values = if found.is_empty() {
        experiment_values(e, &repaired, joint_names, options)?
    } else {
        let kept = crate::logs::log_dropouts::without_dropouts(&repaired, &found)?;
        let mut v = experiment_values(e, &kept, joint_names, options)
            .map_err(|error| crate::logs::log_dropouts::after_removing(error, &found))?;
        let rows = crate::logs::log_dropouts::kept_rows(repaired.len(), &found);
        for c in v.crossings.iter_mut().chain(v.reference.iter_mut()) {
            for g in &mut c.glitches {
                g.sample = rows[g.sample];
            }
        }
        v
    };
    let times: Vec<f64> = values.crossings.iter().map(|c| c.time).collect();
    said.push(crate::logs::torque_saturation::crossing_warning(
        &clipped,
        &times,
        e.window,
        joint_names,
    ));
    said.push(crate::logs::log_dropouts::dropout_warning(
        &found,
        &r.name,
        joint_names,
        "before the crossing windows were read (their fits use the samples left)",
    ));
    let of_experiment = Some(name.to_string());
    Ok(ReadExperiment {
        values,
        dropouts: found
            .into_iter()
            .map(|d| LogDropout {
                experiment: of_experiment.clone(),
                ..d
            })
            .collect(),
        held: held
            .into_iter()
            .map(|g| LogGlitch {
                experiment: of_experiment.clone(),
                ..g
            })
            .collect(),
        warnings: said
            .into_iter()
            .flatten()
            .map(|w| format!("experiment '{name}': {w}"))
            .collect(),
    })
}
