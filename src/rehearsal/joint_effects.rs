//! What the joints of the true robot add to the torque: friction (viscous, asymmetric Coulomb,
//! Stribeck, position-dependent, drifting), torque ripple and cogging; the formulas are in
//! [`super::true_robot::FrictionSpec`] and [`super::TrueRobot`].

use super::true_robot::{harmonics_at, per_joint, Harmonic, TrueRobot};
use crate::error::Result;

/// The joint effects of a [`TrueRobot`], resolved for `n` joints.
#[derive(Clone, Debug, PartialEq)]
pub struct JointEffects {
    viscous: Vec<f64>,
    coulomb: Vec<f64>,
    coulomb_negative: Vec<f64>,
    stribeck: Vec<f64>,
    stribeck_velocity: Vec<f64>,
    position: Vec<Vec<Harmonic>>,
    drift: Vec<f64>,
    ripple: Vec<Vec<Harmonic>>,
    cogging: Vec<Vec<Harmonic>>,
}

impl JointEffects {
    /// The effects of `robot` for `n` joints (lengths checked).
    pub fn new(robot: &TrueRobot, n: usize) -> Result<JointEffects> {
        let f = &robot.friction;
        let coulomb = per_joint("friction.coulomb", &f.coulomb, n, 0.0)?;
        let lists = |h: &Option<Vec<Vec<Harmonic>>>| h.clone().unwrap_or_else(|| vec![vec![]; n]);
        Ok(JointEffects {
            viscous: per_joint("friction.viscous", &f.viscous, n, 0.0)?,
            coulomb_negative: match &f.coulomb_negative {
                None => coulomb.clone(),
                v => per_joint("friction.coulomb_negative", v, n, 0.0)?,
            },
            coulomb,
            stribeck: per_joint("friction.stribeck", &f.stribeck, n, 0.0)?,
            stribeck_velocity: per_joint(
                "friction.stribeck_velocity",
                &f.stribeck_velocity,
                n,
                1.0,
            )?,
            position: lists(&f.position),
            drift: per_joint("friction.drift", &f.drift, n, 0.0)?,
            ripple: lists(&robot.ripple),
            cogging: lists(&robot.cogging),
        })
    }

    /// Friction torque of joint `j` (N m) at position `q` (rad), speed `v` (rad/s), time `t`
    /// (s from the start); 0 at exactly zero speed.
    pub fn friction(&self, j: usize, q: f64, v: f64, t: f64) -> f64 {
        self.friction_moving(j, q, v, crate::parameters::sign0(v), t)
    }

    /// [`Self::friction`] moving in `direction` (the sign of `v`, or where `v` is zero the
    /// direction of motion around it, [`crate::simulation::directions_of_motion`]: 1, -1, or
    /// 0 at rest).
    pub fn friction_moving(&self, j: usize, q: f64, v: f64, direction: f64, t: f64) -> f64 {
        if direction == 0.0 {
            return 0.0;
        }
        let level = if direction > 0.0 {
            self.coulomb[j]
        } else {
            self.coulomb_negative[j]
        } + harmonics_at(&self.position[j], q);
        let stribeck = if self.stribeck[j] == 0.0 {
            0.0
        } else {
            self.stribeck[j] * (-(v / self.stribeck_velocity[j]).powi(2)).exp()
        };
        (1.0 + self.drift[j] * t) * (self.viscous[j] * v + direction.signum() * (level + stribeck))
    }

    /// The torque applied to joint `j` at position `q` when its motor is commanded `u` (N m):
    /// `u (1 + ripple(q)) + cogging(q)`.
    pub fn applied(&self, j: usize, q: f64, u: f64) -> f64 {
        u * (1.0 + harmonics_at(&self.ripple[j], q)) + harmonics_at(&self.cogging[j], q)
    }

    /// The command `u` that applies `torque` to joint `j` at `q` (inverse of [`Self::applied`]).
    pub fn command_for(&self, j: usize, q: f64, torque: f64) -> f64 {
        (torque - harmonics_at(&self.cogging[j], q)) / (1.0 + harmonics_at(&self.ripple[j], q))
    }
}
