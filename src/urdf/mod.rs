//! Building a [`Model`] from a URDF (parsed by urdf-rs).
//!
//! What is read: the kinematic tree (any tree, not only chains) of revolute, continuous,
//! prismatic and fixed joints; joint origins (xyz, rpy); axes (normalised); link inertials with
//! their origin and rpy (the inertia is rotated into the link frame); `<limit>` (URDF 1.2
//! `acceleration` included) and `<dynamics damping friction>`; the armature (reflected rotor
//! inertia, see `armature`); `<mimic>` couplings. Links behind
//! fixed joints are merged into their parent body. Joints can be locked at a position when the
//! model is built, which turns them into fixed joints.
//!
//! What is checked, each failure naming the file, line and element: the URDF syntax; floating,
//! planar and spherical joints; the number of root links; cycles; links that are the child of
//! two joints; unknown links; invalid inertias (negative mass, not positive semi-definite,
//! principal moments breaking the triangle inequality); zero or non-finite axes; non-finite
//! numbers; revolute or prismatic joints without `<limit>`; moving joints that carry no mass.

//!
//! The reader is split by step: `lines` finds where each element stands in the file,
//! `checks` refuses what no robot can have, `graph` links joints and links into a tree,
//! `roles` resolves mimic couplings and locks, `bodies` merges links into moving bodies and
//! `assemble` numbers the degrees of freedom into a [`Model`]; `convert` turns urdf-rs values
//! into ours. `write` writes a model back as URDF, its changed parameters in the file it came
//! from, through the text edits of `edits`.

mod armature;
mod assemble;
mod bodies;
mod checks;
mod convert;
mod edits;
mod graph;
mod lines;
mod roles;
mod write;

pub use crate::model::source::{LoadOptions, UrdfSource};
pub use lines::{MAX_XML_DEPTH, MAX_XML_ELEMENTS};
pub use write::{write_urdf, WriteOptions, WrittenUrdf};

use std::collections::HashMap;
use std::path::Path;

use crate::error::{Error, Location, Result};
use crate::model::Model;
use lines::LineIndex;

/// Reads and builds a model from a URDF file.
pub fn model_from_urdf_file(path: impl AsRef<Path>, options: &LoadOptions) -> Result<Model> {
    let path = path.as_ref();
    let text = crate::io::read_document(path)?;
    model_from_urdf_str(&text, &path.display().to_string(), options)
}

/// Builds a model from URDF text. `source_name` names the text in error messages.
pub fn model_from_urdf_str(text: &str, source_name: &str, options: &LoadOptions) -> Result<Model> {
    lines::check_depth(text, source_name)?;
    let doc = lines::parse_xml(text, source_name)?;
    let lines = LineIndex::new(text, &doc);
    let armature = armature::read(text, &doc, source_name)?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| Error::UrdfSyntax {
        source_name: source_name.to_string(),
        message: e.to_string(),
    })?;
    Builder {
        text,
        robot: &robot,
        source: source_name,
        lines: &lines,
        armature: &armature,
        options,
    }
    .build()
}

/// The URDF being read, with where it came from and how to read it.
struct Builder<'a> {
    text: &'a str,
    robot: &'a urdf_rs::Robot,
    source: &'a str,
    lines: &'a LineIndex,
    armature: &'a HashMap<String, armature::ArmatureEntry>,
    options: &'a LoadOptions,
}

impl Builder<'_> {
    /// The steps in order; each fails with the file, line and element of the first problem.
    fn build(&self) -> Result<Model> {
        let graph = self.graph()?;
        for link in &self.robot.links {
            self.check_link_inertial(link)?;
        }
        let roles = self.resolve_roles(&graph.joint_index)?;
        let bodies = self.bodies(&graph, &roles)?;
        self.assemble(&graph, &roles, bodies)
    }

    /// Where joint `name` stands in the file.
    fn joint_location(&self, name: &str) -> Box<Location> {
        Box::new(Location {
            source: self.source.to_string(),
            line: self.lines.joints.get(name).map(|j| j.0),
        })
    }

    /// Where link `name` stands in the file.
    fn link_location(&self, name: &str) -> Box<Location> {
        Box::new(Location {
            source: self.source.to_string(),
            line: self.lines.links.get(name).copied(),
        })
    }

    /// Fails on the first non-finite value of `field` of element `name`.
    fn finite(
        &self,
        element: &'static str,
        name: &str,
        field: &'static str,
        values: &[f64],
    ) -> Result<()> {
        // beyond 1e12 (m, kg, N m...) no robot number lies, and products would overflow
        if let Some(&value) = values.iter().find(|v| !v.is_finite() || v.abs() > 1e12) {
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
}
