//! Forward kinematics: the pose of every body in its parent.

use crate::data::Data;
use crate::model::Model;

/// Poses `data.li_mi[i]` of every body in its parent's frame for the body coordinates in
/// `data.qb` (set by the caller from `q`).
pub(crate) fn update_placements(model: &Model, data: &mut Data) {
    for (i, b) in model.bodies.iter().enumerate() {
        data.li_mi[i] = b.pose_in_parent(data.qb[i]);
    }
}
