//! Whether each recording shows its own plan's perturbations: the recordings of two
//! experiments swapped (D's file given as H's), a run of another plan, or a controller that did
//! not perturb what was planned. The separated regressions use the perturbations as recorded,
//! so such a recording still gives numbers, but of another experiment than the user thinks: its
//! block comes out unresolved or wrong with no word of why.
//!
//! For each perturbed experiment the recorded perturbations of its variable at the crossings
//! (the crossings' states less the operating point's, or less the rest posture's for G-static)
//! are compared with the planned ones by their cosine, over every crossing and joint. A robot
//! that follows its plan gives a cosine near 1 (tracking errors and noise lower it a little);
//! below [`MIN_COSINE`] the recording is said not to follow its plan, and where it follows
//! another experiment's plan at the same crossing times to at least [`MATCH_COSINE`], that
//! experiment is named. Perturbations are judged only where the planned ones exceed
//! [`MEASURABLE`] times the measurement noise of the recorded ones (RMS), so a plan too small
//! for the sensors is left to the response test.

use nalgebra::DMatrix;

use super::identify::{state, ExperimentValues};
use super::plan::{Experiment, Plan};

/// The cosine between recorded and planned perturbations below which a recording is said not
/// to follow its plan.
pub const MIN_COSINE: f64 = 0.5;
/// The cosine at which a recording is said to follow another experiment's plan.
pub const MATCH_COSINE: f64 = 0.9;
/// How many times the recorded perturbations' measurement noise (RMS) the planned ones must
/// exceed to be judged.
pub const MEASURABLE: f64 = 3.0;

/// The recorded perturbations against planned ones.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Agreement {
    /// `<recorded, planned> / (|recorded| |planned|)` over every crossing and joint (0 where
    /// nothing was recorded moving).
    cosine: f64,
    /// `<recorded, planned> / |planned|^2`: how large the recorded ones are along the planned.
    scale: f64,
}

/// The recorded perturbations of variable `var` (0: q, 1: qd, 2: qdd) at `values`' crossings
/// about `base` (`K x N`), and the sum of their measurement variances.
fn recorded(values: &ExperimentValues, var: usize, base: &[f64]) -> (DMatrix<f64>, f64) {
    let (k, n) = (values.crossings.len(), base.len());
    let x = DMatrix::from_fn(k, n, |i, j| {
        state(&values.crossings[i], var)
            .get(j)
            .copied()
            .unwrap_or(f64::NAN)
            - base[j]
    });
    let noise = (values.crossings.iter())
        .flat_map(|c| c.state_stderr[var].iter().take(n))
        .map(|s| s * s)
        .sum();
    (x, noise)
}

/// `recorded` perturbations (`K x N`, their measurement variances summing to `noise`) against
/// `planned` ones; None where the shapes differ, the planned ones are not measurable over the
/// noise, or a number is not finite.
fn agreement(recorded: &DMatrix<f64>, noise: f64, planned: &DMatrix<f64>) -> Option<Agreement> {
    if planned.shape() != recorded.shape() {
        return None;
    }
    let xp = recorded.dot(planned);
    let (xx, pp) = (recorded.norm_squared(), planned.norm_squared());
    let judged = pp > MEASURABLE * MEASURABLE * noise && pp > 0.0;
    if !(judged && xp.is_finite() && xx.is_finite() && pp.is_finite()) {
        return None;
    }
    let cosine = if xx > 0.0 {
        xp / (xx.sqrt() * pp.sqrt())
    } else {
        0.0
    };
    Some(Agreement {
        cosine,
        scale: xp / pp,
    })
}

/// True where `a` and `b` cross at the same times.
fn same_times(a: &Experiment, b: &Experiment) -> bool {
    a.crossings.len() == b.crossings.len()
        && (a.crossings.iter().zip(&b.crossings))
            .all(|(x, y)| (x.time - y.time).abs() <= 1e-9 * (1.0 + x.time.abs()))
}

