//! Arithmetic on `W` samples side by side (structure of arrays): a scalar per lane
//! [`Lanes`], 3-vectors [`Vector3Lanes`], 3x3 matrices [`Rotation3Lanes`] (by rows) and spatial
//! vectors [`SpatialLanes`] of lanes. Each operation is a short loop over the lanes that the
//! compiler maps onto one SIMD register per scalar when the caller is compiled for a vector
//! instruction set (see [`super::Isa`]); products are summed with fused multiply-adds
//! ([`f64::mul_add`]), which those sets do in one instruction. Only call these from code compiled
//! for such a set: elsewhere `mul_add` is a library call.

// index loops over the lanes: the form the compiler turns into one vector instruction
#![allow(clippy::needless_range_loop)]

use nalgebra::{Matrix3, Vector3};

/// Counts `n` floating-point operations (with the `count-flops` feature; nothing otherwise).
#[inline(always)]
fn flops(n: usize) {
    #[cfg(feature = "count-flops")]
    super::flops::add(n);
    #[cfg(not(feature = "count-flops"))]
    let _ = n;
}

/// One scalar per lane. Aligned to 32 bytes: four lanes are one AVX2 register, eight one AVX-512
/// register whose two 32-byte halves (the halves a Zen 4 executes it in) each lie within one
/// cache line. With the 8-byte alignment of a plain array, buffers and stack spills sat
/// anywhere in a line: loads split across lines, and loads right after a split store to the
/// same place were not forwarded from it (on AVX-512, RNEA 7-17 % and the regressor up to 13 %
/// slower).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Lanes<const W: usize>(pub(crate) [f64; W]);

impl<const W: usize> Default for Lanes<W> {
    #[inline(always)]
    fn default() -> Self {
        Lanes([0.0; W])
    }
}

impl<const W: usize> Lanes<W> {
    #[inline(always)]
    pub(crate) fn splat(x: f64) -> Self {
        Lanes([x; W])
    }
    /// `self * b + c`, fused.
    #[inline(always)]
    pub(crate) fn mul_add(self, b: Lanes<W>, c: Lanes<W>) -> Lanes<W> {
        flops(2 * W);
        let mut r = c.0;
        for l in 0..W {
            r[l] = self.0[l].mul_add(b.0[l], r[l]);
        }
        Lanes(r)
    }
    /// `self * b + c` for a constant `b`, fused.
    #[inline(always)]
    pub(crate) fn mul_add_s(self, b: f64, c: Lanes<W>) -> Lanes<W> {
        flops(2 * W);
        let mut r = c.0;
        for l in 0..W {
            r[l] = self.0[l].mul_add(b, r[l]);
        }
        Lanes(r)
    }
    /// `self * b - c`, fused.
    #[inline(always)]
    pub(crate) fn mul_sub(self, b: Lanes<W>, c: Lanes<W>) -> Lanes<W> {
        flops(2 * W);
        let mut r = c.0;
        for l in 0..W {
            r[l] = self.0[l].mul_add(b.0[l], -r[l]);
        }
        Lanes(r)
    }
    /// `c - self * b`, fused.
    #[inline(always)]
    pub(crate) fn neg_mul_add(self, b: Lanes<W>, c: Lanes<W>) -> Lanes<W> {
        flops(2 * W);
        let mut r = c.0;
        for l in 0..W {
            r[l] = (-self.0[l]).mul_add(b.0[l], r[l]);
        }
        Lanes(r)
    }
    /// Whether any lane is NaN or larger than `bound` in magnitude.
    #[inline(always)]
    pub(crate) fn any_nan_or_beyond(self, bound: f64) -> bool {
        // NaN fails `<=` too; reduced without a branch per lane
        let mut inside = true;
        for x in self.0 {
            inside &= x.abs() <= bound;
        }
        !inside
    }
}

