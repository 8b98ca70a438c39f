//! Joint-limit checks of sampled trajectories.

use crate::error::{Error, Result};
use crate::model::{JointKind, Model};

use super::samples::Samples;

fn units(kind: JointKind) -> [&'static str; 3] {
    match kind {
        JointKind::Revolute => ["rad", "rad/s", "rad/s^2"],
        JointKind::Prismatic => ["m", "m/s", "m/s^2"],
    }
}

/// Checks every sample against the model's position, velocity and acceleration limits (infinite
/// limits are not checked). Fails on the first sample that breaks one, naming `context`, the
/// joint, the time and the limit. A relative tolerance of 1e-9 absorbs rounding.
pub fn check_limits(model: &Model, samples: &Samples, context: &str, hint: &str) -> Result<()> {
    let n = model.nv;
    let tol = 1e-9;
    for i in 0..samples.len() {
        let (q, qd, qdd) = (samples.q_at(i), samples.qd_at(i), samples.qdd_at(i));
        for j in 0..n {
            let lim = &model.limits[j];
            let [_, vu, au] = units(model.joint_kinds[j]);
            let scale = 1.0 + tol;
            if q[j] < lim.lower - tol * lim.lower.abs().max(1.0)
                || q[j] > lim.upper + tol * lim.upper.abs().max(1.0)
            {
                return Err(Error::PositionLimit {
                    context: context.to_string(),
                    joint: model.joint_names[j].clone(),
                    time: samples.t[i],
                    value: q[j],
                    lower: lim.lower,
                    upper: lim.upper,
                    hint: hint.to_string(),
                });
            }
            for (quantity, value, limit, unit) in [
                ("velocity", qd[j], lim.velocity, vu),
                ("acceleration", qdd[j], lim.acceleration, au),
            ] {
                if value.abs() > limit * scale {
                    return Err(Error::LimitViolation {
                        context: context.to_string(),
                        joint: model.joint_names[j].clone(),
                        time: samples.t[i],
                        quantity,
                        value,
                        limit,
                        unit,
                        hint: hint.to_string(),
                    });
                }
            }
        }
    }
    Ok(())
}