/// A warning for each experiment of `values` whose recording does not show its plan's
/// perturbations (the operating point's state `op_state`: q, qd, qdd as identified), naming
/// the experiment whose plan it follows where one does; then one for each crossing that strays
/// from its plan in an experiment that follows it ([`stray_crossings`]).
pub(super) fn warnings(
    plan: &Plan,
    values: &[ExperimentValues],
    op_state: &[Vec<f64>; 3],
) -> Vec<String> {
    let mut out = vec![];
    for v in values {
        let (Some(var), Some(exp)) = (v.kind.perturbed(), plan.experiment(v.kind)) else {
            continue;
        };
        let base = match &v.reference {
            Some(r) => state(r, var),
            None => &op_state[var][..],
        };
        let (x, noise) = recorded(v, var, base);
        let Some(own) = agreement(&x, noise, &exp.deltas) else {
            continue;
        };
        if own.cosine >= MIN_COSINE {
            out.extend(stray_crossings(v, exp, var, &x));
            continue;
        }
        let other = (plan.experiments.iter())
            .filter(|e| e.kind != v.kind && e.reference.is_none() && same_times(e, exp))
            .filter_map(|e| {
                let var = e.kind.perturbed()?;
                let (x, noise) = recorded(v, var, &op_state[var]);
                let a = agreement(&x, noise, &e.deltas)?;
                (a.cosine >= MATCH_COSINE).then_some((e.kind, a.cosine))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let (name, variable) = (v.kind.name(), v.kind.perturbation_name());
        let cause = match other {
            Some((kind, cosine)) => format!(
                "it follows the plan of experiment '{}' instead (cosine {cosine:.2} with its {}): are the recordings of '{name}' and '{}' swapped?",
                kind.name(),
                kind.perturbation_name(),
                kind.name()
            ),
            None => "check that it is a run of this experiment's plan, and that the controller was sent its trajectory".into(),
        };
        out.push(format!(
            "experiment '{name}': the perturbations its recording shows ({variable}) do not follow the plan's (cosine {:.2} between recorded and planned, {:.2} times the planned along them), and its regression uses them as recorded: {cause}",
            own.cosine, own.scale
        ));
    }
    out
}

/// How far one crossing's recorded perturbation may lie from its planned one, as a fraction of
/// the planned one's size, where the experiment as a whole follows its plan: further than that
/// it shows another perturbation altogether (zero lies at 1). A closed-loop A465 with Coulomb
/// friction up to 3 N m and low gains strayed up to 0.98 at its worst crossing.
pub const STRAY_FRACTION: f64 = 1.0;
/// ... and how many times the experiment's median stray (as a fraction) it must be: a crossing
/// unlike the others, not a robot that tracks all of them loosely (the same A465: 1.7 times its
/// median; a replayed stretch of log: 250 times).
pub const STRAY_MEDIAN: f64 = 4.0;

/// A warning for each crossing of `v` (a run of `exp`, its perturbed variable `var`, `x` its
/// recorded perturbations, `K x N`), an experiment that follows its plan as a whole, whose recorded
/// perturbation lies further than [`STRAY_FRACTION`] of the planned one's size from it, beyond
/// [`STRAY_MEDIAN`] times the experiment's median and [`MEASURABLE`] times its measurement
/// noise: a log that replays or drops samples there (300 samples of D's session log replayed
/// from 0.3 s earlier read crossing 3 with crossing 2's accelerations, and D* came out 179 % off
/// with no word of it), or a robot thrown off its trajectory there.
fn stray_crossings(
    v: &ExperimentValues,
    exp: &Experiment,
    var: usize,
    x: &DMatrix<f64>,
) -> Vec<String> {
    let mut out = vec![];
    let planned = &exp.deltas;
    // each crossing's stray as a fraction of its planned perturbation's size
    let strays: Vec<f64> = (0..x.nrows())
        .map(|i| (x.row(i) - planned.row(i)).norm() / planned.row(i).norm())
        .collect();
    let mut sorted: Vec<f64> = strays.iter().copied().filter(|s| s.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else {
        return out;
    };
    for (i, &stray) in strays.iter().enumerate() {
        let p = planned.row(i);
        let noise_i: f64 = (v.crossings[i].state_stderr[var].iter().take(x.ncols()))
            .map(|s| s * s)
            .sum::<f64>()
            .sqrt();
        let gap = stray * p.norm();
        let odd = stray > STRAY_FRACTION && stray > STRAY_MEDIAN * median;
        if !(odd && gap > MEASURABLE * noise_i) {
            continue;
        }
        let shown = |r: nalgebra::RowDVector<f64>| {
            let cells: Vec<String> = r.iter().map(|v| format!("{v:+.3e}")).collect();
            format!("[{}]", cells.join(", "))
        };
        out.push(format!(
                "experiment '{}', crossing {i} at t = {:.4} s: the perturbation its recording shows ({}) is {stray:.2} times the planned one's size away from it (recorded {}, planned {}), where the experiment's crossings stray {median:.2} times at the median; its regression uses it as recorded: check the log there for replayed, dropped or shifted samples, or the robot thrown off its trajectory",
                v.kind.name(),
                exp.crossings[i].time + v.offset,
                v.kind.perturbation_name(),
                shown(x.row(i).into_owned()),
                shown(p.into_owned()),
            ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cosine_and_scale_are_those_of_the_vectors() {
        let planned = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let recorded = DMatrix::from_row_slice(2, 2, &[2.0, -2.0, 0.0, 0.0]);
        // (2, -2, 0, 0) against (1, 0, 0, 1): cosine 2 / (sqrt(8) sqrt(2)), scale 2 / 2
        let a = agreement(&recorded, 0.0, &planned).unwrap();
        assert!((a.cosine - 0.5).abs() < 1e-12, "{a:?}");
        assert!((a.scale - 1.0).abs() < 1e-12, "{a:?}");
        // nothing recorded: cosine 0
        let a = agreement(&DMatrix::zeros(2, 2), 0.0, &planned).unwrap();
        assert_eq!((a.cosine, a.scale), (0.0, 0.0));
        // planned perturbations within 3 noise levels (variance sum 2 / 9 or more) not judged
        assert!(agreement(&recorded, 2.0 / 9.0, &planned).is_none());
        assert!(agreement(&recorded, 0.2, &planned).is_some());
        // other shapes or numbers that are not finite are not judged
        assert!(agreement(&recorded, 0.0, &DMatrix::zeros(2, 3)).is_none());
        let mut bad = recorded.clone();
        bad[(0, 0)] = f64::NAN;
        assert!(agreement(&bad, 0.0, &planned).is_none());
    }
}
