//! How the true robot follows a reference: exactly (the joints are where the reference says,
//! in encoder coordinates), or closed loop under a PD controller with computed-torque
//! feed-forward, the true plant integrated by fixed-step Runge-Kutta (see
//! [`super::true_robot::Controller`]).

use super::joint_effects::JointEffects;
use super::true_robot::Controller;
use crate::algorithms::forward_dynamics::forward_dynamics;
use crate::algorithms::parallel;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;
use crate::trajectory::Samples;

/// The true motion on the reference's grid (row-major, `n` per sample): what the encoders
/// read (rad, before quantisation: true position plus offset), the speeds (rad/s) and the
/// torque command the robot logs (N m).
pub struct Motion {
    pub encoder: Vec<f64>,
    pub qd: Vec<f64>,
    pub command: Vec<f64>,
}

/// Exact tracking: the encoders read the reference, so the true joints are at `q_ref -
/// offset`; the command is the one that applies the torque the true robot needs there. With
/// `successive`, the samples follow each other in time and the friction acts in each joint's
/// direction of motion ([`crate::simulation::directions_of_motion`]: a joint touching zero
/// speed at one sample keeps its friction there); otherwise each sample stands alone (zero
/// friction at exactly zero speed).
pub fn follow_exactly(
    robot: &Model,
    effects: &JointEffects,
    gravity: Gravity,
    reference: &Samples,
    offsets: &[f64],
    successive: bool,
) -> Result<Motion> {
    let n = robot.nv;
    let k = reference.len();
    let mut q = reference.q.clone();
    for i in 0..k {
        for j in 0..n {
            q[i * n + j] -= offsets[j];
        }
    }
    let states = States::new(n, &q, Some(&reference.qd), Some(&reference.qdd))?;
    let mut rigid = vec![0.0; k * n];
    let mut ws = parallel::Workspace::new(robot);
    parallel::rnea(robot, &mut ws, &states, gravity, &mut rigid)?;
    let mut command = rigid;
    let directions = successive.then(|| crate::simulation::directions_of_motion(&reference.qd, n));
    for i in 0..k {
        for j in 0..n {
            let (x, v) = (q[i * n + j], reference.qd[i * n + j]);
            let direction = match &directions {
                Some(d) => d[i * n + j],
                None => crate::parameters::sign0(v),
            };
            let t = reference.t[i] - reference.t[0];
            let need = command[i * n + j] + effects.friction_moving(j, x, v, direction, t);
            command[i * n + j] = effects.command_for(j, x, need);
        }
    }
    Ok(Motion {
        encoder: reference.q.clone(),
        qd: reference.qd.clone(),
        command,
    })
}

/// Closed-loop tracking of `reference` by the true robot `robot` under `controller`, the
/// feed-forward computed on `nominal`; starts at the reference's first state (in true
/// coordinates); a command beyond the controller's `effort` is clipped to it, applied and
/// logged so. Checks for Ctrl-C every 1000 samples.
///
/// Errors: a controller with the wrong number of gains; a state that leaves the finite range
/// (an unstable controller), naming the time.
pub fn follow_closed_loop(
    nominal: &Model,
    robot: &Model,
    effects: &JointEffects,
    gravity: Gravity,
    controller: &Controller,
    reference: &Samples,
    offsets: &[f64],
) -> Result<Motion> {
    let n = robot.nv;
    let k = reference.len();
    for (what, g) in [
        ("controller.kp", &controller.kp),
        ("controller.kd", &controller.kd),
    ] {
        crate::model::check_finite_vector(what, g, n)?;
    }
    if let Some(effort) = &controller.effort {
        crate::model::check_finite_vector("controller.effort", effort, n)?;
    }
    let feedforward = if controller.feedforward {
        let states = States::new(n, &reference.q, Some(&reference.qd), Some(&reference.qdd))?;
        let mut ff = vec![0.0; k * n];
        let mut ws = parallel::Workspace::new(nominal);
        parallel::rnea(nominal, &mut ws, &states, gravity, &mut ff)?;
        ff
    } else {
        vec![0.0; k * n]
    };
    let mut data = Data::new(robot);
    let t0 = reference.t[0];
    // qdd of the true robot at (q, qd) under command u at time t
    let mut accel = |q: &[f64], qd: &[f64], u: &[f64], t: f64, out: &mut [f64]| -> Result<()> {
        let applied: Vec<f64> = (0..n)
            .map(|j| effects.applied(j, q[j], u[j]) - effects.friction(j, q[j], qd[j], t - t0))
            .collect();
        forward_dynamics(robot, &mut data, q, qd, &applied, gravity)?;
        out.copy_from_slice(data.qdd.as_slice());
        Ok(())
    };
    let mut q: Vec<f64> = (0..n).map(|j| reference.q[j] - offsets[j]).collect();
    let mut qd: Vec<f64> = reference.qd[..n].to_vec();
    let mut out = Motion {
        encoder: Vec::with_capacity(k * n),
        qd: Vec::with_capacity(k * n),
        command: Vec::with_capacity(k * n),
    };
    let mut u = vec![0.0; n];
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut qs, mut vs) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..k {
        if i % 1000 == 0 {
            crate::interrupt::check("closed-loop simulation")?;
        }
        if q.iter().chain(&qd).any(|x| !x.is_finite() || x.abs() > 1e6) {
            return Err(Error::numerical(
                "closed-loop simulation",
                format!(
                    "the tracked robot diverges at t = {:.4} s: the controller is unstable at this sample rate and these gains (lower kp/kd or raise substeps)",
                    reference.t[i]
                ),
            ));
        }
        for j in 0..n {
            let r = i * n + j;
            let encoder = q[j] + offsets[j];
            u[j] = feedforward[r]
                + controller.kp[j] * (reference.q[r] - encoder)
                + controller.kd[j] * (reference.qd[r] - qd[j]);
            if let Some(effort) = &controller.effort {
                u[j] = u[j].clamp(-effort[j], effort[j]);
            }
        }
        out.encoder.extend((0..n).map(|j| q[j] + offsets[j]));
        out.qd.extend_from_slice(&qd);
        out.command.extend_from_slice(&u);
        if i + 1 == k {
            break;
        }
        let h = (reference.t[i + 1] - reference.t[i]) / controller.substeps as f64;
        for s in 0..controller.substeps {
            let t = reference.t[i] + s as f64 * h;
            accel(&q, &qd, &u, t, &mut k1)?;
            for j in 0..n {
                qs[j] = q[j] + 0.5 * h * qd[j];
                vs[j] = qd[j] + 0.5 * h * k1[j];
            }
            accel(&qs, &vs, &u, t + 0.5 * h, &mut k2)?;
            let v2 = vs.clone();
            for j in 0..n {
                qs[j] = q[j] + 0.5 * h * v2[j];
                vs[j] = qd[j] + 0.5 * h * k2[j];
            }
            accel(&qs, &vs, &u, t + 0.5 * h, &mut k3)?;
            let v3 = vs.clone();
            for j in 0..n {
                qs[j] = q[j] + h * v3[j];
                vs[j] = qd[j] + h * k3[j];
            }
            accel(&qs, &vs, &u, t + h, &mut k4)?;
            let v4 = vs.clone();
            for j in 0..n {
                q[j] += h / 6.0 * (qd[j] + 2.0 * v2[j] + 2.0 * v3[j] + v4[j]);
                qd[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
        }
    }
    Ok(out)
}
