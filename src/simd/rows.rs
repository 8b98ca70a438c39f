//! Lanes to rows: quantities held one sample per lane, written out sample by sample (the
//! transpose every multi-sample kernel makes to fill a row-major output).

use super::Lanes;

#[cfg(target_arch = "x86_64")]
mod blocks;
#[cfg(target_arch = "x86_64")]
use blocks::{blocks_avx, blocks_avx512};
#[cfg(target_arch = "x86_64")]
pub(super) use blocks::{load8, transposed4x4, transposed8};
mod scalars;
mod stores;
mod zero_pattern;
use scalars::scalars;
#[cfg(test)]
use stores::{intel_l2_bytes, lined_rows, stream_bytes};
pub(crate) use stores::{store_fence, Stores};
pub(crate) use zero_pattern::ZeroPattern;

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
/// `blocks::transpose4`; a sum that overflows from finite values has the rows read back), the
/// values written singly tested by `v - v` (+0 for a finite `v`, NaN otherwise).
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
            unsafe { blocks_avx512(src, zeros, dst, stride, stores) }
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

    /// Every combination of the store options.
    const ALL_STORES: [Stores; 8] = {
        let mut all = [Stores {
            wide: false,
            stream: false,
            lined: false,
        }; 8];
        let mut i = 0;
        while i < 8 {
            all[i] = Stores {
                wide: i & 1 != 0,
                stream: i & 2 != 0,
                lined: i & 4 != 0,
            };
            i += 1;
        }
        all
    };

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

    /// `f(used, dst, stride, start)` for every count of lanes used, every stride of
    /// [`strides`] and every start of the rows within a cache line.
    fn each_layout<const W: usize>(n: usize, mut f: impl FnMut(usize, &mut [f64], usize, usize)) {
        for used in 1..=W {
            for stride in strides(n) {
                let mut store = vec![0.0; used * stride + 8];
                for start in 0..8 {
                    f(
                        used,
                        &mut store[start..start + used * stride],
                        stride,
                        start,
                    );
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
                    each_layout::<W>(n, |used, dst, stride, start| {
                        let finite = write_rows(&src, used, dst, stride, stores);
                        assert_eq!(
                            finite,
                            l >= used,
                            "W {W} n {n} c {c} l {l} used {used} start {start}"
                        );
                    });
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
                each_layout::<W>(n, |used, dst, stride, _| {
                    let finite = write_rows(&src, used, dst, stride, stores);
                    assert_eq!(finite, bad.is_none(), "W {W} n {n} used {used}");
                });
            }
        }
    }

    fn zeros_unread<const W: usize>(zero: fn(usize) -> bool, stores: Stores) {
        // quantities marked zero are written as zeros or, where the blocks do not cover them,
        // read (here NaN: reported); the others are the lanes transposed; a long run of zeros
        // is not read in full
        for n in [4, 7, 12, 13, 16, 21, 24, 35, 64] {
            let pattern = ZeroPattern::new((0..n).map(|c| !zero(c)));
            // each lane its own values (`100 c + l`), so that a lane written into another
            // lane's row is caught
            let mut src = numbered::<W>(n);
            for (c, x) in src.iter_mut().enumerate() {
                if zero(c) {
                    *x = Lanes::splat(f64::NAN);
                }
            }
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
                            // nothing written past a row's quantities (the runs' masked stores)
                            let gap = &dst[l * stride + n..(l + 1) * stride];
                            assert!(gap.iter().all(|v| *v == -1.0), "W {W} n {n} l {l}");
                            let row = &dst[l * stride..l * stride + n];
                            for (c, got) in row.iter().enumerate() {
                                if !zero(c) {
                                    assert_eq!(*got, (100 * c + l) as f64, "W {W} n {n}");
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
                        assert!(store[..start].iter().all(|v| *v == -1.0));
                        assert!(store[start + used * stride..].iter().all(|v| *v == -1.0));
                        store.fill(-1.0);
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
    fn segments_list_every_block_once_as_the_pattern_has_it() {
        // from each head: the blocks of 8 up to the last whole one, in order, each zero block
        // in a run and every other one alone; runs are maximal
        let patterns: [fn(usize) -> bool; 4] = [
            |c| (c / 8) % 3 != 0,
            |c| c % 11 < 6,
            |c| (5..60).contains(&c),
            |_| false,
        ];
        for zero in patterns {
            for n in [0, 7, 8, 9, 40, 75] {
                let z = ZeroPattern::new((0..n).map(|c| !zero(c)));
                assert_eq!(z.len(), n);
                for head in 0..8 {
                    let mut blocks = Vec::new();
                    for s in z.segments(head) {
                        let (start, k) = (s.start as usize, s.zero_blocks as usize);
                        if k == 0 {
                            assert!(!z.zero(start, 8), "n {n} head {head} {start}");
                            let halves = [z.zero(start, 4), z.zero(start + 4, 4)];
                            assert_eq!(
                                [s.zero_halves & 1 != 0, s.zero_halves & 2 != 0],
                                halves,
                                "n {n} head {head} {start}"
                            );
                            blocks.push(start);
                        } else {
                            assert_eq!(s.zero_halves, 0);
                        }
                        for b in 0..k {
                            assert!(z.zero(start + 8 * b, 8), "n {n} head {head} {start}");
                            blocks.push(start + 8 * b);
                        }
                    }
                    let expected: Vec<usize> = (head..n.saturating_sub(7)).step_by(8).collect();
                    assert_eq!(blocks, expected, "n {n} head {head}");
                    for w in z.segments(head).windows(2) {
                        let joined = w[0].zero_blocks > 0 && w[1].zero_blocks > 0;
                        assert!(!joined, "n {n} head {head}: two runs side by side");
                    }
                }
            }
        }
        assert!(ZeroPattern::default().segments(0).is_empty());
    }

    #[test]
    fn intel_l2_from_cpuid_is_the_one_linux_reports() {
        // CPUID leaf 4 against Linux's own reading of the caches (sysfs), where both exist
        let Some(l2) = intel_l2_bytes() else {
            assert_eq!(
                stream_bytes(),
                Stores::STREAM_BYTES,
                "not Intel: the fixed threshold"
            );
            return;
        };
        let dir = std::path::Path::new("/sys/devices/system/cpu/cpu0/cache");
        let level2 = (0..8).find_map(|i| {
            let read = |f: &str| std::fs::read_to_string(dir.join(format!("index{i}/{f}")));
            let (level, kind, size) = (read("level").ok()?, read("type").ok()?, read("size").ok()?);
            (level.trim() == "2" && kind.trim() != "Instruction").then(|| size.trim().to_string())
        });
        match level2 {
            Some(size) => {
                let kib: usize = size
                    .trim_end_matches('K')
                    .parse()
                    .expect("sysfs cache size");
                assert_eq!(l2, kib * 1024, "CPUID leaf 4 against sysfs ({size})");
            }
            None => assert!((128 << 10..=64 << 20).contains(&l2), "L2 of {l2} bytes"),
        }
        assert_eq!(stream_bytes(), l2.max(1 << 20));
    }

    #[test]
    fn rows_are_lined_on_intel_processors_only() {
        // CPUID's vendor against Linux's reading of it, where there is one
        let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
            return;
        };
        let Some(vendor) = info.lines().find_map(|l| {
            l.strip_prefix("vendor_id")
                .map(|v| v.trim_start_matches([' ', '\t', ':']))
        }) else {
            return;
        };
        let intel = vendor.trim() == "GenuineIntel";
        assert_eq!(lined_rows(), intel, "vendor {vendor}");
        for wide in [false, true] {
            assert_eq!(Stores::for_output(wide, 0).lined, wide && intel);
        }
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
