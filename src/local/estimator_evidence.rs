//! Which estimator the data favour: the separated regressions and the combined one, each fitted
//! without a fold of the crossings, predict the torque changes of the crossings left out from
//! their measured state changes; the paired difference of their errors over every crossing of
//! the nominal, G, H and D experiments, with a p value, is the evidence the advice rests on
//! (docs/method.md, "Closed-loop identification").
//!
//! Under tracking errors the separated fits miss the motion of the variables an experiment did
//! not perturb, and predict the crossings of the other experiments worse; where those deltas are
//! measurement noise, the combined fit reads noise as motion and does no better.

use nalgebra::DMatrix;

use super::diagnostics::EstimatorEvidence;
use super::identify::{state, ExperimentValues};
use super::nominal_point::NominalPoint;
use super::plan::ExperimentKind;
use crate::regression::least_squares;

/// Folds the crossings of each experiment are dealt into.
const FOLDS: usize = 4;

/// One crossing: the variable its experiment perturbed (none for the nominal), its fold, its
/// deltas `[dq, dqd, dqdd]` from the operating point and its torque change from T*.
struct Row {
    perturbed: Option<usize>,
    fold: usize,
    deltas: [Vec<f64>; 3],
    y: Vec<f64>,
}

/// The evidence from `values` about `point`; `None` without the nominal, G, H and D
/// experiments, with too few crossings, or where a fold's fit is singular.
pub(super) fn held_out_evidence(
    values: &[ExperimentValues],
    point: &NominalPoint,
    n: usize,
) -> Option<EstimatorEvidence> {
    let find = |k: ExperimentKind| values.iter().find(|v| v.kind == k);
    let experiments = [
        (find(ExperimentKind::Nominal)?, None),
        (find(ExperimentKind::GDynamic)?, Some(0)),
        (find(ExperimentKind::H)?, Some(1)),
        (find(ExperimentKind::D)?, Some(2)),
    ];
    // every crossing: its experiment's perturbed variable, its deltas [dq dqd dqdd] and torque change
    let mut rows: Vec<Row> = vec![];
    for (v, var) in experiments {
        for (i, c) in v.crossings.iter().enumerate() {
            let deltas: [Vec<f64>; 3] = std::array::from_fn(|s| {
                (0..n).map(|j| state(c, s)[j] - point.state[s][j]).collect()
            });
            let y = (0..n).map(|j| c.tau[j] - point.torque[j]).collect();
            rows.push(Row {
                perturbed: var,
                fold: i % FOLDS,
                deltas,
                y,
            });
        }
    }
    let scale: Vec<f64> = (0..n)
        .map(|j| (rows.iter().map(|r| r.y[j].powi(2)).sum::<f64>() / rows.len() as f64).sqrt())
        .collect();
    if scale.iter().any(|s| s.is_nan() || *s <= 0.0) {
        return None;
    }
    let mut differences = vec![];
    let (mut sep_ss, mut comb_ss) = (0.0, 0.0);
    for fold in 0..FOLDS {
        let train: Vec<&Row> = rows.iter().filter(|r| r.fold != fold).collect();
        let fit = |pick: &dyn Fn(&Row) -> bool, vars: &[usize]| -> Option<DMatrix<f64>> {
            let used: Vec<_> = train.iter().filter(|r| pick(r)).collect();
            let p = vars.len() * n;
            if used.len() <= p {
                return None;
            }
            let x = DMatrix::from_fn(used.len(), p, |i, c| used[i].deltas[vars[c / n]][c % n]);
            let y = DMatrix::from_fn(used.len(), n, |i, j| used[i].y[j]);
            let names: Vec<String> = (0..p).map(|c| format!("column {c}")).collect();
            least_squares(&x, &y, "held-out fit", &names)
                .ok()
                .map(|f| f.coef)
        };
        // separated: each matrix from its own experiment; combined: all of them at once
        let separated: Vec<DMatrix<f64>> = (0..3)
            .map(|s| fit(&|r| r.perturbed == Some(s), &[s]))
            .collect::<Option<_>>()?;
        let combined = fit(&|_| true, &[0, 1, 2])?;
        for r in rows.iter().filter(|r| r.fold == fold) {
            let (mut es, mut ec) = (0.0, 0.0);
            for i in 0..n {
                let (mut ps, mut pc) = (0.0, 0.0);
                for s in 0..3 {
                    for j in 0..n {
                        ps += separated[s][(i, j)] * r.deltas[s][j];
                        pc += combined[(i, s * n + j)] * r.deltas[s][j];
                    }
                }
                es += ((r.y[i] - ps) / scale[i]).powi(2);
                ec += ((r.y[i] - pc) / scale[i]).powi(2);
            }
            sep_ss += es;
            comb_ss += ec;
            // the paired statistic: the crossing's error norms (squares are heavy-tailed)
            differences.push(es.sqrt() - ec.sqrt());
        }
    }
    let m = differences.len();
    if m < 3 {
        return None;
    }
    let mean = differences.iter().sum::<f64>() / m as f64;
    let var = differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (m - 1) as f64;
    let p_value = if var > 0.0 {
        let t = mean / (var / m as f64).sqrt();
        (2.0 * crate::student_t::upper_tail(t.abs(), (m - 1) as f64)).min(1.0)
    } else if mean == 0.0 {
        1.0
    } else {
        0.0
    };
    let rms = |ss: f64| (ss / (m * n) as f64).sqrt();
    Some(EstimatorEvidence {
        crossings: m,
        separated: rms(sep_ss),
        combined: rms(comb_ss),
        p_value,
    })
}
