//! Arithmetic on a few samples side by side (structure of arrays): a scalar per lane
//! [`Lanes`], 3-vectors [`Vector3Lanes`], rotations [`Rotation3Lanes`] and spatial vectors
//! [`SpatialLanes`] of lanes. Each operation is a short loop over the lanes that the compiler
//! maps onto SIMD registers; used by the multi-sample kernels ([`crate::algorithms::batch`]).

/// Defines `$vis fn $name(args) -> ret` that runs `$body(args)` (an `#[inline(always)]`
/// function) compiled for AVX2 and FMA when the processor has them (checked at run time, then
/// cached by the standard library), and compiled for the baseline instruction set otherwise.
/// The AVX2 copy is the private `$avx`.
macro_rules! simd_dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident, $avx:ident => $body:ident ($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
            {
                // SAFETY: the processor supports the features `$avx` is compiled for.
                return unsafe { $avx($($arg),*) };
            }
            $body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn $avx($($arg: $ty),*) -> $ret {
            $body($($arg),*)
        }
    };
}
pub(crate) use simd_dispatch;

/// Samples processed together.
pub const LANES: usize = 4;

/// One scalar per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Lanes(pub(crate) [f64; LANES]);

impl Lanes {
    #[inline(always)]
    pub(crate) fn splat(x: f64) -> Self {
        Lanes([x; LANES])
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl std::ops::$tr for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, o: Lanes) -> Lanes {
                Lanes(std::array::from_fn(|l| self.0[l] $op o.0[l]))
            }
        }
        impl std::ops::$tr<f64> for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, o: f64) -> Lanes {
                Lanes(self.0.map(|a| a $op o))
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

/// A 3-vector per lane.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Vector3Lanes {
    pub(crate) x: Lanes,
    pub(crate) y: Lanes,
    pub(crate) z: Lanes,
}

