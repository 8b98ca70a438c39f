//! Forward kinematics: the pose of every body in its parent.

use crate::data::Data;
use crate::gravity::Gravity;
use crate::model::{JointKind, Model};
use crate::spatial::Motion;

/// Poses `data.li_mi[i]` of every body in its parent's frame for the body coordinates in
/// `data.qb` (set by the caller from `q`).
pub(crate) fn update_placements(model: &Model, data: &mut Data) {
    for (i, b) in model.bodies.iter().enumerate() {
        data.li_mi[i] = b.pose_in_parent(data.qb[i]);
    }
}

/// The forward pass of the Newton-Euler recursion on the body coordinates in `data` (`qb`, `vb`,
/// `ab`): every body's pose in its parent `li_mi`, twist `v` and spatial acceleration `a` in
/// its own frame, the base accelerating upwards at `g` when `gravity` (so `a` includes gravity).
// inlined into every algorithm: measured 5-10 % faster one-sample calls
#[inline(always)]
pub(crate) fn motion_pass(model: &Model, data: &mut Data, gravity: Gravity) {
    let a0 = model.base_acceleration(gravity);
    for (i, b) in model.bodies.iter().enumerate() {
        let x = b.pose_in_parent(data.qb[i]);
        let (vp, ap) = match b.parent {
            Some(p) => (data.v[p], data.a[p]),
            None => (Motion::zeros(), a0),
        };
        let mut v = x.act_inv_motion(&vp);
        let mut a = x.act_inv_motion(&ap);
        // joint twist vj = S qd and acceleration S qdd; a += v x vj (written out: S has one
        // nonzero half)
        let (vj, aj) = (b.axis * data.vb[i], b.axis * data.ab[i]);
        match b.kind {
            JointKind::Revolute => {
                v.angular += vj;
                a.angular += aj + v.angular.cross(&vj);
                a.linear += v.linear.cross(&vj);
            }
            JointKind::Prismatic => {
                v.linear += vj;
                a.linear += aj + v.angular.cross(&vj);
            }
        }
        data.a[i] = a;
        data.li_mi[i] = x;
        data.v[i] = v;
    }
}
