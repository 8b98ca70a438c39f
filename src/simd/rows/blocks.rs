//! The x86 writers of [`super::write_rows`]: blocks of quantities by lanes transposed in
//! registers (4x4 in 256-bit ones with AVX, 8x8 in 512-bit ones with AVX-512), stored a row at a
//! time (non-temporally where asked), with the finiteness test of the values on the way.

use super::scalars::scalars;
use super::stores::Stores;
use super::zero_pattern::ZeroPattern;
use crate::simd::Lanes;

/// [`super::write_rows_with_zeros`]'s work with AVX-512 (8 full lanes, `W == 8`): blocks of 8
/// by 8 in 512-bit registers ([`transpose8`]), from a cache line's start where every row falls
/// alike on the lines (`stride` a multiple of 8), each row on its own lines where they do not
/// and `stores.lined` asks for it ([`lined8`]), the rest by [`narrow`]. Returns the
/// finiteness bits: 0 when every value is vouched finite.
///
/// # Safety
/// The processor has AVX-512F and DQ, and `W == 8`.
#[target_feature(enable = "avx,avx512f,avx512dq")]
#[inline(never)]
pub(super) unsafe fn blocks_avx512<const W: usize>(
    src: &[Lanes<W>],
    zeros: Option<&ZeroPattern>,
    dst: &mut [f64],
    stride: usize,
    stores: Stores,
) -> u64 {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_setzero_pd, _mm512_add_pd, _mm512_setzero_pd};
    let stream = stores.stream;
    let (n, used) = (src.len(), W);
    let zero = |c: usize, len: usize| zeros.is_some_and(|z| z.zero(c, len));
    let (mut sum, mut wide_sum) = (_mm256_setzero_pd(), _mm512_setzero_pd());
    // where the rows start in a cache line (in values; f64 slices are 8-byte aligned)
    let offset = (dst.as_ptr() as usize / 8) % 8;
    let head = if stride.is_multiple_of(8) {
        ((8 - offset) % 8).min(n)
    } else {
        0
    };
    if stores.lined && !stride.is_multiple_of(8) {
        // rows that fall each its own way on the lines: each laid on its own
        let c = lined8(src, &zero, dst, stride, stream, &mut wide_sum);
        let bits = narrow(src, &zero, used, dst, stride, c, n, &mut sum);
        return bits | not_finite4(_mm256_add_pd(sum, halves(wide_sum)));
    }
    let mut bits = narrow(src, &zero, used, dst, stride, 0, head, &mut sum);
    let mut c = head;
    if let Some(z) = zeros.filter(|z| stream && z.len() == n) {
        // streaming: the blocks as the pattern lists them (runs of zeros, blocks holding
        // values), not scanned for every group (measured, whole builds alternated on a Zen 4:
        // the 60-dof tree's regressor 4.5 % faster, its mass matrix level; outputs kept in the
        // caches, such as the Panda's regressor, were 4 % slower so and are scanned below).
        // The blocks' sum in a register of this loop's own: one shared with the loop below
        // was kept in memory, a store and a load on every block's chain.
        debug_assert!(head < 8, "the blocks start within the first line");
        let mut block_sum = _mm512_setzero_pd();
        for s in z.segments(head) {
            let c = s.start as usize;
            if s.zero_blocks > 0 {
                zero_run(dst, stride, c, c + 8 * s.zero_blocks as usize, true);
            } else if s.zero_halves != 0 {
                // half of the block structural zeros: only the other half read and turned
                half8(src, dst, stride, c, s.zero_halves & 1 != 0, &mut block_sum);
            } else {
                transpose8(&src[c..c + 8], dst, stride, c, true, &mut block_sum);
            }
        }
        wide_sum = _mm512_add_pd(wide_sum, block_sum);
        c = head + (n - head) / 8 * 8;
    }
    while c + 8 <= n {
        if zero(c, 8) {
            // a run of zero blocks: each row's part written in one go (whole lines, one row
            // after the other, rather than the rows in turn a line at a time)
            let mut end = c + 8;
            while end + 8 <= n && zero(end, 8) {
                end += 8;
            }
            zero_run(dst, stride, c, end, stream);
            c = end;
            continue;
        } else if !stream && (zero(c, 4) || zero(c + 4, 4)) {
            // (streaming, such a block goes whole, its zeros read from the buffer: a 32-byte
            // store into a line beside non-temporal ones costs 40 % on the tree's mass matrix)
            block4(src, zero(c, 4), used, dst, stride, c, &mut sum);
            block4(src, zero(c + 4, 4), used, dst, stride, c + 4, &mut sum);
        } else {
            transpose8(&src[c..c + 8], dst, stride, c, stream, &mut wide_sum);
        }
        c += 8;
    }
    bits |= narrow(src, &zero, used, dst, stride, c, n, &mut sum);
    bits | not_finite4(_mm256_add_pd(sum, halves(wide_sum)))
}

