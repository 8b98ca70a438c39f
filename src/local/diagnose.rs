//! The diagnostics of a local identification, computed from the values read at the crossings
//! and the estimates: clock offsets, velocity reversals met by the torque fits, how far the
//! unperturbed variables strayed, and the combined estimate against the separated one, with
//! the warnings that follow (see [`super::diagnostics`] for the types).

use super::diagnostics::{BlockAgreement, ClockOffset, Diagnostics, Reversal, ReversalHandling};
use super::identify::{state, ExperimentValues};
use super::model::{Estimate, Estimator};
use super::plan::ExperimentKind;

/// Each block (D, H, G) of the combined estimate against the separated one: the relative
/// difference and the largest difference in standard errors of the separated estimate. The separated
/// regressions read each matrix from its own experiment; the combined one also uses the
/// measured deviations of the variables an experiment did not perturb, where measurement noise
/// (encoder quantisation reaches qdd through two derivatives) leaks the large D* into the
/// small H* and G*.
pub(super) fn compare_combined(
    combined: &Estimate,
    separated: [&Option<Estimate>; 3],
    n: usize,
) -> Vec<BlockAgreement> {
    let mut out = vec![];
    for (b, (name, s)) in ["D", "H", "G"].into_iter().zip(separated).enumerate() {
        let Some(s) = s else { continue };
        let c = combined.matrix.columns(b * n, n);
        let diff = c - &s.matrix;
        let relative = diff.norm() / s.matrix.norm().max(f64::MIN_POSITIVE);
        let mut worst: f64 = 0.0;
        for i in 0..n {
            for j in 0..n {
                let se = s.stderr[(i, j)];
                if se.is_finite() && se > 0.0 {
                    worst = worst.max(diff[(i, j)].abs() / se);
                }
            }
        }
        out.push(BlockAgreement {
            block: name.to_string(),
            relative,
            standard_errors: worst,
        });
    }
    out
}

/// How far the variables an experiment did not perturb stray from the operating point at the
/// crossings of nominal, G, H and D, in standard errors of their measurement (RMS over
/// crossings, joints and variables): about 1 when the deviations are measurement noise, far
/// above when the robot did not follow its plan (tracking errors). `None` without such values.
pub(super) fn unperturbed_deviation(
    values: &[ExperimentValues],
    op_state: &[Vec<f64>; 3],
) -> Option<f64> {
    let (mut ss, mut count) = (0.0, 0usize);
    for v in values.iter().filter(|v| v.kind != ExperimentKind::GStatic) {
        let perturbed = v.kind.perturbed();
        for c in &v.crossings {
            for var in (0..3).filter(|&var| Some(var) != perturbed) {
                for (j, x) in state(c, var).iter().enumerate() {
                    let se = c.state_stderr[var][j];
                    let dev = x - op_state[var][j];
                    // a floor against noise-free data, where both are rounding errors
                    let se = se.max(1e-9 * (x.abs() + 1e-3));
                    if se.is_finite() {
                        ss += (dev / se).powi(2);
                        count += 1;
                    }
                }
            }
        }
    }
    (count > 0).then(|| (ss / count as f64).sqrt())
}

/// A warning when the combined estimate disagrees with the separated one beyond its noise in
/// some block (by more than half, or by more than 5 % and 10 standard errors), saying which to
/// trust: the separated one when the deviations of the unperturbed variables are measurement
/// noise (`deviation` about 1), the combined one when they are tracking errors.
pub(super) fn disagreement_warning(
    blocks: &[BlockAgreement],
    estimator: Estimator,
    deviation: Option<f64>,
) -> Option<String> {
    let bad: Vec<String> = blocks
        .iter()
        .filter(|b| b.relative > 0.5 || (b.relative > 0.05 && b.standard_errors > 10.0))
        .map(|b| {
            format!(
                "{} by {:.0} % ({:.0} standard errors)",
                b.block,
                100.0 * b.relative,
                b.standard_errors
            )
        })
        .collect();
    if bad.is_empty() {
        return None;
    }
    let deviation = deviation.unwrap_or(f64::NAN);
    let tracking = deviation > 3.0;
    let subject = match (estimator, tracking) {
        (Estimator::Combined, _) => "the model's D, H, G (estimator 'combined') disagree",
        (Estimator::Separated, true) => "the model's D, H, G (estimator 'separated') disagree",
        (Estimator::Separated, false) => "the combined estimate kept in the model disagrees",
    };
    let cause = if tracking {
        format!(
            "the robot did not follow its plan: the variables an experiment did not perturb stray from the operating point by {deviation:.0} times their measurement noise (tracking errors), which the separated regressions ignore and the combined one accounts for; trust the combined estimate (estimator 'combined')"
        )
    } else {
        format!(
            "the variables an experiment did not perturb deviate only by their measurement noise ({deviation:.1} standard errors RMS), which the combined regression takes for motion (encoder quantisation reaches qdd through two derivatives and leaks D* into the smaller H* and G*); trust the separated estimate"
        )
    };
    Some(format!(
        "{subject} with the {} regressions in {}: {cause}",
        if estimator == Estimator::Combined || !tracking {
            "separated"
        } else {
            "combined"
        },
        bad.join(", ")
    ))
}

/// The diagnostics of an identification from the values read: the offsets, the reversals
/// and a warning per experiment for the crossings whose friction step had to be modelled.
pub(super) fn diagnose(values: &[ExperimentValues]) -> Diagnostics {
    let mut d = Diagnostics::default();
    for v in values {
        d.offsets.push(ClockOffset {
            experiment: v.kind.name().to_string(),
            offset: v.offset,
        });
        let steps: Vec<&Reversal> = v
            .reversals
            .iter()
            .filter(|r| r.handling == ReversalHandling::Step)
            .collect();
        if !steps.is_empty() {
            let list: Vec<String> = steps
                .iter()
                .take(5)
                .map(|r| {
                    let at = match r.crossing {
                        Some(k) => format!("crossing {k}"),
                        None => "reference posture".into(),
                    };
                    format!("{at} joint '{}' ({:+.4} s)", r.joint, r.at)
                })
                .collect();
            let more = if steps.len() > 5 {
                format!(" and {} more", steps.len() - 5)
            } else {
                String::new()
            };
            d.warnings.push(format!(
                "experiment '{}': the velocity reverses too close to {} crossing(s) to be left out of the torque fit: {}{more}; a Coulomb step was fitted there, exact for Coulomb friction only (Stribeck or other friction that is steep near zero speed biases these values): move the operating point's speeds away from zero or use smaller perturbations",
                v.kind.name(),
                steps.len(),
                list.join(", ")
            ));
        }
        d.reversals.extend(v.reversals.iter().cloned());
    }
    d
}
