//! Lanes to rows: quantities held one sample per lane, written out sample by sample (the
//! transpose every multi-sample kernel makes to fill a row-major output).

use super::Lanes;

/// How [`write_rows`] stores its blocks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Stores {
    /// With 8 full lanes and AVX-512F and DQ: blocks of 8 quantities by 8 lanes in 512-bit
    /// registers, each row's 8 values one 64-byte store (half the stores of two 4x4 blocks,
    /// whole cache lines when aligned). Otherwise blocks of 4 by 4 in 256-bit registers (AVX2;
    /// the AVX2 kernels on 8 lanes too, so that they keep to AVX2 instructions).
    pub(crate) wide: bool,
    /// The blocks that fill whole cache lines stored non-temporally (`vmovntpd`: straight to
    /// memory, neither read for ownership first nor left in the caches; with 4x4 blocks, two
    /// of them make a row's line, its two halves stored back to back), for an output far
    /// larger than the caches, whose every line would otherwise be read from memory only to be
    /// overwritten and would push the kernel's buffers out of the caches on its way (measured,
    /// AVX-512: the 60-dof tree's regressor, 288 kB a sample, 40 % faster so). A smaller
    /// output stays in the caches without (the A465's regressor, a few MB, 20-45 % slower
    /// with these). The kernels fence the stores ([`store_fence`]) before they return.
    pub(crate) stream: bool,
}

impl Stores {
    /// Outputs of at least this many bytes are written with `stream`: half the 32 MB L3 cache
    /// of the Zen 3 and Zen 4 measured, past which an output does not stay in the caches from
    /// one call to the next. (Measured on the A465's regressor, serially, AVX-512: streaming
    /// 20-25 % slower at 6 MB, level at 12 MB, 25-30 % faster from 24 MB on.)
    pub(crate) const STREAM_BYTES: usize = 16 << 20;

    /// The stores for AVX-512 buffers (`wide`) or not, for an output of `bytes` in all.
    #[inline]
    pub(crate) fn for_output(wide: bool, bytes: usize) -> Self {
        Self {
            wide,
            stream: bytes >= Self::STREAM_BYTES,
        }
    }
}

/// Orders the non-temporal stores made so far before any later store (`sfence`): after a kernel
/// that wrote with [`Stores::stream`], before its output is handed on.
#[inline]
pub(crate) fn store_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE, which every x86_64 processor has
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

/// The structural zeros of a lane buffer (entries a kernel never writes, zero in every lane):
/// [`write_rows_with_zeros`] stores those as zeros without reading them.
#[derive(Clone, Debug, Default)]
pub(crate) struct ZeroPattern {
    /// `written[c]`: how many of entries `0..c` the kernel writes (`n + 1` counts).
    written: Vec<u32>,
}

impl ZeroPattern {
    /// From whether the kernel writes each entry of the buffer, in order.
    pub(crate) fn new(written: impl IntoIterator<Item = bool>) -> Self {
        let mut counts = vec![0u32];
        let mut sum = 0u32;
        for w in written {
            sum += u32::from(w);
            counts.push(sum);
        }
        Self { written: counts }
    }

    /// Whether entries `c..c + len` are all structural zeros (false past the pattern's end).
    #[inline(always)]
    fn zero(&self, c: usize, len: usize) -> bool {
        match (self.written.get(c), self.written.get(c + len)) {
            (Some(a), Some(b)) => a == b,
            _ => false,
        }
    }
}