/// The halves of a 512-bit finiteness sum added into one of 256 bits (finite only if both are).
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn halves(sum: std::arch::x86_64::__m512d) -> std::arch::x86_64::__m256d {
    use std::arch::x86_64::{_mm256_add_pd, _mm512_castpd512_pd256, _mm512_extractf64x4_pd};
    _mm256_add_pd(
        _mm512_castpd512_pd256(sum),
        _mm512_extractf64x4_pd::<1>(sum),
    )
}

/// [`blocks_avx512`]'s blocks of 8 where the rows do not fall alike on the cache lines
/// (`stride` no multiple of 8 values: the Panda's 7 x 70 regressor, its 7 x 7 matrices): every
/// store one aligned cache line of one row. Each row's values are shifted to its own lines
/// across two consecutive transposed blocks (one `vpermt2pd` a row); a row's first and last
/// lines, shared with what lies beside it, are masked stores. Where the same blocks went
/// straight to `c..c + 8`, most of their 64-byte stores straddled two lines, each costing
/// twice. Writes quantities `0..8 (n / 8)`, which it returns (the rest for [`narrow`]); their
/// values are added to `sum` (see [`transpose4`]). Blocks that `zero` marks are not read.
/// With `stream`, the whole lines are stored non-temporally (as [`store8`]).
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn lined8<const W: usize>(
    src: &[Lanes<W>],
    zero: &impl Fn(usize, usize) -> bool,
    dst: &mut [f64],
    stride: usize,
    stream: bool,
    sum: &mut std::arch::x86_64::__m512d,
) -> usize {
    use std::arch::x86_64::{
        _mm512_add_epi64, _mm512_mask_storeu_pd, _mm512_permutex2var_pd, _mm512_set1_epi64,
        _mm512_set_epi64, _mm512_setzero_pd, _mm512_store_pd, _mm512_stream_pd,
    };
    let blocks = src.len() / 8;
    if blocks == 0 {
        return 0;
    }
    // rows 0..8, quantities 0..8 blocks (bounds-checked once)
    let rows = &mut dst[..7 * stride + 8 * blocks];
    let base = rows.as_mut_ptr();
    // row l starts `shift[l]` values into a line; line k of the row holds its quantities
    // 8 k - shift .. 8 k - shift + 8: the last `shift` of block k - 1, the first of block k,
    // which `vpermt2pd` picks by `pick[l]` (entry j: 8 - shift + j, of the first block if
    // below 8)
    let shift: [usize; 8] = std::array::from_fn(|l| (base.add(l * stride) as usize / 8) % 8);
    // (a loop, not a closure: one compiled out of line would lose the target feature)
    let mut pick = [_mm512_set1_epi64(0); 8];
    for (p, s) in pick.iter_mut().zip(shift) {
        *p = _mm512_add_epi64(
            _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0),
            _mm512_set1_epi64((8 - s) as i64),
        );
    }
    // the start of the line of row l that holds quantity c - shift (before `base` for the
    // first line of row 0 when it starts within a line: only the masked store's lanes within
    // the rows touch memory)
    let start = |l: usize, c: usize| base.add(l * stride + c).wrapping_sub(shift[l]);
    let mut previous = ([_mm512_setzero_pd(); 8], true);
    for k in 0..blocks {
        let c = 8 * k;
        let current = if zero(c, 8) {
            ([_mm512_setzero_pd(); 8], true)
        } else {
            let r = loaded8(&src[c..c + 8], sum);
            (transposed8(r), false)
        };
        for l in 0..8 {
            let (p, v) = if current.1 && previous.1 {
                (start(l, c), _mm512_setzero_pd())
            } else {
                let v = _mm512_permutex2var_pd(previous.0[l], pick[l], current.0[l]);
                (start(l, c), v)
            };
            // SAFETY: `p` is on a 64-byte boundary; the line's values are quantities
            // c - shift .. c - shift + 8 of row l, all within `rows` for k > 0 (c - shift >= 0,
            // c + 8 - shift <= 8 blocks), for k = 0 those from `shift` on (the mask)
            if k == 0 && shift[l] > 0 {
                _mm512_mask_storeu_pd(p, 0xffu8 << shift[l], v);
            } else if stream {
                _mm512_stream_pd(p, v);
            } else {
                _mm512_store_pd(p, v);
            }
        }
        previous = current;
    }
    // each row's last line: the last `shift` values of the last block
    for (l, s) in shift.into_iter().enumerate() {
        if s > 0 {
            let v = _mm512_permutex2var_pd(previous.0[l], pick[l], _mm512_setzero_pd());
            // SAFETY: the lanes below `shift` are quantities 8 blocks - shift .. 8 blocks of
            // row l, within `rows`
            _mm512_mask_storeu_pd(start(l, 8 * blocks), (1u8 << s) - 1, v);
        }
    }
    8 * blocks
}

