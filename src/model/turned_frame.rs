//! Body frames turned so that each joint moves about or along its frame's z axis: the frames the
//! multi-sample mass matrix and derivatives work in (`algorithms::batch::mass_matrix`,
//! `algorithms::batch::derivatives`, whose recursions are in the base frame).
//!
//! A body's turned frame is its frame turned by a constant rotation `Q` with `Q e_z = a` (`a`
//! the unit joint axis). Then the joint's rotation `Rot_a(x) = Q Rot_z(x) Q^T`, so the turned
//! frame's pose in the base frame is `R'_p C Rot_z(x)`, with `R'_p` the parent's turned frame
//! there and the constant `C = Q_p^T R0 Q`: `C Rot_z(x)` (two columns of `C` mixed by the
//! cosine and sine) and one product by `R'_p`, where the joint's own frame takes the Rodrigues
//! terms and a 3x3 product of two variable matrices. The motion subspace in the base
//! frame is the turned frame's third column, read, not computed. Neither the mass matrix nor
//! the derivatives depend on the frames the bodies are described in, only on the inertias
//! being described in the frame used, so the inertias are turned too (`Q^T h`, `Q^T I Q`).
//!
//! Only the bodies that gain are turned: an axis-aligned revolute joint below a body that is
//! not turned keeps its frame and its own path (`AlignedRevolute`: columns of the parent's
//! rotation, no product), so the arms of the paper (every joint aligned) are untouched.

use nalgebra::{Matrix3, Vector3};

use crate::spatial::{OriginInertia, SplitInertia};

/// The constants of one body's turned frame (see the module's documentation). Frames: "the
/// parent's turned frame" is the base frame for a root body.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct TurnedFrame {
    /// `C = Q_p^T R0 Q`: the turned frame at zero joint coordinate in the parent's turned frame.
    pub(crate) rot: Matrix3<f64>,
    /// `Q_p^T p0` (m): the joint's placement translation in the parent's turned frame.
    pub(crate) pos: Vector3<f64>,
    /// `Q_p^T R0 a` (m per m): a prismatic joint's translation per unit coordinate in the
    /// parent's turned frame; zero for a revolute joint.
    pub(crate) slide: Vector3<f64>,
    /// `Q^T h` (kg m): the body's first moment about its origin in the turned frame.
    pub(crate) h: Vector3<f64>,
    /// The body's rotational inertia about its origin in the turned frame, `Q^T I Q`, split.
    pub(crate) split: SplitInertia,
}

impl TurnedFrame {
    /// Sets `h` and `split` from a body's inertia about its origin and its joint's unit axis
    /// (the body's own terms, which `Body::refresh` renews after an edit of the inertia; the
    /// frame's placement depends on the parent's and is `Model::refresh`'s).
    pub(crate) fn turn_inertia(&mut self, axis: &Vector3<f64>, inertia: &OriginInertia) {
        let q = turn_onto(axis);
        let i = q.transpose() * inertia.i * q;
        self.h = q.transpose() * inertia.h;
        self.split = SplitInertia::of(&((i + i.transpose()) * 0.5));
    }
}

/// A rotation `Q` with `Q e_z = a` for a unit axis `a` (the identity for `a = e_z` exactly):
/// columns `(u, a x u, a)`, `u` a unit vector orthogonal to `a`.
pub(crate) fn turn_onto(a: &Vector3<f64>) -> Matrix3<f64> {
    if *a == Vector3::z() {
        return Matrix3::identity();
    }
    // the coordinate axis least aligned with a, crossed with it
    let k = a.iamin();
    let u = Vector3::ith(k, 1.0).cross(a).normalize();
    Matrix3::from_columns(&[u, a.cross(&u), *a])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_turn_is_a_rotation_taking_z_onto_the_axis() {
        for a in [
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.4, 0.5).normalize(),
            Vector3::new(-1e-9, 1.0, 1e-9).normalize(),
        ] {
            let q = turn_onto(&a);
            assert!((q * Vector3::z() - a).amax() < 1e-15, "{a}");
            assert!(
                (q.transpose() * q - Matrix3::identity()).amax() < 1e-15,
                "{a}"
            );
            assert!((q.determinant() - 1.0).abs() < 1e-15, "{a}");
        }
    }
}