/// Writes lanes `0..used` of `src` (`n` quantities, one value per lane each) into `dst` as rows:
/// lane `l`'s `n` values at `dst[l * stride..l * stride + n]`, in the order of `src`.
///
/// `used <= W`, and `dst` must hold `(used - 1) * stride + n` values (slice indexing panics
/// otherwise: the callers size `dst` from the same shapes). With AVX2, blocks of 4 quantities by
/// 4 lanes are transposed in registers (4 loads, 8 shuffles, 4 stores) instead of being copied
/// one value at a time.
///
/// `stores`: how (see [`Stores`]); `wide` only from buffers that run on AVX-512
/// (`LaneBuffers::wide_stores`), and used only with 8 lanes all in use and a processor with
/// AVX-512F and DQ; `stream` only for full groups (`used == W`).
///
/// The blocks are laid on `dst`'s cache lines where every row falls alike on them (`stride` a
/// multiple of the block): the first quantities up to a line's start go singly, so that no
/// store of a block straddles two lines (a split store costs twice; numpy's arrays start
/// 16 bytes into a line).
///
/// Returns whether every value written is finite, tested on the way in registers, so that a
/// caller need not read its output back to vouch for it: the blocks' values are summed (see
/// [`transpose4`]; a sum that overflows from finite values has the rows read back), the values
/// written singly tested by `v - v` (+0 for a finite `v`, NaN otherwise).
#[inline(always)]
pub(crate) fn write_rows<const W: usize>(
    src: &[Lanes<W>],
    used: usize,
    dst: &mut [f64],
    stride: usize,
    stores: Stores,
) -> bool {
    write_rows_with_zeros(src, None, used, dst, stride, stores)
}

/// As [`write_rows`], where `zeros` marks structural zeros of `src` (quantities zero in every
/// lane): with AVX, blocks of those are stored as zeros without being read (with
/// [`Stores::stream`] whole blocks of 8 only). The values written are then equal to
/// [`write_rows`]'s.
///
/// The blocks are written by functions kept out of line, one per instruction set
/// ([`blocks_avx512`], [`blocks_avx`]): inlined into the kernels, the writes' code perturbed
/// the kernels' own (measured: a change in the writes alone made the 60-dof tree's AVX2 RNEA,
/// whose output is 60 values a sample, 5 % slower), and the AVX2 kernels on 8 lanes carried
/// the AVX-512 blocks compiled to calls, never taken.
#[inline(always)]
pub(crate) fn write_rows_with_zeros<const W: usize>(
    src: &[Lanes<W>],
    zeros: Option<&ZeroPattern>,
    used: usize,
    dst: &mut [f64],
    stride: usize,
    stores: Stores,
) -> bool {
    let n = src.len();
    let mut c = 0;
    let mut bits = 0u64;
    #[cfg(target_arch = "x86_64")]
    if W.is_multiple_of(4) && std::arch::is_x86_feature_detected!("avx") {
        // 8 full lanes with AVX-512: blocks of 8 quantities, each row's 8 values one 64-byte
        // store (half the stores of two 4x4 blocks, and whole cache lines when aligned)
        let avx512 = std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512dq");
        bits = if stores.wide && W == 8 && used == 8 && avx512 {
            // SAFETY: the processor has AVX-512F and DQ (checked above), `W == 8 == used`
            unsafe { blocks_avx512(src, zeros, dst, stride, stores.stream) }
        } else {
            // SAFETY: the processor has AVX (checked above)
            unsafe { blocks_avx(src, zeros, used, dst, stride, stores.stream) }
        };
        c = n;
    }
    bits |= scalars(src, used, dst, stride, c, n);
    bits == 0 || rows_finite(dst, used, stride, n)
}

/// Whether the first `n` values of rows `0..used` of `dst` (row `l` at `l * stride`) are all
/// finite: read back after a block sum that overflowed (or a value that is not finite), which
/// flags finite values too. Rare, and kept out of the kernels.
#[cold]
#[inline(never)]
fn rows_finite(dst: &[f64], used: usize, stride: usize, n: usize) -> bool {
    (0..used).all(|l| {
        dst[l * stride..l * stride + n]
            .iter()
            .all(|v| v.is_finite())
    })
}