/// [`super::write_rows_with_zeros`]'s work with AVX: blocks of 4 by 4 in 256-bit registers,
/// from a half cache line's start where every row falls alike on them (`stride` a multiple of
/// 4), or whole lines streamed ([`stream_lines4`]). Returns the finiteness bits as
/// [`blocks_avx512`].
///
/// # Safety
/// The processor has AVX.
#[target_feature(enable = "avx")]
#[inline(never)]
pub(super) unsafe fn blocks_avx<const W: usize>(
    src: &[Lanes<W>],
    zeros: Option<&ZeroPattern>,
    used: usize,
    dst: &mut [f64],
    stride: usize,
    stream: bool,
) -> u64 {
    let n = src.len();
    let zero = |c: usize, len: usize| zeros.is_some_and(|z| z.zero(c, len));
    let mut sum = std::arch::x86_64::_mm256_setzero_pd();
    let offset = (dst.as_ptr() as usize / 8) % 8;
    let mut bits = 0;
    let mut c = 0;
    if stream && used == W && stride.is_multiple_of(8) {
        // whole lines from pairs of 4x4 blocks, streamed: the first quantities singly up to a
        // line's start
        let head = ((8 - offset) % 8).min(n);
        bits |= narrow(src, &zero, used, dst, stride, 0, head, &mut sum);
        c = stream_lines4(src, zeros, dst, stride, head, &mut sum);
    } else if stride.is_multiple_of(4) {
        // 32-byte stores within one line each: the first quantities singly up to a half line
        let head = ((4 - offset % 4) % 4).min(n);
        bits |= narrow(src, &zero, used, dst, stride, 0, head, &mut sum);
        c = head;
    }
    bits |= narrow(src, &zero, used, dst, stride, c, n, &mut sum);
    bits | not_finite4(sum)
}

/// 1 unless every lane of the running sum `sum` is finite (see [`transpose4`]).
///
/// # Safety
/// The processor has AVX; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn not_finite4(sum: std::arch::x86_64::__m256d) -> u64 {
    let mut lanes = [0.0; 4];
    std::arch::x86_64::_mm256_storeu_pd(lanes.as_mut_ptr(), sum);
    u64::from(!lanes.iter().all(|v| v.is_finite()))
}

/// Quantities `from..to` of `src` into those columns of rows `0..used` of `dst`: blocks of 4
/// by 4x4 transposes from `from` on (zeros unread where `zero` says so), the last fewer than 4
/// one value at a time. The blocks' values are added to `sum` (see [`transpose4`]); returns the
/// finiteness bits of the values written singly (as [`scalars`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn narrow<const W: usize>(
    src: &[Lanes<W>],
    zero: &impl Fn(usize, usize) -> bool,
    used: usize,
    dst: &mut [f64],
    stride: usize,
    from: usize,
    to: usize,
    sum: &mut std::arch::x86_64::__m256d,
) -> u64 {
    let mut c = from;
    while c + 4 <= to {
        block4(src, zero(c, 4), used, dst, stride, c, sum);
        c += 4;
    }
    scalars(src, used, dst, stride, c, to)
}

/// Quantities `c..c + 4` of `src` (zeros if `zero`) into columns `c..c + 4` of the rows
/// `0..used` of `dst` by 4x4 transposes, their values added to `sum` (see [`transpose4`]).
#[inline(always)]
fn block4<const W: usize>(
    src: &[Lanes<W>],
    zero: bool,
    used: usize,
    dst: &mut [f64],
    stride: usize,
    c: usize,
    sum: &mut std::arch::x86_64::__m256d,
) {
    if zero {
        if used == W {
            // one bounds check for the rows, then plain 32-byte stores
            let block = &mut dst[c..c + (W - 1) * stride + 4];
            let at = block.as_mut_ptr();
            for l in 0..W {
                // SAFETY: `block` holds `(W - 1) * stride + 4` values, so `l * stride + 4` fit
                // for l < W; the callers checked for AVX
                unsafe {
                    std::arch::x86_64::_mm256_storeu_pd(
                        at.add(l * stride),
                        std::arch::x86_64::_mm256_setzero_pd(),
                    )
                };
            }
        } else {
            for l in 0..used {
                let at = l * stride + c;
                dst[at..at + 4].fill(0.0);
            }
        }
    } else {
        // the block's own sum first, then one add to the running one: a single chain of adds
        // through every block would bound the blocks' rate by the adds' latency
        // SAFETY: the callers checked for AVX
        let mut block = unsafe { std::arch::x86_64::_mm256_setzero_pd() };
        if used == W {
            // (the usual case: every row count known to the compiler)
            for lb in (0..W).step_by(4) {
                // SAFETY: the callers checked for AVX; every pointer comes from a
                // bounds-checked slice.
                unsafe { transpose4(&src[c..c + 4], lb, 4, dst, stride, c, &mut block) };
            }
        } else {
            for lb in (0..used).step_by(4) {
                // SAFETY: as above
                unsafe { transpose4(&src[c..c + 4], lb, used - lb, dst, stride, c, &mut block) };
            }
        }
        // SAFETY: as above
        *sum = unsafe { std::arch::x86_64::_mm256_add_pd(*sum, block) };
    }
}

