//! Building a [`Model`] from a URDF (parsed by urdf-rs).
//!
//! What is read: the kinematic tree (any tree, not only chains) of revolute, continuous,
//! prismatic and fixed joints; joint origins (xyz, rpy); axes (normalised); link inertials with
//! their origin and rpy (the inertia is rotated into the link frame); `<limit>` (URDF 1.2
//! `acceleration` included) and `<dynamics damping friction>`; `<mimic>` couplings. Links behind
//! fixed joints are merged into their parent body. Joints can be locked at a position when the
//! model is built, which turns them into fixed joints.
//!
//! What is checked, each failure naming the file, line and element: the URDF syntax; floating,
//! planar and spherical joints; the number of root links; cycles; links that are the child of
//! two joints; unknown links; invalid inertias (negative mass, not positive semi-definite,
//! principal moments breaking the triangle inequality); zero or non-finite axes; non-finite
//! numbers; revolute or prismatic joints without `<limit>`; moving joints that carry no mass.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use crate::error::{Error, Location, Result};
use crate::model::{joint_pose, Body, JointKind, JointLimits, Model};
use crate::spatial::{Inertia, Se3};

/// Options for building a model from a URDF.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Joints held at a fixed position (rad or m), by URDF joint name. A locked joint becomes a
    /// fixed joint (like Pinocchio's reduced model); mimic joints that follow it are locked too.
    pub lock: BTreeMap<String, f64>,
    /// Reject link inertias whose principal moments break the triangle inequality
    /// (`I1 + I2 >= I3`). On by default; turn it off for models that lump rotor inertia into a
    /// link about one axis only (the `kinsheel2010` A465 does).
    pub check_triangle_inequality: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            lock: BTreeMap::new(),
            check_triangle_inequality: true,
        }
    }
}

/// Reads and builds a model from a URDF file.
pub fn model_from_urdf_file(path: impl AsRef<Path>, options: &LoadOptions) -> Result<Model> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.display().to_string(),
        source,
    })?;
    model_from_urdf_str(&text, &path.display().to_string(), options)
}

/// Builds a model from URDF text. `source_name` names the text in error messages.
pub fn model_from_urdf_str(text: &str, source_name: &str, options: &LoadOptions) -> Result<Model> {
    let lines = LineIndex::new(text);
    let robot = urdf_rs::read_from_string(text).map_err(|e| Error::UrdfSyntax {
        source_name: source_name.to_string(),
        message: e.to_string(),
    })?;
    Builder {
        robot: &robot,
        source: source_name,
        lines: &lines,
        options,
    }
    .build()
}

/// Lines of the URDF's joints and links, and which joints have a `<limit>`, from a light XML
/// pass (urdf-rs keeps no positions).
struct LineIndex {
    joints: HashMap<String, (u32, bool)>,
    links: HashMap<String, u32>,
}

impl LineIndex {
    fn new(text: &str) -> Self {
        let mut joints = HashMap::new();
        let mut links = HashMap::new();
        if let Ok(doc) = roxmltree::Document::parse(text) {
            for node in doc.root_element().children().filter(|n| n.is_element()) {
                let Some(name) = node.attribute("name") else {
                    continue;
                };
                let line = doc.text_pos_at(node.range().start).row;
                match node.tag_name().name() {
                    "joint" => {
                        let has_limit = node.children().any(|c| c.has_tag_name("limit"));
                        joints.entry(name.to_string()).or_insert((line, has_limit));
                    }
                    "link" => {
                        links.entry(name.to_string()).or_insert(line);
                    }
                    _ => {}
                }
            }
        }
        Self { joints, links }
    }
}

/// How a URDF joint enters the model once mimic couplings and locks are resolved.
#[derive(Clone, Copy, Debug)]
enum Role {
    /// Rigid: the child link is merged into the parent body, posed at this coordinate.
    Rigid { position: f64 },
    /// Moves; its coordinate is `multiplier * q(leader) + offset`, leader a URDF joint index.
    Moving {
        leader: usize,
        multiplier: f64,
        offset: f64,
    },
}

