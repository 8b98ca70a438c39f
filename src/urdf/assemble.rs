//! The [`Model`] from the bodies: degrees of freedom numbered (the independent moving joints in
//! body order; mimic followers share their leader's), subtree ranges, caches, and the check
//! that every degree of freedom moves some mass.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::bodies::Bodies;
use super::convert::joint_limits;
use super::graph::Graph;
use super::reader::Builder;
use super::roles::Role;
use crate::error::{Error, Result};
use crate::model::{Model, STANDARD_GRAVITY};

impl Builder<'_> {
    pub(super) fn assemble(
        &self,
        graph: &Graph<'_>,
        roles: &[Role],
        walked: Bodies,
    ) -> Result<Model> {
        let robot = self.robot;
        let Bodies {
            mut bodies,
            body_joint,
            base_inertia,
            frames,
        } = walked;
        let mut dof_of_joint: HashMap<usize, usize> = HashMap::new();
        let mut joint_names = Vec::new();
        let mut joint_kinds = Vec::new();
        let mut limits = Vec::new();
        for (b, &j) in body_joint.iter().enumerate() {
            if let Role::Moving { leader, .. } = roles[j] {
                if leader == j {
                    dof_of_joint.insert(j, joint_names.len());
                    joint_names.push(robot.joints[j].name.clone());
                    joint_kinds.push(bodies[b].kind);
                    limits.push(joint_limits(&robot.joints[j]));
                }
            }
        }
        for (b, &j) in body_joint.iter().enumerate() {
            if let Role::Moving { leader, .. } = roles[j] {
                bodies[b].dof = dof_of_joint[&leader];
            }
        }
        let armature = self.armature_per_dof(roles, &dof_of_joint, joint_names.len())?;
        // Subtree ranges (children come after their parent in pre-order).
        let n = bodies.len();
        for (i, b) in bodies.iter_mut().enumerate() {
            b.subtree_end = i + 1;
        }
        for i in (0..n).rev() {
            if let Some(p) = bodies[i].parent {
                bodies[p].subtree_end = bodies[p].subtree_end.max(bodies[i].subtree_end);
            }
        }
        let coupled = bodies.len() != joint_names.len()
            || bodies
                .iter()
                .any(|b| b.multiplier != 1.0 || b.offset != 0.0);
        let joint_lines = bodies
            .iter()
            .map(|b| self.lines.joints.get(&b.joint).map(|j| j.0))
            .collect();
        if joint_names.is_empty() {
            return Err(Error::NoDegreeOfFreedom {
                source_name: self.source.to_string(),
                robot: robot.name.clone(),
            });
        }
        if bodies.len() > crate::limits::MAX_BODIES {
            return Err(Error::TooManyBodies {
                source_name: self.source.to_string(),
                robot: robot.name.clone(),
                bodies: bodies.len(),
                limit: crate::limits::MAX_BODIES,
            });
        }
        let mut model = Model {
            name: robot.name.clone(),
            source: self.source.to_string(),
            nv: joint_names.len(),
            bodies,
            joint_names,
            joint_kinds,
            limits,
            armature,
            frames,
            gravity: Vector3::new(0.0, 0.0, -STANDARD_GRAVITY),
            root_link: robot.links[graph.root].name.clone(),
            base_mass: base_inertia.mass,
            coupled,
            joint_lines,
            urdf: std::sync::Arc::new(super::UrdfSource {
                text: self.text.to_string(),
                options: self.options.clone(),
            }),
        };
        // (every body's own terms again, and those that depend on several bodies)
        model.refresh();
        model.check_every_dof_moves_mass()?;
        Ok(model)
    }
}

impl Builder<'_> {
    /// The armature of every degree of freedom (zero where none is given); fails on an
    /// armature for a joint that does not exist, is fixed in the URDF or follows another
    /// through `<mimic>`. A joint locked by the caller keeps its rotor still: its armature is
    /// dropped with the joint.
    fn armature_per_dof(
        &self,
        roles: &[Role],
        dof_of_joint: &HashMap<usize, usize>,
        nv: usize,
    ) -> Result<Vec<f64>> {
        let mut out = vec![0.0; nv];
        let mut given: Vec<_> = self.armature.iter().collect();
        given.sort_by_key(|(_, e)| e.line);
        for (name, entry) in given {
            let error = |message: String| Error::InvalidArmature {
                location: Box::new(crate::error::Location {
                    source: self.source.to_string(),
                    line: Some(entry.line),
                }),
                joint: name.clone(),
                message,
            };
            let Some(j) = self.robot.joints.iter().position(|x| &x.name == name) else {
                return Err(error("no joint of this name in the URDF".into()));
            };
            match roles[j] {
                Role::Moving { leader, .. } if leader == j => out[dof_of_joint[&j]] = entry.value,
                Role::Moving { leader, .. } => {
                    return Err(error(format!(
                        "the joint follows '{}' through <mimic>; give the armature of the driving joint",
                        self.robot.joints[leader].name
                    )))
                }
                Role::Rigid { .. } if self.robot.joints[j].joint_type != urdf_rs::JointType::Fixed => {}
                Role::Rigid { .. } => {
                    return Err(error("the joint is fixed: a rotor that never turns has no armature".into()))
                }
            }
        }
        Ok(out)
    }
}
