//! A realistic true robot for a model, in the ranges industrial and collaborative arms have
//! (docs/rehearsal.md, "A realistic robot"): a payload the URDF lacks, link parameter errors,
//! asymmetric Coulomb friction with a Stribeck hump and viscous friction, torque ripple,
//! encoder counts, torque noise, a torque delay, and a PD controller whose bandwidth is set
//! from each joint's inertia. What a method must survive before it is called done.

use super::true_robot::{Controller, Harmonic, TrueRobot};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::payload::Payload;
use crate::model::Model;

/// The knobs of [`realistic_robot`]; the defaults sit mid-range.
#[derive(Clone, Debug, PartialEq)]
pub struct Realism {
    /// Seed of the random parameter errors and noise.
    pub seed: u64,
    /// Closed-loop bandwidth of every joint (Hz); `None`: the joints follow the reference
    /// exactly (open loop).
    pub bandwidth: Option<f64>,
    /// Torque delay behind the positions (s).
    pub delay: f64,
    /// Payload on the last link (kg), its centre of mass 5 cm off the flange axis.
    pub payload: f64,
    /// Relative standard deviation of the links' masses, centres of mass and inertias.
    pub parameter_error: f64,
    /// Coulomb level as a fraction of each joint's effort limit (100 N m where the URDF has
    /// none); the negative side 10 % higher, a Stribeck hump 40 % above it at 0.05 rad/s.
    pub coulomb: f64,
    /// Torque noise as a fraction of the effort limit, within 0.02-0.5 N m.
    pub noise: f64,
    /// Encoder counts per revolution.
    pub counts: f64,
    /// Relative torque ripple, 12 cycles per radian of joint travel.
    pub ripple: f64,
}

impl Default for Realism {
    fn default() -> Self {
        Self {
            seed: 0,
            bandwidth: Some(25.0),
            delay: 1.5e-3,
            payload: 1.5,
            parameter_error: 0.05,
            coulomb: 0.02,
            noise: 1e-3,
            counts: 262_144.0,
            ripple: 0.01,
        }
    }
}

/// A true robot built on `model` as [`Realism`] says, its controller tuned at posture `q`.
///
/// Errors: a posture of another length or where the mass matrix is singular.
pub fn realistic_robot(model: &Model, q: &[f64], realism: &Realism) -> Result<TrueRobot> {
    let n = model.nv;
    let effort: Vec<f64> = (model.effort_limit().iter())
        .map(|&e| if e.is_finite() && e > 0.0 { e } else { 100.0 })
        .collect();
    let per = |f: &dyn Fn(f64) -> f64| -> Option<Vec<f64>> {
        Some(effort.iter().map(|&e| f(e)).collect())
    };
    let mut robot = TrueRobot {
        seed: realism.seed,
        parameter_error: realism.parameter_error,
        ..TrueRobot::default()
    };
    let last = model
        .bodies
        .last()
        .ok_or_else(|| Error::invalid("model", "no moving link"))?;
    if realism.payload > 0.0 {
        let m = realism.payload;
        robot.payload = Some(Payload {
            link: last.link.clone(),
            mass: m,
            com: [0.05, 0.0, 0.08],
            inertia: [2e-3 * m, 0.0, 0.0, 2e-3 * m, 0.0, 1e-3 * m],
        });
    }
    let c = realism.coulomb;
    let f = &mut robot.friction;
    f.coulomb = per(&|e| c * e);
    f.coulomb_negative = per(&|e| 1.1 * c * e);
    f.stribeck = per(&|e| 0.4 * c * e);
    f.stribeck_velocity = Some(vec![0.05; n]);
    f.viscous = per(&|e| (0.01 * e).clamp(0.1, 5.0));
    if realism.ripple > 0.0 {
        let h = Harmonic {
            order: 12.0,
            amplitude: realism.ripple,
            phase: 0.0,
        };
        robot.ripple = Some(vec![vec![h]; n]);
    }
    let s = &mut robot.sensors;
    s.encoder_counts = (realism.counts > 0.0).then(|| vec![realism.counts; n]);
    s.torque_noise = per(&|e| (realism.noise * e).clamp(0.02, 0.5));
    s.delay = realism.delay;
    if let Some(hz) = realism.bandwidth {
        robot.controller = Some(tracking_controller(model, q, hz)?);
    }
    Ok(robot)
}

/// A PD controller of bandwidth `hz` on every joint, damping ratio 0.8, tuned at posture `q`
/// with each joint's effective inertia `1 / (M^-1)_jj` (what the joint feels with the others
/// free: tuning on the diagonal of M instead drives light wrists unstable through the coupling).
pub fn tracking_controller(model: &Model, q: &[f64], hz: f64) -> Result<Controller> {
    let n = model.nv;
    if !(hz.is_finite() && hz > 0.0) {
        return Err(Error::invalid(
            "bandwidth",
            format!("{hz} Hz; expected a positive bandwidth"),
        ));
    }
    let mut data = Data::new(model);
    crate::algorithms::crba::mass_matrix(model, &mut data, q)?;
    let inverse = data.m.clone().try_inverse().ok_or_else(|| {
        Error::numerical(
            "tracking controller",
            "the mass matrix is singular at this posture",
        )
    })?;
    let w = 2.0 * std::f64::consts::PI * hz;
    let inertia: Vec<f64> = (0..n).map(|j| 1.0 / inverse[(j, j)]).collect();
    Ok(Controller {
        kp: inertia.iter().map(|m| m * w * w).collect(),
        kd: inertia.iter().map(|m| 2.0 * 0.8 * m * w).collect(),
        substeps: 4,
        feedforward: true,
        effort: None,
    })
}
