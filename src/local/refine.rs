//! The next round's plan from a round's recordings: an iterative learning update of each
//! experiment's commanded trajectory, so that a robot that tracks it with the errors it showed
//! passes the crossings themselves (docs/method.md, "Closed-loop identification").
//!
//! Per crossing (and G-static's rest postures), the commanded state moves by what the robot
//! missed it by: `commanded += planned - measured`. The crossing windows stay quadratics
//! through the commanded states at the same times; the transitions between them are the
//! quintics that join them again (C2) over the same durations, so every crossing keeps its
//! time. The plan's crossings, perturbations and windows are unchanged: identification reads
//! the same experiments.

use super::crossing_values::{CrossingValues, ExperimentValues};
use super::identify::IdentifyOptions;
use super::identify_local::read_experiments;
use super::plan::{Commanded, Experiment, ExperimentKind, Plan, StateOffset};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::trajectory::{quintic, Segment, SegmentKind, Trajectory};

/// `plan` refined by `recordings` (one per experiment, read as `options` says): every
/// experiment's trajectory commanded off its crossings by what the robot missed them by, on
/// top of earlier rounds'. With `model`, each refined trajectory is checked against its
/// limits.
///
/// Errors: what [`super::identify_local`] refuses in the recordings; a refined trajectory
/// beyond the model's limits, naming the experiment.
pub fn refine_plan(
    plan: &Plan,
    recordings: &[Recording],
    options: &IdentifyOptions,
    model: Option<&Model>,
) -> Result<Plan> {
    plan.validate()?;
    let read = read_experiments(plan, recordings, options)?;
    let mut out = plan.clone();
    for (e, v) in out.experiments.iter_mut().zip(&read.values) {
        learn(e, v);
        e.trajectory = commanded_trajectory(e);
        if let Some(model) = model {
            let context = format!("refined experiment '{}'", e.kind.name());
            let sampled = e.trajectory.sample(plan.rate);
            crate::trajectory::check_limits(
                model,
                &sampled,
                &context,
                "; the robot misses its plan by more than the limits leave room for: tune its tracking",
            )?;
        }
    }
    out.validate().map_err(|e| {
        Error::invalid(
            "refined plan",
            format!("{e}; the recordings' misses cannot be commanded away"),
        )
    })?;
    Ok(out)
}

/// Moves `e`'s commanded offsets by what the crossings `v` missed the plan by.
fn learn(e: &mut Experiment, v: &ExperimentValues) {
    let at_rest = e.kind == ExperimentKind::GStatic;
    let update = |k: Option<usize>, measured: &CrossingValues| -> StateOffset {
        let [q, qd, qdd] = e.commanded_state(k).expect("a crossing of the experiment");
        // the new commanded state, commanded + (planned - measured), less the planned one
        let step = |commanded: &[f64], measured: &[f64]| -> Vec<f64> {
            (0..commanded.len())
                .map(|j| commanded[j] - measured[j])
                .collect()
        };
        let zero = vec![0.0; q.len()];
        StateOffset {
            q: step(&q, &measured.q),
            qd: if at_rest {
                zero.clone()
            } else {
                step(&qd, &measured.qd)
            },
            qdd: if at_rest {
                zero
            } else {
                step(&qdd, &measured.qdd)
            },
        }
    };
    let crossings = (v.crossings.iter().enumerate())
        .map(|(k, c)| update(Some(k), c))
        .collect();
    let reference = v.reference.as_ref().map(|r| update(None, r));
    let rounds = e.commanded.as_ref().map_or(0, |c| c.rounds) + 1;
    e.commanded = Some(Commanded {
        crossings,
        reference,
        rounds,
    });
}

/// `e`'s trajectory through its commanded states: its windows and rests moved, the
/// transitions joining them again over their durations.
fn commanded_trajectory(e: &Experiment) -> Trajectory {
    let mut segments = e.trajectory.segments.clone();
    for s in segments.iter_mut() {
        let index = match s.kind {
            SegmentKind::Crossing { index } | SegmentKind::Dwell { index } => Some(index),
            SegmentKind::Reference => None,
            SegmentKind::Transition => continue,
        };
        let [q, qd, qdd] = e
            .commanded_state(index)
            .expect("a segment of the experiment");
        *s = Segment::quadratic(s.kind, s.t0, s.t1, s.t_ref, &q, &qd, &qdd);
    }
    let last = segments.len() - 1;
    for i in 0..segments.len() {
        if segments[i].kind != SegmentKind::Transition {
            continue;
        }
        let s = &segments[i];
        let from = if i == 0 {
            s.state(s.t0)
        } else {
            segments[i - 1].state(segments[i - 1].t1)
        };
        let to = if i == last {
            s.state(s.t1)
        } else {
            segments[i + 1].state(segments[i + 1].t0)
        };
        let duration = s.t1 - s.t0;
        let coeffs = (0..e.trajectory.n)
            .map(|j| {
                quintic(
                    from.0[j], from.1[j], from.2[j], to.0[j], to.1[j], to.2[j], duration,
                )
            })
            .collect();
        segments[i] = Segment {
            kind: SegmentKind::Transition,
            t0: s.t0,
            t1: s.t1,
            t_ref: s.t0,
            coeffs,
        };
    }
    Trajectory {
        n: e.trajectory.n,
        segments,
    }
}
