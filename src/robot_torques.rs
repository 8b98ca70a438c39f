//! A robot model's own torques as a [`TorqueModel`]: what its URDF says the joints need, to
//! be validated against a log like any identified model (the vendor's URDF, or one written
//! by [`crate::urdf::write_urdf`] from an identification).
//!
//! `tau = rnea(q, qd, qdd) + damping * qd + friction * c`: the links' inertial parameters and
//! each joint's armature through the recursive Newton-Euler algorithm, and each joint's
//! `<dynamics>` friction, viscous (`damping`) and Coulomb (`friction`, with `c = sign(qd)`, 0
//! at rest, or the Coulomb column a filtered log brings: [`States::with_coulomb`]).

use nalgebra::{DMatrix, DVector};

use crate::algorithms::parallel::{self, Workspace};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::states::States;
use crate::torque_model::{Expansion, TorqueModel};

/// Said of a robot whose file gives no friction when it is validated against a log.
pub const NO_FRICTION: &str = "the robot's file gives its joints no friction (<dynamics damping friction>): the log's friction is in the residuals";

/// `robot`'s own torques, with gravity as `gravity` says (see [this module](self)).
#[derive(Clone, Copy, Debug)]
pub struct RobotTorques<'a> {
    pub robot: &'a Model,
    pub gravity: Gravity,
}

impl<'a> RobotTorques<'a> {
    /// The torques of `robot` with gravity included, as its joints feel them.
    pub fn new(robot: &'a Model) -> Self {
        Self {
            robot,
            gravity: Gravity::Included,
        }
    }

    /// [`TorqueModel::predict`] into `tau` (row-major `k x nv`, checked by the batch engine)
    /// with the engine's workspace `ws` (of this robot), for callers that hold one.
    pub fn predict_into(
        &self,
        ws: &mut Workspace,
        states: &States<'_>,
        tau: &mut [f64],
    ) -> Result<()> {
        let (robot, n) = (self.robot, self.robot.nv);
        parallel::rnea(robot, ws, states, self.gravity, tau)?;
        if let Some(qd) = states.qd() {
            for s in 0..states.len() {
                for (j, l) in robot.limits.iter().enumerate() {
                    let i = s * n + j;
                    tau[i] += l.damping * qd[i] + l.friction * states.coulomb_at(s, j);
                }
            }
        }
        Ok(())
    }

    /// Whether the robot's file gives any friction (some joint's `damping` or `friction`
    /// above 0): without it, a log's friction shows in the residuals.
    pub fn has_friction(&self) -> bool {
        (self.robot.limits.iter()).any(|l| l.damping > 0.0 || l.friction > 0.0)
    }
}

impl TorqueModel for RobotTorques<'_> {
    fn joint_names(&self) -> &[String] {
        &self.robot.joint_names
    }

    /// Row-major `k x nv` torques (N m, or N for a prismatic joint) at the samples of
    /// `states` (rad, rad/s, rad/s^2; missing velocities or accelerations are zeros).
    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        crate::torque_model::check_joints(states, self.robot.nv)?;
        let mut tau = vec![0.0; states.len() * self.robot.nv];
        self.predict_into(&mut Workspace::new(self.robot), states, &mut tau)?;
        Ok(tau)
    }

    /// The exact first-order expansion at `op`: `D = M(q)` (with the armature), `H = d rnea /
    /// d qd + diag(damping)`, `G = d rnea / d q`, and `G_static = d g / d q` at rest at `op`'s
    /// positions. The Coulomb term's derivative is 0 away from `qd = 0`, where it steps.
    fn linearize(&self, op: &OperatingPoint) -> Result<Expansion> {
        let robot = self.robot;
        let n = robot.nv;
        let mut data = Data::new(robot);
        crate::algorithms::derivatives::rnea_derivatives(
            robot,
            &mut data,
            &op.q,
            &op.qd,
            &op.qdd,
            self.gravity,
        )?;
        let torque = DVector::from_fn(n, |j, _| {
            let l = &robot.limits[j];
            data.tau[j] + l.damping * op.qd[j] + l.friction * crate::parameters::sign0(op.qd[j])
        });
        let (d, g) = (data.m.clone(), data.dtau_dq.clone());
        let h = &data.dtau_dv
            + DMatrix::from_diagonal(&DVector::from_fn(n, |j, _| robot.limits[j].damping));
        let zeros = vec![0.0; n];
        crate::algorithms::derivatives::rnea_derivatives(
            robot,
            &mut data,
            &op.q,
            &zeros,
            &zeros,
            self.gravity,
        )?;
        Ok(Expansion {
            torque,
            d,
            h,
            g,
            g_static: Some(data.dtau_dq.clone()),
        })
    }
}
