//! The local model identified with the recordings' torque delay estimated first, from the
//! robot's rigid-body model ([`crate::direct::torque_delay`]), and read past.

use super::identify::IdentifyOptions;
use super::identify_local::identify_local;
use super::model::LocalModel;
use super::plan::Plan;
use super::pooled_rounds::identify_local_rounds;
use crate::direct::torque_delay::{estimate_torque_delay, DelayOptions};
use crate::error::{Error, Result};
use crate::logs::recording::Recording;
use crate::model::Model;

/// [`identify_local`] with `options.fit.torque_delay` replaced by the delay
/// [`estimate_torque_delay`] finds in `recordings` with `robot` (the plan's robot: its joints,
/// in the plan's order). The estimate is kept in the model's
/// [`Diagnostics::torque_delay`](super::Diagnostics::torque_delay) and printed by its summary.
///
/// Errors: a robot with other joints than the plan's, and those of the two steps.
pub fn identify_local_with_delay(
    robot: &Model,
    plan: &Plan,
    recordings: &[Recording],
    options: &IdentifyOptions,
    delay_options: &DelayOptions,
) -> Result<LocalModel> {
    identify_local_rounds_with_delay(robot, &[(plan, recordings)], options, delay_options)
}

/// [`identify_local_rounds`] with the torque delay found as [`identify_local_with_delay`]
/// finds it, over the recordings of every round at once (one robot, one logging chain).
///
/// Errors: a robot with other joints than the plans', and those of the two steps.
pub fn identify_local_rounds_with_delay(
    robot: &Model,
    rounds: &[(&Plan, &[Recording])],
    options: &IdentifyOptions,
    delay_options: &DelayOptions,
) -> Result<LocalModel> {
    let names = &robot.joint_names;
    if let Some((plan, _)) = rounds.iter().find(|(p, _)| p.joint_names != *names) {
        return Err(Error::invalid(
            "robot",
            format!(
                "joints [{}]; the plan is for [{}]",
                names.join(", "),
                plan.joint_names.join(", ")
            ),
        ));
    }
    let refs: Vec<&Recording> = rounds.iter().flat_map(|(_, r)| r.iter()).collect();
    let delay = estimate_torque_delay(robot, &refs, delay_options)?;
    let mut options = *options;
    options.fit.torque_delay = delay.delay;
    let mut model = match rounds {
        [(plan, recordings)] => identify_local(plan, recordings, &options)?,
        _ => identify_local_rounds(rounds, &options)?,
    };
    model.diagnostics.torque_delay = Some(delay);
    Ok(model)
}
