//! Joint positions that wrap: an encoder or a driver that reports a revolute joint's angle
//! within one turn (in [-pi, pi) or [0, 2 pi)) steps by a whole turn where a continuous joint
//! passes the end of that range, and a counter that overflows does alike. The step is not the
//! robot's motion: differentiated into a velocity and filtered, it spread a spike over a
//! second of the log, and one joint's positions of a test excitation that stepped by a turn
//! once moved the direct method's base parameters by 7,800 of their standard errors (a joint
//! passing pi back and forth, 6 wraps, by 11,500), with no warning but that the positions left
//! the joint's limits (a continuous joint has none).
//!
//! A step between two neighbouring samples of one joint's positions is a wrap where it is a
//! whole, nonzero number of turns (2 pi each) to within [`MAX_MOTION_AT_WRAP`]: what is left
//! is the joint's own motion in one sample interval, and no robot turns a joint by more than
//! an eighth of a turn between two samples of a log fit for identification (785 rad/s at
//! 1 kHz, 31 rad/s at 40 Hz). From such a step on, the turns are taken back out of the joint's
//! positions (an unwrap, as `numpy.unwrap` does), so that the derivatives and the filter see
//! the motion. A revolute joint's dynamics repeat every turn, so the positions' new offset of
//! whole turns changes no torque; the unwrapped positions may lie outside the joint's limits
//! by whole turns. A single sample off by about a turn (a glitch) steps there and back, and is
//! unwrapped by both steps: it is left for the glitch screening as it was.

pub use crate::logs::findings::position_wraps::*;

/// One turn (rad).
const TURN: f64 = std::f64::consts::TAU;
use crate::logs::recording::Recording;

/// `rec` with the wraps of its positions taken back out (see the module documentation), and
/// the wraps, in log order (by sample, then joint). Each joint's positions from a wrap on are
/// shifted by whole turns (rad); nothing else changes.
pub fn unwrap_positions(rec: &Recording) -> (Recording, Vec<PositionWrap>) {
    let (n, k) = (rec.n, rec.len());
    let mut wraps = vec![];
    let mut q = rec.q.clone();
    for j in 0..n {
        let mut undone: i64 = 0;
        for i in 1..k {
            let step = rec.q[i * n + j] - rec.q[(i - 1) * n + j];
            let turns = (step / TURN).round();
            // bounded: a step of more than a million turns is no wrap but a broken reading
            if turns != 0.0
                && turns.abs() < 1e6
                && (step - turns * TURN).abs() <= MAX_MOTION_AT_WRAP
            {
                undone -= turns as i64;
                wraps.push(PositionWrap {
                    joint: j,
                    sample: i,
                    time: rec.t[i],
                    turns: -(turns as i64),
                });
            }
            if undone != 0 {
                q[i * n + j] = rec.q[i * n + j] + undone as f64 * TURN;
            }
        }
    }
    wraps.sort_by_key(|w| (w.sample, w.joint));
    if wraps.is_empty() {
        return (rec.clone(), wraps);
    }
    (Recording { q, ..rec.clone() }, wraps)
}

/// How many wraps a warning lists before "and N more".
const LISTED: usize = 5;

/// The warning that tells of the `wraps` of the log `recording` (None for none), taken out
/// `when` (such as "before preprocessing"); `joint_names` name the joints by index (where it
/// has none, `joint 3` names index 2).
pub fn warning(
    wraps: &[PositionWrap],
    recording: &str,
    joint_names: &[String],
    when: &str,
) -> Option<String> {
    if wraps.is_empty() {
        return None;
    }
    let mut listed: Vec<String> = wraps
        .iter()
        .take(LISTED)
        .map(|w| {
            format!(
                "{} at t = {:.4} s (sample {}) by {} turn(s)",
                crate::logs::log_screening::joint_called(joint_names, w.joint),
                w.time,
                w.sample,
                -w.turns
            )
        })
        .collect();
    if wraps.len() > LISTED {
        listed.push(format!("and {} more", wraps.len() - LISTED));
    }
    Some(format!(
        "log '{recording}': {} step(s) of a joint's positions by whole turns between two samples (a joint angle logged within one turn that a continuous joint passes, or a counter that overflowed), taken back out {when} so that the derivatives see the motion (the positions after each are shifted by whole turns, which changes no torque): {}",
        wraps.len(),
        listed.join("; ")
    ))
}
