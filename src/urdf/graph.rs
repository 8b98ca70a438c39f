//! The kinematic graph: names indexed, every joint's parent and child link found, one root,
//! no link the child of two joints, only joint types the library models.

use std::collections::HashMap;

use super::convert::kind_name;
use super::reader::Builder;
use crate::error::{Error, Result};

/// The URDF's links and joints as a tree (indices into `robot.links` and `robot.joints`).
pub(super) struct Graph<'a> {
    pub(super) link_index: HashMap<&'a str, usize>,
    pub(super) joint_index: HashMap<&'a str, usize>,
    /// The joints leaving each link, in document order.
    pub(super) children: Vec<Vec<usize>>,
    pub(super) root: usize,
}

impl<'a> Builder<'a> {
    /// Indexes the names and links the joints; checks each joint's numbers on the way.
    pub(super) fn graph(&self) -> Result<Graph<'a>> {
        let robot = self.robot;
        let mut link_index: HashMap<&str, usize> = HashMap::with_capacity(robot.links.len());
        for (i, link) in robot.links.iter().enumerate() {
            if link_index.insert(link.name.as_str(), i).is_some() {
                return Err(Error::DuplicateName {
                    location: self.link_location(&link.name),
                    element: "link",
                    name: link.name.clone(),
                });
            }
        }
        let mut joint_index: HashMap<&str, usize> = HashMap::with_capacity(robot.joints.len());
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
        for (j, joint) in robot.joints.iter().enumerate() {
            if joint_index.insert(joint.name.as_str(), j).is_some() {
                return Err(Error::DuplicateName {
                    location: self.joint_location(&joint.name),
                    element: "joint",
                    name: joint.name.clone(),
                });
            }
            use urdf_rs::JointType::*;
            if matches!(joint.joint_type, Floating | Planar | Spherical) {
                return Err(Error::UnsupportedJoint {
                    location: self.joint_location(&joint.name),
                    joint: joint.name.clone(),
                    kind: kind_name(&joint.joint_type).to_string(),
                });
            }
            let lookup = |role: &'static str, link: &str| {
                link_index
                    .get(link)
                    .copied()
                    .ok_or_else(|| Error::UnknownLink {
                        location: self.joint_location(&joint.name),
                        joint: joint.name.clone(),
                        role,
                        link: link.to_string(),
                    })
            };
            let p = lookup("parent", &joint.parent.link)?;
            let c = lookup("child", &joint.child.link)?;
            if let Some(first) = parent_joint[c] {
                return Err(Error::DuplicateChild {
                    location: self.joint_location(&joint.name),
                    link: joint.child.link.clone(),
                    first: robot.joints[first].name.clone(),
                    second: joint.name.clone(),
                });
            }
            parent_joint[c] = Some(j);
            children[p].push(j);
            self.check_joint_numbers(joint)?;
        }
        let roots: Vec<usize> = (0..robot.links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let &[root] = roots.as_slice() else {
            if roots.is_empty() && !robot.links.is_empty() {
                return Err(Error::Cycle {
                    source_name: self.source.to_string(),
                    links: robot.links.iter().map(|l| l.name.clone()).collect(),
                });
            }
            return Err(Error::RootCount {
                source_name: self.source.to_string(),
                roots: roots.iter().map(|&l| robot.links[l].name.clone()).collect(),
            });
        };
        Ok(Graph {
            link_index,
            joint_index,
            children,
            root,
        })
    }
}
