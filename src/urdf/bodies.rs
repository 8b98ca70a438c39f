//! The moving bodies: a depth-first walk from the root that starts a body at every moving
//! joint (numbered in pre-order, so every subtree is a contiguous range) and merges the links
//! behind rigid (fixed or locked) joints into the body they hang from.

use nalgebra::Vector3;

use super::convert::{joint_kind, link_inertia};
use super::graph::Graph;
use super::reader::Builder;
use super::roles::Role;
use crate::error::{Error, Result};
use crate::model::{joint_pose, Body, Frame};
use crate::spatial::{Inertia, Se3};

/// The bodies in pre-order, the URDF joint of each, and the inertia fixed to the base.
pub(super) struct Bodies {
    pub(super) bodies: Vec<Body>,
    pub(super) body_joint: Vec<usize>,
    pub(super) base_inertia: Inertia,
    /// Every link's frame: the body it moves with and its pose there.
    pub(super) frames: Vec<Frame>,
}

/// A link to visit.
struct Visit {
    link: usize,
    /// The body the link's parent belongs to.
    body: Option<usize>,
    /// Pose of the link frame (or, for a new body, of its joint frame at zero) in that body's
    /// frame.
    pose: Se3,
    /// The moving joint that starts a new body at this link, with its coupling
    /// `(joint, multiplier, offset)`.
    joint: Option<(usize, f64, f64)>,
}

impl Builder<'_> {
    /// Walks the tree; fails on links the walk cannot reach (a cycle).
    pub(super) fn bodies(&self, graph: &Graph<'_>, roles: &[Role]) -> Result<Bodies> {
        let robot = self.robot;
        let mut bodies: Vec<Body> = Vec::new();
        let mut body_joint: Vec<usize> = Vec::new();
        let mut base_inertia = Inertia::zeros();
        let mut visited = vec![false; robot.links.len()];
        let mut frames = Vec::with_capacity(robot.links.len());
        let mut stack = vec![Visit {
            link: graph.root,
            body: None,
            pose: Se3::identity(),
            joint: None,
        }];
        while let Some(v) = stack.pop() {
            visited[v.link] = true;
            let (body, pose) = match v.joint {
                Some((j, multiplier, offset)) => {
                    let joint = &robot.joints[j];
                    let axis = Vector3::from(joint.axis.xyz.0);
                    bodies.push(Body {
                        joint: joint.name.clone(),
                        link: joint.child.link.clone(),
                        parent: v.body,
                        subtree_end: 0,
                        placement: v.pose,
                        kind: joint_kind(&joint.joint_type),
                        axis: axis / axis.norm(),
                        inertia: Inertia::zeros(),
                        dof: usize::MAX,
                        multiplier,
                        offset,
                        origin_inertia: Default::default(),
                        split_inertia: Default::default(),
                        pose_terms: Default::default(),
                        turned: None,
                    });
                    body_joint.push(j);
                    (Some(bodies.len() - 1), Se3::identity())
                }
                None => (v.body, v.pose),
            };
            frames.push(Frame {
                link: robot.links[v.link].name.clone(),
                body,
                pose,
            });
            let inertia = pose.act_inertia(&link_inertia(&robot.links[v.link]));
            match body {
                Some(b) => bodies[b].inertia = bodies[b].inertia.add(&inertia),
                None => base_inertia = base_inertia.add(&inertia),
            }
            // Reverse push so that children are visited in document order.
            for &j in graph.children[v.link].iter().rev() {
                let joint = &robot.joints[j];
                let child = graph.link_index[joint.child.link.as_str()];
                let placement =
                    pose.compose(&Se3::from_xyz_rpy(joint.origin.xyz.0, joint.origin.rpy.0));
                stack.push(match roles[j] {
                    Role::Rigid { position } => {
                        let pose = if joint.joint_type == urdf_rs::JointType::Fixed {
                            placement
                        } else {
                            let axis = Vector3::from(joint.axis.xyz.0);
                            joint_pose(
                                joint_kind(&joint.joint_type),
                                &placement,
                                &(axis / axis.norm()),
                                position,
                            )
                        };
                        Visit {
                            link: child,
                            body,
                            pose,
                            joint: None,
                        }
                    }
                    Role::Moving {
                        multiplier, offset, ..
                    } => Visit {
                        link: child,
                        body,
                        pose: placement,
                        joint: Some((j, multiplier, offset)),
                    },
                });
            }
        }
        let unreached: Vec<String> = (0..robot.links.len())
            .filter(|&l| !visited[l])
            .map(|l| robot.links[l].name.clone())
            .collect();
        if !unreached.is_empty() {
            return Err(Error::Cycle {
                source_name: self.source.to_string(),
                links: unreached,
            });
        }
        Ok(Bodies {
            bodies,
            body_joint,
            base_inertia,
            frames,
        })
    }
}
