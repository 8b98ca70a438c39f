//! Isolated glitches in a crossing window (docs/method.md, section 7): each signal's window is
//! screened with the fit that reads it (the same basis and samples) by [`crate::logs::outliers`];
//! this module reports what it found, as diagnostics and warnings. One torque sample of 50 N m
//! in a window of the A465's D experiment moved D* by 440 of its standard errors, silently,
//! before the screening.

pub use crate::logs::outliers::{level, screen, Flagged, Screened, MAX_PER_WINDOW, NOISE_LEVELS};

use super::crossing_values::{CrossingValues, ExperimentValues, WindowGlitch};
use super::diagnostics::Glitch;
use crate::error::shown;

/// How many glitches a warning lists before "and N more".
const LISTED: usize = 5;

/// The glitches found in one experiment's windows (each sample once, in the order found) as
/// diagnostics, and the warnings that tell of them: one for the isolated glitches replaced,
/// one per window whose far-off samples were not isolated. `recording` names the experiment's
/// recording, `joint_names` the joints.
pub(super) fn report(
    values: &ExperimentValues,
    recording: &str,
    joint_names: &[String],
) -> (Vec<Glitch>, Vec<String>) {
    let experiment = values.kind.name();
    let windows = values
        .crossings
        .iter()
        .enumerate()
        .map(|(k, c)| (Some(k), c))
        .chain(values.reference.iter().map(|c| (None, c)));
    let joint = |j: usize| {
        joint_names
            .get(j)
            .cloned()
            .unwrap_or_else(|| format!("{}", j + 1))
    };
    let mut seen: Vec<(&str, usize, usize)> = vec![];
    let mut found: Vec<(Option<usize>, &WindowGlitch)> = vec![];
    for (crossing, c) in windows {
        let c: &CrossingValues = c;
        for g in &c.glitches {
            let key = (g.signal.name(), g.joint, g.sample);
            if !seen.contains(&key) {
                seen.push(key);
                found.push((crossing, g));
            }
        }
    }
    let describe = |g: &WindowGlitch| {
        let off = if g.noise_levels.is_finite() {
            format!("{:.0} noise levels off", g.noise_levels)
        } else {
            "off beyond any scale".to_string()
        };
        format!(
            "{} of '{}' at t = {:.4} s (sample {}) read {} {}, {off}",
            g.signal.name(),
            joint(g.joint),
            g.time,
            g.sample,
            shown(g.value),
            g.signal.unit(),
        )
    };
    let where_ = |crossing: Option<usize>| {
        crossing.map_or("the reference posture".to_string(), |k| {
            format!("crossing {k}")
        })
    };
    let mut warnings = vec![];
    let replaced: Vec<&WindowGlitch> = found
        .iter()
        .filter(|(_, g)| g.replaced)
        .map(|(_, g)| *g)
        .collect();
    // the windows with a glitch replaced (found in window order)
    let affected = {
        let mut w: Vec<Option<usize>> = found
            .iter()
            .filter(|(_, g)| g.replaced)
            .map(|(c, _)| *c)
            .collect();
        w.dedup();
        w.len()
    };
    if !replaced.is_empty() {
        let mut listed: Vec<String> = replaced.iter().take(LISTED).map(|g| describe(g)).collect();
        if replaced.len() > LISTED {
            listed.push(format!("and {} more", replaced.len() - LISTED));
        }
        // glitches of a log are rare; in most windows they have a cause common to the windows
        let windows = values.crossings.len() + usize::from(values.reference.is_some());
        let systematic = if affected >= 3.max(windows.div_ceil(2)) {
            format!(" (in {affected} windows of {windows}: so many suggest a cause common to the windows rather than glitches, such as a clock offset that misplaces a modelled velocity reversal (check the detected offsets), or a step in the signal the plan does not have)")
        } else {
            String::new()
        };
        warnings.push(format!(
            "experiment '{experiment}' (recording '{recording}'): {} sample(s), each alone in its crossing window beyond {NOISE_LEVELS} noise levels of the fit of the others, were taken for glitches of the log and replaced by that fit, as if not recorded{systematic}: {}; all are in the model's diagnostics ('glitches')",
            replaced.len(),
            listed.join("; ")
        ));
    }
    let mut kept: Vec<(Option<usize>, &WindowGlitch)> = vec![];
    for &(crossing, g) in found.iter().filter(|(_, g)| !g.replaced) {
        if !kept
            .iter()
            .any(|(c, k)| *c == crossing && k.signal == g.signal && k.joint == g.joint)
        {
            kept.push((crossing, g));
        }
    }
    for (crossing, g) in kept {
        warnings.push(format!(
            "experiment '{experiment}' (recording '{recording}'), {}: more than {MAX_PER_WINDOW} samples of {} of '{}' lie beyond {NOISE_LEVELS} noise levels of its fit (the first found at t = {:.4} s, sample {}): not isolated glitches but something the fit does not model (an impact, a step in the signal, a velocity reversal the plan does not have); they were kept, and this reading of {} is in doubt",
            where_(crossing),
            g.signal.name(),
            joint(g.joint),
            g.time,
            g.sample,
            where_(crossing),
        ));
    }
    let glitches = found
        .into_iter()
        .map(|(crossing, g)| Glitch {
            experiment: experiment.to_string(),
            crossing,
            signal: g.signal.name().to_string(),
            joint: joint(g.joint),
            sample: g.sample,
            time: g.time,
            value: g.value,
            noise_levels: Some(g.noise_levels).filter(|z| z.is_finite()),
            replaced: g.replaced,
        })
        .collect();
    (glitches, warnings)
}
