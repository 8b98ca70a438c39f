//! A payload: inertial parameters added to, or changed on, one link of a robot, and the body
//! that link moves with. What a tool or a load carried by the robot is, shared by the true
//! robot of a rehearsal, the payload estimate of the direct method and the URDF writer.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::Model;

/// Inertial parameters added to, or changed on, one link (the body that starts at this URDF
/// link), in that body's joint frame: kg, m, kg m^2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Payload {
    pub link: String,
    pub mass: f64,
    /// Centre of mass of the payload (m).
    #[serde(default)]
    pub com: [f64; 3],
    /// Rotational inertia about the payload's centre of mass: `[ixx, ixy, ixz, iyy, iyz, izz]`.
    #[serde(default)]
    pub inertia: [f64; 6],
}

impl Payload {
    /// What makes this payload one nobody could bolt on (a centre of mass beyond
    /// [`MAX_COM_OFFSET`], a negative or non-finite mass, an inertia that is no rigid body's),
    /// `what` naming it in the message; None where it is sound.
    pub fn problem(&self, what: &str) -> Option<String> {
        if let Some(i) = self.com.iter().position(|c| !c.is_finite()) {
            return Some(format!(
                "{what}.com[{i}] is {}, expected a finite number",
                self.com[i]
            ));
        }
        if let Some(i) = self.com.iter().position(|c| c.abs() > MAX_COM_OFFSET) {
            return Some(format!(
                "{what}.com[{i}] is {} m, expected at most {MAX_COM_OFFSET} m in magnitude",
                crate::error::shown(self.com[i])
            ));
        }
        if let Some(i) = self.inertia.iter().position(|c| !c.is_finite()) {
            return Some(format!(
                "{what}.inertia[{i}] is {}, expected a finite number",
                self.inertia[i]
            ));
        }
        if !(self.mass.is_finite() && self.mass >= 0.0) {
            return Some(format!("{what}.mass is {}, expected >= 0 kg", self.mass));
        }
        // a body someone could bolt on: the simulation's mass matrix stays positive
        let s = self.spatial_inertia();
        crate::spatial::rigid_body_problem(self.mass, &s.inertia_com, Some("")).map(|reason| {
            format!(
                "{what} ([ixx, ixy, ixz, iyy, iyz, izz] = {:?}): {reason}",
                self.inertia
            )
        })
    }

    /// Its spatial inertia in its link's frame (kg, m, kg m^2).
    pub fn spatial_inertia(&self) -> crate::spatial::Inertia {
        let [xx, xy, xz, yy, yz, zz] = self.inertia;
        let inertia = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
        crate::spatial::Inertia::new(self.mass, Vector3::from(self.com), inertia)
    }

    /// The index of the body of `model` its link moves with (the body that starts at it, or,
    /// for a link behind fixed joints such as a flange or tool frame, its parent's); an
    /// error lists the links a payload can be fixed to.
    pub fn body(&self, model: &Model) -> Result<usize> {
        Ok(link_in_body(model, &self.link)?.0)
    }

    /// The body of `model` its link moves with ([`Self::body`]) and its spatial inertia in
    /// that body's frame: the link's pose in the body applied.
    pub fn in_body(&self, model: &Model) -> Result<(usize, crate::spatial::Inertia)> {
        let (b, pose) = link_in_body(model, &self.link)?;
        Ok((b, pose.act_inertia(&self.spatial_inertia())))
    }
}

/// The body of `model` URDF link `link` moves with and the link's pose in that body's frame
/// (the identity for the body's own link): a payload's. Refused for a link fixed to the base
/// (it moves no joint) and a link the robot lacks, listing those a payload can be fixed to.
pub fn link_in_body(model: &Model, link: &str) -> Result<(usize, crate::spatial::Se3)> {
    match model.frame(link) {
        Some(crate::model::Frame {
            body: Some(b),
            pose,
            ..
        }) => Ok((*b, *pose)),
        found => Err(Error::invalid(
            "true robot: link",
            format!(
                "'{link}' {} '{}'; links that move: {}",
                if found.is_some() {
                    "is fixed to the base (a payload there moves no joint) of"
                } else {
                    "is not a link of"
                },
                model.name,
                (model.frames.iter())
                    .filter(|f| f.body.is_some())
                    .map(|f| f.link.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// The largest offset (m) of a payload's centre of mass, or of a link error's, from its joint
/// frame: no robot reaches a kilometre.
pub const MAX_COM_OFFSET: f64 = 1e3;
