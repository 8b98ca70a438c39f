//! Spatial algebra (Featherstone's notation) on nalgebra: 6-D motion and force vectors, rigid
//! transforms and spatial inertias.
//!
//! Conventions, used everywhere in the crate:
//! - a [`Motion`] (twist) holds the angular velocity `angular` (rad/s) and the linear velocity
//!   `linear` (m/s) of the point at the origin of the frame it is expressed in;
//! - a [`Force`] (wrench) holds the moment `angular` (N m) about the frame origin and the force
//!   `linear` (N);
//! - as 6-vectors and 6x6 matrices, the order is `[angular; linear]`;
//! - an [`Se3`] `aXb` is the pose of frame b in frame a: `p_a = rotation * p_b + translation`.

use nalgebra::{Matrix3, Matrix6, Rotation3, Unit, Vector3, Vector6};

/// Skew-symmetric matrix of `v`: `skew(v) * x == v.cross(&x)`.
#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// A spatial motion vector (twist or spatial acceleration).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Motion {
    pub angular: Vector3<f64>,
    pub linear: Vector3<f64>,
}

impl Motion {
    pub const fn new(angular: Vector3<f64>, linear: Vector3<f64>) -> Self {
        Self { angular, linear }
    }

    pub fn zeros() -> Self {
        Self::default()
    }

    /// Motion cross product `self x m` (the derivative of `m` in a frame moving with `self`).
    #[inline]
    pub fn cross(&self, m: &Motion) -> Motion {
        Motion {
            angular: self.angular.cross(&m.angular),
            linear: self.angular.cross(&m.linear) + self.linear.cross(&m.angular),
        }
    }

    /// Force cross product `self x* f`.
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force {
            angular: self.angular.cross(&f.angular) + self.linear.cross(&f.linear),
            linear: self.angular.cross(&f.linear),
        }
    }

    /// Power pairing `self . f` (W).
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.angular.dot(&f.angular) + self.linear.dot(&f.linear)
    }

    #[inline]
    pub fn scale(&self, s: f64) -> Motion {
        Motion {
            angular: self.angular * s,
            linear: self.linear * s,
        }
    }

    /// `[angular; linear]`.
    #[inline]
    pub fn to_vector(&self) -> Vector6<f64> {
        Vector6::new(
            self.angular.x,
            self.angular.y,
            self.angular.z,
            self.linear.x,
            self.linear.y,
            self.linear.z,
        )
    }

    /// Inverse of [`Motion::to_vector`].
    #[inline]
    pub fn from_vector(v: &Vector6<f64>) -> Motion {
        Motion {
            angular: Vector3::new(v[0], v[1], v[2]),
            linear: Vector3::new(v[3], v[4], v[5]),
        }
    }

    /// The 6x6 matrix of `self x .` acting on motion vectors.
    pub fn cross_matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        let w = skew(&self.angular);
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
        m.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&skew(&self.linear));
        m
    }

    /// The 6x6 matrix of `self x* .` acting on force vectors (`-cross_matrix()^T`).
    pub fn cross_force_matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        let w = skew(&self.angular);
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
        m.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&skew(&self.linear));
        m
    }
}

impl std::ops::Add for Motion {
    type Output = Motion;
    #[inline]
    fn add(self, o: Motion) -> Motion {
        Motion {
            angular: self.angular + o.angular,
            linear: self.linear + o.linear,
        }
    }
}

impl std::ops::Sub for Motion {
    type Output = Motion;
    #[inline]
    fn sub(self, o: Motion) -> Motion {
        Motion {
            angular: self.angular - o.angular,
            linear: self.linear - o.linear,
        }
    }
}

/// A spatial force vector (wrench or momentum).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Force {
    pub angular: Vector3<f64>,
    pub linear: Vector3<f64>,
}

impl Force {
    pub fn zeros() -> Self {
        Self::default()
    }

    /// `[angular; linear]`.
    #[inline]
    pub fn to_vector(&self) -> Vector6<f64> {
        Vector6::new(
            self.angular.x,
            self.angular.y,
            self.angular.z,
            self.linear.x,
            self.linear.y,
            self.linear.z,
        )
    }