// `x = x op y` rather than `x op= y`: one macro for the three operators (clippy's assign-op
// rewrite would take one operator for all)
macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const W: usize> std::ops::$tr for Lanes<W> {
            type Output = Lanes<W>;
            #[inline(always)]
            #[allow(clippy::assign_op_pattern)]
            fn $f(self, o: Lanes<W>) -> Lanes<W> {
                flops(W);
                let mut r = self.0;
                for l in 0..W {
                    r[l] = r[l] $op o.0[l];
                }
                Lanes(r)
            }
        }
        impl<const W: usize> std::ops::$tr<f64> for Lanes<W> {
            type Output = Lanes<W>;
            #[inline(always)]
            #[allow(clippy::assign_op_pattern)]
            fn $f(self, o: f64) -> Lanes<W> {
                flops(W);
                let mut r = self.0;
                for x in &mut r {
                    *x = *x $op o;
                }
                Lanes(r)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

impl<const W: usize> std::ops::Neg for Lanes<W> {
    type Output = Lanes<W>;
    #[inline(always)]
    fn neg(self) -> Lanes<W> {
        let mut r = self.0;
        for x in &mut r {
            *x = -*x;
        }
        Lanes(r)
    }
}

/// A 3-vector per lane (laid out as `[Lanes<W>; 3]`: see [`Vector3Lanes::at`]).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub(crate) struct Vector3Lanes<const W: usize> {
    pub(crate) x: Lanes<W>,
    pub(crate) y: Lanes<W>,
    pub(crate) z: Lanes<W>,
}

impl<const W: usize> Default for Vector3Lanes<W> {
    #[inline(always)]
    fn default() -> Self {
        let z = Lanes::default();
        Vector3Lanes { x: z, y: z, z }
    }
}

impl<const W: usize> Vector3Lanes<W> {
    #[inline(always)]
    pub(crate) fn splat(v: &Vector3<f64>) -> Self {
        Vector3Lanes {
            x: Lanes::splat(v.x),
            y: Lanes::splat(v.y),
            z: Lanes::splat(v.z),
        }
    }
    #[inline(always)]
    pub(crate) fn cross(&self, o: &Self) -> Self {
        Vector3Lanes {
            x: self.y.mul_sub(o.z, self.z * o.y),
            y: self.z.mul_sub(o.x, self.x * o.z),
            z: self.x.mul_sub(o.y, self.y * o.x),
        }
    }
    /// `self x o` for a constant vector `o`.
    #[inline(always)]
    pub(crate) fn cross_const(&self, o: &Vector3<f64>) -> Self {
        Vector3Lanes {
            x: self.y.mul_add_s(o.z, self.z * -o.y),
            y: self.z.mul_add_s(o.x, self.x * -o.z),
            z: self.x.mul_add_s(o.y, self.y * -o.x),
        }
    }
    #[inline(always)]
    pub(crate) fn add(&self, o: &Self) -> Self {
        Vector3Lanes {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    pub(crate) fn sub(&self, o: &Self) -> Self {
        Vector3Lanes {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    pub(crate) fn scale(&self, s: f64) -> Self {
        Vector3Lanes {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    /// `self * s + o`, fused.
    #[inline(always)]
    pub(crate) fn scale_add(&self, s: f64, o: &Self) -> Self {
        Vector3Lanes {
            x: self.x.mul_add_s(s, o.x),
            y: self.y.mul_add_s(s, o.y),
            z: self.z.mul_add_s(s, o.z),
        }
    }
    /// `a * s` for a constant vector `a` and a lane scalar `s`.
    #[inline(always)]
    pub(crate) fn of(a: &Vector3<f64>, s: Lanes<W>) -> Self {
        Vector3Lanes {
            x: s * a.x,
            y: s * a.y,
            z: s * a.z,
        }
    }
    #[inline(always)]
    pub(crate) fn dot(&self, o: &Self) -> Lanes<W> {
        self.x.mul_add(o.x, self.y.mul_add(o.y, self.z * o.z))
    }
    /// `self . o + c`, fused.
    #[inline(always)]
    pub(crate) fn dot_add(&self, o: &Self, c: Lanes<W>) -> Lanes<W> {
        self.x
            .mul_add(o.x, self.y.mul_add(o.y, self.z.mul_add(o.z, c)))
    }
    /// `self * s` for a lane scalar `s`.
    #[inline(always)]
    pub(crate) fn mul_lanes(&self, s: Lanes<W>) -> Self {
        Vector3Lanes {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    /// `self * s + o` for a lane scalar `s`, fused.
    #[inline(always)]
    pub(crate) fn mul_lanes_add(&self, s: Lanes<W>, o: &Self) -> Self {
        Vector3Lanes {
            x: self.x.mul_add(s, o.x),
            y: self.y.mul_add(s, o.y),
            z: self.z.mul_add(s, o.z),
        }
    }
    /// `a . self` for a constant vector `a`.
    #[inline(always)]
    pub(crate) fn dot_const(&self, a: &Vector3<f64>) -> Lanes<W> {
        self.x.mul_add_s(a.x, self.y.mul_add_s(a.y, self.z * a.z))
    }
    /// `a . self + c` for a constant vector `a`, fused (three fused multiply-adds).
    #[inline(always)]
    pub(crate) fn dot_const_add(&self, a: &Vector3<f64>, c: Lanes<W>) -> Lanes<W> {
        self.x
            .mul_add_s(a.x, self.y.mul_add_s(a.y, self.z.mul_add_s(a.z, c)))
    }
    /// `m * self` for a constant matrix `m`.
    #[inline(always)]
    pub(crate) fn mul_const(&self, m: &Matrix3<f64>) -> Self {
        Vector3Lanes {
            x: self.dot_const(&m.row(0).transpose()),
            y: self.dot_const(&m.row(1).transpose()),
            z: self.dot_const(&m.row(2).transpose()),
        }
    }
    /// Component `k` (0, 1, 2) for an index known only at run time: one load from memory
    /// (where [`Vector3Lanes::get`] would select among registers).
    #[inline(always)]
    pub(crate) fn at(&self, k: usize) -> &Lanes<W> {
        // SAFETY: `repr(C)` with three fields of one type and no padding between them is laid
        // out as `[Lanes<W>; 3]`, and the reference's lifetime is `self`'s
        let a = unsafe { &*(self as *const Self as *const [Lanes<W>; 3]) };
        &a[k]
    }
    /// [`Vector3Lanes::at`], for writing.
    #[inline(always)]
    pub(crate) fn at_mut(&mut self, k: usize) -> &mut Lanes<W> {
        // SAFETY: as in `at`, with the exclusive borrow of `self`
        let a = unsafe { &mut *(self as *mut Self as *mut [Lanes<W>; 3]) };
        &mut a[k]
    }
    /// Component `k` (0, 1, 2).
    #[inline(always)]
    pub(crate) fn get(&self, k: usize) -> Lanes<W> {
        match k {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }
}

/// A 3x3 matrix (a rotation, or a rotational inertia) per lane, by rows.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rotation3Lanes<const W: usize>(pub(crate) [Vector3Lanes<W>; 3]);

impl<const W: usize> Default for Rotation3Lanes<W> {
    #[inline(always)]
    fn default() -> Self {
        Rotation3Lanes([Vector3Lanes::default(); 3])
    }
}

impl<const W: usize> Rotation3Lanes<W> {
    /// `self * o`.
    #[inline(always)]
    pub(crate) fn compose(&self, o: &Self) -> Self {
        // row r of the product is row r of self times o: o^T applied to that row
        Rotation3Lanes([
            o.tr_mul(&self.0[0]),
            o.tr_mul(&self.0[1]),
            o.tr_mul(&self.0[2]),
        ])
    }
    /// The matrix of columns `x`, `y`, `z`.
    #[inline(always)]
    pub(crate) fn from_columns(
        x: &Vector3Lanes<W>,
        y: &Vector3Lanes<W>,
        z: &Vector3Lanes<W>,
    ) -> Self {
        Rotation3Lanes([
            Vector3Lanes {
                x: x.x,
                y: y.x,
                z: z.x,
            },
            Vector3Lanes {
                x: x.y,
                y: y.y,
                z: z.y,
            },
            Vector3Lanes {
                x: x.z,
                y: y.z,
                z: z.z,
            },
        ])
    }
    /// `self * a` for a constant vector `a`.
    #[inline(always)]
    pub(crate) fn mul_const_vector(&self, a: &Vector3<f64>) -> Vector3Lanes<W> {
        Vector3Lanes {
            x: self.0[0].dot_const(a),
            y: self.0[1].dot_const(a),
            z: self.0[2].dot_const(a),
        }
    }
    /// `self * a + c` for a constant vector `a`, fused (a point placed by this rotation and
    /// the origin `c`: nine fused multiply-adds where the product and the sum took twelve
    /// operations).
    #[inline(always)]
    pub(crate) fn mul_const_vector_add(
        &self,
        a: &Vector3<f64>,
        c: &Vector3Lanes<W>,
    ) -> Vector3Lanes<W> {
        Vector3Lanes {
            x: self.0[0].dot_const_add(a, c.x),
            y: self.0[1].dot_const_add(a, c.y),
            z: self.0[2].dot_const_add(a, c.z),
        }
    }
    /// `self * v + c`, fused (nine fused multiply-adds).
    #[inline(always)]
    pub(crate) fn mul_add(&self, v: &Vector3Lanes<W>, c: &Vector3Lanes<W>) -> Vector3Lanes<W> {
        Vector3Lanes {
            x: self.0[0].dot_add(v, c.x),
            y: self.0[1].dot_add(v, c.y),
            z: self.0[2].dot_add(v, c.z),
        }
    }
    #[inline(always)]
    pub(crate) fn mul(&self, v: &Vector3Lanes<W>) -> Vector3Lanes<W> {
        Vector3Lanes {
            x: self.0[0].dot(v),
            y: self.0[1].dot(v),
            z: self.0[2].dot(v),
        }
    }
    /// `self^T v`.
    #[inline(always)]
    pub(crate) fn tr_mul(&self, v: &Vector3Lanes<W>) -> Vector3Lanes<W> {
        let [a, b, c] = &self.0;
        Vector3Lanes {
            x: a.x.mul_add(v.x, b.x.mul_add(v.y, c.x * v.z)),
            y: a.y.mul_add(v.x, b.y.mul_add(v.y, c.y * v.z)),
            z: a.z.mul_add(v.x, b.z.mul_add(v.y, c.z * v.z)),
        }
    }
    #[inline(always)]
    pub(crate) fn add(&self, o: &Self) -> Self {
        Rotation3Lanes([
            self.0[0].add(&o.0[0]),
            self.0[1].add(&o.0[1]),
            self.0[2].add(&o.0[2]),
        ])
    }
}

/// A spatial vector per lane (`angular`, `linear`): a motion or a force.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpatialLanes<const W: usize> {
    pub(crate) ang: Vector3Lanes<W>,
    pub(crate) lin: Vector3Lanes<W>,
}

impl<const W: usize> Default for SpatialLanes<W> {
    #[inline(always)]
    fn default() -> Self {
        SpatialLanes {
            ang: Vector3Lanes::default(),
            lin: Vector3Lanes::default(),
        }
    }
}

impl<const W: usize> SpatialLanes<W> {
    #[inline(always)]
    pub(crate) fn add(&self, o: &Self) -> Self {
        SpatialLanes {
            ang: self.ang.add(&o.ang),
            lin: self.lin.add(&o.lin),
        }
    }
    /// The pairing `<self, o>` of a motion and a force (or the 6-vector dot product).
    #[inline(always)]
    pub(crate) fn dot(&self, o: &Self) -> Lanes<W> {
        self.ang.dot_add(&o.ang, self.lin.dot(&o.lin))
    }
    /// `<self, o> + c`, fused.
    #[inline(always)]
    pub(crate) fn dot_add(&self, o: &Self, c: Lanes<W>) -> Lanes<W> {
        self.ang.dot_add(&o.ang, self.lin.dot_add(&o.lin, c))
    }
    /// `self * s` for a lane scalar.
    #[inline(always)]
    pub(crate) fn mul_lanes(&self, s: Lanes<W>) -> Self {
        SpatialLanes {
            ang: self.ang.mul_lanes(s),
            lin: self.lin.mul_lanes(s),
        }
    }
    /// Motion cross product `self x m` (both motions).
    #[inline(always)]
    pub(crate) fn cross(&self, m: &Self) -> Self {
        SpatialLanes {
            ang: self.ang.cross(&m.ang),
            lin: self.ang.cross(&m.lin).add(&self.lin.cross(&m.ang)),
        }
    }
    /// Dual cross product `self x* f` (a motion acting on a force).
    #[inline(always)]
    pub(crate) fn cross_force(&self, f: &Self) -> Self {
        SpatialLanes {
            ang: self.ang.cross(&f.ang).add(&self.lin.cross(&f.lin)),
            lin: self.ang.cross(&f.lin),
        }
    }
}

impl<const W: usize> Lanes<W> {
    /// `*dst = self`, on 4 lanes as one 32-byte store. A plain assignment of lanes assembled
    /// from parts (a rotation from its columns) was stored in pieces, 8 and 16 bytes at a time:
    /// a 32-byte load right after it (a child's pose reading its parent's) then could not be
    /// forwarded from those stores and waited for them to reach the cache (measured, wheels
    /// alternated on a Zen 4: the tree's AVX2 mass matrix 3.5 % faster with the poses stored
    /// so, the Panda's derivatives 3.7 %). 4 lanes are only used on AVX2's path, so AVX is
    /// there (checked in debug builds).
    #[inline(always)]
    pub(crate) fn put(self, dst: &mut Lanes<W>) {
        #[cfg(target_arch = "x86_64")]
        if W == 4 {
            use std::arch::x86_64::{__m256d, _mm256_store_pd};
            debug_assert!(std::arch::is_x86_feature_detected!("avx"));
            // SAFETY: W == 4: 32 bytes, 32-aligned (`Lanes` is), read as one __m256d; the
            // processor has AVX (above)
            unsafe {
                let v = std::ptr::read(&self as *const Lanes<W> as *const __m256d);
                _mm256_store_pd(dst.0.as_mut_ptr(), v);
            }
            return;
        }
        *dst = self;
    }
}
impl<const W: usize> Vector3Lanes<W> {
    /// `*dst = self` by [`Lanes::put`].
    #[inline(always)]
    pub(crate) fn put(&self, dst: &mut Vector3Lanes<W>) {
        self.x.put(&mut dst.x);
        self.y.put(&mut dst.y);
        self.z.put(&mut dst.z);
    }
}
impl<const W: usize> Rotation3Lanes<W> {
    /// `*dst = self` by [`Lanes::put`].
    #[inline(always)]
    pub(crate) fn put(&self, dst: &mut Rotation3Lanes<W>) {
        for r in 0..3 {
            self.0[r].put(&mut dst.0[r]);
        }
    }
}
impl<const W: usize> SpatialLanes<W> {
    /// `*dst = self` by [`Lanes::put`].
    #[inline(always)]
    pub(crate) fn put(&self, dst: &mut SpatialLanes<W>) {
        self.ang.put(&mut dst.ang);
        self.lin.put(&mut dst.lin);
    }
}
