//! One case of a local-method campaign on a rehearsed robot: plan at an operating point,
//! rehearse the plan on a true robot, identify, and measure the model against the true robot's
//! own expansion ([`super::true_local`]), in units of the model's standard errors as well as
//! relative to the truth.

use nalgebra::DMatrix;

use super::true_robot::TrueRobot;
use crate::error::Result;
use crate::local::{identify_local, plan_experiments, IdentifyOptions, LocalModel, PlanOptions};
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::operating_point::OperatingPoint;

/// How one identified model compares with the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalCase {
    /// Per joint, `(T* - truth) / stderr`.
    pub torque_errors: Vec<f64>,
    /// Relative Frobenius errors of D*, H*, G* (the model's estimator).
    pub relative: [f64; 3],
    /// The same of the combined estimate's blocks (NaN without it).
    pub combined_relative: [f64; 3],
    /// Per block D, H, G, the share of entries within 3 of their standard errors.
    pub covered: [f64; 3],
    /// The largest miss of the nominal passes in `q`, `qd`, `qdd`, in perturbations.
    pub miss: [f64; 3],
    /// The same in the standard errors of their measurement (NaN without them).
    pub miss_stderr: [f64; 3],
    pub model: LocalModel,
}

/// The case: `plan_options` at `op` on `nominal`, rehearsed on `robot` with every recording's
/// clock `clock_offset` s ahead, identified with `identify_options`.
pub fn local_case(
    nominal: &Model,
    robot: &TrueRobot,
    op: &OperatingPoint,
    plan_options: &PlanOptions,
    identify_options: &IdentifyOptions,
    clock_offset: f64,
) -> Result<LocalCase> {
    let plan = plan_experiments(nominal, op, plan_options)?;
    let recordings: Vec<Recording> = super::recorded::rehearse_plan(nominal, robot, &plan)?
        .into_iter()
        .map(|mut r| {
            r.t.iter_mut().for_each(|t| *t += clock_offset);
            r
        })
        .collect();
    let model = identify_local(&plan, &recordings, identify_options)?;
    compare(nominal, robot, model)
}

/// `model` against the truth of `robot` at its planned operating point.
pub fn compare(nominal: &Model, robot: &TrueRobot, model: LocalModel) -> Result<LocalCase> {
    let truth = super::local_truth::true_local(nominal, robot, &model.planned_op)?;
    let n = model.n();
    let torque_errors = (0..n)
        .map(|j| (model.torque[j] - truth.torque[j]) / model.torque_stderr[j])
        .collect();
    let truths = [&truth.d, &truth.h, &truth.g];
    let parts = [&model.d, &model.h, &model.g];
    let rel = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).norm() / b.norm();
    let relative = std::array::from_fn(|b| {
        parts[b]
            .as_ref()
            .map_or(f64::NAN, |e| rel(&e.matrix, truths[b]))
    });
    let combined_relative = std::array::from_fn(|b| {
        (model.combined.as_ref()).map_or(f64::NAN, |c| {
            rel(&c.matrix.columns(b * n, n).into_owned(), truths[b])
        })
    });
    let covered = std::array::from_fn(|b| {
        parts[b].as_ref().map_or(f64::NAN, |e| {
            let inside = (e.matrix.iter().zip(e.stderr.iter()).zip(truths[b].iter()))
                .filter(|((x, s), t)| (*x - *t).abs() <= 3.0 * **s)
                .count();
            inside as f64 / (n * n) as f64
        })
    });
    // per variable, the largest finite magnitude
    let largest =
        |x: &[f64]| (x.iter().filter(|v| v.is_finite()).map(|v| v.abs())).reduce(f64::max);
    let (miss, miss_stderr) = match &model.miss {
        None => ([0.0; 3], [f64::NAN; 3]),
        Some(m) => {
            let sizes = [
                &m.q_perturbations,
                &m.qd_perturbations,
                &m.qdd_perturbations,
            ];
            let z = m.in_stderr();
            (
                sizes.map(|x| largest(x).unwrap_or(0.0)),
                std::array::from_fn(|v| largest(&z[v]).unwrap_or(f64::NAN)),
            )
        }
    };
    Ok(LocalCase {
        torque_errors,
        relative,
        combined_relative,
        covered,
        miss,
        miss_stderr,
        model,
    })
}
