//! How each URDF joint enters the model once `<mimic>` couplings and locks are resolved.

use std::collections::HashMap;

use super::reader::Builder;
use crate::error::{Error, Result};

/// How a URDF joint enters the model once mimic couplings and locks are resolved.
#[derive(Clone, Copy, Debug)]
pub(super) enum Role {
    /// Rigid: the child link is merged into the parent body, posed at this coordinate.
    Rigid { position: f64 },
    /// Moves; its coordinate is `multiplier * q(leader) + offset`, leader a URDF joint index.
    Moving {
        leader: usize,
        multiplier: f64,
        offset: f64,
    },
}

impl Builder<'_> {
    /// Resolves mimic chains and locks into a role per URDF joint.
    pub(super) fn resolve_roles(&self, joint_index: &HashMap<&str, usize>) -> Result<Vec<Role>> {
        let joints = &self.robot.joints;
        for (name, value) in &self.options.lock {
            let context = format!("lock '{name}'");
            let Some(&j) = joint_index.get(name.as_str()) else {
                return Err(Error::JointReference {
                    context,
                    message: format!("{}: no joint of that name", self.source),
                });
            };
            if joints[j].joint_type == urdf_rs::JointType::Fixed {
                return Err(Error::JointReference {
                    context,
                    message: format!("{}: the joint is fixed already", self.joint_location(name)),
                });
            }
            if let Some(m) = &joints[j].mimic {
                return Err(Error::JointReference {
                    context,
                    message: format!(
                        "{}: the joint mimics '{}'; lock that joint instead",
                        self.joint_location(name),
                        m.joint
                    ),
                });
            }
            if !value.is_finite() {
                return Err(Error::NonFiniteInput {
                    argument: context,
                    index: 0,
                    value: *value,
                });
            }
        }
        let mut roles = Vec::with_capacity(joints.len());
        for (j, joint) in joints.iter().enumerate() {
            if joint.joint_type == urdf_rs::JointType::Fixed {
                roles.push(Role::Rigid { position: 0.0 });
                continue;
            }
            // Follow the mimic chain to an independent joint.
            let (mut leader, mut multiplier, mut offset) = (j, 1.0, 0.0);
            let mut steps = 0;
            while let Some(m) = &joints[leader].mimic {
                let context = format!(
                    "{}: joint '{}' <mimic>",
                    self.joint_location(&joints[leader].name),
                    joints[leader].name
                );
                let Some(&next) = joint_index.get(m.joint.as_str()) else {
                    return Err(Error::JointReference {
                        context,
                        message: format!("no joint named '{}'", m.joint),
                    });
                };
                if joints[next].joint_type == urdf_rs::JointType::Fixed {
                    return Err(Error::JointReference {
                        context,
                        message: format!("joint '{}' is fixed and cannot be mimicked", m.joint),
                    });
                }
                steps += 1;
                if steps > joints.len() {
                    return Err(Error::JointReference {
                        context,
                        message: "the mimic tags form a cycle".to_string(),
                    });
                }
                // q_leader = mult * q_next + off  =>  q_j = multiplier * (mult * q_next + off) + offset
                let mult = m.multiplier.unwrap_or(1.0);
                let off = m.offset.unwrap_or(0.0);
                offset += multiplier * off;
                multiplier *= mult;
                leader = next;
            }
            roles.push(match self.options.lock.get(&joints[leader].name) {
                Some(value) => Role::Rigid {
                    position: multiplier * value + offset,
                },
                None => Role::Moving {
                    leader,
                    multiplier,
                    offset,
                },
            });
        }
        Ok(roles)
    }
}
