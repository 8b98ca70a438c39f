//! Lanes to rows one value at a time: the quantities the blocks of [`super::write_rows`] leave.

use crate::simd::Lanes;

/// Quantities `from..to` of `src` into those columns of rows `0..used` of `dst`, one value at a
/// time; the finiteness bits.
#[inline(always)]
#[allow(clippy::eq_op)] // `v - v` is the finiteness test, not a mistake
pub(in crate::simd) fn scalars<const W: usize>(
    src: &[Lanes<W>],
    used: usize,
    dst: &mut [f64],
    stride: usize,
    from: usize,
    to: usize,
) -> u64 {
    let mut bits = 0u64;
    if from < to {
        for l in 0..used {
            let row = &mut dst[l * stride..l * stride + to];
            for c in crate::simd::serial(from..to) {
                let v = src[c].0[l];
                row[c] = v;
                bits |= (v - v).to_bits();
            }
        }
    }
    bits
}