impl Vector3Lanes {
    #[inline(always)]
    pub(crate) fn splat(v: &nalgebra::Vector3<f64>) -> Self {
        Vector3Lanes {
            x: Lanes::splat(v.x),
            y: Lanes::splat(v.y),
            z: Lanes::splat(v.z),
        }
    }
    #[inline(always)]
    pub(crate) fn cross(&self, o: &Vector3Lanes) -> Vector3Lanes {
        Vector3Lanes {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
    #[inline(always)]
    pub(crate) fn add(&self, o: &Vector3Lanes) -> Vector3Lanes {
        Vector3Lanes {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    pub(crate) fn sub(&self, o: &Vector3Lanes) -> Vector3Lanes {
        Vector3Lanes {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    pub(crate) fn scale(&self, s: f64) -> Vector3Lanes {
        Vector3Lanes {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    /// `a * s` for a constant vector `a` and a lane scalar `s`.
    #[inline(always)]
    pub(crate) fn of(a: &nalgebra::Vector3<f64>, s: Lanes) -> Vector3Lanes {
        Vector3Lanes {
            x: s * a.x,
            y: s * a.y,
            z: s * a.z,
        }
    }
    #[inline(always)]
    pub(crate) fn dot(&self, o: &Vector3Lanes) -> Lanes {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// `self * s` for a lane scalar `s`.
    #[inline(always)]
    pub(crate) fn mul_lanes(&self, s: Lanes) -> Vector3Lanes {
        Vector3Lanes {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    /// `a . self` for a constant vector `a`.
    #[inline(always)]
    pub(crate) fn dot_const(&self, a: &nalgebra::Vector3<f64>) -> Lanes {
        self.x * a.x + self.y * a.y + self.z * a.z
    }
    /// `m * self` for a constant matrix `m`.
    #[inline(always)]
    pub(crate) fn mul_const(&self, m: &nalgebra::Matrix3<f64>) -> Vector3Lanes {
        Vector3Lanes {
            x: self.x * m[(0, 0)] + self.y * m[(0, 1)] + self.z * m[(0, 2)],
            y: self.x * m[(1, 0)] + self.y * m[(1, 1)] + self.z * m[(1, 2)],
            z: self.x * m[(2, 0)] + self.y * m[(2, 1)] + self.z * m[(2, 2)],
        }
    }
}

/// A rotation per lane, by rows.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Rotation3Lanes(pub(crate) [Vector3Lanes; 3]);

impl Rotation3Lanes {
    /// `self * o`.
    #[inline(always)]
    pub(crate) fn compose(&self, o: &Rotation3Lanes) -> Rotation3Lanes {
        let row = |a: &Vector3Lanes| Vector3Lanes {
            x: a.x * o.0[0].x + a.y * o.0[1].x + a.z * o.0[2].x,
            y: a.x * o.0[0].y + a.y * o.0[1].y + a.z * o.0[2].y,
            z: a.x * o.0[0].z + a.y * o.0[1].z + a.z * o.0[2].z,
        };
        Rotation3Lanes([row(&self.0[0]), row(&self.0[1]), row(&self.0[2])])
    }
    /// Column `k`.
    #[inline(always)]
    pub(crate) fn column(&self, k: usize) -> Vector3Lanes {
        let pick = |r: &Vector3Lanes| match k {
            0 => r.x,
            1 => r.y,
            _ => r.z,
        };
        Vector3Lanes {
            x: pick(&self.0[0]),
            y: pick(&self.0[1]),
            z: pick(&self.0[2]),
        }
    }
    /// `self * a` for a constant vector `a`.
    #[inline(always)]
    pub(crate) fn mul_const_vector(&self, a: &nalgebra::Vector3<f64>) -> Vector3Lanes {
        Vector3Lanes {
            x: self.0[0].dot_const(a),
            y: self.0[1].dot_const(a),
            z: self.0[2].dot_const(a),
        }
    }
    #[inline(always)]
    pub(crate) fn mul(&self, v: &Vector3Lanes) -> Vector3Lanes {
        let d = |r: &Vector3Lanes| r.x * v.x + r.y * v.y + r.z * v.z;
        Vector3Lanes {
            x: d(&self.0[0]),
            y: d(&self.0[1]),
            z: d(&self.0[2]),
        }
    }
    #[inline(always)]
    pub(crate) fn tr_mul(&self, v: &Vector3Lanes) -> Vector3Lanes {
        let [a, b, c] = &self.0;
        Vector3Lanes {
            x: a.x * v.x + b.x * v.y + c.x * v.z,
            y: a.y * v.x + b.y * v.y + c.y * v.z,
            z: a.z * v.x + b.z * v.y + c.z * v.z,
        }
    }
}

/// A spatial vector per lane (`angular`, `linear`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SpatialLanes {
    pub(crate) ang: Vector3Lanes,
    pub(crate) lin: Vector3Lanes,
}

/// `pi / 2` split in three: the first two with 33 significant bits (so `k * P1`, `k * P2` are
/// exact for |k| < 2^20), the third the rest (fdlibm's `pio2_1`, `pio2_2`, `pio2_2t`).
const PIO2: [f64; 3] = [
    1.5707963267341256,     // 0x1.921fb54400000p+0
    6.077100506303966e-11,  // 0x1.0b4611a600000p-34
    2.0222662487959506e-21, // 0x1.3198a2e037073p-69
];

/// Lanes up to this magnitude (rad) take the polynomial path; larger ones, and non-finite
/// ones, the standard library's `sin_cos`.
const SINCOS_RANGE: f64 = 1e6;

/// Taylor coefficients of `sin(r) / r` and `cos(r)` in powers of `z = r^2`.
const SIN: [f64; 9] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362880.0,
    -1.0 / 39916800.0,
    1.0 / 6227020800.0,
    -1.0 / 1307674368000.0,
    1.0 / 355687428096000.0,
];
const COS: [f64; 10] = [
    1.0,
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40320.0,
    -1.0 / 3628800.0,
    1.0 / 479001600.0,
    -1.0 / 87178291200.0,
    1.0 / 20922789888000.0,
    -1.0 / 6402373705728000.0,
];

/// `(sin x, cos x)` of every lane, within about 1 ulp of the standard library's: the argument is
/// reduced by multiples of `pi / 2` (Cody-Waite, three parts) to `[-pi/4, pi/4]`, where Taylor
/// series to degree 17 (sin) and 18 (cos) are exact to below half an ulp.
#[inline(always)]
pub(crate) fn sin_cos(x: Lanes) -> (Lanes, Lanes) {
    if x.0.iter().any(|v| v.is_nan() || v.abs() > SINCOS_RANGE) {
        let sc = x.0.map(f64::sin_cos);
        return (Lanes(sc.map(|v| v.0)), Lanes(sc.map(|v| v.1)));
    }
    // k = round(x 2 / pi) by the 1.5 * 2^52 trick (exact for |k| < 2^51); the low bits of the
    // shifted value are k's, so the quadrant k mod 4 needs no float-to-integer conversion
    const SHIFTER: f64 = 6755399441055744.0;
    let shifted = x * std::f64::consts::FRAC_2_PI + SHIFTER;
    let k = shifted - SHIFTER;
    let r = ((x - k * PIO2[0]) - k * PIO2[1]) - k * PIO2[2];
    let z = r * r;
    // sin r = r (1 - z/3! + z^2/5! - ...), cos r = 1 - z/2! + z^2/4! - ... (Horner, unrolled)
    let mut ps = Lanes::splat(SIN[SIN.len() - 1]);
    for &ci in SIN[..SIN.len() - 1].iter().rev() {
        ps = ps * z + ci;
    }
    let mut pc = Lanes::splat(COS[COS.len() - 1]);
    for &ci in COS[..COS.len() - 1].iter().rev() {
        pc = pc * z + ci;
    }
    let s = r * ps;
    let mut sin = [0.0; LANES];
    let mut cos = [0.0; LANES];
    for l in 0..LANES {
        // quadrant q: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s) for q = 0, 1, 2, 3
        let q = shifted.0[l].to_bits();
        let swap = q & 1 == 1;
        let (a, b) = if swap {
            (pc.0[l], s.0[l])
        } else {
            (s.0[l], pc.0[l])
        };
        sin[l] = f64::from_bits(a.to_bits() ^ ((q & 2) << 62));
        cos[l] = f64::from_bits(b.to_bits() ^ (((q + 1) & 2) << 62));
    }
    (Lanes(sin), Lanes(cos))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_matches_the_standard_library() {
        let mut xs: Vec<f64> = (0..200_000)
            .map(|i| (i as f64 - 100_000.0) * 3.3e-4)
            .collect();
        for k in -40..=40 {
            let m = k as f64 * std::f64::consts::FRAC_PI_2;
            xs.extend([m, m.next_up(), m.next_down(), m + 1e-9, m - 1e-7]);
        }
        xs.extend([0.0, -0.0, 1e-300, -1e-12, 123456.789, -999999.0, 2e6, -3e7]);
        let mut worst: f64 = 0.0;
        for group in xs.chunks_exact(LANES) {
            let (s, c) = sin_cos(Lanes(group.try_into().unwrap()));
            for (l, x) in group.iter().enumerate() {
                let (es, ec) = x.sin_cos();
                worst = worst.max((s.0[l] - es).abs()).max((c.0[l] - ec).abs());
            }
        }
        assert!(worst <= 4.5e-16, "worst absolute difference {worst:e}");
        let (s, c) = sin_cos(Lanes([f64::NAN, 0.5, f64::INFINITY, -0.5]));
        assert!(s.0[0].is_nan() && c.0[2].is_nan() && s.0[1] == 0.5f64.sin());
        assert_eq!(c.0[3], (-0.5f64).cos());
    }
}
