//! A plan as the files a robot's controller runs, and the recordings it logged as files beside
//! them: what `perturbid plan` and `perturbid simulate` write, and Python's `Plan.save`.

use std::path::Path;

use crate::document::Document;
use crate::error::{Error, Result};
use crate::io::OutputSet;
use crate::local::Plan;
use crate::logs::recording::Recording;
use crate::logs::recording_csv::{recording_table, samples_table};

/// The files of `plan` in folder `dir`, not yet written ([`OutputSet::commit`] writes them
/// whole or not at all): one `<experiment>.csv` per experiment (`nominal.csv`, `D.csv`, ...:
/// `t` (s), `q1..qN` (rad or m), `qd1..qN`, `qdd1..qN`, sampled at the plan's rate), in the
/// plan's order, then `plan.json`. The output set is named `plan`.
pub fn plan_files(plan: &Plan, dir: &Path) -> Result<OutputSet> {
    let mut set = OutputSet::new(dir, "plan");
    for e in &plan.experiments {
        let name = format!("{}.csv", e.kind.name());
        set.add(
            &name,
            samples_table(&e.trajectory.sample(plan.rate), "").to_csv(),
        )?;
    }
    set.add("plan.json", plan.to_json())?;
    Ok(set)
}

/// The recordings `recs` of the experiments of `plan` (one each, in the plan's order) as files
/// in folder `dir`, not yet written: `<experiment>.csv` with `t, q1..qN, [qd1..qN, qdd1..qN,]
/// tau1..tauN`. The output set is named `recordings`. Refused when the counts differ.
pub fn recording_files(plan: &Plan, recs: &[Recording], dir: &Path) -> Result<OutputSet> {
    if recs.len() != plan.experiments.len() {
        return Err(Error::invalid(
            "recordings",
            format!(
                "{} recordings for the plan's {} experiments ({}); expected one each",
                recs.len(),
                plan.experiments.len(),
                plan.kinds()
            ),
        ));
    }
    let mut set = OutputSet::new(dir, "recordings");
    for (e, r) in plan.experiments.iter().zip(recs) {
        set.add(
            &format!("{}.csv", e.kind.name()),
            recording_table(r, "").to_csv(),
        )?;
    }
    Ok(set)
}
