//! The local model identified with the recordings' torque delay estimated first, from the
//! robot's rigid-body model ([`crate::direct::torque_delay`]), and read past.

use super::identify::IdentifyOptions;
use super::identify_local::identify_local;
use super::model::LocalModel;
use super::plan::Plan;
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
    let names = &robot.joint_names;
    if *names != plan.joint_names {
        return Err(Error::invalid(
            "robot",
            format!(
                "joints [{}]; the plan is for [{}]",
                names.join(", "),
                plan.joint_names.join(", ")
            ),
        ));
    }
    let refs: Vec<&Recording> = recordings.iter().collect();
    let delay = estimate_torque_delay(robot, &refs, delay_options)?;
    let mut options = *options;
    options.fit.torque_delay = delay.delay;
    let mut model = identify_local(plan, recordings, &options)?;
    model.diagnostics.torque_delay = Some(delay);
    Ok(model)
}
