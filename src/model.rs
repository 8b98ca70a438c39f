//! The immutable robot model: a kinematic tree of rigid bodies, each behind one revolute or
//! prismatic joint, built once (from a URDF, see [`crate::urdf`]) and shared by all algorithms.
//!
//! Two index spaces:
//! - **bodies** `0..model.nbodies()`: one per moving joint of the tree, in depth-first order, so
//!   the subtree of body `i` is the contiguous range `i..bodies[i].subtree_end` and a parent
//!   always comes before its children. Bodies behind fixed or locked joints are merged into
//!   their parent body.
//! - **degrees of freedom** `0..model.nv`: the generalised coordinates `q, qd, qdd, tau` that
//!   users see. A body's joint coordinate is `multiplier * q[dof] + offset`: 1 and 0 for an
//!   ordinary joint, the URDF `<mimic>` values for a coupled joint, which adds no degree of
//!   freedom of its own.

use nalgebra::{Matrix3, Vector3};

use crate::error::{Error, Location, Result};
use crate::gravity::Gravity;
use crate::spatial::{skew, Inertia, Motion, OriginInertia, Se3, SplitInertia};

pub mod payload;
pub mod source;
mod turned_frame;
pub(crate) use turned_frame::TurnedFrame;

pub use crate::gravity::STANDARD_GRAVITY;

/// The kind of a moving joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about `axis`; coordinate in rad.
    Revolute,
    /// Translation along `axis`; coordinate in m.
    Prismatic,
}

/// One rigid body of the tree with the joint that carries it.
#[derive(Clone, Debug)]
pub struct Body {
    /// URDF name of the joint that moves this body.
    pub joint: String,
    /// URDF name of the link this body starts at (links merged into it behind fixed joints are
    /// not named here).
    pub link: String,
    /// Parent body, `None` for a body attached to the fixed base.
    pub parent: Option<usize>,
    /// One past the last body of this body's subtree (depth-first order).
    pub subtree_end: usize,
    /// Pose of the joint frame at zero joint coordinate in the parent body's frame (the base
    /// frame when `parent` is `None`).
    pub placement: Se3,
    pub kind: JointKind,
    /// Unit joint axis in the joint (= body) frame.
    pub axis: Vector3<f64>,
    /// Spatial inertia of the body, with everything rigidly attached to it, in its own frame.
    pub inertia: Inertia,
    /// The degree of freedom that drives this body.
    pub dof: usize,
    /// Joint coordinate = `multiplier * q[dof] + offset` (mimic coupling).
    pub multiplier: f64,
    pub offset: f64,
    /// `inertia` in the form the composite-body algorithms sum.
    pub(crate) origin_inertia: OriginInertia,
    /// `origin_inertia.i` split for turning (the multi-sample mass matrix).
    pub(crate) split_inertia: SplitInertia,
    /// `placement` and `axis` premultiplied for [`Body::pose_in_parent`].
    pub(crate) pose_terms: PoseTerms,
    /// The body's frame turned for the multi-sample mass matrix (`None`: its own frame). It
    /// depends on the parent's, so [`Model::refresh`] sets it, not [`Body::refresh`].
    pub(crate) turned: Option<TurnedFrame>,
}

/// A joint's pose in its parent as a function of its coordinate `x`, premultiplied once:
/// revolute `R(x) = R0 + sin(x) R1 + (1 - cos(x)) R2` (Rodrigues' formula with the placement's
/// rotation `R0` folded in: `R1 = R0 [a]x`, `R2 = R0 [a]x^2`), prismatic `p(x) = p0 + x t1`
/// with `t1 = R0 a`.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PoseTerms {
    pub(crate) r1: Matrix3<f64>,
    pub(crate) r2: Matrix3<f64>,
    pub(crate) t1: Vector3<f64>,
    /// Set for a revolute joint whose placement rotation permutes and flips the axes and whose
    /// axis is one of them: the multi-sample kernels then form its base-frame rotation from
    /// columns of its parent's, without 3x3 products.
    pub(crate) aligned: Option<AlignedRevolute>,
}