/// [`write_rows_with_zeros`]'s work with AVX-512 (8 full lanes, `W == 8`): blocks of 8 by 8 in
/// 512-bit registers ([`transpose8`]), from a cache line's start where every row falls alike
/// on the lines (`stride` a multiple of 8), the rest by [`narrow`]. Returns the finiteness
/// bits: 0 when every value is vouched finite.
///
/// # Safety
/// The processor has AVX-512F and DQ, and `W == 8`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx512f,avx512dq")]
#[inline(never)]
unsafe fn blocks_avx512<const W: usize>(
    src: &[Lanes<W>],
    zeros: Option<&ZeroPattern>,
    dst: &mut [f64],
    stride: usize,
    stream: bool,
) -> u64 {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_setzero_pd, _mm512_castpd512_pd256, _mm512_extractf64x4_pd,
        _mm512_setzero_pd,
    };
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
    let mut bits = narrow(src, &zero, used, dst, stride, 0, head, &mut sum);
    let mut c = head;
    while c + 8 <= n {
        if zero(c, 8) {
            zero8(dst, stride, c, stream);
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
    // the 512-bit sum's halves into the 256-bit one (finite only if both are)
    let halves = _mm256_add_pd(
        _mm512_castpd512_pd256(wide_sum),
        _mm512_extractf64x4_pd::<1>(wide_sum),
    );
    bits | not_finite4(_mm256_add_pd(sum, halves))
}

/// [`write_rows_with_zeros`]'s work with AVX: blocks of 4 by 4 in 256-bit registers, from a
/// half cache line's start where every row falls alike on them (`stride` a multiple of 4), or
/// whole lines streamed ([`stream_lines4`]). Returns the finiteness bits as
/// [`blocks_avx512`].
///
/// # Safety
/// The processor has AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline(never)]
unsafe fn blocks_avx<const W: usize>(
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
#[cfg(target_arch = "x86_64")]
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
#[cfg(target_arch = "x86_64")]
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

/// Quantities `from..to` of `src` into those columns of rows `0..used` of `dst`, one value at a
/// time; the finiteness bits.
#[inline(always)]
#[allow(clippy::eq_op)] // `v - v` is the finiteness test, not a mistake
fn scalars<const W: usize>(
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
            for c in super::serial(from..to) {
                let v = src[c].0[l];
                row[c] = v;
                bits |= (v - v).to_bits();
            }
        }
    }
    bits
}

/// Quantities `c..c + 4` of `src` (zeros if `zero`) into columns `c..c + 4` of the rows
/// `0..used` of `dst` by 4x4 transposes, their values added to `sum` (see [`transpose4`]).
#[cfg(target_arch = "x86_64")]
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

/// Zeros into columns `c..c + 8` of rows `0..8` of `dst` (row `l` at `l * stride`): one bounds
/// check, 8 stores of 64 bytes (non-temporal if `stream`, as [`store8`]).
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn zero8(dst: &mut [f64], stride: usize, c: usize, stream: bool) {
    let zero = std::arch::x86_64::_mm512_setzero_pd();
    store8(dst, stride, c, [zero; 8], stream);
}

/// `rows[l]` into columns `c..c + 8` of row `l` of `dst` (at `l * stride`) for `l < 8`: one
/// bounds check, 8 stores of 64 bytes. With `stream`, where those are whole cache lines (the
/// block's first row on a line, `stride` a multiple of 8 values), non-temporal ones.
///
/// # Safety
/// The processor has AVX-512F; no `target_feature` of its own, as [`transpose8`].
#[cfg(target_arch = "x86_64")]
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
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn transpose8<const W: usize>(
    src: &[Lanes<W>],
    dst: &mut [f64],
    stride: usize,
    c: usize,
    stream: bool,
    sum: &mut std::arch::x86_64::__m512d,
) {
    use std::arch::x86_64::{
        _mm512_add_pd, _mm512_loadu_pd, _mm512_shuffle_f64x2, _mm512_unpackhi_pd,
        _mm512_unpacklo_pd,
    };
    // one 8-lane quantity (bounds-checked: fails unless W >= 8)
    #[inline(always)]
    fn at<const W: usize>(src: &[Lanes<W>], q: usize) -> *const f64 {
        src[q].0[..8].as_ptr()
    }
    let r = [
        _mm512_loadu_pd(at(src, 0)),
        _mm512_loadu_pd(at(src, 1)),
        _mm512_loadu_pd(at(src, 2)),
        _mm512_loadu_pd(at(src, 3)),
        _mm512_loadu_pd(at(src, 4)),
        _mm512_loadu_pd(at(src, 5)),
        _mm512_loadu_pd(at(src, 6)),
        _mm512_loadu_pd(at(src, 7)),
    ];
    let block = _mm512_add_pd(
        _mm512_add_pd(_mm512_add_pd(r[0], r[1]), _mm512_add_pd(r[2], r[3])),
        _mm512_add_pd(_mm512_add_pd(r[4], r[5]), _mm512_add_pd(r[6], r[7])),
    );
    *sum = _mm512_add_pd(*sum, block);
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
    let out = [
        _mm512_shuffle_f64x2::<0x88>(u[0], u[4]),
        _mm512_shuffle_f64x2::<0x88>(u[2], u[6]),
        _mm512_shuffle_f64x2::<0x88>(u[1], u[5]),
        _mm512_shuffle_f64x2::<0x88>(u[3], u[7]),
        _mm512_shuffle_f64x2::<0xdd>(u[0], u[4]),
        _mm512_shuffle_f64x2::<0xdd>(u[2], u[6]),
        _mm512_shuffle_f64x2::<0xdd>(u[1], u[5]),
        _mm512_shuffle_f64x2::<0xdd>(u[3], u[7]),
    ];
    store8(dst, stride, c, out, stream);
}

