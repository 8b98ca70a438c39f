//! Gaps in a log's time stamps: intervals longer than
//! [`MAX_GAP_INTERVALS`](crate::limits::MAX_GAP_INTERVALS) median sample intervals.

use crate::logs::recording::Recording;

/// The median sample interval of `rec` and the indices `i` after which `t[i + 1] - t[i]` is
/// longer than [`MAX_GAP_INTERVALS`] medians.
///
/// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
pub(crate) fn gaps(rec: &Recording) -> (f64, Vec<usize>) {
    let dt: Vec<f64> = rec.t.windows(2).map(|w| w[1] - w[0]).collect();
    if dt.is_empty() {
        return (0.0, vec![]);
    }
    let mut sorted = dt.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let limit = crate::limits::MAX_GAP_INTERVALS * median;
    let at = (0..dt.len()).filter(|&i| dt[i] > limit).collect();
    (median, at)
}

/// The indices `i` after which `t[i + 1] - t[i]` is a gap (longer than
/// [`MAX_GAP_INTERVALS`](crate::limits::MAX_GAP_INTERVALS) median sample intervals).
pub(crate) fn gap_positions(rec: &Recording) -> Vec<usize> {
    gaps(rec).1
}