/// A revolute joint with `R(x) = R0 Rot_k(sign x)`: the axis is `sign e_k`, and the placement
/// rotation `R0` a signed permutation (entries within 1e-12 of 0 or +-1 taken as exact: a
/// rotation from an `rpy` of multiples of pi/2 holds `6e-17` for its zeros). Held by role, in
/// the order `(k, a, b)` with `(k, a, b)` cyclic (`Rot_k` turns `e_a` towards `e_b`): the body
/// axes `roles = [k, a, b]`; column `roles[j]` of `R0` is `signs[j] e_{rows[j]}`; `p_roles` is
/// the placement translation `p` (parent frame) in the body's axes, `(R0^T p)[roles[j]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AlignedRevolute {
    pub(crate) k: usize,
    pub(crate) sign: f64,
    pub(crate) roles: [usize; 3],
    pub(crate) rows: [usize; 3],
    pub(crate) signs: [f64; 3],
    pub(crate) p_roles: [f64; 3],
}

impl AlignedRevolute {
    /// The alignment of a revolute joint of placement rotation `r0` and unit `axis`, if any.
    pub(crate) fn of(placement: &Se3, axis: &Vector3<f64>) -> Option<Self> {
        let r0 = &placement.rotation;
        let (k, sign) = signed_unit(axis)?;
        let mut col_row = [0; 3];
        let mut col_sign = [0.0; 3];
        for j in 0..3 {
            (col_row[j], col_sign[j]) = signed_unit(&r0.column(j).into_owned())?;
        }
        let roles = [k, (k + 1) % 3, (k + 2) % 3];
        let rows = roles.map(|j| col_row[j]);
        let signs = roles.map(|j| col_sign[j]);
        Some(Self {
            k,
            sign,
            roles,
            rows,
            signs,
            p_roles: [0, 1, 2].map(|j| signs[j] * placement.translation[rows[j]]),
        })
    }
}

/// `(k, s)` when `v` is `s e_k` for `s = +-1` (each component within 1e-12).
fn signed_unit(v: &Vector3<f64>) -> Option<(usize, f64)> {
    const TOL: f64 = 1e-12;
    let k = v.iamax();
    let s = v[k].signum();
    let unit = (v[k] - s).abs() <= TOL && (0..3).all(|j| j == k || v[j].abs() <= TOL);
    unit.then_some((k, s))
}

impl PoseTerms {
    pub(crate) fn new(kind: JointKind, placement: &Se3, axis: &Vector3<f64>) -> Self {
        let k = skew(axis);
        let r1 = placement.rotation * k;
        Self {
            r2: r1 * k,
            r1,
            t1: placement.rotation * axis,
            aligned: match kind {
                JointKind::Revolute => AlignedRevolute::of(placement, axis),
                JointKind::Prismatic => None,
            },
        }
    }
}

impl Body {
    /// Recomputes the terms the algorithms cache from `placement`, `axis` and `inertia`, those
    /// of this body alone (an edited `inertia` is then fully in effect). The builders call it;
    /// call [`Model::refresh`] after editing `placement` or `axis` (it also recomputes the
    /// terms that depend on several bodies: the frames the multi-sample mass matrix turns).
    pub fn refresh(&mut self) {
        self.origin_inertia = OriginInertia::from(&self.inertia);
        self.split_inertia = SplitInertia::of(&self.origin_inertia.i);
        self.pose_terms = PoseTerms::new(self.kind, &self.placement, &self.axis);
        // an edited inertia reaches the turned frame's too (its placement needs the parent's)
        if let Some(mut t) = self.turned.take() {
            t.turn_inertia(&self.axis, &self.origin_inertia);
            self.turned = Some(t);
        }
    }

    /// The joint's motion subspace: the body's twist per unit joint velocity, in its own frame.
    #[inline]
    pub fn motion_subspace(&self) -> Motion {
        match self.kind {
            JointKind::Revolute => Motion::new(self.axis, Vector3::zeros()),
            JointKind::Prismatic => Motion::new(Vector3::zeros(), self.axis),
        }
    }