/// Zeros into columns `from..to` (`to - from` a multiple of 8) of rows `0..8` of `dst` (row
/// `l` at `l * stride`), a row at a time: 64-byte stores, non-temporal if `stream` where they
/// are whole cache lines (as [`store8`]).
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn zero_run(dst: &mut [f64], stride: usize, from: usize, to: usize, stream: bool) {
    use std::arch::x86_64::{_mm512_setzero_pd, _mm512_storeu_pd, _mm512_stream_pd};
    let block = &mut dst[from..to + 7 * stride];
    let at = block.as_mut_ptr();
    let z = _mm512_setzero_pd();
    let lines = stream && (at as usize).is_multiple_of(64) && stride.is_multiple_of(8);
    for l in 0..8 {
        let mut c = 0;
        while c < to - from {
            // SAFETY: `block` holds `to - from + 7 * stride` values, so `l * stride + c + 8`
            // fit for l <= 7 and c + 8 <= to - from; whole lines where streamed (checked above)
            let p = at.add(l * stride + c);
            if lines {
                _mm512_stream_pd(p, z);
            } else {
                _mm512_storeu_pd(p, z);
            }
            c += 8;
        }
    }
}

/// `rows[l]` into columns `c..c + 8` of row `l` of `dst` (at `l * stride`) for `l < 8`: one
/// bounds check, 8 stores of 64 bytes. With `stream`, where those are whole cache lines (the
/// block's first row on a line, `stride` a multiple of 8 values), non-temporal ones.
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn store8(
    dst: &mut [f64],
    stride: usize,
    c: usize,
    rows: [std::arch::x86_64::__m512d; 8],
    stream: bool,
) {
    use std::arch::x86_64::{_mm512_storeu_pd, _mm512_stream_pd};
    let block = &mut dst[c..c + 7 * stride + 8];
    let at = block.as_mut_ptr();
    if stream && (at as usize).is_multiple_of(64) && stride.is_multiple_of(8) {
        for (l, v) in rows.into_iter().enumerate() {
            // SAFETY: `block` holds `7 * stride + 8` values, so `l * stride + 8` fit for
            // l <= 7; each row starts on a 64-byte boundary (checked above)
            _mm512_stream_pd(at.add(l * stride), v);
        }
    } else {
        for (l, v) in rows.into_iter().enumerate() {
            // SAFETY: as above
            _mm512_storeu_pd(at.add(l * stride), v);
        }
    }
}

/// The 8 lanes of the 8 quantities `src` (`W == 8`) into columns `c..c + 8` of rows `0..8` of
/// `dst` (row `l` at `l * stride`): 8 loads, 24 shuffles, 8 stores of 64 bytes ([`store8`]).
/// The loaded quantities are added to `sum` (8 adds; see [`transpose4`]).
///
/// # Safety
/// The processor has AVX-512F. The function has no `target_feature` of its own (that would
/// forbid `inline(always)`): inlined into [`blocks_avx512`], its intrinsics compile to single
/// instructions there.
#[inline(always)]
unsafe fn transpose8<const W: usize>(
    src: &[Lanes<W>],
    dst: &mut [f64],
    stride: usize,
    c: usize,
    stream: bool,
    sum: &mut std::arch::x86_64::__m512d,
) {
    let r = loaded8(src, sum);
    let out = transposed8(r);
    store8(dst, stride, c, out, stream);
}

