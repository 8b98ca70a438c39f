//! How far a state lies from the operating point, measured in the perturbations the local model
//! was identified over: the region where its linear expansion was tested against torques.
//!
//! `T* + D* dqdd + H* dqd + G* dq` is the first-order expansion of the torque about the
//! operating point. The experiments perturbed `q` (G), `qd` (H) and `qdd` (D) by up to some
//! amount per joint; within those amounts the fits saw the second-order terms the model leaves
//! out (in their residuals, and in the standard errors drawn from them). Beyond them nothing did:
//! the neglected terms grow with the square of the distance, and neither the prediction nor its
//! standard error says how large they have become. A state's **reach** is its largest deviation
//! from the operating point over the joints and the three variables, each in units of the
//! largest perturbation the experiments gave that joint's variable: at most 1 within the
//! identified region.

use serde::{Deserialize, Serialize};

use super::plan::{ExperimentKind, Plan};
use crate::document::{check_bounded, invalid};
use crate::error::Result;
use crate::states::States;
use crate::torque_model::check_joints;

/// Reach past which a state counts as beyond the identified region
/// ([`Extrapolation::of`]): half again the largest perturbation, which leaves room for a
/// measured state's tracking error and noise about the planned perturbations.
pub const REACH_LIMIT: f64 = 1.5;

/// The largest perturbation the experiments gave each joint (per joint in the model's order):
/// of `q` in the G experiment (rad, or m for a prismatic joint), of `qd` in H (rad/s or m/s),
/// of `qdd` in D (rad/s^2 or m/s^2); the planned amounts, `max |delta|` over the crossings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Perturbations {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl Perturbations {
    /// The perturbations of `plan`'s G, H and D experiments; `None` when one is missing (the
    /// model does not predict then).
    pub fn of_plan(plan: &Plan) -> Option<Self> {
        let largest = |kind| {
            let e = plan.experiment(kind)?;
            Some(
                (0..e.deltas.ncols())
                    .map(|j| e.deltas.column(j).amax())
                    .collect::<Vec<f64>>(),
            )
        };
        Some(Self {
            q: largest(ExperimentKind::GDynamic)?,
            qd: largest(ExperimentKind::H)?,
            qdd: largest(ExperimentKind::D)?,
        })
    }

    /// Checks a document's perturbations (`what` names the document): one per joint of `n`,
    /// finite, `>= 0`, and no larger than any robot's motion (docs/limits.md).
    pub(crate) fn check(&self, what: &str, n: usize) -> Result<()> {
        for (field, v) in self.fields() {
            if v.len() != n {
                return Err(invalid(
                    what,
                    format!(
                        "perturbations.{field} has {} entries for {n} joints",
                        v.len()
                    ),
                ));
            }
            if let Some(j) = v.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(invalid(
                    what,
                    format!(
                        "perturbations.{field}[{j}] is {}: expected the largest perturbation (>= 0)",
                        v[j]
                    ),
                ));
            }
            check_bounded(what, "a local model", &format!("perturbations.{field}"), v)?;
        }
        Ok(())
    }

    fn fields(&self) -> [(&'static str, &[f64]); 3] {
        [("q", &self.q), ("qd", &self.qd), ("qdd", &self.qdd)]
    }
}

/// A variable's name, the states' values (row-major), the operating point's and the largest
/// perturbations (per joint).
type Variable<'a> = (&'static str, &'a [f64], &'a [f64], &'a [f64]);

/// Where a set of states leaves the identified region.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Extrapolation {
    /// States whose reach exceeds [`REACH_LIMIT`], of `states`.
    pub beyond: usize,
    pub states: usize,
    /// The largest reach (inf for a deviation where the experiments gave no perturbation).
    pub largest: f64,
    /// Where the largest reach is: the joint's name and the variable (`q`, `qd` or `qdd`), with
    /// the deviation and the largest perturbation it is measured against.
    pub joint: String,
    pub variable: String,
    pub deviation: f64,
    pub perturbation: f64,
}

impl Extrapolation {
    /// How far the `k` samples of `states` reach beyond the region the model's `perturbations`
    /// span about `op` (q*, qd*, qdd*): per state its reach (see the module), and, when some
    /// exceed [`REACH_LIMIT`], the summary; `joint_names` name the joints. Errors: states not
    /// for the model's joints.
    pub fn of(
        perturbations: &Perturbations,
        op: &super::OperatingPoint,
        joint_names: &[String],
        states: &States<'_>,
    ) -> Result<(Vec<f64>, Option<Self>)> {
        let n = joint_names.len();
        check_joints(states, n)?;
        let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
        // per variable: its name, the states' values, the operating point's, the largest perturbation
        let values: [Variable<'_>; 3] = [
            ("q", states.q(), &op.q, &perturbations.q),
            ("qd", &qd, &op.qd, &perturbations.qd),
            ("qdd", &qdd, &op.qdd, &perturbations.qdd),
        ];
        let ratio = |deviation: f64, range: f64| {
            if deviation == 0.0 {
                0.0
            } else if range > 0.0 {
                deviation / range
            } else {
                f64::INFINITY
            }
        };
        let mut reach = vec![0.0; states.len()];
        // (reach, state, variable, joint) of the largest
        let mut worst = (0.0, 0, 0, 0);
        for (s, r) in reach.iter_mut().enumerate() {
            for (v, (_, x, x0, range)) in values.iter().enumerate() {
                for j in 0..n {
                    let d = ratio((x[s * n + j] - x0[j]).abs(), range[j]);
                    // NaN cannot come: States holds finite values
                    if d > *r {
                        *r = d;
                    }
                    if d > worst.0 {
                        worst = (d, s, v, j);
                    }
                }
            }
        }
        let beyond = reach.iter().filter(|r| **r > REACH_LIMIT).count();
        let summary = (beyond > 0).then(|| {
            let (largest, s, v, j) = worst;
            let (variable, x, x0, range) = values[v];
            Self {
                beyond,
                states: states.len(),
                largest,
                joint: joint_names[j].clone(),
                variable: variable.into(),
                deviation: x[s * n + j] - x0[j],
                perturbation: range[j],
            }
        });
        Ok((reach, summary))
    }

    /// The warning: how many states, how far, where.
    pub fn message(&self) -> String {
        let unit = match self.variable.as_str() {
            "q" => "rad or m",
            "qd" => "rad/s or m/s",
            _ => "rad/s^2 or m/s^2",
        };
        let which = if self.states == 1 {
            "the state lies".to_string()
        } else {
            format!("{} of {} states lie", self.beyond, self.states)
        };
        format!(
            "{which} beyond the perturbations the local model was identified over (more than {REACH_LIMIT} times the largest; up to {:.3} times, {} of '{}' {:+.4} {unit} from the operating point, where the experiments perturbed it by up to {:.4}): there the model extrapolates its linear expansion, whose neglected second-order terms neither the prediction nor its standard error includes",
            self.largest,
            self.variable,
            self.joint,
            self.deviation,
            self.perturbation
        )
    }
}
