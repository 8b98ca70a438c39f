//! Joint-limit checks of sampled trajectories.

use crate::error::{Error, Limit, LimitViolation, Result};
use crate::model::{JointKind, Model};

use super::samples::Samples;

fn unit(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Revolute => "rad",
        JointKind::Prismatic => "m",
    }
}

/// Checks every sample against the model's position, velocity and acceleration limits (infinite
/// limits are not checked). Fails on the first sample that breaks one, naming `context`, the
/// joint, the time and the limit. A relative tolerance of 1e-9 absorbs rounding.
pub fn check_limits(model: &Model, samples: &Samples, context: &str, hint: &str) -> Result<()> {
    let n = model.nv;
    let tol = 1e-9;
    let violation = |j: usize, i: usize, value: f64, limit: Limit| {
        Error::LimitViolation(Box::new(LimitViolation {
            context: context.to_string(),
            joint: model.joint_names[j].clone(),
            time: samples.t[i],
            value,
            limit,
            unit: unit(model.joint_kinds[j]),
            hint: hint.to_string(),
        }))
    };
    for i in 0..samples.len() {
        let (q, qd, qdd) = (samples.q_at(i), samples.qd_at(i), samples.qdd_at(i));
        for j in 0..n {
            let lim = &model.limits[j];
            let scale = 1.0 + tol;
            if q[j] < lim.lower - tol * lim.lower.abs().max(1.0)
                || q[j] > lim.upper + tol * lim.upper.abs().max(1.0)
            {
                let range = Limit::Position {
                    lower: lim.lower,
                    upper: lim.upper,
                };
                return Err(violation(j, i, q[j], range));
            }
            if qd[j].abs() > lim.velocity * scale {
                return Err(violation(j, i, qd[j], Limit::Velocity(lim.velocity)));
            }
            if qdd[j].abs() > lim.acceleration * scale {
                let l = Limit::Acceleration(lim.acceleration);
                return Err(violation(j, i, qdd[j], l));
            }
        }
    }
    Ok(())
}
