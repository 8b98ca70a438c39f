//! `sin` and `cos` of every lane at once, by polynomials the vector units evaluate (the standard
//! library's are one call per value).

use super::lanes::Lanes;

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

/// Minimax coefficients on `[-pi/4, pi/4]` (fdlibm's `__kernel_sin` `S1..S6`): `sin r = r + r z
/// (S1 + S2 z + ... + S6 z^5)`, `z = r^2`, within 2^-58 relative.
const SIN: [f64; 6] = [
    -1.666_666_666_666_663_2e-1,
    8.333_333_333_322_49e-3,
    -1.984_126_982_985_795e-4,
    2.755_731_370_707_006_8e-6,
    -2.505_076_025_340_686_3e-8,
    1.589_690_995_211_55e-10,
];
/// fdlibm's `__kernel_cos` `C1..C6`: `cos r = 1 - z / 2 + z^2 (C1 + C2 z + ... + C6 z^5)`.
const COS: [f64; 6] = [
    4.166_666_666_666_66e-2,
    -1.388_888_888_887_411e-3,
    2.480_158_728_947_673e-5,
    -2.755_731_435_139_066_3e-7,
    2.087_572_321_298_175e-9,
    -1.135_964_755_778_819_5e-11,
];

/// `(sin x, cos x)` of every lane, within about 1 ulp of the standard library's: the argument is
/// reduced by multiples of `pi / 2` (Cody-Waite, three parts) to `[-pi/4, pi/4]`, where fdlibm's
/// minimax polynomials (degree 13 and 14) are exact to below half an ulp.
#[inline(always)]
pub(crate) fn sin_cos<const W: usize>(x: Lanes<W>) -> (Lanes<W>, Lanes<W>) {
    if x.any_nan_or_beyond(SINCOS_RANGE) {
        let sc = x.0.map(f64::sin_cos);
        return (Lanes(sc.map(|v| v.0)), Lanes(sc.map(|v| v.1)));
    }
    // k = round(x 2 / pi) by the 1.5 * 2^52 trick (exact for |k| < 2^51); the low bits of the
    // shifted value are k's, so the quadrant k mod 4 needs no float-to-integer conversion
    const SHIFTER: f64 = 6755399441055744.0;
    let shifted = x.mul_add_s(std::f64::consts::FRAC_2_PI, Lanes::splat(SHIFTER));
    let k = shifted - SHIFTER;
    let r = k.neg_mul_add(
        Lanes::splat(PIO2[2]),
        k.neg_mul_add(
            Lanes::splat(PIO2[1]),
            k.neg_mul_add(Lanes::splat(PIO2[0]), x),
        ),
    );
    let z = r * r;
    // the polynomials in z by Estrin's scheme (pairs of terms, then pairs of pairs): each value
    // three or four dependent operations from z where Horner's took six to eight, so that the
    // kernels' passes, which wait on a joint's sine and cosine, wait less
    let c = |v: f64| Lanes::splat(v);
    let (z2, rz) = (z * z, r * z);
    let z4 = z2 * z2;
    let p = z2.mul_add(
        z2.mul_add(
            c(SIN[5]).mul_add(z, c(SIN[4])),
            c(SIN[3]).mul_add(z, c(SIN[2])),
        ),
        c(SIN[1]).mul_add(z, c(SIN[0])),
    );
    let s = rz.mul_add(p, r);
    let low = z2.mul_add(c(COS[1]).mul_add(z, c(COS[0])), c(-0.5).mul_add(z, c(1.0)));
    let high = z2.mul_add(
        c(COS[5]).mul_add(z, c(COS[4])),
        c(COS[3]).mul_add(z, c(COS[2])),
    );
    let pc = z4.mul_add(high, low);
    let mut sin = [0.0; W];
    let mut cos = [0.0; W];
    for l in 0..W {
        // quadrant q: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s) for q = 0, 1, 2, 3; by
        // selects (blends) and sign flips, not branches, the same operations in every lane (so
        // that they vectorise whole: a per-lane branch split the polynomials into pieces of 1,
        // 2 and 4 lanes). The selects measured against and-or masks, whole builds alternated
        // on a Zen 4: the Panda's AVX2 regressor 3 % faster, its mass matrix 2 %, the tree's
        // kernels level
        let q = shifted.0[l].to_bits();
        let (a, b) = if q & 1 != 0 {
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
        for group in xs.chunks_exact(4) {
            let (s, c) = sin_cos::<4>(Lanes(group.try_into().unwrap()));
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