struct Builder<'a> {
    robot: &'a urdf_rs::Robot,
    source: &'a str,
    lines: &'a LineIndex,
    options: &'a LoadOptions,
}

fn kind_name(t: &urdf_rs::JointType) -> &'static str {
    use urdf_rs::JointType::*;
    match t {
        Revolute => "revolute",
        Continuous => "continuous",
        Prismatic => "prismatic",
        Fixed => "fixed",
        Floating => "floating",
        Planar => "planar",
        Spherical => "spherical",
    }
}

impl<'a> Builder<'a> {
    fn joint_location(&self, name: &str) -> Location {
        Location {
            source: self.source.to_string(),
            line: self.lines.joints.get(name).map(|j| j.0),
        }
    }

    fn link_location(&self, name: &str) -> Location {
        Location {
            source: self.source.to_string(),
            line: self.lines.links.get(name).copied(),
        }
    }

    fn finite(
        &self,
        element: &'static str,
        name: &str,
        field: &'static str,
        values: &[f64],
    ) -> Result<()> {
        if let Some(&value) = values.iter().find(|v| !v.is_finite()) {
            let location = if element == "link" {
                self.link_location(name)
            } else {
                self.joint_location(name)
            };
            return Err(Error::NonFiniteUrdf {
                location,
                element,
                name: name.to_string(),
                field,
                value,
            });
        }
        Ok(())
    }