/// As [`transpose8`] streamed, for quantities `c..c + 8` of `src` of which the first four
/// (`low_zero`) or the last four are structural zeros: only the other four read (and added to
/// `sum`), turned into rows by 16 shuffles instead of 24, the zeros put beside them.
///
/// # Safety
/// As [`transpose8`].
#[inline(always)]
unsafe fn half8<const W: usize>(
    src: &[Lanes<W>],
    dst: &mut [f64],
    stride: usize,
    c: usize,
    low_zero: bool,
    sum: &mut std::arch::x86_64::__m512d,
) {
    use std::arch::x86_64::{
        _mm512_add_pd, _mm512_loadu_pd, _mm512_setzero_pd, _mm512_shuffle_f64x2,
        _mm512_unpackhi_pd, _mm512_unpacklo_pd,
    };
    let q = &src[if low_zero { c + 4 } else { c }..][..4];
    let [a, b, x, y] = [
        _mm512_loadu_pd(q[0].0[..8].as_ptr()),
        _mm512_loadu_pd(q[1].0[..8].as_ptr()),
        _mm512_loadu_pd(q[2].0[..8].as_ptr()),
        _mm512_loadu_pd(q[3].0[..8].as_ptr()),
    ];
    *sum = _mm512_add_pd(
        *sum,
        _mm512_add_pd(_mm512_add_pd(a, b), _mm512_add_pd(x, y)),
    );
    // pairs of quantities by lane: even lanes (lo) and odd lanes (hi) of a, b and of x, y
    let (t0, t1) = (_mm512_unpacklo_pd(a, b), _mm512_unpackhi_pd(a, b));
    let (t2, t3) = (_mm512_unpacklo_pd(x, y), _mm512_unpackhi_pd(x, y));
    // u[l] (l < 4): 128-bit pieces [a b of lane l, a b of lane l + 4, x y of lane l, x y of
    // lane l + 4]
    let u = [
        _mm512_shuffle_f64x2::<0x88>(t0, t2),
        _mm512_shuffle_f64x2::<0x88>(t1, t3),
        _mm512_shuffle_f64x2::<0xdd>(t0, t2),
        _mm512_shuffle_f64x2::<0xdd>(t1, t3),
    ];
    let z = _mm512_setzero_pd();
    // lane l's row: u[l]'s pieces 0, 2 (lanes below 4) or 1, 3, into the row's half that
    // holds values, zeros in the other
    let rows = if low_zero {
        [
            _mm512_shuffle_f64x2::<0x80>(z, u[0]),
            _mm512_shuffle_f64x2::<0x80>(z, u[1]),
            _mm512_shuffle_f64x2::<0x80>(z, u[2]),
            _mm512_shuffle_f64x2::<0x80>(z, u[3]),
            _mm512_shuffle_f64x2::<0xd0>(z, u[0]),
            _mm512_shuffle_f64x2::<0xd0>(z, u[1]),
            _mm512_shuffle_f64x2::<0xd0>(z, u[2]),
            _mm512_shuffle_f64x2::<0xd0>(z, u[3]),
        ]
    } else {
        [
            _mm512_shuffle_f64x2::<0x08>(u[0], z),
            _mm512_shuffle_f64x2::<0x08>(u[1], z),
            _mm512_shuffle_f64x2::<0x08>(u[2], z),
            _mm512_shuffle_f64x2::<0x08>(u[3], z),
            _mm512_shuffle_f64x2::<0x0d>(u[0], z),
            _mm512_shuffle_f64x2::<0x0d>(u[1], z),
            _mm512_shuffle_f64x2::<0x0d>(u[2], z),
            _mm512_shuffle_f64x2::<0x0d>(u[3], z),
        ]
    };
    store8(dst, stride, c, rows, true);
}

/// The 8 lanes of the 8 quantities `src` (`W == 8`; bounds-checked: fails unless `W >= 8` and
/// `src` holds 8), loaded; their sum added to `sum` (8 adds; see [`transpose4`]).
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
unsafe fn loaded8<const W: usize>(
    src: &[Lanes<W>],
    sum: &mut std::arch::x86_64::__m512d,
) -> [std::arch::x86_64::__m512d; 8] {
    use std::arch::x86_64::_mm512_add_pd;
    let r = load8(|q| src[q].0[..8].as_ptr());
    let block = _mm512_add_pd(
        _mm512_add_pd(_mm512_add_pd(r[0], r[1]), _mm512_add_pd(r[2], r[3])),
        _mm512_add_pd(_mm512_add_pd(r[4], r[5]), _mm512_add_pd(r[6], r[7])),
    );
    *sum = _mm512_add_pd(*sum, block);
    r
}