    /// The 6x6 matrix `X` with `X m == m x* self` for every motion `m`.
    pub fn cross_matrix_of_motion(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        let n = -skew(&self.angular);
        let f = -skew(&self.linear);
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&n);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&f);
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&f);
        m
    }
}

impl std::ops::Add for Force {
    type Output = Force;
    #[inline]
    fn add(self, o: Force) -> Force {
        Force {
            angular: self.angular + o.angular,
            linear: self.linear + o.linear,
        }
    }
}

impl std::ops::AddAssign for Force {
    #[inline]
    fn add_assign(&mut self, o: Force) {
        self.angular += o.angular;
        self.linear += o.linear;
    }
}

/// A rigid transform `aXb`: the pose of frame b expressed in frame a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
}

impl Default for Se3 {
    fn default() -> Self {
        Self::identity()
    }
}

impl Se3 {
    pub fn identity() -> Self {
        Self {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    pub fn new(rotation: Matrix3<f64>, translation: Vector3<f64>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// From a URDF `<origin xyz rpy>`: fixed-axis roll about x, then pitch about y, then yaw
    /// about z (`R = Rz(yaw) Ry(pitch) Rx(roll)`), translation `xyz` (m).
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        let r = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
        Self::new(*r.matrix(), Vector3::new(xyz[0], xyz[1], xyz[2]))
    }

    /// Rotation by `angle` (rad) about the unit vector `axis`.
    pub fn rotation_about(axis: &Vector3<f64>, angle: f64) -> Self {
        let r = Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), angle);
        Self::new(*r.matrix(), Vector3::zeros())
    }

    /// Composition `aXc = self(aXb) * other(bXc)`.
    #[inline]
    pub fn compose(&self, other: &Se3) -> Se3 {
        Se3 {
            rotation: self.rotation * other.rotation,
            translation: self.translation + self.rotation * other.translation,
        }
    }

    pub fn inverse(&self) -> Se3 {
        let rt = self.rotation.transpose();
        Se3 {
            rotation: rt,
            translation: -(rt * self.translation),
        }
    }

    /// Expresses a motion given in frame b in frame a.
    #[inline]
    pub fn act_motion(&self, m: &Motion) -> Motion {
        let w = self.rotation * m.angular;
        Motion {
            angular: w,
            linear: self.rotation * m.linear + self.translation.cross(&w),
        }
    }

    /// Expresses a motion given in frame a in frame b.
    #[inline]
    pub fn act_inv_motion(&self, m: &Motion) -> Motion {
        Motion {
            angular: self.rotation.tr_mul(&m.angular),
            linear: self
                .rotation
                .tr_mul(&(m.linear - self.translation.cross(&m.angular))),
        }
    }

    /// Expresses a force given in frame b in frame a.
    #[inline]
    pub fn act_force(&self, f: &Force) -> Force {
        let lin = self.rotation * f.linear;
        Force {
            angular: self.rotation * f.angular + self.translation.cross(&lin),
            linear: lin,
        }
    }

    /// Expresses an inertia given in frame b in frame a.
    #[inline]
    pub fn act_inertia(&self, i: &Inertia) -> Inertia {
        Inertia {
            mass: i.mass,
            com: self.rotation * i.com + self.translation,
            inertia_com: self.rotation * i.inertia_com * self.rotation.transpose(),
        }
    }
}

/// A rigid-body spatial inertia: mass (kg), centre of mass `com` (m) and rotational inertia
/// about the centre of mass `inertia_com` (kg m^2), all expressed in the body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    pub mass: f64,
    pub com: Vector3<f64>,
    pub inertia_com: Matrix3<f64>,
}

impl Default for Inertia {
    fn default() -> Self {
        Self::zeros()
    }
}

impl Inertia {
    pub fn zeros() -> Self {
        Self {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia_com: Matrix3::zeros(),
        }
    }

    pub fn new(mass: f64, com: Vector3<f64>, inertia_com: Matrix3<f64>) -> Self {
        Self {
            mass,
            com,
            inertia_com,
        }
    }

