//! The URDF reader's entry points and the [`Builder`] its steps share (one step a file: see
//! the module [`crate::urdf`]).

use std::collections::HashMap;
use std::path::Path;

use super::lines::{self, LineIndex};
use super::{armature, LoadOptions};
use crate::error::{Error, Location, Result};
use crate::model::Model;

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
pub(super) struct Builder<'a> {
    pub(super) text: &'a str,
    pub(super) robot: &'a urdf_rs::Robot,
    pub(super) source: &'a str,
    pub(super) lines: &'a LineIndex,
    pub(super) armature: &'a HashMap<String, armature::ArmatureEntry>,
    pub(super) options: &'a LoadOptions,
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
    pub(super) fn joint_location(&self, name: &str) -> Box<Location> {
        Box::new(Location {
            source: self.source.to_string(),
            line: self.lines.joints.get(name).map(|j| j.0),
        })
    }

    /// Where link `name` stands in the file.
    pub(super) fn link_location(&self, name: &str) -> Box<Location> {
        Box::new(Location {
            source: self.source.to_string(),
            line: self.lines.links.get(name).copied(),
        })
    }

    /// Fails on the first non-finite value of `field` of element `name`.
    pub(super) fn finite(
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