/// The 8 values at each of `at(0)`, ..., `at(7)` (512-bit loads).
///
/// # Safety
/// The processor has AVX-512F; each pointer is valid for 8 values. No `target_feature` of
/// its own, as [`transpose8`] (`at` computes pointers only: compiled out of line, it would
/// lose no instruction set).
#[inline(always)]
pub(in crate::simd) unsafe fn load8(
    at: impl Fn(usize) -> *const f64,
) -> [std::arch::x86_64::__m512d; 8] {
    use std::arch::x86_64::_mm512_loadu_pd;
    [
        _mm512_loadu_pd(at(0)),
        _mm512_loadu_pd(at(1)),
        _mm512_loadu_pd(at(2)),
        _mm512_loadu_pd(at(3)),
        _mm512_loadu_pd(at(4)),
        _mm512_loadu_pd(at(5)),
        _mm512_loadu_pd(at(6)),
        _mm512_loadu_pd(at(7)),
    ]
}

/// The 8x8 matrix of rows `r` transposed (entry `j` of output `l` is entry `l` of `r[j]`): 24
/// shuffles.
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
pub(in crate::simd) unsafe fn transposed8(
    r: [std::arch::x86_64::__m512d; 8],
) -> [std::arch::x86_64::__m512d; 8] {
    use std::arch::x86_64::{_mm512_shuffle_f64x2, _mm512_unpackhi_pd, _mm512_unpacklo_pd};
    // pairs: t0 = [r0_0 r1_0 r0_2 r1_2 r0_4 r1_4 r0_6 r1_6], t1 the odd lanes, ...
    let t = [
        _mm512_unpacklo_pd(r[0], r[1]),
        _mm512_unpackhi_pd(r[0], r[1]),
        _mm512_unpacklo_pd(r[2], r[3]),
        _mm512_unpackhi_pd(r[2], r[3]),
        _mm512_unpacklo_pd(r[4], r[5]),
        _mm512_unpackhi_pd(r[4], r[5]),
        _mm512_unpacklo_pd(r[6], r[7]),
        _mm512_unpackhi_pd(r[6], r[7]),
    ];
    // 128-bit pieces 0, 2 of a then of b (0x88), or 1, 3 (0xdd): u0 = [r0_0 r1_0 r0_4 r1_4
    // r2_0 r3_0 r2_4 r3_4], u1 = the same of lanes 2 and 6, u2 of 1 and 5, u3 of 3 and 7
    let u = [
        _mm512_shuffle_f64x2::<0x88>(t[0], t[2]),
        _mm512_shuffle_f64x2::<0xdd>(t[0], t[2]),
        _mm512_shuffle_f64x2::<0x88>(t[1], t[3]),
        _mm512_shuffle_f64x2::<0xdd>(t[1], t[3]),
        _mm512_shuffle_f64x2::<0x88>(t[4], t[6]),
        _mm512_shuffle_f64x2::<0xdd>(t[4], t[6]),
        _mm512_shuffle_f64x2::<0x88>(t[5], t[7]),
        _mm512_shuffle_f64x2::<0xdd>(t[5], t[7]),
    ];
    // lane l's 8 quantities: [u(l) pieces 0, 2 | u(l + 4) pieces 0, 2], or 1, 3 for l + 4
    [
        _mm512_shuffle_f64x2::<0x88>(u[0], u[4]),
        _mm512_shuffle_f64x2::<0x88>(u[2], u[6]),
        _mm512_shuffle_f64x2::<0x88>(u[1], u[5]),
        _mm512_shuffle_f64x2::<0x88>(u[3], u[7]),
        _mm512_shuffle_f64x2::<0xdd>(u[0], u[4]),
        _mm512_shuffle_f64x2::<0xdd>(u[2], u[6]),
        _mm512_shuffle_f64x2::<0xdd>(u[1], u[5]),
        _mm512_shuffle_f64x2::<0xdd>(u[3], u[7]),
    ]
}

/// The 4x4 matrix of rows `a`, `b`, `x`, `y` transposed: 8 shuffles.
///
/// # Safety
/// The processor has AVX; no `target_feature` of its own, as [`transpose8`].
#[inline(always)]
pub(in crate::simd) unsafe fn transposed4x4(
    [a, b, x, y]: [std::arch::x86_64::__m256d; 4],
) -> [std::arch::x86_64::__m256d; 4] {
    use std::arch::x86_64::{_mm256_permute2f128_pd, _mm256_unpackhi_pd, _mm256_unpacklo_pd};
    // [a0 b0 a2 b2], [a1 b1 a3 b3], [x0 y0 x2 y2], [x1 y1 x3 y3]
    let (t0, t1) = (_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b));
    let (t2, t3) = (_mm256_unpacklo_pd(x, y), _mm256_unpackhi_pd(x, y));
    [
        _mm256_permute2f128_pd::<0x20>(t0, t2),
        _mm256_permute2f128_pd::<0x20>(t1, t3),
        _mm256_permute2f128_pd::<0x31>(t0, t2),
        _mm256_permute2f128_pd::<0x31>(t1, t3),
    ]
}