    /// The motion subspace expressed in another frame, for the body's pose `x` in it (the same
    /// as `x.act_motion(&self.motion_subspace())`, without the products by zero).
    #[inline]
    pub fn motion_subspace_in(&self, x: &Se3) -> Motion {
        let r = x.rotation * self.axis;
        match self.kind {
            JointKind::Revolute => Motion::new(r, x.translation.cross(&r)),
            JointKind::Prismatic => Motion::new(Vector3::zeros(), r),
        }
    }

    /// Pose of this body's frame in the parent's frame at joint coordinate `x` (rad or m).
    #[inline(always)] // in every recursion's loop: a call per body costs 8 % of a CRBA
    pub fn pose_in_parent(&self, x: f64) -> Se3 {
        let p = &self.placement;
        let t = &self.pose_terms;
        match self.kind {
            JointKind::Revolute => {
                let (s, c) = x.sin_cos();
                Se3 {
                    rotation: p.rotation + t.r1 * s + t.r2 * (1.0 - c),
                    translation: p.translation,
                }
            }
            JointKind::Prismatic => Se3 {
                rotation: p.rotation,
                translation: p.translation + t.t1 * x,
            },
        }
    }
}

/// Pose of a joint's child frame in its parent frame: the joint `placement` followed by the
/// joint motion of coordinate `x` (rad or m) about or along the unit `axis`.
#[inline]
pub fn joint_pose(kind: JointKind, placement: &Se3, axis: &Vector3<f64>, x: f64) -> Se3 {
    match kind {
        JointKind::Revolute => placement.compose(&Se3::rotation_about(axis, x)),
        JointKind::Prismatic => Se3 {
            rotation: placement.rotation,
            translation: placement.translation + placement.rotation * (axis * x),
        },
    }
}

/// A link's frame: the body it moves with (`None`: fixed to the base) and its pose in that
/// body's frame (links behind fixed or locked joints share their parent's body).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub link: String,
    pub body: Option<usize>,
    pub pose: Se3,
}

/// Per-degree-of-freedom data from the URDF: limits and `<dynamics>`.
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimits {
    /// Position limits (rad or m); infinite for continuous joints.
    pub lower: f64,
    pub upper: f64,
    /// Speed limit (rad/s or m/s); infinite when the URDF gives none.
    pub velocity: f64,
    /// Effort limit (N m or N); infinite when the URDF gives none.
    pub effort: f64,
    /// Acceleration limit (rad/s^2 or m/s^2), from URDF 1.2 `acceleration`; infinite if absent.
    pub acceleration: f64,
    /// Viscous friction coefficient (N m s/rad or N s/m), URDF `<dynamics damping>`.
    pub damping: f64,
    /// Coulomb friction (N m or N), URDF `<dynamics friction>`.
    pub friction: f64,
}

/// The robot model. Immutable once built; algorithms take `&Model` and a [`crate::Data`].
#[derive(Clone, Debug)]
pub struct Model {
    /// Robot name from the URDF.
    pub name: String,
    /// Where the model came from (file path, `<string>` or a built-in name).
    pub source: String,
    /// Moving bodies in depth-first order. After editing a body's `placement`, `axis` or
    /// `inertia`, call [`Model::refresh`].
    pub bodies: Vec<Body>,
    /// Number of degrees of freedom.
    pub nv: usize,
    /// Joint name of every degree of freedom (the independent, non-mimic joints).
    pub joint_names: Vec<String>,
    /// Joint kind of every degree of freedom.
    pub joint_kinds: Vec<JointKind>,
    /// Limits and friction of every degree of freedom.
    pub limits: Vec<JointLimits>,
    /// Armature of every degree of freedom: the motor's rotor inertia reflected to the joint
    /// (kg m^2 or kg), as Pinocchio's `armature`; it adds `armature[i] * qdd[i]` to `tau[i]`
    /// and `armature[i]` to `M[i, i]`. Zero unless the URDF gives it (see [`crate::urdf`]).
    pub armature: Vec<f64>,
    /// Every link's frame (URDF links, the root's included), for poses of named links.
    pub frames: Vec<Frame>,
    /// Gravity acceleration in the base frame (m/s^2); `(0, 0, -9.81)`.
    pub gravity: Vector3<f64>,
    /// Name of the root (base) link.
    pub root_link: String,
    /// Mass (kg) fixed to the base, which no joint moves (reported, unused by dynamics).
    pub base_mass: f64,
    /// `true` when some body is driven through a mimic coupling or a degree of freedom drives
    /// several bodies; algorithms then map between body and dof coordinates.
    pub coupled: bool,
    /// Line of each moving joint in its URDF source, by body index (for error messages).
    pub(crate) joint_lines: Vec<Option<u32>>,
    /// The URDF text the model was built from, with the options it was built with: what
    /// [`crate::urdf::write_urdf`] writes the model's parameters into.
    pub(crate) urdf: std::sync::Arc<source::UrdfSource>,
}

