//! Rounds of one plan pooled into one identification: the plan and its refinements
//! ([`super::refine_plan`]) keep their crossings and perturbations and change only what is
//! commanded, so every round's passes read the same local model. Each round's recordings are
//! read against its own plan (its clock, its commanded trajectories); their crossings are then
//! joined, experiment by experiment, as the passes of one plan whose every crossing is
//! planned once a round, and identified as [`super::identify_local`] does.

use nalgebra::DMatrix;

use super::crossing_values::ExperimentValues;
use super::identify::IdentifyOptions;
use super::identify_local::{identify_read, read_experiments, ReadExperiments};
use super::model::LocalModel;
use super::plan::Plan;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// The local model from `rounds` of one plan (the first the plan, each later one a
/// refinement of it, each with one recording per experiment), their crossings pooled.
///
/// Errors: no round; a round whose plan is not the first's refined (another robot, other
/// experiments, crossings or perturbations), naming it; what [`super::identify_local`]
/// refuses in a round's recordings.
pub fn identify_local_rounds(
    rounds: &[(&Plan, &[Recording])],
    options: &IdentifyOptions,
) -> Result<LocalModel> {
    let Some(&(first, _)) = rounds.first() else {
        return Err(Error::invalid(
            "rounds",
            "no round given; expected at least one",
        ));
    };
    for (r, (plan, _)) in rounds.iter().enumerate().skip(1) {
        if let Some(why) = differs(first, plan) {
            return Err(Error::invalid(
                "rounds",
                format!(
                    "round {}: its plan is not the first round's refined ({why}); pool only the rounds of one plan",
                    r + 1
                ),
            ));
        }
    }
    let mut reads = Vec::with_capacity(rounds.len());
    for (plan, recordings) in rounds {
        reads.push(read_experiments(plan, recordings, options)?);
    }
    let pooled = pooled_plan(first, rounds.len());
    identify_read(&pooled, pool(reads), options)
}

/// What makes `plan` other than a refinement of `first`, if anything.
fn differs(first: &Plan, plan: &Plan) -> Option<String> {
    if plan.joint_names != first.joint_names || plan.robot != first.robot {
        return Some(format!(
            "robot '{}' [{}]",
            plan.robot,
            plan.joint_names.join(", ")
        ));
    }
    if plan.op != first.op {
        return Some("another operating point".into());
    }
    if plan.experiments.len() != first.experiments.len() {
        return Some(format!("experiments {}", plan.kinds()));
    }
    (first.experiments.iter().zip(&plan.experiments)).find_map(|(a, b)| {
        let same = a.kind == b.kind
            && a.crossings == b.crossings
            && a.deltas == b.deltas
            && a.reference == b.reference;
        (!same).then(|| format!("experiment '{}' has other crossings", b.kind.name()))
    })
}

/// `plan` with every experiment's crossings and perturbations planned `rounds` times over,
/// nothing commanded.
fn pooled_plan(plan: &Plan, rounds: usize) -> Plan {
    let mut out = plan.clone();
    for e in &mut out.experiments {
        let k = e.crossings.len();
        e.crossings = (e.crossings.iter().cycle().take(k * rounds).cloned()).collect();
        let deltas = e.deltas.clone();
        e.deltas = DMatrix::from_fn(k * rounds, deltas.ncols(), |i, j| deltas[(i % k, j)]);
        e.commanded = None;
    }
    out
}

/// The rounds' readings joined experiment by experiment: crossings in round order (the
/// reversals' indices moved with them); the reference posture, clock offset and grids of
/// the first round; a flat torque only where every round read the same one.
fn pool(reads: Vec<ReadExperiments>) -> ReadExperiments {
    let mut reads = reads.into_iter();
    let mut out = reads.next().expect("at least one round");
    for read in reads {
        for (i, (mine, theirs)) in out.values.iter_mut().zip(read.values).enumerate() {
            join(mine, theirs);
            let name = &read.names[i];
            out.names[i] = format!("{} + {name}", out.names[i]);
        }
        out.dropouts.extend(read.dropouts);
        out.held.extend(read.held);
        out.warnings.extend(read.warnings);
    }
    out
}

fn join(mine: &mut ExperimentValues, theirs: ExperimentValues) {
    let shift = mine.crossings.len();
    mine.reversals
        .extend(theirs.reversals.into_iter().map(|mut r| {
            r.crossing = r.crossing.map(|c| c + shift);
            r
        }));
    mine.crossings.extend(theirs.crossings);
    for (a, b) in mine.flat_torque.iter_mut().zip(&theirs.flat_torque) {
        if *a != *b {
            *a = None;
        }
    }
}
