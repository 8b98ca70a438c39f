//! The planner's warnings about a plan's own perturbations (before any robot time): a design
//! whose columns are far from orthogonal, H perturbations that reverse a joint, and
//! trajectories that need more torque than the URDF's effort limits.

use nalgebra::DMatrix;

use super::plan::{ExperimentKind, PlanOptions, DESIGN_COND_WARNING};
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::trajectory::Samples;

/// The warning for a perturbation design whose cond(X) exceeds [`DESIGN_COND_WARNING`], with
/// how much precision it gives away and what to plan instead.
pub(super) fn design(kind: ExperimentKind, deltas: &DMatrix<f64>) -> Option<String> {
    let s = crate::regression::scaled_singular_values(deltas)?;
    let (largest, smallest) = (s[0], s[s.len() - 1]);
    let cond = largest / smallest;
    (cond > DESIGN_COND_WARNING).then(|| {
        let estimate = kind.estimate_name();
        format!(
            "experiment '{}': its perturbations have cond(X) = {cond:.1} (each joint's column scaled to unit norm): the least well determined combination of {estimate}'s entries will be {:.1} times less precise than with an orthogonal design of the same column norms; plan with design 'orthogonal' (--design orthogonal) for cond(X) = 1, or with more perturbations (n, --n)",
            kind.name(),
            1.0 / smallest
        )
    })
}

/// The warning for H perturbations that reverse a joint's velocity between passes (`|delta| >
/// |qd*|`): friction then changes sign and enters H*. None if there are none, or if the plan
/// is made for the friction-aware regression.
pub(super) fn velocity_reversal(
    model: &Model,
    op: &OperatingPoint,
    deltas: &DMatrix<f64>,
    o: &PlanOptions,
) -> Option<String> {
    if o.friction_aware_h {
        return None;
    }
    let reversed: Vec<String> = (0..deltas.ncols())
        .filter_map(|j| {
            let largest = deltas.column(j).amax();
            (largest > op.qd[j].abs()).then(|| {
                format!(
                    "'{}' (up to {largest:.3} against |qd*| = {:.3})",
                    model.joint_names[j],
                    op.qd[j].abs()
                )
            })
        })
        .collect();
    (!reversed.is_empty()).then(|| {
        format!(
            "experiment 'H': the velocity perturbations reverse joint(s) {} between passes, so their friction changes sign and enters H* unless it is modelled: plan with keep_velocity_sign (--keep-velocity-sign) to keep them below 0.9 |qd*|, or with friction_aware_h (--friction-aware-h) and identify with the friction-aware H regression",
            reversed.join(", ")
        )
    })
}

/// Adds to `warnings` the warning for an experiment whose sampled trajectory `s` needs, by the
/// model (gravity included, friction not), more torque than some joint's effort limit in the
/// URDF: the robot would saturate there, and a crossing's torques clip where it does so in a
/// window. A joint that needs more already at the operating point `op` is warned of once for
/// the plan, not per experiment. Nothing where no joint with a limit exceeds it.
pub(super) fn effort(
    model: &Model,
    op: &OperatingPoint,
    kind: ExperimentKind,
    s: &Samples,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let n = model.nv;
    let limits = model.effort_limit();
    if !limits.iter().any(|l| l.is_finite()) || s.t.is_empty() {
        return Ok(());
    }
    let mut data = crate::data::Data::new(model);
    crate::rnea(model, &mut data, &op.q, &op.qd, &op.qdd, Gravity::Included)?;
    let at_op: Vec<f64> = data.tau.iter().copied().collect();
    let states = crate::states::States::new(n, &s.q, Some(&s.qd), Some(&s.qdd))?;
    let mut tau = vec![0.0; s.q.len()];
    let mut ws = crate::parallel::Workspace::new(model);
    crate::parallel::rnea(model, &mut ws, &states, Gravity::Included, &mut tau)?;
    let (mut held, mut moving) = (vec![], vec![]);
    for j in (0..n).filter(|&j| limits[j].is_finite()) {
        let name = &model.joint_names[j];
        if at_op[j].abs() > limits[j] {
            held.push(format!(
                "'{name}' ({:.1} against {:.1})",
                at_op[j], limits[j]
            ));
            continue;
        }
        let (i, peak) = (0..s.t.len())
            .map(|i| (i, tau[i * n + j].abs()))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        if peak > limits[j] {
            moving.push(format!(
                "'{name}' ({peak:.1} at t = {:.3} s against {:.1})",
                s.t[i], limits[j]
            ));
        }
    }
    if !held.is_empty() {
        let w = format!(
            "by the model (gravity included, friction not) the operating point itself needs more torque than the URDF's effort limit of joint(s) {}: the robot cannot pass it there unless the model's masses or the limits are off; check them, or choose another point",
            held.join(", ")
        );
        if !warnings.contains(&w) {
            warnings.push(w);
        }
    }
    if !moving.is_empty() {
        warnings.push(format!(
            "experiment '{}': by the model (gravity included, friction not) its trajectory needs more torque than the URDF's effort limit of joint(s) {}: the robot would saturate there, and a crossing's torques clip where it does so in a window; perturb less, or give the URDF the robot's real speed and acceleration limits (the transitions use up to the margin of them)",
            kind.name(),
            moving.join(", ")
        ));
    }
    Ok(())
}