    /// Momentum `I v` of a body moving with twist `v`.
    #[inline]
    pub fn apply(&self, v: &Motion) -> Force {
        let lin = (v.linear - self.com.cross(&v.angular)) * self.mass;
        Force {
            angular: self.inertia_com * v.angular + self.com.cross(&lin),
            linear: lin,
        }
    }

    /// Rotational inertia about the frame origin (kg m^2).
    pub fn inertia_origin(&self) -> Matrix3<f64> {
        let c = &self.com;
        self.inertia_com + (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * self.mass
    }

    /// The inertia of two bodies rigidly joined (both expressed in the same frame).
    pub fn add(&self, other: &Inertia) -> Inertia {
        let mass = self.mass + other.mass;
        if mass <= 0.0 {
            return Inertia {
                mass: 0.0,
                com: Vector3::zeros(),
                inertia_com: self.inertia_com + other.inertia_com,
            };
        }
        let com = (self.com * self.mass + other.com * other.mass) / mass;
        let shifted = |i: &Inertia| {
            let d = i.com - com;
            i.inertia_com + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * i.mass
        };
        Inertia {
            mass,
            com,
            inertia_com: shifted(self) + shifted(other),
        }
    }

    /// The 6x6 matrix in `[angular; linear]` order.
    pub fn to_matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        let cx = skew(&self.com) * self.mass;
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&self.inertia_origin());
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&cx);
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&cx.transpose());
        m.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(Matrix3::identity() * self.mass));
        m
    }
}

/// A spatial inertia in the form that adds and moves cheaply (Featherstone's): mass `mass`
/// (kg), first mass moment `h = m c` (kg m) and rotational inertia `i` about the frame origin
/// (kg m^2, symmetric), all in one frame. Composite-body algorithms sum these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OriginInertia {
    pub mass: f64,
    pub h: Vector3<f64>,
    pub i: Matrix3<f64>,
}

impl Default for OriginInertia {
    fn default() -> Self {
        Self {
            mass: 0.0,
            h: Vector3::zeros(),
            i: Matrix3::zeros(),
        }
    }
}

impl From<&Inertia> for OriginInertia {
    fn from(b: &Inertia) -> Self {
        Self {
            mass: b.mass,
            h: b.com * b.mass,
            i: b.inertia_origin(),
        }
    }
}

impl OriginInertia {
    /// Momentum `I v` (in this frame) of a body moving with twist `v`.
    #[inline]
    pub fn apply(&self, v: &Motion) -> Force {
        Force {
            angular: self.i * v.angular + self.h.cross(&v.linear),
            linear: v.linear * self.mass - self.h.cross(&v.angular),
        }
    }

    /// This inertia (given in frame b) expressed in frame a, for `x = aXb`.
    #[inline]
    pub fn transformed(&self, x: &Se3) -> OriginInertia {
        let r = &x.rotation;
        let p = &x.translation;
        let hr = r * self.h;
        // about a's origin: R I R^T - S(p) S(hr) - S(hr) S(p) - m S(p) S(p)
        //                 = R I R^T - (w p^T + p w^T) + 2 (p . w) 1,  w = hr + m p / 2
        let w = hr + p * (0.5 * self.mass);
        let d = 2.0 * p.dot(&w);
        let ri = r * self.i;
        // upper triangle of R I R^T (symmetric), then the shift
        let mut i = Matrix3::zeros();
        for c in 0..3 {
            for l in 0..=c {
                let v = ri.row(l).dot(&r.row(c)) - w[l] * p[c] - p[l] * w[c];
                i[(l, c)] = v;
                i[(c, l)] = v;
            }
            i[(c, c)] += d;
        }
        OriginInertia {
            mass: self.mass,
            h: hr + p * self.mass,
            i,
        }
    }
}

/// A rotational inertia `I` (symmetric 3x3, kg m^2) written as `base 1 + x x^T + y y^T`, from
/// its eigenvalues `l0 <= l1 <= l2` and unit eigenvectors `u1`, `u2`: `base = l0`, `x =
/// sqrt(l1 - l0) u1`, `y = sqrt(l2 - l0) u2` (x, y in kg^0.5 m, in `I`'s frame). Turned by a
/// rotation `R`, `R I R^T = base 1 + (R x)(R x)^T + (R y)(R y)^T`: two vectors turned and six
/// entries of two products each, where `R I R^T` takes a 3x3 product and six dot products (the
/// multi-sample mass matrix, 29 flops a body fewer).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SplitInertia {
    pub(crate) base: f64,
    pub(crate) x: Vector3<f64>,
    pub(crate) y: Vector3<f64>,
}

