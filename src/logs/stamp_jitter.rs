//! Time stamps that jitter while the samples were taken on a regular clock: stamps taken when a
//! message arrived rather than when the sensor was read (a ROS bag's receive time), or stamps
//! rounded coarser than the sample interval. Resampling and differentiation take the stamps'
//! jitter for motion: on the A465's excitation at 1 kHz (torque noise 0.03 N m, filtered at
//! 10 Hz), stamps scattered by 10 µs tripled a direct fit's held-out error, by 0.1 ms made it 30
//! times the noise's, and nothing said so.
//!
//! Told by the positions: each sample's distance from the straight line through its two
//! neighbours, drawn once against the stamps and once against the sample count. Where the
//! samples were taken when stamped (an irregular clock, stamped right), the positions are
//! smooth against the stamps and rough against the count; where they were taken on a regular
//! clock and the stamps jitter, the other way round. A joint whose positions lie on average
//! [`ROUGHER`] times or more farther from the line against the stamps is a finding. The log
//! is not changed: which of the stamps are late cannot be told from the log alone (the real
//! Panda log's stamps scatter by 0.1 ms and it lost about 2 % of its samples, so a count
//! cannot stand in for its clock).

pub use crate::logs::findings::stamp_jitter::*;
use crate::logs::log_screening::{joint_called, median};
use crate::logs::recording::Recording;

/// The stamps of `rec` found jittering (see the module's documentation), or None. Triples of
/// samples across a gap (an interval longer than
/// [`MAX_GAP_INTERVALS`](crate::limits::MAX_GAP_INTERVALS) median intervals) are left out.
pub fn find_stamp_jitter(rec: &Recording) -> Option<StampJitter> {
    let (k, n) = (rec.len(), rec.n);
    if k < 3 {
        return None;
    }
    let intervals: Vec<f64> = rec.t.windows(2).map(|w| w[1] - w[0]).collect();
    let interval = median(intervals.clone())?;
    let longest = crate::limits::MAX_GAP_INTERVALS * interval;
    let (mut by_stamp, mut by_count) = (vec![0.0; n], vec![0.0; n]);
    for i in 1..k - 1 {
        let (before, after) = (intervals[i - 1], intervals[i]);
        if before > longest || after > longest {
            continue;
        }
        let w = before / (before + after);
        for j in 0..n {
            let (a, b, c) = (
                rec.q[(i - 1) * n + j],
                rec.q[i * n + j],
                rec.q[(i + 1) * n + j],
            );
            by_stamp[j] += (b - (a + (c - a) * w)).abs();
            by_count[j] += (b - 0.5 * (a + c)).abs();
        }
    }
    let (joint, rougher) = (0..n)
        .filter(|&j| by_count[j] > 0.0 && by_stamp[j].is_finite())
        .map(|j| (j, by_stamp[j] / by_count[j]))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    if rougher < ROUGHER {
        return None;
    }
    let deviations: Vec<f64> = intervals.iter().map(|d| (d - interval).abs()).collect();
    Some(StampJitter {
        interval,
        scatter: 1.4826 * median(deviations).unwrap_or(0.0),
        joint,
        rougher,
    })
}

/// The warning for stamps found jittering in the log `recording` (joints named after
/// `joint_names` where given), or None.
pub fn warning(
    jitter: &Option<StampJitter>,
    recording: &str,
    joint_names: &[String],
) -> Option<String> {
    let j = jitter.as_ref()?;
    Some(format!(
        "log '{recording}': its time stamps jitter while its samples were taken on a regular clock: the positions of {} lie {:.1} times farther from their neighbours' line against the stamps than against the sample count (its intervals, {} s at the median, scatter by {} s): the stamps were taken when the messages arrived rather than when the sensors were read (a ROS bag's receive time), or rounded coarser than the sample interval. Resampling and the derivatives take the jitter for motion (on the A465 at 1 kHz, 10 µs of it tripled a direct fit's error on other data): read the sensors' own stamps (read_joint_states(stamp='header')), or stamp the log on its sample count if it lost no samples",
        joint_called(joint_names, j.joint),
        j.rougher,
        crate::error::shown5(j.interval),
        crate::error::shown5(j.scatter)
    ))
}