/// Lanes `lb..lb + rows.min(4)` of the 4 quantities `src` into columns `c..c + 4` of those
/// rows of `dst` (row `l` at `l * stride`), the values written added to `sum`.
///
/// The sum is the finiteness test of every value a call of [`super::write_rows`] writes in
/// blocks: kept in a register across the blocks (4 adds a block, where `v - v` or-ed and tested
/// took 8 operations and a test), it is finite only if every value added is (an infinity or a
/// NaN makes it infinite or NaN). It can also overflow from finite values; the caller then
/// reads the values back.
///
/// # Safety
/// The processor has AVX. No `target_feature` of its own, as [`transpose8`]: always inlined
/// into [`blocks_avx`] and [`blocks_avx512`], which have it.
#[inline(always)]
unsafe fn transpose4<const W: usize>(
    src: &[Lanes<W>],
    lb: usize,
    rows: usize,
    dst: &mut [f64],
    stride: usize,
    c: usize,
    sum: &mut std::arch::x86_64::__m256d,
) {
    use std::arch::x86_64::_mm256_storeu_pd;
    let out = transposed4(src, lb, rows, sum);
    let first = lb * stride + c;
    if rows >= 4 {
        // the usual case: one bounds check for the 4 rows, then 4 plain stores
        let block = &mut dst[first..first + 3 * stride + 4];
        let at = block.as_mut_ptr();
        for (l, v) in out.into_iter().enumerate() {
            // SAFETY: `block` holds `3 * stride + 4` values, so `l * stride + 4` fit for l <= 3
            _mm256_storeu_pd(at.add(l * stride), v);
        }
    } else {
        for (l, v) in out.iter().enumerate().take(rows) {
            let at = first + l * stride;
            _mm256_storeu_pd(dst[at..at + 4].as_mut_ptr(), *v);
        }
    }
}

/// Lanes `lb..lb + 4` of the 4 quantities `src` as 4 rows of 4 values; those of the first
/// `rows` added to `sum` (as [`transpose4`]).
///
/// # Safety
/// As [`transpose4`].
#[inline(always)]
unsafe fn transposed4<const W: usize>(
    src: &[Lanes<W>],
    lb: usize,
    rows: usize,
    sum: &mut std::arch::x86_64::__m256d,
) -> [std::arch::x86_64::__m256d; 4] {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_loadu_pd};
    // no closures here: one compiled out of line would lose the target feature
    let a = _mm256_loadu_pd(src[0].0[lb..lb + 4].as_ptr());
    let b = _mm256_loadu_pd(src[1].0[lb..lb + 4].as_ptr());
    let x = _mm256_loadu_pd(src[2].0[lb..lb + 4].as_ptr());
    let y = _mm256_loadu_pd(src[3].0[lb..lb + 4].as_ptr());
    let out = transposed4x4([a, b, x, y]);
    if rows >= 4 {
        // all four rows: the quantities as loaded, without waiting for the shuffles
        let block = _mm256_add_pd(_mm256_add_pd(a, b), _mm256_add_pd(x, y));
        *sum = _mm256_add_pd(*sum, block);
    } else {
        for v in out.iter().take(rows) {
            *sum = _mm256_add_pd(*sum, *v);
        }
    }
    out
}

/// Quantities from `from` on, by blocks of 8, into those columns of all `W` rows of `dst` (row
/// `l` at `l * stride`) with [`lines4`] (blocks that are all zeros by `zeros` not read); runs of
/// such blocks are written a row at a time ([`zero_run4`]; on 4 lanes too since measured
/// in-process, alternating with the blocks in turn on a Zen 4: the tree's AVX2 mass matrix 3 %
/// faster, its regressor 10 %, derivatives and linearisation 4-7 %). Their values are added to
/// `sum` (see [`transpose4`]); returns where the blocks end. Kept out of line, the streamed
/// outputs' own path (inlined into [`blocks_avx`], the tree's AVX2 mass matrix, which streams,
/// measured 1-4 % slower: near the noise).
///
/// # Safety
/// The processor has AVX.
#[target_feature(enable = "avx")]
#[inline(never)]
unsafe fn stream_lines4<const W: usize>(
    src: &[Lanes<W>],
    zeros: Option<&ZeroPattern>,
    dst: &mut [f64],
    stride: usize,
    from: usize,
    sum: &mut std::arch::x86_64::__m256d,
) -> usize {
    let n = src.len();
    let zero = |c: usize| zeros.is_some_and(|z| z.zero(c, 8));
    let mut c = from;
    if let Some(z) = zeros.filter(|z| z.len() == n) {
        // the blocks as the pattern lists them (runs of zeros, blocks holding values)
        debug_assert!(from < 8, "the blocks start within the first line");
        for s in z.segments(from) {
            let c = s.start as usize;
            if s.zero_blocks > 0 {
                // SAFETY: as this function's
                unsafe { zero_run4::<W>(dst, stride, c, c + 8 * s.zero_blocks as usize) };
            } else {
                // SAFETY: as this function's
                unsafe { lines4(src, dst, stride, c, s.zero_halves, sum) };
            }
        }
        c = from + (n - from) / 8 * 8;
    }
    while c + 8 <= n {
        if zero(c) {
            // a run of zero blocks, a row at a time (as in `blocks_avx512`)
            let mut end = c + 8;
            while end + 8 <= n && zero(end) {
                end += 8;
            }
            // SAFETY: as this function's
            unsafe { zero_run4::<W>(dst, stride, c, end) };
            c = end;
            continue;
        }
        // SAFETY: as this function's
        unsafe { lines4(src, dst, stride, c, 0, sum) };
        c += 8;
    }
    c
}