    fn build(&self) -> Result<Model> {
        let robot = self.robot;
        // Names and graph.
        let mut link_index: HashMap<&str, usize> = HashMap::new();
        for (i, link) in robot.links.iter().enumerate() {
            if link_index.insert(link.name.as_str(), i).is_some() {
                return Err(Error::DuplicateName {
                    location: self.link_location(&link.name),
                    element: "link",
                    name: link.name.clone(),
                });
            }
        }
        let mut joint_index: HashMap<&str, usize> = HashMap::new();
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
        if roots.len() != 1 {
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
        }
        let root = roots[0];
        for link in &robot.links {
            self.check_link_inertial(link)?;
        }

        let roles = self.resolve_roles(&joint_index)?;

        // Depth-first walk from the root: a body per moving joint (numbered in pre-order, so
        // every subtree is a contiguous range), links behind rigid joints merged into their body.
        struct Visit {
            link: usize,
            /// The body the link's parent belongs to.
            body: Option<usize>,
            /// Pose of the link frame (or, for a new body, of its joint frame at zero) in that
            /// body's frame.
            pose: Se3,
            /// The moving joint that starts a new body at this link.
            joint: Option<usize>,
        }
        let mut bodies: Vec<Body> = Vec::new();
        let mut body_joint: Vec<usize> = Vec::new();
        let mut base_inertia = Inertia::zeros();
        let mut visited = vec![false; robot.links.len()];
        let mut stack = vec![Visit {
            link: root,
            body: None,
            pose: Se3::identity(),
            joint: None,
        }];
        while let Some(v) = stack.pop() {
            visited[v.link] = true;
            let (body, pose) = match v.joint {
                Some(j) => {
                    let joint = &robot.joints[j];
                    let Role::Moving {
                        multiplier, offset, ..
                    } = roles[j]
                    else {
                        unreachable!("only moving joints start bodies")
                    };
                    let axis = Vector3::from(joint.axis.xyz.0);
                    let axis = axis / axis.norm();
                    bodies.push(Body {
                        joint: joint.name.clone(),
                        link: joint.child.link.clone(),
                        parent: v.body,
                        subtree_end: 0,
                        placement: v.pose,
                        kind: joint_kind(&joint.joint_type),
                        axis,
                        inertia: Inertia::zeros(),
                        dof: usize::MAX,
                        multiplier,
                        offset,
                        origin_inertia: Default::default(),
                        pose_terms: Default::default(),
                    });
                    body_joint.push(j);
                    (Some(bodies.len() - 1), Se3::identity())
                }
                None => (v.body, v.pose),
            };
            let inertia = pose.act_inertia(&link_inertia(&robot.links[v.link]));
            match body {
                Some(b) => bodies[b].inertia = bodies[b].inertia.add(&inertia),
                None => base_inertia = base_inertia.add(&inertia),
            }
            // Reverse push so that children are visited in document order.
            for &j in children[v.link].iter().rev() {
                let joint = &robot.joints[j];
                let child = link_index[joint.child.link.as_str()];
                let placement =
                    pose.compose(&Se3::from_xyz_rpy(joint.origin.xyz.0, joint.origin.rpy.0));
                let next = match roles[j] {
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
                    Role::Moving { .. } => Visit {
                        link: child,
                        body,
                        pose: placement,
                        joint: Some(j),
                    },
                };
                stack.push(next);
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

        // Degrees of freedom: the independent moving joints in body order; followers share
        // their leader's.
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
        // Subtree ranges (children come after their parent in pre-order).
        let n = bodies.len();
        for (i, b) in bodies.iter_mut().enumerate() {
            b.subtree_end = i + 1;
            b.refresh();
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
        let model = Model {
            name: robot.name.clone(),
            source: self.source.to_string(),
            nv: joint_names.len(),
            bodies,
            joint_names,
            joint_kinds,
            limits,
            gravity: Vector3::new(0.0, 0.0, -crate::model::STANDARD_GRAVITY),
            root_link: robot.links[root].name.clone(),
            base_mass: base_inertia.mass,
            coupled,
            joint_lines,
        };
        model.check_every_dof_moves_mass()?;
        Ok(model)
    }

    /// Finite numbers, a usable axis and a `<limit>` where the URDF requires one.
    fn check_joint_numbers(&self, joint: &urdf_rs::Joint) -> Result<()> {
        let name = joint.name.as_str();
        self.finite("joint", name, "origin xyz", &joint.origin.xyz.0)?;
        self.finite("joint", name, "origin rpy", &joint.origin.rpy.0)?;
        use urdf_rs::JointType::*;
        if joint.joint_type == Fixed {
            return Ok(());
        }
        let axis = joint.axis.xyz.0;
        let norm = Vector3::from(axis).norm();
        if !norm.is_finite() || norm < 1e-12 {
            return Err(Error::InvalidAxis {
                location: self.joint_location(name),
                joint: name.to_string(),
                axis,
            });
        }
        if matches!(joint.joint_type, Revolute | Prismatic) {
            let has_limit = self.lines.joints.get(name).map(|j| j.1).unwrap_or(true);
            if !has_limit {
                return Err(Error::MissingLimit {
                    location: self.joint_location(name),
                    joint: name.to_string(),
                    kind: kind_name(&joint.joint_type),
                });
            }
        }
        let l = &joint.limit;
        for (field, value) in [
            ("limit lower", l.lower),
            ("limit upper", l.upper),
            ("limit effort", l.effort),
            ("limit velocity", l.velocity),
            ("limit acceleration", l.acceleration),
        ] {
            // Infinite limits mean "no limit" (URDF 1.2); NaN is never meaningful.
            if value.is_nan() {
                return Err(Error::NonFiniteUrdf {
                    location: self.joint_location(name),
                    element: "joint",
                    name: name.to_string(),
                    field,
                    value,
                });
            }
        }
        if joint.joint_type != Continuous && l.lower > l.upper {
            return Err(Error::InvalidArgument {
                argument: format!("{}: joint '{name}' <limit>", self.joint_location(name)),
                message: format!("lower ({}) is above upper ({})", l.lower, l.upper),
            });
        }
        if let Some(d) = &joint.dynamics {
            self.finite(
                "joint",
                name,
                "dynamics damping/friction",
                &[d.damping, d.friction],
            )?;
        }
        if let Some(m) = &joint.mimic {
            self.finite(
                "joint",
                name,
                "mimic multiplier/offset",
                &[m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0)],
            )?;
        }
        Ok(())
    }

    /// A link inertia must be one a rigid body can have (beyond rounding).
    fn check_link_inertial(&self, link: &urdf_rs::Link) -> Result<()> {
        let name = link.name.as_str();
        let inertial = &link.inertial;
        let i = &inertial.inertia;
        self.finite("link", name, "inertial origin xyz", &inertial.origin.xyz.0)?;
        self.finite("link", name, "inertial origin rpy", &inertial.origin.rpy.0)?;
        self.finite("link", name, "mass", &[inertial.mass.value])?;
        self.finite(
            "link",
            name,
            "inertia",
            &[i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz],
        )?;
        let invalid = |reason: String| Error::InvalidInertia {
            location: self.link_location(name),
            link: name.to_string(),
            reason,
        };
        if inertial.mass.value < 0.0 {
            return Err(invalid(format!(
                "mass {} kg is negative",
                inertial.mass.value
            )));
        }
        let m = Matrix3::new(
            i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
        );
        let mut eig: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
        eig.sort_by(|a, b| a.total_cmp(b));
        // "Rounding": URDFs print inertias to a few significant digits.
        let tol = 1e-6 * eig.iter().map(|e| e.abs()).sum::<f64>() + 1e-12;
        if eig[0] < -tol {
            return Err(invalid(format!(
                "the inertia tensor is not positive semi-definite (principal moments {:.6e}, {:.6e}, {:.6e} kg m^2)",
                eig[0], eig[1], eig[2]
            )));
        }
        if self.options.check_triangle_inequality && eig[0] + eig[1] < eig[2] - tol {
            return Err(invalid(format!(
                "principal moments {:.6e} + {:.6e} < {:.6e} kg m^2 break the triangle inequality (no rigid body has them; load with the triangle-inequality check off to accept lumped rotor inertias)",
                eig[0], eig[1], eig[2]
            )));
        }
        Ok(())
    }

    /// Resolves mimic chains and locks into a role per URDF joint.
    fn resolve_roles(&self, joint_index: &HashMap<&str, usize>) -> Result<Vec<Role>> {
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

fn joint_kind(t: &urdf_rs::JointType) -> JointKind {
    match t {
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        _ => JointKind::Revolute,
    }
}

/// A link's inertia in its own frame (the URDF gives it about the CoM in the inertial frame).
fn link_inertia(link: &urdf_rs::Link) -> Inertia {
    let inertial = &link.inertial;
    let i = &inertial.inertia;
    let frame = Se3::from_xyz_rpy(inertial.origin.xyz.0, inertial.origin.rpy.0);
    let local = Inertia::new(
        inertial.mass.value,
        Vector3::zeros(),
        Matrix3::new(
            i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
        ),
    );
    frame.act_inertia(&local)
}

fn joint_limits(joint: &urdf_rs::Joint) -> JointLimits {
    let l = &joint.limit;
    let continuous = joint.joint_type == urdf_rs::JointType::Continuous;
    let (damping, friction) = joint
        .dynamics
        .as_ref()
        .map(|d| (d.damping, d.friction))
        .unwrap_or((0.0, 0.0));
    // A continuous joint's <limit> may be absent (urdf-rs then reports zeros) or give only
    // effort and velocity: zeros there mean "not given".
    let given = |v: f64| {
        if continuous && v == 0.0 {
            f64::INFINITY
        } else {
            v
        }
    };
    JointLimits {
        lower: if continuous {
            f64::NEG_INFINITY
        } else {
            l.lower
        },
        upper: if continuous { f64::INFINITY } else { l.upper },
        velocity: given(l.velocity),
        effort: given(l.effort),
        acceleration: l.acceleration,
        damping,
        friction,
    }
}
