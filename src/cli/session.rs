//! `perturbid split`: one log of a whole session, the plan's experiments run one after the
//! other, split into a recording per experiment for `perturbid identify`.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::refuse_overwriting_inputs;
use super::out_dir;
use crate::document::Document;
use crate::error::Result;
use crate::local::plan_files::recording_files;
use crate::local::{gaps_in_runs, repeated_runs, split_session, Plan, SplitOptions};

#[derive(Args)]
pub(crate) struct SplitArgs {
    /// The plan (plan.json) whose experiments the session ran, in the plan's order.
    plan: PathBuf,
    /// The session's log: a CSV (t, q1..qN, optional qd1..qN and qdd1..qN, tau1..tauN, or
    /// named after the joints), its time in seconds on any clock; moves and pauses of any
    /// length between the runs.
    log: PathBuf,
    /// Output folder: one <experiment>.csv per experiment on the plan's clock (`perturbid
    /// identify PLAN FOLDER` reads them).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seconds of log kept before and after each run.
    #[arg(long, default_value_t = 0.2)]
    margin: f64,
    #[command(flatten)]
    columns: super::files::ColumnArgs,
}

pub(crate) fn split(a: SplitArgs) -> Result<String> {
    let plan = Plan::load(&a.plan)?;
    let mut out = String::new();
    let log = a.columns.load(&a.log, &plan.joint_names, &mut out)?;
    let runs = split_session(&plan, &log, &SplitOptions { margin: a.margin })?;
    let mut warnings = repeated_runs(&plan, &log, &runs)?;
    warnings.extend(gaps_in_runs(&plan, &log, &runs));
    for w in warnings {
        eprintln!("perturbid: warning: {w}");
    }
    let (recordings, offsets): (Vec<_>, Vec<f64>) = runs.into_iter().unzip();
    let set = recording_files(&plan, &recordings, &out_dir(&a.out))?;
    for ((e, run), offset) in plan.experiments.iter().zip(&recordings).zip(&offsets) {
        let name = format!("{}.csv", e.kind.name());
        refuse_overwriting_inputs(&set.path_of(&name), &[a.log.as_path(), a.plan.as_path()])?;
        let _ = writeln!(
            out,
            "{:<9} from {:>10.3} s of the log, {:>7} samples -> {}",
            e.kind.name(),
            offset + e.trajectory.start(),
            run.len(),
            set.path_of(&name).display()
        );
    }
    set.commit()?;
    Ok(out)
}