impl Model {
    /// Recomputes every body's cached terms (see [`Body::refresh`]): needed after editing
    /// `placement`, `axis` or `inertia` of a body, e.g. to simulate other inertial parameters.
    pub fn refresh(&mut self) {
        for b in &mut self.bodies {
            b.refresh();
        }
        let turned = turned_frames(&self.bodies);
        for (b, t) in self.bodies.iter_mut().zip(turned) {
            b.turned = t;
        }
    }

    /// Whether bodies `i` and `j` (indices into `bodies`, below [`Model::nbodies`]; panics
    /// past it, as indexing does) lie on one chain from the base (one is the other, or an
    /// ancestor of it): the pairs whose mass matrix entry can be non-zero.
    pub fn related(&self, i: usize, j: usize) -> bool {
        let (a, b) = (i.min(j), i.max(j));
        b < self.bodies[a].subtree_end
    }

    /// Number of moving bodies (>= `nv` when joints are coupled).
    pub fn nbodies(&self) -> usize {
        self.bodies.len()
    }

    /// The frame of the link named `name`, if any.
    pub fn frame(&self, name: &str) -> Option<&Frame> {
        self.frames.iter().find(|f| f.link == name)
    }

    /// Index of the degree of freedom named `name`, if any.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_names.iter().position(|n| n == name)
    }

    /// Lower position limits, one per dof (rad or m).
    pub fn lower(&self) -> Vec<f64> {
        self.limits.iter().map(|l| l.lower).collect()
    }

    /// Upper position limits, one per dof (rad or m).
    pub fn upper(&self) -> Vec<f64> {
        self.limits.iter().map(|l| l.upper).collect()
    }

    /// Speed limits, one per dof (rad/s or m/s).
    pub fn velocity_limit(&self) -> Vec<f64> {
        self.limits.iter().map(|l| l.velocity).collect()
    }

    /// Effort limits, one per dof (N m or N).
    pub fn effort_limit(&self) -> Vec<f64> {
        self.limits.iter().map(|l| l.effort).collect()
    }

    /// Acceleration limits, one per dof (rad/s^2 or m/s^2).
    pub fn acceleration_limit(&self) -> Vec<f64> {
        self.limits.iter().map(|l| l.acceleration).collect()
    }

    /// Spatial acceleration given to the fixed base in the Newton-Euler recursions: upwards at g
    /// when `gravity` is on (instead of applying gravity to every body), zero otherwise.
    #[inline]
    pub fn base_acceleration(&self, gravity: Gravity) -> Motion {
        if gravity.is_included() {
            Motion::new(Vector3::zeros(), -self.gravity)
        } else {
            Motion::zeros()
        }
    }

    /// The degrees of freedom that look like a gripper's fingers: prismatic, or named
    /// `finger`/`gripper`, and moving less than 1 % of the robot's moving mass. Their torque is
    /// seldom measured and their parameters are noise in an identification: lock them.
    /// Returns (joint name, mass it moves in kg).
    pub fn light_joints(&self) -> Vec<(String, f64)> {
        let n = self.nbodies();
        let mut subtree = vec![0.0; n];
        for i in (0..n).rev() {
            subtree[i] += self.bodies[i].inertia.mass;
            if let Some(p) = self.bodies[i].parent {
                subtree[p] += subtree[i];
            }
        }
        let total = self.moving_mass();
        let mut moved = vec![0.0; self.nv];
        for (i, b) in self.bodies.iter().enumerate() {
            moved[b.dof] += subtree[i];
        }
        (0..self.nv)
            .filter(|&j| {
                let name = self.joint_names[j].to_lowercase();
                (self.joint_kinds[j] == JointKind::Prismatic
                    || name.contains("finger")
                    || name.contains("gripper"))
                    && moved[j] < 0.01 * total
                    && self.nv > 1
            })
            .map(|j| (self.joint_names[j].clone(), moved[j]))
            .collect()
    }

    /// One warning per [`Model::light_joints`] joint, saying how to lock it.
    pub fn light_joint_warnings(&self) -> Vec<String> {
        self.light_joints()
            .into_iter()
            .map(|(joint, mass)| {
                format!(
                    "joint '{joint}' moves {mass:.3} kg of the robot's {:.2} kg (a gripper finger?): its torque is seldom measured and its fit is noise; lock it (--lock {joint}=VALUE on the command line, lock={{'{joint}': VALUE}} in Python)",
                    self.moving_mass()
                )
            })
            .collect()
    }

    /// Whether some degree of freedom has a non-zero armature.
    #[inline]
    pub fn has_armature(&self) -> bool {
        self.armature.iter().any(|&a| a != 0.0)
    }

    /// Adds the armature torques `armature[i] * qdd[i]` to `tau` (both `nv`); returns whether
    /// the entries it changed are finite (true when there is no armature).
    #[inline]
    pub(crate) fn add_armature_torque(&self, qdd: &[f64], tau: &mut [f64]) -> bool {
        let mut finite = true;
        if self.has_armature() {
            for ((t, a), x) in tau.iter_mut().zip(&self.armature).zip(qdd) {
                *t += a * x;
                finite &= t.is_finite();
            }
        }
        finite
    }

    /// Adds the armature to the diagonal of the column-major `nv x nv` matrix `m`; returns
    /// whether the diagonal is finite after it.
    #[inline]
    pub(crate) fn add_armature_inertia(&self, m: &mut [f64]) -> bool {
        let n = self.nv;
        let mut finite = true;
        for (i, a) in self.armature.iter().enumerate() {
            m[i * n + i] += a;
            finite &= m[i * n + i].is_finite();
        }
        finite
    }

    /// Total moving mass (kg).
    pub fn moving_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.inertia.mass).sum()
    }

    /// Checks that `x` has one entry per degree of freedom and holds finite numbers.
    pub fn check_vector(&self, argument: &str, x: &[f64]) -> Result<()> {
        check_finite_vector(argument, x, self.nv)
    }

    /// Fails when a degree of freedom drives no mass (M(q) singular). Run by the builders.
    pub(crate) fn check_every_dof_moves_mass(&self) -> Result<()> {
        let n = self.nbodies();
        // "weight" of each subtree: mass plus trace of the rotational inertia.
        let mut weight = vec![0.0; n];
        for i in (0..n).rev() {
            let b = &self.bodies[i];
            weight[i] += b.inertia.mass + b.inertia.inertia_com.trace();
            if let Some(p) = b.parent {
                weight[p] += weight[i];
            }
        }
        // per dof, what its bodies move, and its first body (one pass: linear in the bodies)
        let mut moved = vec![0.0; self.nv];
        let mut first = vec![usize::MAX; self.nv];
        for (i, b) in self.bodies.iter().enumerate() {
            moved[b.dof] += weight[i];
            first[b.dof] = first[b.dof].min(i);
        }
        for dof in 0..self.nv {
            if moved[dof] <= 0.0 {
                let i = first[dof].min(n.saturating_sub(1));
                return Err(Error::MasslessSubtree {
                    location: Box::new(Location {
                        source: self.source.clone(),
                        line: self.joint_lines.get(i).copied().flatten(),
                    }),
                    joint: self.joint_names[dof].clone(),
                });
            }
        }
        Ok(())
    }
}

