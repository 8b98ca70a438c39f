//! The structural zeros of a lane buffer, which [`super::write_rows_with_zeros`] stores
//! without reading them.

/// The structural zeros of a lane buffer (entries a kernel never writes, zero in every lane):
/// [`write_rows_with_zeros`] stores those as zeros without reading them.
#[derive(Clone, Debug, Default)]
pub(crate) struct ZeroPattern {
    /// `written[c]`: how many of entries `0..c` the kernel writes (`n + 1` counts).
    written: Vec<u32>,
    /// For each of the 8 places the blocks of 8 can start at (the writers' `head`), the blocks
    /// from there on as runs of zero blocks and blocks holding values, so that the writers do
    /// not scan the pattern block by block every group.
    segments: Vec<Vec<Segment>>,
}

/// Blocks of 8 quantities from `start` on: `zero_blocks` blocks of structural zeros, or (0)
/// one block holding values, of which the first four are all structural zeros if bit 0 of
/// `zero_halves` is set, the last four if bit 1 is (so that a writer of 4x4 blocks need not
/// read and transpose them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Segment {
    pub(crate) start: u32,
    pub(crate) zero_blocks: u32,
    pub(crate) zero_halves: u8,
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
        let mut pattern = Self {
            written: counts,
            segments: Vec::new(),
        };
        pattern.segments = (0..8).map(|head| pattern.segments_from(head)).collect();
        pattern
    }

    /// The blocks of 8 from `head` on, as [`Self::segments`] keeps them.
    fn segments_from(&self, head: usize) -> Vec<Segment> {
        let n = self.written.len() - 1;
        let mut out: Vec<Segment> = Vec::new();
        let mut c = head;
        while c + 8 <= n {
            let start = c as u32;
            if self.zero(c, 8) {
                match out.last_mut() {
                    Some(last)
                        if last.zero_blocks > 0 && last.start + 8 * last.zero_blocks == start =>
                    {
                        last.zero_blocks += 1
                    }
                    _ => out.push(Segment {
                        start,
                        zero_blocks: 1,
                        zero_halves: 0,
                    }),
                }
            } else {
                out.push(Segment {
                    start,
                    zero_blocks: 0,
                    zero_halves: u8::from(self.zero(c, 4)) | u8::from(self.zero(c + 4, 4)) << 1,
                });
            }
            c += 8;
        }
        out
    }

    /// The blocks of 8 quantities from `head` (below 8) on, in order: runs of structural zeros
    /// and blocks holding values (see [`Segment`]); empty for a pattern made by `default`.
    #[inline(always)]
    pub(crate) fn segments(&self, head: usize) -> &[Segment] {
        self.segments.get(head).map_or(&[], Vec::as_slice)
    }

    /// The number of entries the pattern covers.
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.written.len().saturating_sub(1)
    }

    /// Whether entries `c..c + len` are all structural zeros (false past the pattern's end).
    #[inline(always)]
    pub(in crate::simd) fn zero(&self, c: usize, len: usize) -> bool {
        match (self.written.get(c), self.written.get(c + len)) {
            (Some(a), Some(b)) => a == b,
            _ => false,
        }
    }
}
