//! The planner's warnings about a plan's own perturbations (before any robot time): a design
//! whose columns are far from orthogonal, and H perturbations that reverse a joint.

use nalgebra::DMatrix;

use super::operating_point::OperatingPoint;
use super::plan::{ExperimentKind, PlanOptions, DESIGN_COND_WARNING};
use crate::model::Model;

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
