//! What no robot can have: non-finite numbers, unusable axes, missing `<limit>` elements,
//! inverted limits, and link inertias that no rigid body has.

use nalgebra::{Matrix3, Vector3};

use super::convert::kind_name;
use super::reader::Builder;
use crate::error::{shown, Error, Result};

impl Builder<'_> {
    /// Finite numbers, a usable axis and a `<limit>` where the URDF requires one.
    pub(super) fn check_joint_numbers(&self, joint: &urdf_rs::Joint) -> Result<()> {
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
        let invalid = |message: String| Error::InvalidLimit {
            location: self.joint_location(name),
            joint: name.to_string(),
            message,
        };
        if joint.joint_type != Continuous {
            if l.lower > l.upper {
                return Err(invalid(format!(
                    "lower ({}) is above upper ({})",
                    shown(l.lower),
                    shown(l.upper)
                )));
            }
            if l.lower == l.upper {
                return Err(invalid(format!(
                    "lower = upper = {}: the joint cannot move; make it fixed, or lock it when loading",
                    shown(l.lower)
                )));
            }
        }
        // On a continuous joint zeros mean "not given" (see `convert::joint_limits`).
        let given = |v: f64| !(joint.joint_type == Continuous && v == 0.0);
        let unit = if joint.joint_type == urdf_rs::JointType::Prismatic {
            "m"
        } else {
            "rad"
        };
        if l.velocity <= 0.0 && given(l.velocity) {
            return Err(invalid(format!(
                "velocity {} {unit}/s is not positive; a moving joint needs a positive speed limit",
                shown(l.velocity)
            )));
        }
        if l.effort < 0.0 {
            let effort_unit = if unit == "m" { "N" } else { "N m" };
            return Err(invalid(format!(
                "effort {} {effort_unit} is negative; give a positive limit, or 0 for none",
                shown(l.effort)
            )));
        }
        if l.acceleration <= 0.0 {
            return Err(invalid(format!(
                "acceleration {} {unit}/s^2 is not positive; leave it out for none",
                shown(l.acceleration)
            )));
        }
        if let Some(d) = &joint.dynamics {
            self.finite(
                "joint",
                name,
                "dynamics damping/friction",
                &[d.damping, d.friction],
            )?;
            for (field, value) in [("damping", d.damping), ("friction", d.friction)] {
                if value < 0.0 {
                    return Err(Error::InvalidDynamics {
                        location: self.joint_location(name),
                        joint: name.to_string(),
                        message: format!(
                            "{field} {} is negative: it would push the joint instead of resisting its motion; expected >= 0",
                            shown(value)
                        ),
                    });
                }
            }
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
    pub(super) fn check_link_inertial(&self, link: &urdf_rs::Link) -> Result<()> {
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
        let m = Matrix3::new(
            i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
        );
        let triangle = self.options.check_triangle_inequality.then_some(
            "; load with the triangle-inequality check off to accept lumped rotor inertias",
        );
        match crate::spatial::rigid_body_problem(inertial.mass.value, &m, triangle) {
            Some(reason) => Err(invalid(reason)),
            None => Ok(()),
        }
    }
}
