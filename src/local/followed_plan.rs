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
/// the experiment whose plan it follows where one does.
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