impl SplitInertia {
    /// The split of the symmetric `i` (its upper triangle read). Eigenvalue gaps that rounding
    /// makes negative are taken as 0. NaN throughout where `i` is not finite (what is computed
    /// with it is NaN, and refused as such).
    pub(crate) fn of(i: &Matrix3<f64>) -> Self {
        let Some(e) = crate::decomposition::symmetric_eigen(*i) else {
            return Self {
                base: f64::NAN,
                x: Vector3::repeat(f64::NAN),
                y: Vector3::repeat(f64::NAN),
            };
        };
        let mut order = [0, 1, 2];
        order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
        let [l0, l1, l2] = order.map(|k| e.eigenvalues[k]);
        let u = |k: usize| e.eigenvectors.column(order[k]).into_owned();
        Self {
            base: l0,
            x: u(1) * (l1 - l0).max(0.0).sqrt(),
            y: u(2) * (l2 - l0).max(0.0).sqrt(),
        }
    }
}

impl std::ops::AddAssign for OriginInertia {
    #[inline]
    fn add_assign(&mut self, o: OriginInertia) {
        self.mass += o.mass;
        self.h += o.h;
        self.i += o.i;
    }
}

/// Why a mass `mass` (kg) and a symmetric rotational inertia `inertia` (kg m^2, about the
/// centre of mass or any point) are not a rigid body's, or `None`: a negative mass, a mass or
/// entry beyond [`crate::limits::MAX_INERTIAL`] (whose products would overflow), a tensor that
/// is not positive semi-definite or, where `triangle` is given (a hint that ends that
/// reason), principal moments that break the triangle inequality; each beyond rounding (1e-6
/// of the principal moments' sum: files print inertias to a few digits). The reason names the
/// principal moments where they are at fault.
pub(crate) fn rigid_body_problem(
    mass: f64,
    inertia: &Matrix3<f64>,
    triangle: Option<&str>,
) -> Option<String> {
    use crate::limits::MAX_INERTIAL;
    if mass < 0.0 {
        return Some(format!("mass {} kg is negative", crate::error::shown(mass)));
    }
    if mass.abs() > MAX_INERTIAL || inertia.iter().any(|v| v.abs() > MAX_INERTIAL) {
        return Some(format!(
            "a mass or inertia beyond {MAX_INERTIAL:e} (kg, kg m^2); no robot has them"
        ));
    }
    let mut eig: Vec<f64> = crate::decomposition::symmetric_eigen(*inertia)
        .map_or(vec![f64::NAN; 3], |e| {
            e.eigenvalues.iter().copied().collect()
        });
    eig.sort_by(|a, b| a.total_cmp(b));
    let tol = 1e-6 * eig.iter().map(|e| e.abs()).sum::<f64>() + 1e-12;
    if eig.iter().any(|e| !e.is_finite()) || eig[0] < -tol {
        return Some(format!(
            "the inertia tensor is not positive semi-definite (principal moments {:.6e}, {:.6e}, {:.6e} kg m^2)",
            eig[0], eig[1], eig[2]
        ));
    }
    match triangle {
        Some(hint) if eig[0] + eig[1] < eig[2] - tol => Some(format!(
            "principal moments {:.6e} + {:.6e} < {:.6e} kg m^2 break the triangle inequality (no rigid body has them{hint})",
            eig[0], eig[1], eig[2]
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_inertia_turns_as_the_inertia() {
        let b = OriginInertia::from(&sample_inertia());
        let split = SplitInertia::of(&b.i);
        let r = Rotation3::from_euler_angles(0.3, -1.1, 2.0).into_inner();
        let whole = r * b.i * r.transpose();
        let (x, y) = (r * split.x, r * split.y);
        let parts = Matrix3::identity() * split.base + x * x.transpose() + y * y.transpose();
        assert!(
            (whole - parts).amax() < 1e-14 * b.i.amax(),
            "{whole} vs {parts}"
        );
        // a point mass at the origin: all zeros; a rod: two equal eigenvalues
        assert_eq!(SplitInertia::of(&Matrix3::zeros()), SplitInertia::default());
        let rod = Matrix3::from_diagonal(&Vector3::new(0.0, 2.0, 2.0));
        let s = SplitInertia::of(&rod);
        let back = Matrix3::identity() * s.base + s.x * s.x.transpose() + s.y * s.y.transpose();
        assert!((back - rod).amax() < 1e-14, "{back}");
    }

    fn sample_inertia() -> Inertia {
        Inertia::new(
            2.5,
            Vector3::new(0.1, -0.2, 0.3),
            Matrix3::new(0.3, 0.01, 0.02, 0.01, 0.2, 0.03, 0.02, 0.03, 0.25),
        )
    }

    #[test]
    fn inertia_matrix_matches_apply() {
        let i = sample_inertia();
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let a = i.to_matrix() * v.to_vector();
        assert!((a - i.apply(&v).to_vector()).norm() < 1e-12);
    }

    #[test]
    fn transforms_preserve_power_and_invert() {
        let x = Se3::from_xyz_rpy([0.1, 0.2, -0.3], [0.4, -0.5, 0.6]);
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let f = sample_inertia().apply(&v);
        // power is frame-invariant
        let p1 = v.dot(&f);
        let p2 = x.act_motion(&v).dot(&x.act_force(&f));
        assert!((p1 - p2).abs() < 1e-12);
        let back = x.act_inv_motion(&x.act_motion(&v));
        assert!((back.to_vector() - v.to_vector()).norm() < 1e-12);
        let inv = x.inverse().compose(&x);
        assert!((inv.rotation - Matrix3::identity()).norm() < 1e-12);
        assert!(inv.translation.norm() < 1e-12);
        // inertia transform: I_a (X v) == X* (I_b v)
        let ia = x.act_inertia(&sample_inertia());
        let lhs = ia.apply(&x.act_motion(&v)).to_vector();
        let rhs = x.act_force(&sample_inertia().apply(&v)).to_vector();
        assert!((lhs - rhs).norm() < 1e-12);
    }

    #[test]
    fn cross_matrices_match_products() {
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let m = Motion::new(Vector3::new(-0.2, 0.4, 0.1), Vector3::new(0.5, -0.3, 0.9));
        let f = sample_inertia().apply(&m);
        assert!((v.cross_matrix() * m.to_vector() - v.cross(&m).to_vector()).norm() < 1e-12);
        assert!(
            (v.cross_force_matrix() * f.to_vector() - v.cross_force(&f).to_vector()).norm() < 1e-12
        );
        assert!(
            (f.cross_matrix_of_motion() * m.to_vector() - m.cross_force(&f).to_vector()).norm()
                < 1e-12
        );
    }

    #[test]
    fn origin_inertia_agrees_with_inertia() {
        let b = sample_inertia();
        let x = Se3::from_xyz_rpy([0.3, -0.4, 0.1], [0.5, 0.2, -0.7]);
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let direct = x.act_inertia(&b).apply(&v).to_vector();
        let moved = OriginInertia::from(&b)
            .transformed(&x)
            .apply(&v)
            .to_vector();
        assert!((direct - moved).norm() < 1e-12);
        let mut sum = OriginInertia::from(&b);
        sum += OriginInertia::from(&x.act_inertia(&b));
        let parts = b.apply(&v) + x.act_inertia(&b).apply(&v);
        assert!((sum.apply(&v).to_vector() - parts.to_vector()).norm() < 1e-12);
    }

    #[test]
    fn adding_inertias_is_consistent_with_apply() {
        let a = sample_inertia();
        let b = Se3::from_xyz_rpy([0.3, 0.0, 0.1], [0.0, 0.2, 0.0]).act_inertia(&a);
        let v = Motion::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.2, -0.7));
        let sum = a.add(&b).apply(&v).to_vector();
        let parts = (a.apply(&v) + b.apply(&v)).to_vector();
        assert!((sum - parts).norm() < 1e-12);
    }
}
