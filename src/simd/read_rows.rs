//! Rows of a row-major array read into lanes: the inverse of [`super::write_rows`], for the
//! kernels' inputs (each sample's coordinates a row, each lane a sample).

use super::Lanes;

/// `dst[i].0[l] = src[rows[l] + i]` for `i < dst.len()` and every lane `l`: lane `l` of the
/// quantities from the row starting at `rows[l]`. Every row must hold `dst.len()` values
/// (`rows[l] + dst.len() <= src.len()`; slice indexing panics otherwise, the callers size
/// both from the same shapes).
///
/// With AVX-512 (8 lanes, `wide`: the kernel runs on AVX-512, so that a kernel on AVX2's path
/// never takes it, whatever else the processor has) blocks of 8 quantities are transposed in
/// 512-bit registers (8 loads, 24 shuffles, 8 stores), with AVX blocks of 4 by 4 in 256-bit
/// ones, instead of gathering one value at a time (measured: the 60-dof tree's inverse dynamics
/// spent 15 % of its time gathering its inputs).
#[inline(always)]
pub(crate) fn read_rows<const W: usize>(
    src: &[f64],
    rows: &[usize; W],
    dst: &mut [Lanes<W>],
    wide: bool,
) {
    let mut c = 0;
    #[cfg(target_arch = "x86_64")]
    if W.is_multiple_of(4) && std::arch::is_x86_feature_detected!("avx") {
        c = if W == 8
            && wide
            && std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512dq")
        {
            // SAFETY: the processor has AVX-512F and DQ (checked above)
            unsafe { blocks_avx512(src, rows, dst) }
        } else {
            // SAFETY: the processor has AVX (checked above)
            unsafe { blocks_avx(src, rows, dst) }
        };
    }
    for (i, d) in dst.iter_mut().enumerate().skip(c) {
        for (o, &r) in d.0.iter_mut().zip(rows) {
            *o = src[r + i];
        }
    }
}

/// [`read_rows`]' blocks of 8 quantities with AVX-512 (`W == 8`); returns how many quantities
/// it read (a multiple of 8).
///
/// # Safety
/// The processor has AVX-512F and DQ.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx512f,avx512dq")]
#[inline(never)]
unsafe fn blocks_avx512<const W: usize>(
    src: &[f64],
    rows: &[usize; W],
    dst: &mut [Lanes<W>],
) -> usize {
    use std::arch::x86_64::_mm512_storeu_pd;
    let n = dst.len();
    let mut c = 0;
    while c + 8 <= n {
        // one bounds-checked row of 8 values
        let r = super::rows::load8(|l| src[rows[l] + c..rows[l] + c + 8].as_ptr());
        for (q, v) in super::rows::transposed8(r).into_iter().enumerate() {
            // (bounds-checked: fails unless W >= 8)
            _mm512_storeu_pd(dst[c + q].0[..8].as_mut_ptr(), v);
        }
        c += 8;
    }
    c
}

/// [`read_rows`]' blocks of 4 quantities by 4 lanes with AVX (`W` a multiple of 4); returns
/// how many quantities it read (a multiple of 4).
///
/// # Safety
/// The processor has AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline(never)]
unsafe fn blocks_avx<const W: usize>(
    src: &[f64],
    rows: &[usize; W],
    dst: &mut [Lanes<W>],
) -> usize {
    use std::arch::x86_64::{_mm256_loadu_pd, _mm256_storeu_pd};
    let n = dst.len();
    let mut c = 0;
    while c + 4 <= n {
        for lb in (0..W).step_by(4) {
            let at = |l: usize| src[rows[lb + l] + c..rows[lb + l] + c + 4].as_ptr();
            let r = [
                _mm256_loadu_pd(at(0)),
                _mm256_loadu_pd(at(1)),
                _mm256_loadu_pd(at(2)),
                _mm256_loadu_pd(at(3)),
            ];
            for (q, v) in super::rows::transposed4x4(r).into_iter().enumerate() {
                _mm256_storeu_pd(dst[c + q].0[lb..lb + 4].as_mut_ptr(), v);
            }
        }
        c += 4;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<const W: usize>() {
        for (n, wide) in [0, 1, 3, 4, 5, 8, 9, 17, 60]
            .into_iter()
            .flat_map(|n| [(n, false), (n, true)])
        {
            for stride in [n, n + 3] {
                let src: Vec<f64> = (0..W * stride + 5).map(|v| v as f64 * 0.5 - 7.0).collect();
                // rows in any order, some repeated (the last sample again past a batch's end)
                let mut rows = [0; W];
                for (l, r) in rows.iter_mut().enumerate() {
                    *r = (l * 5 + 2) % W * stride + usize::from(l % 3 == 1);
                }
                rows[W - 1] = rows[W / 2];
                let mut dst = vec![Lanes::<W>::splat(f64::NAN); n];
                read_rows(&src, &rows, &mut dst, wide);
                for (i, d) in dst.iter().enumerate() {
                    for l in 0..W {
                        assert_eq!(
                            d.0[l],
                            src[rows[l] + i],
                            "W {W} n {n} wide {wide} i {i} lane {l}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn rows_are_read_into_lanes() {
        check::<1>();
        check::<4>();
        check::<8>();
    }
}