/// Lanes `lb..lb + rows.min(4)` of the 4 quantities `src` into columns `c..c + 4` of those
/// rows of `dst` (row `l` at `l * stride`), the values written added to `sum`.
///
/// The sum is the finiteness test of every value a call of [`write_rows`] writes in blocks:
/// kept in a register across the blocks (4 adds a block, where `v - v` or-ed and tested took
/// 8 operations and a test), it is finite only if every value added is (an infinity or a NaN
/// makes it infinite or NaN). It can also overflow from finite values; the caller then reads
/// the values back.
///
/// # Safety
/// The processor has AVX. No `target_feature` of its own, as [`transpose8`]: always inlined
/// into [`blocks_avx`] and [`blocks_avx512`], which have it.
#[cfg(target_arch = "x86_64")]
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
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn transposed4<const W: usize>(
    src: &[Lanes<W>],
    lb: usize,
    rows: usize,
    sum: &mut std::arch::x86_64::__m256d,
) -> [std::arch::x86_64::__m256d; 4] {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_permute2f128_pd, _mm256_unpackhi_pd,
        _mm256_unpacklo_pd,
    };
    // no closures here: one compiled out of line would lose the target feature
    let a = _mm256_loadu_pd(src[0].0[lb..lb + 4].as_ptr());
    let b = _mm256_loadu_pd(src[1].0[lb..lb + 4].as_ptr());
    let x = _mm256_loadu_pd(src[2].0[lb..lb + 4].as_ptr());
    let y = _mm256_loadu_pd(src[3].0[lb..lb + 4].as_ptr());
    // [a0 b0 a2 b2], [a1 b1 a3 b3], [x0 y0 x2 y2], [x1 y1 x3 y3]
    let (t0, t1) = (_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b));
    let (t2, t3) = (_mm256_unpacklo_pd(x, y), _mm256_unpackhi_pd(x, y));
    let out = [
        _mm256_permute2f128_pd::<0x20>(t0, t2),
        _mm256_permute2f128_pd::<0x20>(t1, t3),
        _mm256_permute2f128_pd::<0x31>(t0, t2),
        _mm256_permute2f128_pd::<0x31>(t1, t3),
    ];
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
/// `l` at `l * stride`) with [`lines4`] (blocks that are all zeros by `zeros` not read);
/// their values added to `sum` (see [`transpose4`]); returns where the blocks end. Kept out of
/// line, the streamed outputs' own path (inlined into [`blocks_avx`], the tree's AVX2 mass
/// matrix, which streams, measured 1-4 % slower: near the noise).
///
/// # Safety
/// The processor has AVX.
#[cfg(target_arch = "x86_64")]
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
    let mut c = from;
    while c + 8 <= src.len() {
        let zero = zeros.is_some_and(|z| z.zero(c, 8));
        // SAFETY: as this function's
        unsafe { lines4(src, zero, dst, stride, c, sum) };
        c += 8;
    }
    c
}