/// Checks length `n` and finiteness of a vector argument.
pub(crate) fn check_finite_vector(argument: &str, x: &[f64], n: usize) -> Result<()> {
    if x.len() != n {
        return Err(Error::shape(
            argument.to_string(),
            format!("{n} values (one per degree of freedom)"),
            format!("{} values", x.len()),
        ));
    }
    match crate::finite::first_non_finite(x) {
        Some(index) => Err(Error::NonFiniteInput {
            argument: argument.to_string(),
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// Every body's turned frame, in the bodies' order (parents first): `None` for a revolute joint
/// with an axis-aligned placement (`AlignedRevolute`) below a body that is not turned (or on
/// the base), which keeps its own frame.
fn turned_frames(bodies: &[Body]) -> Vec<Option<TurnedFrame>> {
    let mut turns: Vec<Option<Matrix3<f64>>> = Vec::with_capacity(bodies.len());
    let mut out = Vec::with_capacity(bodies.len());
    for b in bodies {
        // (a parent after its child, which no builder makes, is taken as not turned)
        let parent = b.parent.and_then(|p| turns.get(p).copied().flatten());
        if b.pose_terms.aligned.is_some() && parent.is_none() {
            turns.push(None);
            out.push(None);
            continue;
        }
        let qp_t = parent.unwrap_or_else(Matrix3::identity).transpose();
        let q = turned_frame::turn_onto(&b.axis);
        let r0 = &b.placement.rotation;
        let mut t = TurnedFrame {
            rot: qp_t * r0 * q,
            pos: qp_t * b.placement.translation,
            slide: match b.kind {
                JointKind::Revolute => Vector3::zeros(),
                JointKind::Prismatic => qp_t * r0 * b.axis,
            },
            ..TurnedFrame::default()
        };
        t.turn_inertia(&b.axis, &b.origin_inertia);
        out.push(Some(t));
        turns.push(Some(q));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Se3;

    #[test]
    fn aligned_joints_are_recognised_and_their_rotation_is_the_joints() {
        // quarter-turn origins (with the 6e-17 of cos(pi/2)) and signed unit axes
        let quarter = std::f64::consts::FRAC_PI_2;
        for (rpy, axis) in [
            ([0.0, 0.0, 0.0], Vector3::z()),
            ([quarter, 0.0, -quarter], -Vector3::y()),
            ([-quarter, quarter, std::f64::consts::PI], Vector3::x()),
        ] {
            let placement = Se3::from_xyz_rpy([0.1, 0.0, 0.3], rpy);
            let t = PoseTerms::new(JointKind::Revolute, &placement, &axis);
            let al = t.aligned.expect("aligned");
            // R0 Rot_k(sign x) rebuilt from the description equals the joint's rotation
            let x = 0.7;
            let mut r0 = Matrix3::zeros();
            for j in 0..3 {
                r0[(al.rows[j], al.roles[j])] = al.signs[j];
            }
            let mut e = Vector3::zeros();
            e[al.k] = 1.0;
            let rot = nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(e),
                al.sign * x,
            );
            let want = joint_pose(JointKind::Revolute, &placement, &axis, x).rotation;
            assert!(
                (r0 * rot.matrix() - want).amax() < 1e-15,
                "{rpy:?} {axis:?}"
            );
        }
        // a general axis or origin, or a prismatic joint, is not
        let general = Se3::from_xyz_rpy([0.0; 3], [0.3, 0.0, 0.0]);
        assert!(PoseTerms::new(JointKind::Revolute, &general, &Vector3::z())
            .aligned
            .is_none());
        let tilted = Vector3::new(0.0, 0.6, 0.8);
        assert!(
            PoseTerms::new(JointKind::Revolute, &Se3::identity(), &tilted)
                .aligned
                .is_none()
        );
        assert!(
            PoseTerms::new(JointKind::Prismatic, &Se3::identity(), &Vector3::z())
                .aligned
                .is_none()
        );
    }

    #[test]
    fn the_a465s_joints_take_the_aligned_path() {
        let model = crate::robots::builtin("a465").unwrap();
        assert!(model.bodies.iter().all(|b| b.pose_terms.aligned.is_some()));
    }
}
