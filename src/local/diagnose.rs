//! The diagnostics of a local identification, computed from the values read at the crossings
//! and the estimates: clock offsets, velocity reversals met by the torque fits, how far the
//! unperturbed variables strayed, and the combined estimate against the separated one, with
//! the warnings that follow (see [`super::diagnostics`] for the types).

use super::diagnostics::{
    BlockAgreement, ClockOffset, Diagnostics, EstimatorEvidence, Reversal, ReversalHandling,
};
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
/// crossings of nominal, G, H and D, in standard errors of their measurement (the crossing's
/// and the operating point's, `op_var` its variances; RMS over crossings, joints and
/// variables): about 1 when the deviations are measurement noise, far above when the robot did
/// not follow its plan (tracking errors). `None` without such values.
pub(super) fn unperturbed_deviation(
    values: &[ExperimentValues],
    op_state: &[Vec<f64>; 3],
    op_var: &[Vec<f64>; 3],
) -> Option<f64> {
    let (mut ss, mut count) = (0.0, 0usize);
    for v in values.iter().filter(|v| v.kind != ExperimentKind::GStatic) {
        let perturbed = v.kind.perturbed();
        for c in &v.crossings {
            for var in (0..3).filter(|&var| Some(var) != perturbed) {
                for (j, x) in state(c, var).iter().enumerate() {
                    // the crossing's error and the operating point's
                    let se = (c.state_stderr[var][j].powi(2) + op_var[var][j]).sqrt();
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
/// some block (by more than half, or by more than 5 % and 10 standard errors), with advice from
/// `evidence` (which predicts the crossings left out of its fit better): to switch to the other
/// estimator where it predicts significantly better, none where neither does. None where the
/// estimator in use predicts better: the other one is the worse. `deviation` says why they
/// differ: tracking errors (far above 1) or measurement noise (about 1).
pub(super) fn disagreement_warning(
    blocks: &[BlockAgreement],
    estimator: Estimator,
    deviation: Option<f64>,
    evidence: Option<&EstimatorEvidence>,
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
    let (used, other) = match estimator {
        Estimator::Separated => ("separated", "combined"),
        Estimator::Combined => ("combined", "separated"),
    };
    let deviation = deviation.unwrap_or(f64::NAN);
    let why = if deviation > 3.0 {
        format!("the variables an experiment did not perturb stray from the operating point by {deviation:.0} times their measurement noise (tracking errors), which the separated regressions leave out and the combined one fits")
    } else {
        format!("the variables an experiment did not perturb deviate from the operating point by {deviation:.1} times their measurement noise (RMS), which the combined regression takes for motion")
    };
    let advice = match evidence {
        Some(e) => {
            let numbers = format!(
                "held-out RMS error {:.3} separated, {:.3} combined, over {} crossings, p = {:.1e}",
                e.separated, e.combined, e.crossings, e.p_value
            );
            match e.favours_combined() {
                Some(c) if c == (estimator == Estimator::Combined) => return None,
                Some(_) => format!("the {other} estimate predicts the crossings left out of its fit better ({numbers}): trust it (estimator '{other}')"),
                None => format!("neither predicts the crossings left out of its fit better ({numbers}): the data do not tell which is nearer, so count the difference as uncertainty of the model"),
            }
        }
        None => "too few crossings to tell which predicts better".to_string(),
    };
    Some(format!(
        "the model's D, H, G (estimator '{used}') disagree with the {other} estimate in {}: {why}; {advice}",
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

/// How many standard errors a departure must exceed to be warned about.
const SIGNIFICANT: f64 = 3.0;

/// The chance that noise alone makes [`mass_matrix_warning`] call a sound D* asymmetric, over
/// all its pairs.
const FALSE_ALARM: f64 = 0.01;

/// D* is a mass matrix: symmetric and positive definite. A warning when it departs from either
/// beyond its noise: pairs `D_ij`, `D_ji` that differ by more than Student's t quantile of
/// their combined standard error (the residual degrees of freedom `crossings - N`, Bonferroni
/// over the `N (N - 1) / 2` pairs, so that noise alone warns once in 1 / [`FALSE_ALARM`]; 3
/// standard errors per pair warned on a quarter of sound A465 identifications with 6 degrees
/// of freedom), and a negative eigenvalue of the symmetric part beyond [`SIGNIFICANT`] times
/// the Frobenius norm of the standard errors (which bounds how far noise moves an
/// eigenvalue). Where the rows of the joints whose diagonal entry is negative beyond
/// [`SIGNIFICANT`] standard errors, negated, leave a D* without either departure, those
/// joints' torque columns are named as logged with the opposite sign.
pub(super) fn mass_matrix_warning(d: &Estimate, joints: &[String]) -> Option<String> {
    let n = joints.len();
    let (m, se) = (&d.matrix, &d.stderr);
    let dof = d.crossings.saturating_sub(n);
    if !se.iter().all(|s| s.is_finite()) || dof == 0 {
        return None; // no standard errors: nothing to judge by
    }
    let pairs = (n * (n - 1) / 2).max(1) as f64;
    let threshold = crate::student_t::upper_quantile(FALSE_ALARM / (2.0 * pairs), dof as f64);
    let noise = se.norm();
    let (asymmetric, smallest) = departures(m, se, threshold, joints);
    let indefinite = smallest < -SIGNIFICANT * noise;
    if asymmetric.is_empty() && !indefinite {
        return None;
    }
    let negative: Vec<usize> = (0..n)
        .filter(|&j| m[(j, j)] < -SIGNIFICANT * se[(j, j)])
        .collect();
    if !negative.is_empty() {
        let mut flipped = m.clone();
        for &j in &negative {
            flipped.row_mut(j).neg_mut();
        }
        let (still, smallest) = departures(&flipped, se, threshold, joints);
        if still.is_empty() && smallest >= -SIGNIFICANT * noise {
            let named: Vec<String> = negative
                .iter()
                .map(|&j| format!("'{}' (D({0},{0}) = {:.4})", joints[j], m[(j, j)]))
                .collect();
            return Some(format!(
                "D* is no mass matrix, but its rows of joint(s) {} are a mass matrix's negated: their diagonal entries are negative, and with those rows negated D* is symmetric and positive definite within its noise; the torque column of {} is logged with the opposite sign to its position (another sign convention, in every recording or in the D experiment's): negate it where the log is read, and identify again",
                named.join(", "),
                if negative.len() == 1 { "that joint" } else { "each" }
            ));
        }
    }
    let mut parts = vec![];
    if !asymmetric.is_empty() {
        parts.push(format!(
            "not symmetric beyond {threshold:.1} standard errors, which noise passes once in {:.0} identifications ({})",
            1.0 / FALSE_ALARM,
            asymmetric.join("; ")
        ));
    }
    if indefinite {
        parts.push(format!(
            "not positive definite: smallest eigenvalue {smallest:.4} where the standard errors allow {:.4}",
            -SIGNIFICANT * noise
        ));
    }
    Some(format!(
        "D* is {}: no mass matrix is; the D experiment did not measure what the model assumes (tracking errors, a joint that slipped, unmodelled compliance), so do not trust D*",
        parts.join(" and ")
    ))
}

/// The pairs of `m` whose entries differ beyond `threshold` times their combined standard error
/// (`se`), as text naming the `joints`, and the smallest eigenvalue of its symmetric part (NaN
/// where it cannot be computed).
fn departures(
    m: &nalgebra::DMatrix<f64>,
    se: &nalgebra::DMatrix<f64>,
    threshold: f64,
    joints: &[String],
) -> (Vec<String>, f64) {
    let n = joints.len();
    let mut asymmetric = vec![];
    for i in 0..n {
        for j in (i + 1)..n {
            let diff = (m[(i, j)] - m[(j, i)]).abs();
            let bound = threshold * (se[(i, j)].powi(2) + se[(j, i)].powi(2)).sqrt();
            if diff > bound {
                asymmetric.push(format!(
                    "D({},{}) = {:.4} vs D({},{}) = {:.4}",
                    joints[i],
                    joints[j],
                    m[(i, j)],
                    joints[j],
                    joints[i],
                    m[(j, i)]
                ));
            }
        }
    }
    let symmetric = (m + m.transpose()) * 0.5;
    let smallest = crate::decomposition::symmetric_eigen(symmetric).map_or(f64::NAN, |e| {
        e.eigenvalues.iter().copied().fold(f64::INFINITY, f64::min)
    });
    (asymmetric, smallest)
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::*;

    fn estimate(m: DMatrix<f64>, se: f64) -> Estimate {
        let n = m.nrows();
        Estimate {
            matrix: m,
            stderr: DMatrix::from_element(n, n, se),
            cond: 1.0,
            residual_rms: vec![0.0; n],
            crossings: 100,
            correlation: vec![],
        }
    }

    #[test]
    fn a_d_star_no_mass_matrix_has_is_named() {
        let joints: Vec<String> = (1..=3).map(|j| format!("j{j}")).collect();
        let m = DMatrix::from_row_slice(3, 3, &[2.0, 0.3, 0.0, 0.3, 1.0, 0.1, 0.0, 0.1, 0.5]);
        // sound, and within the noise either way
        assert_eq!(
            mass_matrix_warning(&estimate(m.clone(), 0.01), &joints),
            None
        );
        let mut skew = m.clone();
        skew[(0, 2)] += 0.05; // 0.05 apart with standard errors 0.01: 3.5 sigma
        let w = mass_matrix_warning(&estimate(skew.clone(), 0.01), &joints).unwrap();
        // 97 degrees of freedom, 3 pairs: t at 1 - 0.01 / 6
        assert!(
            w.contains(
                "not symmetric beyond 3.0 standard errors, which noise passes once in 100 identifications (D(j1,j3) = 0.0500 vs D(j3,j1) = 0.0000)"
            ),
            "{w}"
        );
        assert_eq!(
            mass_matrix_warning(&estimate(skew.clone(), 0.02), &joints),
            None
        );
        // with 3 degrees of freedom the same 3.5 sigma is within the noise (t = 7.5)
        let few = Estimate {
            crossings: 6,
            ..estimate(skew, 0.01)
        };
        assert_eq!(mass_matrix_warning(&few, &joints), None);
        // an indefinite one, beyond its noise
        let mut indefinite = m.clone();
        indefinite[(2, 2)] = -0.4;
        let w = mass_matrix_warning(&estimate(indefinite.clone(), 0.01), &joints).unwrap();
        assert!(
            w.contains("not positive definite: smallest eigenvalue -0.4073"),
            "{w}"
        );
        assert_eq!(
            mass_matrix_warning(&estimate(indefinite, 0.2), &joints),
            None
        );
        // a joint's row negated (its torque column of the opposite sign) is named as such
        let mut negated = m.clone();
        negated.row_mut(1).neg_mut();
        let w = mass_matrix_warning(&estimate(negated.clone(), 0.01), &joints).unwrap();
        assert!(
            w.contains("rows of joint(s) 'j2' (D(j2,j2) = -1.0000) are a mass matrix's negated")
                && w.contains("the torque column of that joint is logged with the opposite sign"),
            "{w}"
        );
        // a negative diagonal whose row negated is still no mass matrix is not named so
        negated[(1, 0)] = 0.0;
        let w = mass_matrix_warning(&estimate(negated, 0.01), &joints).unwrap();
        assert!(w.contains("did not measure what the model assumes"), "{w}");
        // without standard errors nothing is judged
        let mut unknown = estimate(m, 0.01);
        unknown.stderr[(0, 0)] = f64::NAN;
        assert_eq!(mass_matrix_warning(&unknown, &joints), None);
    }
}
