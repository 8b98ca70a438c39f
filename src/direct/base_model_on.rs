//! A base-parameter model on the robot whose regressor it needs: what answers
//! [`TorqueModel`] for a [`BaseModel`].

use super::base_model::BaseModel;
use crate::error::Result;
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::states::States;
use crate::torque_model::{Expansion, TorqueModel};

impl BaseModel {
    /// The model bound to the robot it was identified for, as a [`crate::TorqueModel`]; fails when
    /// `robot` has other joints.
    pub fn on<'a>(&'a self, robot: &'a Model) -> Result<BaseModelOn<'a>> {
        self.check(robot)?;
        Ok(BaseModelOn { fit: self, robot })
    }
}

/// A base-parameter model together with the robot whose regressor it needs
/// ([`BaseModel::on`]).
#[derive(Clone, Copy, Debug)]
pub struct BaseModelOn<'a> {
    pub fit: &'a BaseModel,
    pub robot: &'a Model,
}

impl TorqueModel for BaseModelOn<'_> {
    fn joint_names(&self) -> &[String] {
        &self.fit.joint_names
    }

    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        self.fit.predict(self.robot, states)
    }

    fn linearize(&self, op: &OperatingPoint) -> Result<Expansion> {
        let l = self.fit.linearize(self.robot, &op.q, &op.qd, &op.qdd)?;
        Ok(Expansion {
            torque: l.torque,
            d: l.d,
            h: l.h,
            g: l.g,
            g_static: Some(l.g_static),
        })
    }
}