/// Zeros into columns `from..to` (`to - from` a multiple of 8) of rows `0..W` of `dst` (row
/// `l` at `l * stride`), a row at a time, in pairs of 32-byte stores: non-temporal where they
/// make whole cache lines (as [`lines4`]).
///
/// # Safety
/// As [`transpose4`].
#[inline(always)]
unsafe fn zero_run4<const W: usize>(dst: &mut [f64], stride: usize, from: usize, to: usize) {
    use std::arch::x86_64::{_mm256_setzero_pd, _mm256_storeu_pd, _mm256_stream_pd};
    let block = &mut dst[from..to + (W - 1) * stride];
    let at = block.as_mut_ptr();
    let z = _mm256_setzero_pd();
    let lines = (at as usize).is_multiple_of(64) && stride.is_multiple_of(8);
    for l in 0..W {
        let mut c = 0;
        while c < to - from {
            // SAFETY: `block` holds `to - from + (W - 1) * stride` values, so `l * stride + c
            // + 8` fit for l < W and c + 8 <= to - from; whole lines where streamed
            let p = at.add(l * stride + c);
            if lines {
                _mm256_stream_pd(p, z);
                _mm256_stream_pd(p.add(4), z);
            } else {
                _mm256_storeu_pd(p, z);
                _mm256_storeu_pd(p.add(4), z);
            }
            c += 8;
        }
    }
}

/// Quantities `c..c + 8` of `src` into columns `c..c + 8` of all `W` rows of
/// `dst` (row `l` at `l * stride`) by pairs of 4x4 transposes, each row's 8 values two 32-byte
/// stores back to back: non-temporal where they make a whole cache line (the block's first row
/// on a line, `stride` a multiple of 8 values). The values added to `sum` (see [`transpose4`]).
/// The quantities `c..c + 4` are zeros if bit 0 of `zero_halves` is set, `c + 4..c + 8` if
/// bit 1 is: those are stored as zeros, neither read nor transposed.
///
/// # Safety
/// As [`transpose4`].
#[inline(always)]
unsafe fn lines4<const W: usize>(
    src: &[Lanes<W>],
    dst: &mut [f64],
    stride: usize,
    c: usize,
    zero_halves: u8,
    sum: &mut std::arch::x86_64::__m256d,
) {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_stream_pd};
    let block = &mut dst[c..c + (W - 1) * stride + 8];
    let at = block.as_mut_ptr();
    let stream = (at as usize).is_multiple_of(64) && stride.is_multiple_of(8);
    // the block's own sum, then one add to the running one (as in `block4`)
    let mut values = _mm256_setzero_pd();
    for lb in (0..W).step_by(4) {
        let zero = [_mm256_setzero_pd(); 4];
        let lo = match zero_halves & 1 {
            0 => transposed4(&src[c..c + 4], lb, 4, &mut values),
            _ => zero,
        };
        let hi = match zero_halves & 2 {
            0 => transposed4(&src[c + 4..c + 8], lb, 4, &mut values),
            _ => zero,
        };
        for l in 0..4 {
            // SAFETY: `block` holds `(W - 1) * stride + 8` values, so `(lb + l) * stride + 8`
            // fit for lb + l < W; streamed only on a 64-byte boundary (checked above)
            let row = at.add((lb + l) * stride);
            if stream {
                _mm256_stream_pd(row, lo[l]);
                _mm256_stream_pd(row.add(4), hi[l]);
            } else {
                _mm256_storeu_pd(row, lo[l]);
                _mm256_storeu_pd(row.add(4), hi[l]);
            }
        }
    }
    *sum = _mm256_add_pd(*sum, values);
}
