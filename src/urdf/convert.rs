//! urdf-rs values turned into ours: joint kinds, link inertias in the link frame, limits.

use nalgebra::{Matrix3, Vector3};

use crate::model::{JointKind, JointLimits};
use crate::spatial::{Inertia, Se3};

/// The URDF name of a joint type, for messages.
pub(super) fn kind_name(t: &urdf_rs::JointType) -> &'static str {
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

/// The kind of a moving joint (revolute and continuous joints rotate).
pub(super) fn joint_kind(t: &urdf_rs::JointType) -> JointKind {
    match t {
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        _ => JointKind::Revolute,
    }
}

/// A link's inertia in its own frame (the URDF gives it about the CoM in the inertial frame).
pub(super) fn link_inertia(link: &urdf_rs::Link) -> Inertia {
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

/// The limits of a joint: a continuous joint has no position limits, and zeros in its
/// `<limit>` mean "not given".
pub(super) fn joint_limits(joint: &urdf_rs::Joint) -> JointLimits {
    let l = &joint.limit;
    let continuous = joint.joint_type == urdf_rs::JointType::Continuous;
    let (damping, friction) = joint
        .dynamics
        .as_ref()
        .map(|d| (d.damping, d.friction))
        .unwrap_or((0.0, 0.0));
    // A continuous joint's <limit> may be absent (urdf-rs then reports zeros) or give only
    // effort and velocity: zeros there mean "not given". An effort of 0 means the same on any
    // joint (URDF writers put 0 for "unknown"; no joint moves with no effort at all).
    let given = |v: f64| {
        if continuous && v == 0.0 {
            f64::INFINITY
        } else {
            v
        }
    };
    let effort = if l.effort == 0.0 {
        f64::INFINITY
    } else {
        l.effort
    };
    JointLimits {
        lower: if continuous {
            f64::NEG_INFINITY
        } else {
            l.lower
        },
        upper: if continuous { f64::INFINITY } else { l.upper },
        velocity: given(l.velocity),
        effort,
        acceleration: l.acceleration,
        damping,
        friction,
    }
}
