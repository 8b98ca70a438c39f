//! How [`super::write_rows`] stores its blocks on this processor: AVX-512 rows, streaming
//! stores past the caches, rows laid on cache lines.

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
    /// With `wide`, rows that do not fall alike on the cache lines (a row stride that is no
    /// multiple of 8 values) each laid on its own lines, every 64-byte store one aligned line
    /// (`blocks::lined8`), where the blocks otherwise go straight to their columns and most
    /// of their stores straddle two lines. On Intel's processors only ([`lined_rows`]): on a
    /// Xeon (Emerald Rapids) the Panda's regressor was 27 % faster so, in or out of the caches;
    /// on AMD's Zen 4 the same shift measured level or 2-7 % slower (split stores cost less
    /// there).
    pub(crate) lined: bool,
}

impl Stores {
    /// Outputs of at least this many bytes are written with `stream` on AMD's processors (and
    /// any but Intel's): half the 32 MB L3 cache of the Zen 3 and Zen 4 measured, past which
    /// an output does not stay in the caches from one call to the next. (Measured on the
    /// A465's regressor, serially, AVX-512: streaming 20-25 % slower at 6 MB, level at 12 MB,
    /// 25-30 % faster from 24 MB on.)
    pub(crate) const STREAM_BYTES: usize = 16 << 20;

    /// The stores for AVX-512 buffers (`wide`) or not, for an output of `bytes` in all.
    #[inline]
    pub(crate) fn for_output(wide: bool, bytes: usize) -> Self {
        Self {
            wide,
            stream: bytes >= stream_bytes(),
            lined: wide && lined_rows(),
        }
    }
}

/// Whether [`Stores::lined`] is used on this processor (detected once): on Intel's.
pub(crate) fn lined_rows() -> bool {
    static LINED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *LINED.get_or_init(intel)
}

/// Whether the processor is Intel's (CPUID leaf 0's vendor).
fn intel() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let vendor = std::arch::x86_64::__cpuid_count(0, 0);
        (vendor.ebx, vendor.edx, vendor.ecx) == (0x756e_6547, 0x4965_6e69, 0x6c65_746e)
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The output size from which [`Stores::stream`] is used on this processor (detected once):
/// on Intel's, the core's L2 cache (CPUID leaf 4), past which a row stored the usual way is
/// read from an L3 that is slow to write to (measured on a Xeon, Emerald Rapids, 2 MB of L2:
/// the A465's regressor streamed 20 % slower at 1.5 MB, 7-9 % faster at 3-12 MB);
/// [`Stores::STREAM_BYTES`] elsewhere.
pub(crate) fn stream_bytes() -> usize {
    static BYTES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *BYTES.get_or_init(|| intel_l2_bytes().map_or(Stores::STREAM_BYTES, |l2| l2.max(1 << 20)))
}

/// The size of the L2 cache of an Intel processor (CPUID leaf 4), `None` on any other (or
/// past 1 GB).
pub(super) fn intel_l2_bytes() -> Option<usize> {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::__cpuid_count;
        // leaf 4 is read only where leaf 0 says it exists
        if !intel() || __cpuid_count(0, 0).eax < 4 {
            return None;
        }
        for sub in 0..16 {
            let c = __cpuid_count(4, sub);
            let kind = c.eax & 0x1f;
            if kind == 0 {
                break;
            }
            // a data or unified cache at level 2
            if (c.eax >> 5) & 0x7 == 2 && (kind == 1 || kind == 3) {
                let ways = ((c.ebx >> 22) & 0x3ff) as usize + 1;
                let partitions = ((c.ebx >> 12) & 0x3ff) as usize + 1;
                let line = (c.ebx & 0xfff) as usize + 1;
                let sets = c.ecx as usize + 1;
                // a size no processor has (a hypervisor's invention) is not used
                let bytes = ways
                    .saturating_mul(partitions)
                    .saturating_mul(line)
                    .saturating_mul(sets);
                return (bytes <= 1 << 30).then_some(bytes);
            }
        }
        None
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
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
