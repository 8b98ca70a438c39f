//! Rehearsing a reference on a true robot: what it logs ([`rehearse`], [`rehearse_plan`]) and
//! the torques it needs without noise ([`true_torques`]).

use super::joint_effects::JointEffects;
use super::true_robot::{self, TrueRobot};
use super::{sensors, tracking};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::{shown, Error, Result};
use crate::local::Plan;
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::trajectory::Samples;

/// What `robot` (the true robot built on `nominal`) logs while it follows `reference` (states
/// in the nominal model's joint coordinates, rad, rad/s, rad/s^2; `t` in s): positions as its
/// encoders read them and the torques it commands, through its sensors. `stream` separates the
/// random streams of several recordings made with one seed; `name` names the recording.
///
/// Errors: a reference for another number of joints, a true-robot document that does not fit
/// `nominal` (naming the field), an unstable controller (naming the time).
pub fn rehearse(
    nominal: &Model,
    robot: &TrueRobot,
    reference: &Samples,
    stream: u64,
    name: &str,
) -> Result<Recording> {
    let n = nominal.nv;
    if reference.n != n {
        return Err(Error::shape(
            "reference",
            format!("{n} joints"),
            format!("{} joints", reference.n),
        ));
    }
    if reference.len() < 2 {
        return Err(Error::invalid(
            "reference",
            format!("{} samples; expected at least 2", reference.len()),
        ));
    }
    let true_model = robot.rigid_body_model(nominal)?;
    let effects = JointEffects::new(robot, n)?;
    let offsets = true_robot::per_joint("joint_offsets", &robot.joint_offsets, n, 0.0)?;
    let gravity = robot.gravity;
    let motion = match &robot.controller {
        None => {
            tracking::follow_exactly(&true_model, &effects, gravity, reference, &offsets, true)?
        }
        Some(c) => tracking::follow_closed_loop(
            nominal,
            &true_model,
            &effects,
            gravity,
            c,
            reference,
            &offsets,
        )?,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(robot.seed);
    rng.set_stream(stream);
    let signals = sensors::TrueSignals {
        n,
        t: &reference.t,
        q: &motion.encoder,
        qd: &motion.qd,
        tau: &motion.command,
    };
    let (q, tau) = sensors::measure(&robot.sensors, &signals, &mut rng)?;
    if let Some(i) = crate::finite::first_non_finite(&tau) {
        return Err(Error::numerical(
            format!("rehearsal '{name}'"),
            format!(
                "the torque of joint {} at t = {} s is {}: the true robot's numbers overflow",
                i % n + 1,
                shown(reference.t[i / n]),
                tau[i]
            ),
        ));
    }
    Recording::new(name, n, reference.t.clone(), q, tau, None, None)
}

/// One rehearsed recording per experiment of `plan` (in the plan's order, each marked with
/// its experiment), the plan's trajectories sampled at its rate and checked against the
/// nominal model's limits. Each experiment gets its own random stream of the robot's seed.
pub fn rehearse_plan(nominal: &Model, robot: &TrueRobot, plan: &Plan) -> Result<Vec<Recording>> {
    crate::simulation::check_plan_robot(nominal, plan)?;
    plan.experiments
        .iter()
        .enumerate()
        .map(|(i, e)| {
            crate::interrupt::check("rehearsal")?;
            rehearse(
                nominal,
                robot,
                &crate::simulation::experiment_samples(nominal, plan, e)?,
                i as u64,
                &format!("rehearsed experiment '{}'", e.kind.name()),
            )
            .map(|r| r.for_experiment(e.kind.name()))
        })
        .collect()
}

/// The torques (row-major `k x nv`, N m or N) the true robot `robot` commands to hold the
/// states `states` (the nominal model's joint coordinates as its encoders read them: rad,
/// rad/s, rad/s^2), at the start of its life (friction drift at t = 0), without sensor noise:
/// the plant a study measures every identified model against. Friction at exactly zero speed
/// is zero (see [`JointEffects::friction`]).
pub fn true_torques(
    nominal: &Model,
    robot: &TrueRobot,
    states: &crate::states::States<'_>,
) -> Result<Vec<f64>> {
    let n = nominal.nv;
    if states.nv() != n {
        return Err(Error::shape(
            "states",
            format!("{n} joints"),
            format!("{} joints", states.nv()),
        ));
    }
    robot.check(nominal)?;
    let true_model = robot.rigid_body_model(nominal)?;
    let effects = JointEffects::new(robot, n)?;
    let offsets = true_robot::per_joint("joint_offsets", &robot.joint_offsets, n, 0.0)?;
    let k = states.len();
    let reference = Samples {
        n,
        t: vec![0.0; k],
        q: states.q().to_vec(),
        qd: states.qd_or_zeros().to_vec(),
        qdd: states.qdd_or_zeros().to_vec(),
    };
    let motion = tracking::follow_exactly(
        &true_model,
        &effects,
        robot.gravity,
        &reference,
        &offsets,
        false,
    )?;
    Ok(motion.command)
}