/// Quantities `c..c + 8` of `src` (zeros if `zero`) into columns `c..c + 8` of all `W` rows of
/// `dst` (row `l` at `l * stride`) by pairs of 4x4 transposes, each row's 8 values two 32-byte
/// stores back to back: non-temporal where they make a whole cache line (the block's first row
/// on a line, `stride` a multiple of 8 values). The values added to `sum` (see [`transpose4`]).
///
/// # Safety
/// As [`transpose4`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn lines4<const W: usize>(
    src: &[Lanes<W>],
    zero: bool,
    dst: &mut [f64],
    stride: usize,
    c: usize,
    sum: &mut std::arch::x86_64::__m256d,
) {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_stream_pd};
    let block = &mut dst[c..c + (W - 1) * stride + 8];
    let at = block.as_mut_ptr();
    let stream = (at as usize).is_multiple_of(64) && stride.is_multiple_of(8);
    // the block's own sum, then one add to the running one (as in `block4`)
    let mut values = _mm256_setzero_pd();
    for lb in (0..W).step_by(4) {
        let (lo, hi) = if zero {
            ([_mm256_setzero_pd(); 4], [_mm256_setzero_pd(); 4])
        } else {
            (
                transposed4(&src[c..c + 4], lb, 4, &mut values),
                transposed4(&src[c + 4..c + 8], lb, 4, &mut values),
            )
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` quantities, quantity `c` of lane `l` worth `100 c + l`.
    fn numbered<const W: usize>(n: usize) -> Vec<Lanes<W>> {
        (0..n)
            .map(|c| {
                let mut x = Lanes::<W>::default();
                for l in 0..W {
                    x.0[l] = (100 * c + l) as f64;
                }
                x
            })
            .collect()
    }

    /// Row strides that lay every row alike on the cache lines (multiples of 8 and of 4) and
    /// that do not.
    fn strides(n: usize) -> [usize; 3] {
        [n + 2, n.div_ceil(8) * 8 + 8, n.div_ceil(4) * 4 + 4]
    }

    const ALL_STORES: [Stores; 4] = [
        Stores {
            wide: false,
            stream: false,
        },
        Stores {
            wide: true,
            stream: false,
        },
        Stores {
            wide: false,
            stream: true,
        },
        Stores {
            wide: true,
            stream: true,
        },
    ];

    fn check<const W: usize>(stores: Stores) {
        for n in [0, 1, 3, 4, 5, 8, 13, 16, 21, 24, 35] {
            let src = numbered::<W>(n);
            for used in 1..=W {
                for stride in strides(n) {
                    // every start of the rows within a cache line
                    let mut store = vec![-1.0; used * stride + 8];
                    for start in 0..8 {
                        store.fill(-1.0);
                        let dst = &mut store[start..start + used * stride];
                        assert!(write_rows(&src, used, dst, stride, stores));
                        for l in 0..used {
                            for c in 0..stride {
                                let want = if c < n { (100 * c + l) as f64 } else { -1.0 };
                                assert_eq!(
                                    dst[l * stride + c],
                                    want,
                                    "W {W} n {n} used {used} stride {stride} start {start}"
                                );
                            }
                        }
                        assert!(store[..start].iter().all(|v| *v == -1.0));
                        assert!(store[start + used * stride..].iter().all(|v| *v == -1.0));
                    }
                }
            }
        }
    }

    fn finiteness<const W: usize>(stores: Stores) {
        // a non-finite value is reported wherever it sits among the lanes written, and not
        // when it sits in a lane past `used`
        for n in [1, 4, 7, 8, 17, 30] {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for (c, l) in [(0, 0), (n - 1, W - 1), (n / 2, W / 2)] {
                    let mut src = vec![Lanes::<W>::splat(1.5); n];
                    src[c].0[l] = bad;
                    for used in 1..=W {
                        for stride in strides(n) {
                            let mut store = vec![0.0; used * stride + 8];
                            for start in 0..8 {
                                let dst = &mut store[start..start + used * stride];
                                let finite = write_rows(&src, used, dst, stride, stores);
                                assert_eq!(
                                    finite,
                                    l >= used,
                                    "W {W} n {n} c {c} l {l} used {used} start {start}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn rows_report_whether_the_values_written_are_finite() {
        for stores in ALL_STORES {
            finiteness::<1>(stores);
            finiteness::<4>(stores);
            finiteness::<8>(stores);
            overflow::<1>(stores);
            overflow::<4>(stores);
            overflow::<8>(stores);
        }
    }

    fn overflow<const W: usize>(stores: Stores) {
        // finite values whose sum overflows (the blocks' test) are reported finite, and an
        // infinity beside them is not
        for n in [4, 8, 17, 30] {
            for bad in [None, Some(n / 2)] {
                let mut src = vec![Lanes::<W>::splat(f64::MAX); n];
                if let Some(c) = bad {
                    src[c].0[0] = f64::INFINITY;
                }
                for used in 1..=W {
                    for stride in strides(n) {
                        let mut store = vec![0.0; used * stride + 8];
                        for start in 0..8 {
                            let dst = &mut store[start..start + used * stride];
                            let finite = write_rows(&src, used, dst, stride, stores);
                            assert_eq!(finite, bad.is_none(), "W {W} n {n} used {used}");
                        }
                    }
                }
            }
        }
    }

    fn zeros_unread<const W: usize>(zero: fn(usize) -> bool, stores: Stores) {
        // quantities marked zero are written as zeros or, where the blocks do not cover them,
        // read (here NaN: reported); the others are the lanes transposed; a long run of zeros
        // is not read in full
        for n in [4, 7, 12, 13, 16, 21, 24, 35, 64] {
            let pattern = ZeroPattern::new((0..n).map(|c| !zero(c)));
            let src: Vec<Lanes<W>> = (0..n)
                .map(|c| Lanes::splat(if zero(c) { f64::NAN } else { c as f64 }))
                .collect();
            let avx = W.is_multiple_of(4) && std::arch::is_x86_feature_detected!("avx");
            for used in 1..=W {
                for stride in strides(n) {
                    let mut store = vec![-1.0; used * stride + 8];
                    for start in 0..8 {
                        let dst = &mut store[start..start + used * stride];
                        let finite =
                            write_rows_with_zeros(&src, Some(&pattern), used, dst, stride, stores);
                        let mut nan = false;
                        for l in 0..used {
                            let row = &dst[l * stride..l * stride + n];
                            for (c, got) in row.iter().enumerate() {
                                if !zero(c) {
                                    assert_eq!(*got, c as f64);
                                } else {
                                    assert!(*got == 0.0 || got.is_nan(), "W {W} n {n} c {c}");
                                    nan |= got.is_nan();
                                }
                            }
                            // 16 zeros in a row hold a whole block of 8 wherever the blocks
                            // start
                            let unread = (0..n).filter(|c| zero(*c) && row[*c] == 0.0).count();
                            let run = (0..n.saturating_sub(15)).any(|c| (c..c + 16).all(zero));
                            if avx && run {
                                assert!(unread > 0, "W {W} n {n} stride {stride} start {start}");
                            }
                            if !avx {
                                assert_eq!(unread, 0);
                            }
                        }
                        assert_eq!(finite, !nan, "W {W} n {n} start {start}");
                    }
                }
            }
        }
    }

    #[test]
    fn structural_zeros_are_written_without_being_read() {
        // every other block of 4 (the 8-lane path's blocks of 8 half zero), every other pair of
        // blocks (wholly zero or not), a lone zero block, a long run, and odd runs
        let patterns: [fn(usize) -> bool; 5] = [
            |c| (c / 4) % 2 == 1,
            |c| (c / 8) % 2 == 1,
            |c| c / 4 == 2,
            |c| (5..40).contains(&c),
            |c| c % 11 < 6,
        ];
        for (zero, stores) in patterns
            .into_iter()
            .flat_map(|z| ALL_STORES.map(|s| (z, s)))
        {
            zeros_unread::<1>(zero, stores);
            zeros_unread::<4>(zero, stores);
            zeros_unread::<8>(zero, stores);
        }
    }

    #[test]
    fn zero_pattern_ranges() {
        let z = ZeroPattern::new([true, false, false, false, false, true, false]);
        assert!(z.zero(1, 4) && !z.zero(0, 4) && !z.zero(2, 4) && z.zero(6, 1));
        assert!(!z.zero(5, 4), "past the end is not zero");
        assert!(z.zero(3, 0));
    }

    #[test]
    fn rows_are_the_lanes_transposed() {
        // the AVX-512 buffers' 8x8 blocks (plain or non-temporal stores) where the processor
        // has AVX-512, and the 4x4 ones
        for stores in ALL_STORES {
            check::<1>(stores);
            check::<4>(stores);
            check::<8>(stores);
        }
    }
}
